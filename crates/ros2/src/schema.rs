//! A message type resolved for decoding: every nested type found and numbered once, from
//! the definitions an MCAP file embeds (`ros2msg`) or from interface packages.
//!
//! # The `ros2msg` schema text
//!
//! MCAP's ROS 2 profile stores a channel's type as the root type's `.msg` text followed
//! by the text of every type it uses, each after a separator line of `=` characters and
//! a line `MSG: package/Type` (the format `ros2 bag record` and the `rosbags` and
//! `mcap-ros2-support` writers produce). [`Ros2MsgDefs::parse`] reads it with the one
//! `.msg` reader, [`crate::interface::parse_interface`].
//!
//! # Service events
//!
//! A recording of service introspection has topics `/<service>/_service_event` of type
//! `pkg/srv/Name_Event`. MCAP embeds that type; for a `.db3` recording, whose type names
//! come without definitions, [`Schema::resolve`] builds it from the service's `.srv`
//! definition as rosidl generates it (rosidl's `rosidl_generator_type_description`,
//! service event message): `service_msgs/ServiceEventInfo info`,
//! `Name_Request[<=1] request`, `Name_Response[<=1] response`.

use std::collections::BTreeMap;

use codegen::diag::{Diagnostics, SourceMap};

use crate::interface::{
    parse_interface, ArraySize, BaseType, Field, FieldType, InterfaceKind, MessageDef, Primitive,
};

/// Deepest nesting of message types (a deeper chain is refused).
pub const MAX_DEPTH: usize = 32;

/// Most distinct types one message may use.
const MAX_TYPES: usize = 4096;

/// A message type that cannot be resolved: its name, a definition missing or malformed,
/// or a layout past the limits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SchemaError {
    /// Not `package/Type` or `package/msg/Type`.
    TypeName(String),
    /// A type that contains itself (`package/Type`).
    ContainsItself(String),
    /// Nesting deeper than [`MAX_DEPTH`], at this type.
    TooDeep(String),
    /// More than 4096 distinct types.
    TooManyTypes,
    /// No definition of this type.
    NoDefinition(String),
    /// A `ros2msg` section after a `===` line without `MSG: package/Type`, in the schema
    /// of this root type.
    UnnamedSection(String),
    /// A `ros2msg` section that does not parse: the root type and the reader's
    /// diagnostics (each naming the section and line).
    Definition {
        /// The root type whose schema text it is.
        root: String,
        /// What is wrong, where.
        diagnostics: Diagnostics,
    },
}

impl std::fmt::Display for SchemaError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SchemaError::TypeName(t) => write!(
                f,
                "`{t}` is not a ROS type name (expected `package/msg/Type`)"
            ),
            SchemaError::ContainsItself(t) => write!(
                f,
                "message `{t}` contains itself, so it has no finite layout"
            ),
            SchemaError::TooDeep(t) => {
                write!(f, "messages nest deeper than {MAX_DEPTH} levels at `{t}`")
            }
            SchemaError::TooManyTypes => {
                write!(f, "the message uses more than {MAX_TYPES} types")
            }
            SchemaError::NoDefinition(t) => write!(f, "no definition of message type `{t}`"),
            SchemaError::UnnamedSection(root) => write!(
                f,
                "schema of `{root}`: a section after a `===` line has no `MSG: package/Type` line"
            ),
            SchemaError::Definition { diagnostics, .. } => write!(f, "{diagnostics}"),
        }
    }
}

impl std::error::Error for SchemaError {}

/// Where message definitions come from.
pub trait Definitions {
    /// The definition of message `package/name` (`name` without `msg/`).
    fn message(&self, package: &str, name: &str) -> Option<MessageDef>;
    /// The request and response of service `package/name`.
    fn service(&self, package: &str, name: &str) -> Option<(MessageDef, MessageDef)> {
        let _ = (package, name);
        None
    }
}

/// The element type of a resolved field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Elem {
    /// A primitive.
    Prim(Primitive),
    /// A message: an index into [`Schema::types`].
    Msg(usize),
}

/// One field of a resolved message type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SField {
    /// The field's name.
    pub name: String,
    /// Its element type.
    pub elem: Elem,
    /// Whether and how it is an array.
    pub array: ArraySize,
    /// The bound of a bounded string.
    pub string_bound: Option<u32>,
}

/// A resolved message type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SType {
    /// `package/Type`.
    pub name: String,
    /// The fields, in order. An empty message has rosidl's one `uint8` placeholder.
    pub fields: Vec<SField>,
}

/// A message type with every type it uses, ready to decode.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Schema {
    /// Every type, the root first.
    pub types: Vec<SType>,
}

impl Schema {
    /// The root type.
    pub fn root(&self) -> &SType {
        &self.types[0]
    }

    /// Resolves `type_name` (`pkg/Type`, `pkg/msg/Type`, `pkg/srv/Name_Event` ...) and every
    /// type it uses from `defs`.
    pub fn resolve(type_name: &str, defs: &dyn Definitions) -> Result<Schema, SchemaError> {
        let (pkg, name) = split_type_name(type_name)?;
        let mut b = Builder {
            defs,
            types: Vec::new(),
            index: BTreeMap::new(),
        };
        b.add(&pkg, &name, 0)?;
        Ok(Schema { types: b.types })
    }
}

impl Schema {
    /// The type in MCAP's `ros2msg` format (see the module docs): the root's fields, then
    /// every type it uses after a separator line and `MSG: package/Type`. What
    /// `monitor --ros2 --record` embeds, so any MCAP reader can decode the messages.
    /// Constants and default values are not kept (a decoder needs neither).
    pub fn ros2msg_text(&self) -> String {
        let mut out = String::new();
        for (i, t) in self.types.iter().enumerate() {
            if i > 0 {
                out.push_str(&"=".repeat(80));
                out.push_str("\nMSG: ");
                out.push_str(&t.name);
                out.push('\n');
            }
            for f in &t.fields {
                match f.elem {
                    Elem::Prim(p) => {
                        out.push_str(p.msg_name());
                        if let Some(n) = f.string_bound {
                            out.push_str(&format!("<={n}"));
                        }
                    }
                    Elem::Msg(m) => out.push_str(&self.types[m].name),
                }
                match f.array {
                    ArraySize::Scalar => {}
                    ArraySize::Fixed(n) => out.push_str(&format!("[{n}]")),
                    ArraySize::Bounded(n) => out.push_str(&format!("[<={n}]")),
                    ArraySize::Unbounded => out.push_str("[]"),
                }
                out.push(' ');
                out.push_str(&f.name);
                out.push('\n');
            }
        }
        out
    }
}

/// `pkg/Type` or `pkg/msg/Type` (also `srv`, `action`) -> `(pkg, Type)`.
pub fn split_type_name(type_name: &str) -> Result<(String, String), SchemaError> {
    let parts: Vec<&str> = type_name.trim().split('/').collect();
    match parts.as_slice() {
        [p, n] | [p, "msg" | "srv" | "action", n] if !p.is_empty() && !n.is_empty() => {
            Ok((p.to_string(), n.to_string()))
        }
        _ => Err(SchemaError::TypeName(type_name.to_string())),
    }
}

struct Builder<'a> {
    defs: &'a dyn Definitions,
    types: Vec<SType>,
    /// `(pkg, name)` -> index; `usize::MAX` while the type is being built (a cycle).
    index: BTreeMap<(String, String), usize>,
}

impl Builder<'_> {
    fn add(&mut self, pkg: &str, name: &str, depth: usize) -> Result<usize, SchemaError> {
        let key = (pkg.to_string(), name.to_string());
        match self.index.get(&key) {
            Some(&usize::MAX) => return Err(SchemaError::ContainsItself(format!("{pkg}/{name}"))),
            Some(&i) => return Ok(i),
            None => {}
        }
        if depth > MAX_DEPTH {
            return Err(SchemaError::TooDeep(format!("{pkg}/{name}")));
        }
        if self.types.len() >= MAX_TYPES {
            return Err(SchemaError::TooManyTypes);
        }
        let def = self.lookup(pkg, name)?;
        let at = self.types.len();
        self.types.push(SType {
            name: format!("{pkg}/{name}"),
            fields: Vec::new(),
        });
        self.index.insert(key.clone(), usize::MAX);
        let mut fields = Vec::with_capacity(def.fields.len().max(1));
        for f in &def.fields {
            let (elem, string_bound) = match &f.ty.base {
                BaseType::Primitive { prim, string_bound } => (Elem::Prim(*prim), *string_bound),
                BaseType::Message { package, name } => {
                    (Elem::Msg(self.add(package, name, depth + 1)?), None)
                }
            };
            fields.push(SField {
                name: f.name.clone(),
                elem,
                array: f.ty.array,
                string_bound,
            });
        }
        if fields.is_empty() {
            // rosidl gives an empty message one member (C and C++ have no empty struct);
            // it is serialised as one byte.
            fields.push(SField {
                name: "structure_needs_at_least_one_member".into(),
                elem: Elem::Prim(Primitive::UInt8),
                array: ArraySize::Scalar,
                string_bound: None,
            });
        }
        self.types[at].fields = fields;
        self.index.insert(key, at);
        Ok(at)
    }

    fn lookup(&self, pkg: &str, name: &str) -> Result<MessageDef, SchemaError> {
        if let Some(d) = self.defs.message(pkg, name) {
            return Ok(d);
        }
        // The parts rosidl generates for a service: `Name_Request`, `Name_Response`,
        // `Name_Event`.
        for (suffix, part) in [("_Request", 0), ("_Response", 1), ("_Event", 2)] {
            let Some(srv) = name.strip_suffix(suffix) else {
                continue;
            };
            if let Some((req, resp)) = self.defs.service(pkg, srv) {
                return Ok(match part {
                    0 => req,
                    1 => resp,
                    _ => event_def(pkg, srv),
                });
            }
        }
        Err(SchemaError::NoDefinition(format!("{pkg}/{name}")))
    }
}

/// `Name_Event` of service `pkg/Name`, as rosidl generates it.
fn event_def(pkg: &str, srv: &str) -> MessageDef {
    let field = |name: &str, package: &str, ty: String, array| Field {
        name: name.into(),
        ty: FieldType {
            base: BaseType::Message {
                package: package.into(),
                name: ty,
            },
            array,
        },
        default: None,
        span: codegen::diag::FileId(0).at(0),
    };
    MessageDef {
        fields: vec![
            field(
                "info",
                "service_msgs",
                "ServiceEventInfo".into(),
                ArraySize::Scalar,
            ),
            field(
                "request",
                pkg,
                format!("{srv}_Request"),
                ArraySize::Bounded(1),
            ),
            field(
                "response",
                pkg,
                format!("{srv}_Response"),
                ArraySize::Bounded(1),
            ),
        ],
        constants: Vec::new(),
    }
}

/// The definitions of one `ros2msg` schema text, by `(package, name)`.
#[derive(Clone, Debug, Default)]
pub struct Ros2MsgDefs {
    defs: BTreeMap<(String, String), MessageDef>,
}

impl Ros2MsgDefs {
    /// Reads the `ros2msg` text of root type `type_name`. Errors name the section
    /// (`MSG: pkg/Type`) and line of the text.
    pub fn parse(type_name: &str, text: &str) -> Result<Ros2MsgDefs, SchemaError> {
        let (root_pkg, root_name) = split_type_name(type_name)?;
        let mut sections: Vec<(String, String, String)> =
            vec![(root_pkg, root_name, String::new())];
        for line in text.lines() {
            let t = line.trim();
            if t.len() >= 3 && t.bytes().all(|b| b == b'=') {
                sections.push((String::new(), String::new(), String::new()));
                continue;
            }
            let last = sections.last_mut().expect("one section");
            if let Some(name) = t.strip_prefix("MSG:") {
                if last.1.is_empty() {
                    let (p, n) = split_type_name(name.trim())?;
                    last.0 = p;
                    last.1 = n;
                    continue;
                }
            }
            last.2.push_str(line);
            last.2.push('\n');
        }
        let mut out = Ros2MsgDefs::default();
        let mut sm = SourceMap::new();
        for (pkg, name, body) in sections {
            if name.is_empty() {
                if body.trim().is_empty() {
                    continue;
                }
                return Err(SchemaError::UnnamedSection(type_name.to_string()));
            }
            let file = sm.add(format!("<schema of {type_name}: {pkg}/{name}>"), body);
            let def = parse_interface(&sm, file, &pkg, &name, InterfaceKind::Message).map_err(
                |errs| SchemaError::Definition {
                    root: type_name.to_string(),
                    diagnostics: Diagnostics(errs),
                },
            )?;
            let part = def.parts.into_iter().next().unwrap_or_default();
            out.defs.insert((pkg, name), part);
        }
        Ok(out)
    }
}

impl Definitions for Ros2MsgDefs {
    fn message(&self, package: &str, name: &str) -> Option<MessageDef> {
        self.defs
            .get(&(package.to_string(), name.to_string()))
            .cloned()
    }
}

/// The built-in interface packages ([`crate::interface::builtin`]) as [`Definitions`].
#[derive(Clone, Debug)]
pub struct BuiltinDefs {
    defs: BTreeMap<(String, InterfaceKind, String), Vec<MessageDef>>,
}

impl BuiltinDefs {
    /// Every built-in definition.
    pub fn new() -> BuiltinDefs {
        let defs = crate::interface::builtin::definitions()
            .into_iter()
            .map(|d| ((d.package, d.kind, d.name), d.parts))
            .collect();
        BuiltinDefs { defs }
    }
}

impl Default for BuiltinDefs {
    fn default() -> Self {
        Self::new()
    }
}

impl Definitions for BuiltinDefs {
    fn message(&self, package: &str, name: &str) -> Option<MessageDef> {
        self.defs
            .get(&(package.into(), InterfaceKind::Message, name.into()))
            .and_then(|p| p.first().cloned())
    }

    fn service(&self, package: &str, name: &str) -> Option<(MessageDef, MessageDef)> {
        let parts = self
            .defs
            .get(&(package.into(), InterfaceKind::Service, name.into()))?;
        Some((parts.first()?.clone(), parts.get(1)?.clone()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_ros2msg_text_with_dependencies() {
        let text = "std_msgs/Header header\nfloat32 voltage\nfloat32[] cell_voltage\n\
                    ================================================================================\n\
                    MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\
                    ================================================================================\n\
                    MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
        let defs = Ros2MsgDefs::parse("p/msg/B", text).unwrap();
        let s = Schema::resolve("p/msg/B", &defs).unwrap();
        assert_eq!(s.types.len(), 3);
        assert_eq!(s.root().fields[1].name, "voltage");
        assert_eq!(s.root().fields[0].elem, Elem::Msg(1));
        assert_eq!(s.types[2].name, "builtin_interfaces/Time");
    }

    #[test]
    fn ros2msg_text_reads_back_as_the_same_schema() {
        let s = Schema::resolve("sensor_msgs/msg/BatteryState", &BuiltinDefs::new()).unwrap();
        let text = s.ros2msg_text();
        assert!(
            text.starts_with("std_msgs/Header header\nfloat32 voltage\n"),
            "{text}"
        );
        assert!(text.contains("\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"));
        let back = Ros2MsgDefs::parse("sensor_msgs/msg/BatteryState", &text).unwrap();
        assert_eq!(
            Schema::resolve("sensor_msgs/msg/BatteryState", &back).unwrap(),
            s
        );
    }

    #[test]
    fn a_missing_dependency_and_a_cycle_are_errors() {
        let defs = Ros2MsgDefs::parse("p/A", "q/B b\n").unwrap();
        assert!(matches!(
            Schema::resolve("p/A", &defs).unwrap_err(),
            SchemaError::NoDefinition(t) if t == "q/B"
        ));
        let defs = Ros2MsgDefs::parse("p/A", "B b\n===\nMSG: p/B\nA a\n").unwrap();
        let e = Schema::resolve("p/A", &defs).unwrap_err();
        assert!(
            matches!(&e, SchemaError::ContainsItself(t) if t == "p/A"),
            "{e}"
        );
        assert!(e.to_string().contains("contains itself"));
    }

    #[test]
    fn service_events_are_built_from_the_srv() {
        let s = Schema::resolve(
            "example_interfaces/srv/AddTwoInts_Event",
            &BuiltinDefs::new(),
        )
        .unwrap();
        let names: Vec<&str> = s.root().fields.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["info", "request", "response"]);
        assert_eq!(s.root().fields[1].array, ArraySize::Bounded(1));
        let empty = Schema::resolve("std_msgs/msg/Empty", &BuiltinDefs::new()).unwrap();
        assert_eq!(empty.root().fields.len(), 1);
    }
}
