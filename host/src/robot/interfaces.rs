//! ROS 2 interface definitions (`.msg`, `.srv`, `.action`): read with positions, the standard
//! packages built in, and flattened into the leaf fields the ROS lowering sends.
//!
//! # Main types
//!
//! - [`InterfaceDef`]: one parsed interface file: its package, name, kind and its parts
//!   (one for a message, request/response for a service, goal/result/feedback for an
//!   action), each a [`MessageDef`] of [`Field`]s and [`Constant`]s.
//! - [`Interfaces`]: every known interface, from [`Interfaces::with_builtins`] (our own text
//!   for std_msgs, std_srvs, example_interfaces, action_msgs, builtin_interfaces,
//!   unique_identifier_msgs and common geometry_msgs) plus the packages found beside a model
//!   by [`Interfaces::discover`]. It implements [`InterfaceLookup`].
//!
//! # The file format
//!
//! One field or constant a line, `#` starts a comment (outside quotes), `---` separates the
//! parts of a service (2 parts) or an action (3 parts):
//!
//! ```text
//! int8 MODE_FAST=1                 # a constant
//! int32 count 5                    # a field with a default value
//! string<=10 name "robot"          # a bounded string
//! float64[3] xyz [0.0, 1.0, 2.0]   # a fixed array
//! int32[<=5] few                   # a bounded array
//! geometry_msgs/Point[] points     # an unbounded array of another package's messages
//! Internal inner                   # a message of the same package
//! ```
//!
//! # Flattening
//!
//! A nested message becomes its leaf fields, with paths `inner.i`, `inner.text` (AS2FM's
//! `ros_fields__inner__i`). An array of messages becomes one array per leaf field (a
//! struct of arrays, as AS2FM lowers arrays of data structs): `Internal[] i_arr` gives
//! `i_arr.i: int32[]` and `i_arr.text: string[]`; array dimensions are written outermost
//! first (`Polygon[] p` of `Point[] points` of `float64 x` gives `p.points.x: float64[][]`).
//!
//! Types are spelled as the SCXML reader reads them: ROS's primitive names (`int8` ...
//! `uint64`, `float32`, `float64`, `bool`, `string`); `byte` and `char` become `uint8`,
//! `wstring` becomes `string`, `string<=N` becomes `string`; a fixed array `T[3]` is `T[3]`,
//! a bounded one `T[<=5]` is `T[5]` (a maximum length), an unbounded one `T[]`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::types::{ActionFields, FlatField, InterfaceLookup, ServiceFields};
use crate::model::source::{Diagnostic, FileId, SourceMap, Span};

/// Deepest nesting of messages followed when flattening (a deeper chain is a cycle).
const MAX_NESTING: usize = 32;

/// Most leaf fields one flattened message may have.
const MAX_LEAVES: usize = 10_000;

/// Largest fixed array length accepted (its default literal is written out in full).
const MAX_FIXED_LEN: u32 = 4096;

/// What an interface file defines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum InterfaceKind {
    /// A `.msg` file in `msg/`.
    Message,
    /// A `.srv` file in `srv/`: request and response.
    Service,
    /// An `.action` file in `action/`: goal, result and feedback.
    Action,
}

impl InterfaceKind {
    /// The folder name and the middle word of a full type name: `msg`, `srv`, `action`.
    pub fn dir(self) -> &'static str {
        match self {
            InterfaceKind::Message => "msg",
            InterfaceKind::Service => "srv",
            InterfaceKind::Action => "action",
        }
    }

    /// The kind whose folder (or middle word) is `s`.
    pub fn from_dir(s: &str) -> Option<InterfaceKind> {
        match s {
            "msg" => Some(InterfaceKind::Message),
            "srv" => Some(InterfaceKind::Service),
            "action" => Some(InterfaceKind::Action),
            _ => None,
        }
    }

    /// How many `---`-separated parts a file of this kind has.
    pub fn parts(self) -> usize {
        match self {
            InterfaceKind::Message => 1,
            InterfaceKind::Service => 2,
            InterfaceKind::Action => 3,
        }
    }

    fn noun(self) -> &'static str {
        match self {
            InterfaceKind::Message => "message",
            InterfaceKind::Service => "service",
            InterfaceKind::Action => "action",
        }
    }
}

/// A ROS 2 primitive type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primitive {
    /// `bool`.
    Bool,
    /// `byte` (an octet, read as `uint8`).
    Byte,
    /// `char` (read as `uint8`).
    Char,
    /// `float32`.
    Float32,
    /// `float64`.
    Float64,
    /// `int8`.
    Int8,
    /// `uint8`.
    UInt8,
    /// `int16`.
    Int16,
    /// `uint16`.
    UInt16,
    /// `int32`.
    Int32,
    /// `uint32`.
    UInt32,
    /// `int64`.
    Int64,
    /// `uint64`.
    UInt64,
    /// `string`.
    String,
    /// `wstring` (read as `string`).
    WString,
}

impl Primitive {
    /// The primitive called `name` in a `.msg` file.
    pub fn from_name(name: &str) -> Option<Primitive> {
        Some(match name {
            "bool" => Primitive::Bool,
            "byte" => Primitive::Byte,
            "char" => Primitive::Char,
            "float32" => Primitive::Float32,
            "float64" => Primitive::Float64,
            "int8" => Primitive::Int8,
            "uint8" => Primitive::UInt8,
            "int16" => Primitive::Int16,
            "uint16" => Primitive::UInt16,
            "int32" => Primitive::Int32,
            "uint32" => Primitive::UInt32,
            "int64" => Primitive::Int64,
            "uint64" => Primitive::UInt64,
            "string" => Primitive::String,
            "wstring" => Primitive::WString,
            _ => return None,
        })
    }

    /// The type as the SCXML reader spells it (`byte`/`char` -> `uint8`, `wstring` -> `string`).
    pub fn scxml_name(self) -> &'static str {
        match self {
            Primitive::Bool => "bool",
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => "uint8",
            Primitive::Float32 => "float32",
            Primitive::Float64 => "float64",
            Primitive::Int8 => "int8",
            Primitive::Int16 => "int16",
            Primitive::UInt16 => "uint16",
            Primitive::Int32 => "int32",
            Primitive::UInt32 => "uint32",
            Primitive::Int64 => "int64",
            Primitive::UInt64 => "uint64",
            Primitive::String | Primitive::WString => "string",
        }
    }

    /// The value of an unset field of this type, as an ECMAScript literal.
    pub fn zero(self) -> &'static str {
        match self {
            Primitive::Bool => "false",
            Primitive::Float32 | Primitive::Float64 => "0.0",
            Primitive::String | Primitive::WString => "''",
            _ => "0",
        }
    }

    fn is_string(self) -> bool {
        matches!(self, Primitive::String | Primitive::WString)
    }

    /// Inclusive range of an integer type.
    fn int_range(self) -> Option<(i128, i128)> {
        Some(match self {
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => (0, u8::MAX as i128),
            Primitive::Int8 => (i8::MIN as i128, i8::MAX as i128),
            Primitive::Int16 => (i16::MIN as i128, i16::MAX as i128),
            Primitive::UInt16 => (0, u16::MAX as i128),
            Primitive::Int32 => (i32::MIN as i128, i32::MAX as i128),
            Primitive::UInt32 => (0, u32::MAX as i128),
            Primitive::Int64 => (i64::MIN as i128, i64::MAX as i128),
            Primitive::UInt64 => (0, u64::MAX as i128),
            _ => return None,
        })
    }
}

/// The element type of a field: a primitive or another message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BaseType {
    /// A primitive; `string_bound` is `N` of `string<=N`.
    Primitive {
        /// The primitive.
        prim: Primitive,
        /// The bound of a bounded string.
        string_bound: Option<u32>,
    },
    /// A message, with its package resolved (`Internal` in package `p` is `p/Internal`).
    Message {
        /// The package.
        package: String,
        /// The message name.
        name: String,
    },
}

/// Whether and how a field is an array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArraySize {
    /// Not an array.
    Scalar,
    /// `T[N]`: exactly `N` elements.
    Fixed(u32),
    /// `T[<=N]`: at most `N` elements.
    Bounded(u32),
    /// `T[]`.
    Unbounded,
}

/// A field's type: element type and array size.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldType {
    /// The element type.
    pub base: BaseType,
    /// The array size.
    pub array: ArraySize,
}

/// One field of a message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// The field name.
    pub name: String,
    /// The field type.
    pub ty: FieldType,
    /// The default value written after the name, as an ECMAScript literal.
    pub default: Option<String>,
    /// Where the type token starts.
    pub span: Span,
}

/// A constant (`int8 FAST=1`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Constant {
    /// The constant's name.
    pub name: String,
    /// Its primitive type.
    pub prim: Primitive,
    /// Its value as an ECMAScript literal.
    pub value: String,
    /// Where the line starts.
    pub span: Span,
}

/// One message, or one part of a service or an action.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MessageDef {
    /// Fields in declaration order.
    pub fields: Vec<Field>,
    /// Constants in declaration order.
    pub constants: Vec<Constant>,
}

/// One interface file, parsed.
///
/// Invariant: `parts.len() == kind.parts()`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InterfaceDef {
    /// The package (`std_msgs`).
    pub package: String,
    /// The type name (`Int32`).
    pub name: String,
    /// Message, service or action.
    pub kind: InterfaceKind,
    /// The parts: `[message]`, `[request, response]` or `[goal, result, feedback]`.
    pub parts: Vec<MessageDef>,
    /// The file it was read from; `None` for a built-in definition.
    pub file: Option<FileId>,
}

impl InterfaceDef {
    /// The full name, `pkg/msg/Type`.
    pub fn full_name(&self) -> String {
        format!("{}/{}/{}", self.package, self.kind.dir(), self.name)
    }
}

impl Primitive {
    /// The name as written in a `.msg` file.
    pub fn msg_name(self) -> &'static str {
        match self {
            Primitive::Byte => "byte",
            Primitive::Char => "char",
            Primitive::WString => "wstring",
            Primitive::String => "string",
            other => other.scxml_name(),
        }
    }
}

impl std::fmt::Display for FieldType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.base {
            BaseType::Primitive { prim, string_bound } => {
                write!(f, "{}", prim.msg_name())?;
                if let Some(n) = string_bound {
                    write!(f, "<={n}")?;
                }
            }
            BaseType::Message { package, name } => write!(f, "{package}/{name}")?,
        }
        match self.array {
            ArraySize::Scalar => Ok(()),
            ArraySize::Fixed(n) => write!(f, "[{n}]"),
            ArraySize::Bounded(n) => write!(f, "[<={n}]"),
            ArraySize::Unbounded => write!(f, "[]"),
        }
    }
}

/// The definition in the `.msg`/`.srv`/`.action` format, normalised: constants first, types
/// with their package, defaults as ECMAScript literals. Reading it back gives the same
/// definition.
impl std::fmt::Display for InterfaceDef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, part) in self.parts.iter().enumerate() {
            if i > 0 {
                writeln!(f, "---")?;
            }
            for c in &part.constants {
                writeln!(f, "{} {}={}", c.prim.msg_name(), c.name, c.value)?;
            }
            for fl in &part.fields {
                match &fl.default {
                    Some(d) => writeln!(f, "{} {} {d}", fl.ty, fl.name)?,
                    None => writeln!(f, "{} {}", fl.ty, fl.name)?,
                }
            }
        }
        Ok(())
    }
}

/// Parses the text of interface file `file` (already in `sm`) as `package/kind/name`.
///
/// Message types named without a package are looked for in `package`. Whether the named
/// types exist is checked later, by [`Interfaces::check`].
pub fn parse_interface(
    sm: &SourceMap,
    file: FileId,
    package: &str,
    name: &str,
    kind: InterfaceKind,
) -> Result<InterfaceDef, Vec<Diagnostic>> {
    let Some(src) = sm.file(file) else {
        return Err(vec![Diagnostic::file(
            "<unknown>",
            "internal error: interface file not in the source map",
        )]);
    };
    let text = src.text();
    let at = |offset: usize| Span {
        file,
        offset: offset as u32,
    };
    let mut errs = Vec::new();
    let mut parts = vec![MessageDef::default()];
    // A byte-order mark is not part of the first line.
    let mut line_start = if text.starts_with('\u{feff}') { 3 } else { 0 };
    for raw_line in text[line_start..].split_inclusive('\n') {
        let start = line_start;
        line_start += raw_line.len();
        let line = strip_comment(raw_line.trim_end_matches(['\n', '\r']));
        let trimmed = line.trim();
        if trimmed.is_empty() {
            continue;
        }
        let indent = line.len() - line.trim_start().len();
        let line_span = at(start + indent);
        if trimmed == "---" {
            if parts.len() >= kind.parts() {
                errs.push(sm.diag(
                    line_span,
                    format!(
                        "too many `---` separators: a {} has {} part{}",
                        kind.noun(),
                        kind.parts(),
                        if kind.parts() == 1 { "" } else { "s" }
                    ),
                ));
            } else {
                parts.push(MessageDef::default());
            }
            continue;
        }
        match parse_line(trimmed, start + indent, package) {
            Ok(Item::Field(mut f)) => {
                f.span = at(f.span.offset as usize);
                let part = parts.last_mut().expect("at least one part");
                if part.fields.iter().any(|g| g.name == f.name)
                    || part.constants.iter().any(|c| c.name == f.name)
                {
                    errs.push(sm.diag(line_span, format!("`{}` is declared twice", f.name)));
                } else {
                    part.fields.push(f);
                }
            }
            Ok(Item::Constant(mut c)) => {
                c.span = line_span;
                let part = parts.last_mut().expect("at least one part");
                if part.fields.iter().any(|g| g.name == c.name)
                    || part.constants.iter().any(|d| d.name == c.name)
                {
                    errs.push(sm.diag(line_span, format!("`{}` is declared twice", c.name)));
                } else {
                    part.constants.push(c);
                }
            }
            Err((offset, msg)) => errs.push(sm.diag(at(offset), msg)),
        }
    }
    if parts.len() < kind.parts() && errs.is_empty() {
        let end = at(text.len());
        errs.push(sm.diag(
            end,
            format!(
                "a {} needs {} parts separated by `---`, found {}",
                kind.noun(),
                kind.parts(),
                parts.len()
            ),
        ));
    }
    if errs.is_empty() {
        Ok(InterfaceDef {
            package: package.to_string(),
            name: name.to_string(),
            kind,
            parts,
            file: Some(file),
        })
    } else {
        Err(errs)
    }
}

/// The line without its comment (a `#` outside quotes starts one).
fn strip_comment(line: &str) -> &str {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        if escaped {
            escaped = false;
            continue;
        }
        match (quote, c) {
            (Some(_), '\\') => escaped = true,
            (Some(q), c) if c == q => quote = None,
            (None, '"') | (None, '\'') => quote = Some(c),
            (None, '#') => return &line[..i],
            _ => {}
        }
    }
    line
}

enum Item {
    Field(Field),
    Constant(Constant),
}

type LineError = (usize, String);

/// Parses one non-empty, comment-free, trimmed line that starts at byte `base` of the file.
/// Spans in the result hold absolute offsets with a placeholder file.
fn parse_line(line: &str, base: usize, package: &str) -> Result<Item, LineError> {
    let ty_end = line.find(char::is_whitespace).unwrap_or(line.len());
    let ty_text = &line[..ty_end];
    let rest_full = &line[ty_end..];
    let rest = rest_full.trim_start();
    let name_off = base + ty_end + (rest_full.len() - rest.len());
    if rest.is_empty() {
        return Err((
            base + ty_end,
            format!("expected a field name after the type `{ty_text}`"),
        ));
    }
    let ty = parse_type(ty_text, base, package)?;
    let name_end = rest
        .find(|c: char| c.is_whitespace() || c == '=')
        .unwrap_or(rest.len());
    let name = &rest[..name_end];
    let after = rest[name_end..].trim_start();
    let after_off = name_off + name_end + (rest[name_end..].len() - after.len());
    if name.is_empty() {
        return Err((name_off, "expected a field or constant name".into()));
    }
    if let Some(value) = after.strip_prefix('=') {
        // A constant.
        if !valid_constant_name(name) {
            return Err((
                name_off,
                format!("`{name}` is not a valid constant name (upper-case letters, digits and `_`, starting with a letter)"),
            ));
        }
        let prim = match (&ty.base, ty.array) {
            (BaseType::Primitive { prim, .. }, ArraySize::Scalar) => *prim,
            _ => {
                return Err((
                    base,
                    "a constant must have a primitive, non-array type".into(),
                ))
            }
        };
        let v = value.trim();
        let v_off = after_off + 1 + (value.len() - value.trim_start().len());
        if v.is_empty() {
            return Err((after_off, format!("constant `{name}` has no value")));
        }
        let value = parse_scalar(prim, string_bound(&ty), v, v_off, true)?;
        return Ok(Item::Constant(Constant {
            name: name.to_string(),
            prim,
            value,
            span: placeholder(base),
        }));
    }
    if !valid_field_name(name) {
        return Err((
            name_off,
            format!(
                "`{name}` is not a valid field name (lower-case letters, digits and single `_`, starting with a letter)"
            ),
        ));
    }
    let default = if after.is_empty() {
        None
    } else {
        Some(parse_default(&ty, after, after_off)?)
    };
    Ok(Item::Field(Field {
        name: name.to_string(),
        ty,
        default,
        span: placeholder(base),
    }))
}

fn placeholder(offset: usize) -> Span {
    Span {
        file: FileId(0),
        offset: offset as u32,
    }
}

fn string_bound(ty: &FieldType) -> Option<u32> {
    match ty.base {
        BaseType::Primitive { string_bound, .. } => string_bound,
        BaseType::Message { .. } => None,
    }
}

/// `[a-z][a-z0-9_]*`, no `__`, no trailing `_` (ROS 2's rule; `__` would also clash with the
/// flattened names).
fn valid_field_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !name.contains("__")
        && !name.ends_with('_')
}

fn valid_constant_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_uppercase())
        && name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

fn valid_type_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_uppercase())
        && name.chars().all(|c| c.is_ascii_alphanumeric())
}

fn valid_package_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Parses a type token (`int32`, `string<=5[<=3]`, `pkg/Type[4]`) starting at byte `base`.
fn parse_type(text: &str, base: usize, package: &str) -> Result<FieldType, LineError> {
    let (elem, array_text, array_off) = match text.find('[') {
        Some(i) => (&text[..i], &text[i..], base + i),
        None => (text, "", base + text.len()),
    };
    let array = if array_text.is_empty() {
        ArraySize::Scalar
    } else {
        let Some(inner) = array_text
            .strip_prefix('[')
            .and_then(|s| s.strip_suffix(']'))
        else {
            return Err((
                array_off,
                format!("malformed array size `{array_text}` (expected `[]`, `[N]` or `[<=N]`)"),
            ));
        };
        if inner.contains('[') || inner.contains(']') {
            return Err((array_off, "arrays of arrays are not allowed".into()));
        }
        if inner.is_empty() {
            ArraySize::Unbounded
        } else if let Some(n) = inner.strip_prefix("<=") {
            ArraySize::Bounded(parse_len(n, array_off)?)
        } else {
            let n = parse_len(inner, array_off)?;
            if n > MAX_FIXED_LEN {
                return Err((
                    array_off,
                    format!("fixed array length {n} is larger than {MAX_FIXED_LEN}"),
                ));
            }
            ArraySize::Fixed(n)
        }
    };
    let (elem_name, string_bound) = match elem.split_once("<=") {
        Some((e, n)) => {
            if e != "string" && e != "wstring" {
                return Err((
                    base,
                    format!("only strings can be bounded with `<=`, not `{e}`"),
                ));
            }
            (e, Some(parse_len(n, base + e.len())?))
        }
        None => (elem, None),
    };
    if elem_name.is_empty() {
        return Err((base, "missing type name".into()));
    }
    if let Some(prim) = Primitive::from_name(elem_name) {
        return Ok(FieldType {
            base: BaseType::Primitive { prim, string_bound },
            array,
        });
    }
    let parts: Vec<&str> = elem_name.split('/').collect();
    let (pkg, name) = match parts.as_slice() {
        [name] => {
            // ROS 2 reads a bare `Header` as std_msgs's.
            if *name == "Header" && package != "std_msgs" {
                ("std_msgs", *name)
            } else {
                (package, *name)
            }
        }
        [pkg, name] => (*pkg, *name),
        [pkg, "msg", name] => (*pkg, *name),
        _ => {
            return Err((
                base,
                format!(
                    "`{elem_name}` is not a type (expected a primitive, `Type` or `package/Type`)"
                ),
            ))
        }
    };
    if !valid_type_name(name) || !valid_package_name(pkg) {
        return Err((
            base,
            format!("`{elem_name}` is not a primitive type or a message name (`package/Type`, the type starting with an upper-case letter)"),
        ));
    }
    Ok(FieldType {
        base: BaseType::Message {
            package: pkg.to_string(),
            name: name.to_string(),
        },
        array,
    })
}

fn parse_len(text: &str, offset: usize) -> Result<u32, LineError> {
    text.trim()
        .parse::<u32>()
        .map_err(|_| (offset, format!("`{text}` is not an array or string length")))
}

/// Parses a field's default value (after the name) into an ECMAScript literal.
fn parse_default(ty: &FieldType, text: &str, offset: usize) -> Result<String, LineError> {
    let (prim, sbound) = match &ty.base {
        BaseType::Primitive { prim, string_bound } => (*prim, *string_bound),
        BaseType::Message { .. } => {
            return Err((
                offset,
                "only fields of primitive types can have default values".into(),
            ))
        }
    };
    match ty.array {
        ArraySize::Scalar => parse_scalar(prim, sbound, text, offset, false),
        size => {
            let Some(inner) = text.strip_prefix('[').and_then(|s| s.strip_suffix(']')) else {
                return Err((
                    offset,
                    format!("an array default is written `[a, b, ...]`, found `{text}`"),
                ));
            };
            let items = split_items(inner);
            let mut out = Vec::new();
            for (k, item) in items {
                let t = item.trim();
                if t.is_empty() {
                    if inner.trim().is_empty() {
                        break;
                    }
                    return Err((offset + 1 + k, "empty array element".into()));
                }
                let lead = item.len() - item.trim_start().len();
                out.push(parse_scalar(prim, sbound, t, offset + 1 + k + lead, false)?);
            }
            match size {
                ArraySize::Fixed(n) if out.len() != n as usize => {
                    return Err((
                        offset,
                        format!(
                            "the default has {} elements, the array has exactly {n}",
                            out.len()
                        ),
                    ))
                }
                ArraySize::Bounded(n) if out.len() > n as usize => {
                    return Err((
                        offset,
                        format!(
                            "the default has {} elements, the array has at most {n}",
                            out.len()
                        ),
                    ))
                }
                _ => {}
            }
            Ok(format!("[{}]", out.join(", ")))
        }
    }
}

/// Splits `a, 'b,c', d` at top-level commas; each item with its byte offset in `text`.
fn split_items(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut quote: Option<char> = None;
    let mut escaped = false;
    let mut start = 0;
    for (i, c) in text.char_indices() {
        if escaped {
            escaped = false;
            continue;
        }
        match (quote, c) {
            (Some(_), '\\') => escaped = true,
            (Some(q), c) if c == q => quote = None,
            (None, '"') | (None, '\'') => quote = Some(c),
            (None, ',') => {
                out.push((start, &text[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push((start, &text[start..]));
    out
}

/// Parses one primitive value into an ECMAScript literal. Unquoted strings are accepted
/// for constants (`string NAME=abc`), as ROS 2 does.
fn parse_scalar(
    prim: Primitive,
    string_bound: Option<u32>,
    text: &str,
    offset: usize,
    constant: bool,
) -> Result<String, LineError> {
    let bad = |what: &str| (offset, format!("`{text}` is not {what}"));
    if prim.is_string() {
        let value = match unquote(text) {
            Some(Ok(v)) => v,
            Some(Err(())) => return Err(bad("a well-formed quoted string")),
            None if constant => text.to_string(),
            None => return Err(bad("a quoted string (write \"...\" or '...')")),
        };
        if let Some(n) = string_bound {
            if value.chars().count() > n as usize {
                return Err((offset, format!("the string is longer than its bound {n}")));
            }
        }
        return Ok(ecma_string(&value));
    }
    match prim {
        Primitive::Bool => match text {
            "true" | "True" | "1" => Ok("true".into()),
            "false" | "False" | "0" => Ok("false".into()),
            _ => Err(bad("a bool (true or false)")),
        },
        Primitive::Float32 | Primitive::Float64 => {
            let ok = !text.is_empty()
                && text
                    .chars()
                    .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
            match text.parse::<f64>() {
                Ok(v) if ok && v.is_finite() => Ok(format!("{v:?}")),
                _ => Err(bad("a finite number")),
            }
        }
        _ => {
            let (lo, hi) = prim.int_range().ok_or_else(|| bad("a value"))?;
            let v: i128 = text.parse().map_err(|_| bad("an integer"))?;
            if v < lo || v > hi {
                return Err((
                    offset,
                    format!(
                        "{v} is out of range for {} ({lo} to {hi})",
                        prim.scxml_name()
                    ),
                ));
            }
            Ok(v.to_string())
        }
    }
}

/// `"a\"b"` or `'a'` unquoted; `None` when not quoted; `Err` when malformed.
fn unquote(text: &str) -> Option<Result<String, ()>> {
    let q = text.chars().next()?;
    if q != '"' && q != '\'' {
        return None;
    }
    let body = &text[1..];
    let mut out = String::new();
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(c) => out.push(c),
                None => return Some(Err(())),
            }
        } else if c == q {
            return Some(if chars.as_str().is_empty() {
                Ok(out)
            } else {
                Err(())
            });
        } else {
            out.push(c);
        }
    }
    Some(Err(()))
}

/// A single-quoted ECMAScript string literal.
fn ecma_string(s: &str) -> String {
    let mut out = String::from("'");
    for c in s.chars() {
        match c {
            '\'' => out.push_str("\\'"),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            c => out.push(c),
        }
    }
    out.push('\'');
    out
}

/// Every known ROS interface, by package, kind and name.
#[derive(Clone, Debug, Default)]
pub struct Interfaces {
    defs: BTreeMap<(String, InterfaceKind, String), InterfaceDef>,
}

impl Interfaces {
    /// No interfaces at all.
    pub fn new() -> Self {
        Self::default()
    }

    /// The standard definitions: std_msgs, std_srvs, example_interfaces, action_msgs,
    /// builtin_interfaces, unique_identifier_msgs and the common geometry_msgs.
    pub fn with_builtins() -> Self {
        let mut me = Interfaces::new();
        let mut sm = SourceMap::new();
        for (full, text) in builtin::DEFS {
            let mut it = full.split('/');
            let (Some(pkg), Some(kind), Some(name)) = (it.next(), it.next(), it.next()) else {
                continue;
            };
            let Some(kind) = InterfaceKind::from_dir(kind) else {
                continue;
            };
            let file = sm.add(*full, (*text).to_string());
            // Built-in texts are ours and tested to parse (`builtins_parse_and_resolve`).
            if let Ok(mut def) = parse_interface(&sm, file, pkg, name, kind) {
                def.file = None;
                me.insert(def);
            }
        }
        me
    }

    /// The built-ins plus every interface package found beside `main_file` and in `extra`.
    ///
    /// Looked for, nearest first: packages directly in the main file's folder; then, in that
    /// folder and up to four folders above it, the folders called `ros_support_interfaces`,
    /// `Interfaces` or `interfaces` and every package below them (up to three levels deep,
    /// so `ros_support_interfaces/uc3_interfaces/<pkg>/srv/X.srv` is found). Each `extra`
    /// path is a package or a folder searched the same way. A package is a folder with a
    /// `msg/`, `srv/` or `action/` subfolder; its name is the folder's name. When two
    /// packages have the same name the nearer one is used. A found package replaces a
    /// built-in one of the same name type by type. Every file read is added to `sm`, parsed,
    /// and every named type is checked ([`Interfaces::check`]).
    pub fn discover(
        sm: &mut SourceMap,
        main_file: &Path,
        extra: &[PathBuf],
    ) -> Result<Interfaces, Vec<Diagnostic>> {
        let mut me = Interfaces::with_builtins();
        let mut packages: Vec<(String, PathBuf)> = Vec::new();
        let mut errs = Vec::new();
        for path in extra {
            if !path.is_dir() {
                errs.push(Diagnostic::file(
                    path,
                    "interface folder does not exist or is not a folder",
                ));
                continue;
            }
            find_packages(path, 3, &mut packages);
        }
        let dir = match main_file.parent() {
            Some(d) if d.as_os_str().is_empty() => Path::new("."),
            Some(d) => d,
            None => Path::new("."),
        };
        for child in sorted_dirs(dir) {
            if is_package(&child) {
                packages.push((dir_name(&child), child));
            }
        }
        // Folders above the main file, written relative to it (`dir/..`) when `dir` runs
        // out of components, so relative paths keep working above the current folder.
        let mut anc = dir.to_path_buf();
        let mut last: Option<PathBuf> = None;
        for _ in 0..5 {
            let canon = anc.canonicalize().ok();
            if canon.is_some() && canon == last {
                break; // the file system's root
            }
            for child in sorted_dirs(&anc) {
                let n = dir_name(&child);
                if matches!(
                    n.as_str(),
                    "ros_support_interfaces" | "Interfaces" | "interfaces"
                ) {
                    find_packages(&child, 3, &mut packages);
                }
            }
            last = canon;
            anc = up(&anc);
        }
        let mut seen = BTreeSet::new();
        for (name, path) in packages {
            if !seen.insert(name.clone()) {
                continue;
            }
            if let Err(e) = me.add_package_dir(sm, &path, &name) {
                errs.extend(e);
            }
        }
        if let Err(e) = me.check(sm) {
            errs.extend(e);
        }
        if errs.is_empty() {
            Ok(me)
        } else {
            Err(errs)
        }
    }

    /// Reads every `msg/*.msg`, `srv/*.srv` and `action/*.action` of the package folder
    /// `dir` as package `package`; returns how many interfaces were added.
    pub fn add_package_dir(
        &mut self,
        sm: &mut SourceMap,
        dir: &Path,
        package: &str,
    ) -> Result<usize, Vec<Diagnostic>> {
        let mut errs = Vec::new();
        let mut added = 0;
        for kind in [
            InterfaceKind::Message,
            InterfaceKind::Service,
            InterfaceKind::Action,
        ] {
            let sub = dir.join(kind.dir());
            let Ok(rd) = std::fs::read_dir(&sub) else {
                continue;
            };
            let mut files: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().and_then(|e| e.to_str()) == Some(kind.dir()))
                .collect();
            files.sort();
            for path in files {
                let Some(name) = path
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .map(str::to_string)
                else {
                    continue;
                };
                let text = match std::fs::read_to_string(&path) {
                    Ok(t) => t,
                    Err(e) => {
                        errs.push(Diagnostic::file(&path, format!("cannot read: {e}")));
                        continue;
                    }
                };
                match self.add_text(sm, &path, text, package, kind, &name) {
                    Ok(()) => added += 1,
                    Err(e) => errs.extend(e),
                }
            }
        }
        if errs.is_empty() {
            Ok(added)
        } else {
            Err(errs)
        }
    }

    /// Adds the text of one interface file as `package/kind/name` (replacing an earlier
    /// definition of that name). Named types are not checked here: call
    /// [`Interfaces::check`] once everything is added.
    pub fn add_text(
        &mut self,
        sm: &mut SourceMap,
        path: &Path,
        text: String,
        package: &str,
        kind: InterfaceKind,
        name: &str,
    ) -> Result<(), Vec<Diagnostic>> {
        let file = sm.add(path, text);
        if !valid_type_name(name) {
            return Err(vec![Diagnostic::file(
                path,
                format!("`{name}` is not a valid interface name (it must start with an upper-case letter and have only letters and digits)"),
            )]);
        }
        let def = parse_interface(sm, file, package, name, kind)?;
        self.insert(def);
        Ok(())
    }

    fn insert(&mut self, def: InterfaceDef) {
        self.defs
            .insert((def.package.clone(), def.kind, def.name.clone()), def);
    }

    /// Checks that every message type a field names exists and that no message contains
    /// itself; errors point at the field.
    pub fn check(&self, sm: &SourceMap) -> Result<(), Vec<Diagnostic>> {
        let mut errs = Vec::new();
        for def in self.defs.values() {
            for part in &def.parts {
                for f in &part.fields {
                    let BaseType::Message { package, name } = &f.ty.base else {
                        continue;
                    };
                    let key = (package.clone(), InterfaceKind::Message, name.clone());
                    let msg = if self.defs.contains_key(&key) {
                        if self.contains_cycle(&key) {
                            Some(format!(
                                "message `{package}/{name}` contains itself, so it has no finite layout"
                            ))
                        } else {
                            None
                        }
                    } else {
                        Some(self.unknown(&format!("{package}/{name}"), InterfaceKind::Message))
                    };
                    if let Some(m) = msg {
                        let d = match def.file {
                            Some(_) => sm.diag(f.span, m),
                            None => Diagnostic::file(format!("<built-in {}>", def.full_name()), m),
                        };
                        errs.push(d);
                    }
                }
            }
        }
        if errs.is_empty() {
            Ok(())
        } else {
            Err(errs)
        }
    }

    /// True when message `start` can reach itself through its fields.
    fn contains_cycle(&self, start: &(String, InterfaceKind, String)) -> bool {
        let mut seen = BTreeSet::new();
        let mut stack = vec![start.clone()];
        while let Some(key) = stack.pop() {
            if !seen.insert(key.clone()) {
                continue;
            }
            let Some(def) = self.defs.get(&key) else {
                continue;
            };
            for f in def.parts.iter().flat_map(|p| &p.fields) {
                if let BaseType::Message { package, name } = &f.ty.base {
                    let k = (package.clone(), InterfaceKind::Message, name.clone());
                    if k == *start {
                        return true;
                    }
                    stack.push(k);
                }
            }
        }
        false
    }

    /// All interfaces, ordered by package, kind and name.
    pub fn iter(&self) -> impl Iterator<Item = &InterfaceDef> {
        self.defs.values()
    }

    /// The interface that `type_name` (`pkg/Type` or `pkg/msg/Type`) names, of kind `kind`.
    pub fn get(&self, type_name: &str, kind: InterfaceKind) -> Result<&InterfaceDef, String> {
        let parts: Vec<&str> = type_name.trim().split('/').collect();
        let (pkg, name) = match parts.as_slice() {
            [pkg, name] => (*pkg, *name),
            [pkg, mid, name] => match InterfaceKind::from_dir(mid) {
                Some(k) if k == kind => (*pkg, *name),
                Some(k) => {
                    return Err(format!(
                        "`{type_name}` names a {}, but a {} type is needed here",
                        k.noun(),
                        kind.noun()
                    ))
                }
                None => {
                    return Err(format!(
                        "`{type_name}` is not a type name (expected `package/Type` or `package/{}/Type`)",
                        kind.dir()
                    ))
                }
            },
            _ => {
                return Err(format!(
                    "`{type_name}` is not a type name (expected `package/Type` or `package/{}/Type`); {}",
                    kind.dir(),
                    self.suggest(type_name, kind)
                ))
            }
        };
        let key = (pkg.to_string(), kind, name.to_string());
        if let Some(d) = self.defs.get(&key) {
            return Ok(d);
        }
        for other in [
            InterfaceKind::Message,
            InterfaceKind::Service,
            InterfaceKind::Action,
        ] {
            if other != kind
                && self
                    .defs
                    .contains_key(&(pkg.to_string(), other, name.to_string()))
            {
                return Err(format!(
                    "`{type_name}` is a {}, but a {} type is needed here",
                    other.noun(),
                    kind.noun()
                ));
            }
        }
        Err(self.unknown(&format!("{pkg}/{name}"), kind))
    }

    fn unknown(&self, type_name: &str, kind: InterfaceKind) -> String {
        format!(
            "no {} type `{type_name}`; {}",
            kind.noun(),
            self.suggest(type_name, kind)
        )
    }

    /// "did you mean ..." with up to five close names of the same kind.
    fn suggest(&self, type_name: &str, kind: InterfaceKind) -> String {
        let wanted = type_name.to_ascii_lowercase();
        let wanted_short = wanted.rsplit('/').next().unwrap_or(&wanted).to_string();
        let mut scored: Vec<(usize, String)> = self
            .defs
            .values()
            .filter(|d| d.kind == kind)
            .filter_map(|d| {
                let full = format!("{}/{}", d.package, d.name);
                let lower = full.to_ascii_lowercase();
                let dist = edit_distance(&wanted, &lower)
                    .min(edit_distance(&wanted_short, &d.name.to_ascii_lowercase()) + 1);
                let limit = 2.max(wanted.len() / 4);
                (dist <= limit).then_some((dist, full))
            })
            .collect();
        scored.sort();
        // Only the closest few: a near miss should not drown in far ones.
        if let Some(best) = scored.first().map(|(d, _)| *d) {
            scored.retain(|(d, _)| *d <= best + 1);
        }
        scored.truncate(5);
        if scored.is_empty() {
            let n = self.defs.values().filter(|d| d.kind == kind).count();
            format!(
                "no close name among the {n} known {} types (is its package beside the model, in ros_support_interfaces/<pkg>/{}/?)",
                kind.noun(),
                kind.dir()
            )
        } else {
            let names: Vec<String> = scored.into_iter().map(|(_, n)| n).collect();
            format!("did you mean {}?", names.join(", "))
        }
    }

    /// The constants of message `type_name`, as `(name, ECMAScript literal)`.
    pub fn constants(&self, type_name: &str) -> Result<Vec<(String, String)>, String> {
        let def = self.get(type_name, InterfaceKind::Message)?;
        Ok(def.parts[0]
            .constants
            .iter()
            .map(|c| (c.name.clone(), c.value.clone()))
            .collect())
    }

    /// Flattens one part into leaf fields.
    fn flatten(&self, part: &MessageDef) -> Result<Vec<FlatField>, String> {
        let mut out = Vec::new();
        let mut path = Vec::new();
        let mut dims = Vec::new();
        self.flatten_into(part, &mut path, &mut dims, &mut out, 0)?;
        Ok(out)
    }

    fn flatten_into(
        &self,
        part: &MessageDef,
        path: &mut Vec<String>,
        dims: &mut Vec<ArraySize>,
        out: &mut Vec<FlatField>,
        depth: usize,
    ) -> Result<(), String> {
        if depth > MAX_NESTING {
            return Err(format!(
                "messages nest deeper than {MAX_NESTING} levels at `{}` (a message contains itself?)",
                path.join(".")
            ));
        }
        for f in &part.fields {
            if out.len() >= MAX_LEAVES {
                return Err(format!(
                    "the message has more than {MAX_LEAVES} leaf fields (at `{}`)",
                    path.join(".")
                ));
            }
            path.push(f.name.clone());
            match &f.ty.base {
                BaseType::Primitive { prim, .. } => {
                    let mut all = dims.clone();
                    if f.ty.array != ArraySize::Scalar {
                        all.push(f.ty.array);
                    }
                    let mut ty = prim.scxml_name().to_string();
                    for d in &all {
                        match d {
                            ArraySize::Fixed(n) | ArraySize::Bounded(n) => {
                                ty.push_str(&format!("[{n}]"))
                            }
                            _ => ty.push_str("[]"),
                        }
                    }
                    let default = match &f.default {
                        // An explicit default covers the field's own array (if any).
                        Some(d) => array_default(dims, d),
                        None => array_default(&all, prim.zero()),
                    };
                    out.push(FlatField {
                        path: path.clone(),
                        scxml_type: ty,
                        default,
                    });
                }
                BaseType::Message { package, name } => {
                    let key = (package.clone(), InterfaceKind::Message, name.clone());
                    let Some(def) = self.defs.get(&key) else {
                        return Err(
                            self.unknown(&format!("{package}/{name}"), InterfaceKind::Message)
                        );
                    };
                    let pushed = f.ty.array != ArraySize::Scalar;
                    if pushed {
                        dims.push(f.ty.array);
                    }
                    let r = self.flatten_into(&def.parts[0], path, dims, out, depth + 1);
                    if pushed {
                        dims.pop();
                    }
                    r?;
                }
            }
            path.pop();
        }
        Ok(())
    }
}

/// The default of a value nested in arrays `dims` (outermost first) whose leaf default is
/// `leaf`: fixed arrays are filled, others start empty.
fn array_default(dims: &[ArraySize], leaf: &str) -> String {
    match dims.first() {
        None => leaf.to_string(),
        Some(ArraySize::Fixed(n)) => {
            let inner = array_default(&dims[1..], leaf);
            let items: Vec<&str> = (0..*n).map(|_| inner.as_str()).collect();
            format!("[{}]", items.join(", "))
        }
        Some(_) => "[]".to_string(),
    }
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1];
        for (j, cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != *cb);
            cur.push(sub.min(prev[j + 1] + 1).min(cur[j] + 1));
        }
        prev = cur;
    }
    prev[b.len()]
}

fn sorted_dirs(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    v.sort();
    v
}

/// The folder above `p`: its lexical parent while it has one, `p/..` after that.
fn up(p: &Path) -> PathBuf {
    match p.components().next_back() {
        Some(std::path::Component::Normal(_)) => match p.parent() {
            Some(q) if q.as_os_str().is_empty() => PathBuf::from("."),
            Some(q) => q.to_path_buf(),
            None => p.join(".."),
        },
        _ => p.join(".."),
    }
}

fn dir_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn is_package(dir: &Path) -> bool {
    ["msg", "srv", "action"]
        .iter()
        .any(|k| dir.join(k).is_dir())
}

fn find_packages(dir: &Path, depth: usize, out: &mut Vec<(String, PathBuf)>) {
    if is_package(dir) {
        out.push((dir_name(dir), dir.to_path_buf()));
        return;
    }
    if depth == 0 {
        return;
    }
    for child in sorted_dirs(dir) {
        find_packages(&child, depth - 1, out);
    }
}

impl InterfaceLookup for Interfaces {
    fn message(&self, type_name: &str) -> Result<Vec<FlatField>, String> {
        let def = self.get(type_name, InterfaceKind::Message)?;
        self.flatten(&def.parts[0])
    }

    fn service(&self, type_name: &str) -> Result<ServiceFields, String> {
        let def = self.get(type_name, InterfaceKind::Service)?;
        Ok(ServiceFields {
            request: self.flatten(&def.parts[0])?,
            response: self.flatten(&def.parts[1])?,
        })
    }

    fn action(&self, type_name: &str) -> Result<ActionFields, String> {
        let def = self.get(type_name, InterfaceKind::Action)?;
        Ok(ActionFields {
            goal: self.flatten(&def.parts[0])?,
            result: self.flatten(&def.parts[1])?,
            feedback: self.flatten(&def.parts[2])?,
        })
    }
}

/// Our own text of the standard interfaces models use.
mod builtin {
    /// `(package/kind/Name, file text)`.
    pub(super) const DEFS: &[(&str, &str)] = &[
        // builtin_interfaces
        ("builtin_interfaces/msg/Time", "int32 sec\nuint32 nanosec\n"),
        (
            "builtin_interfaces/msg/Duration",
            "int32 sec\nuint32 nanosec\n",
        ),
        // unique_identifier_msgs
        ("unique_identifier_msgs/msg/UUID", "uint8[16] uuid\n"),
        // std_msgs
        ("std_msgs/msg/Bool", "bool data\n"),
        ("std_msgs/msg/Byte", "byte data\n"),
        ("std_msgs/msg/Char", "char data\n"),
        ("std_msgs/msg/Empty", ""),
        ("std_msgs/msg/Float32", "float32 data\n"),
        ("std_msgs/msg/Float64", "float64 data\n"),
        ("std_msgs/msg/Int8", "int8 data\n"),
        ("std_msgs/msg/Int16", "int16 data\n"),
        ("std_msgs/msg/Int32", "int32 data\n"),
        ("std_msgs/msg/Int64", "int64 data\n"),
        ("std_msgs/msg/UInt8", "uint8 data\n"),
        ("std_msgs/msg/UInt16", "uint16 data\n"),
        ("std_msgs/msg/UInt32", "uint32 data\n"),
        ("std_msgs/msg/UInt64", "uint64 data\n"),
        ("std_msgs/msg/String", "string data\n"),
        (
            "std_msgs/msg/ColorRGBA",
            "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
        ),
        (
            "std_msgs/msg/Header",
            "builtin_interfaces/Time stamp\nstring frame_id\n",
        ),
        (
            "std_msgs/msg/MultiArrayDimension",
            "string label\nuint32 size\nuint32 stride\n",
        ),
        (
            "std_msgs/msg/MultiArrayLayout",
            "MultiArrayDimension[] dim\nuint32 data_offset\n",
        ),
        (
            "std_msgs/msg/Float32MultiArray",
            "MultiArrayLayout layout\nfloat32[] data\n",
        ),
        (
            "std_msgs/msg/Float64MultiArray",
            "MultiArrayLayout layout\nfloat64[] data\n",
        ),
        (
            "std_msgs/msg/Int8MultiArray",
            "MultiArrayLayout layout\nint8[] data\n",
        ),
        (
            "std_msgs/msg/Int16MultiArray",
            "MultiArrayLayout layout\nint16[] data\n",
        ),
        (
            "std_msgs/msg/Int32MultiArray",
            "MultiArrayLayout layout\nint32[] data\n",
        ),
        (
            "std_msgs/msg/Int64MultiArray",
            "MultiArrayLayout layout\nint64[] data\n",
        ),
        (
            "std_msgs/msg/UInt8MultiArray",
            "MultiArrayLayout layout\nuint8[] data\n",
        ),
        (
            "std_msgs/msg/UInt16MultiArray",
            "MultiArrayLayout layout\nuint16[] data\n",
        ),
        (
            "std_msgs/msg/UInt32MultiArray",
            "MultiArrayLayout layout\nuint32[] data\n",
        ),
        (
            "std_msgs/msg/UInt64MultiArray",
            "MultiArrayLayout layout\nuint64[] data\n",
        ),
        // std_srvs
        ("std_srvs/srv/Empty", "---\n"),
        (
            "std_srvs/srv/SetBool",
            "bool data\n---\nbool success\nstring message\n",
        ),
        (
            "std_srvs/srv/Trigger",
            "---\nbool success\nstring message\n",
        ),
        // example_interfaces
        ("example_interfaces/msg/Bool", "bool data\n"),
        ("example_interfaces/msg/Byte", "byte data\n"),
        ("example_interfaces/msg/Char", "char data\n"),
        ("example_interfaces/msg/Empty", ""),
        ("example_interfaces/msg/Float32", "float32 data\n"),
        ("example_interfaces/msg/Float64", "float64 data\n"),
        ("example_interfaces/msg/Int8", "int8 data\n"),
        ("example_interfaces/msg/Int16", "int16 data\n"),
        ("example_interfaces/msg/Int32", "int32 data\n"),
        ("example_interfaces/msg/Int64", "int64 data\n"),
        ("example_interfaces/msg/UInt8", "uint8 data\n"),
        ("example_interfaces/msg/UInt16", "uint16 data\n"),
        ("example_interfaces/msg/UInt32", "uint32 data\n"),
        ("example_interfaces/msg/UInt64", "uint64 data\n"),
        ("example_interfaces/msg/String", "string data\n"),
        ("example_interfaces/msg/WString", "wstring data\n"),
        (
            "example_interfaces/srv/AddTwoInts",
            "int64 a\nint64 b\n---\nint64 sum\n",
        ),
        (
            "example_interfaces/srv/SetBool",
            "bool data\n---\nbool success\nstring message\n",
        ),
        (
            "example_interfaces/srv/Trigger",
            "---\nbool success\nstring message\n",
        ),
        (
            "example_interfaces/action/Fibonacci",
            "int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n",
        ),
        // action_msgs
        (
            "action_msgs/msg/GoalInfo",
            "unique_identifier_msgs/UUID goal_id\nbuiltin_interfaces/Time stamp\n",
        ),
        (
            "action_msgs/msg/GoalStatus",
            "int8 STATUS_UNKNOWN=0\nint8 STATUS_ACCEPTED=1\nint8 STATUS_EXECUTING=2\n\
             int8 STATUS_CANCELING=3\nint8 STATUS_SUCCEEDED=4\nint8 STATUS_CANCELED=5\n\
             int8 STATUS_ABORTED=6\nGoalInfo goal_info\nint8 status\n",
        ),
        (
            "action_msgs/msg/GoalStatusArray",
            "GoalStatus[] status_list\n",
        ),
        (
            "action_msgs/srv/CancelGoal",
            "GoalInfo goal_info\n---\nint8 ERROR_NONE=0\nint8 ERROR_REJECTED=1\n\
             int8 ERROR_UNKNOWN_GOAL_ID=2\nint8 ERROR_GOAL_TERMINATED=3\nint8 return_code\n\
             GoalInfo[] goals_canceling\n",
        ),
        // geometry_msgs
        (
            "geometry_msgs/msg/Point",
            "float64 x\nfloat64 y\nfloat64 z\n",
        ),
        (
            "geometry_msgs/msg/Point32",
            "float32 x\nfloat32 y\nfloat32 z\n",
        ),
        (
            "geometry_msgs/msg/Vector3",
            "float64 x\nfloat64 y\nfloat64 z\n",
        ),
        (
            "geometry_msgs/msg/Quaternion",
            "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
        ),
        (
            "geometry_msgs/msg/Pose",
            "Point position\nQuaternion orientation\n",
        ),
        (
            "geometry_msgs/msg/Pose2D",
            "float64 x\nfloat64 y\nfloat64 theta\n",
        ),
        (
            "geometry_msgs/msg/PoseStamped",
            "std_msgs/Header header\nPose pose\n",
        ),
        (
            "geometry_msgs/msg/PoseWithCovariance",
            "Pose pose\nfloat64[36] covariance\n",
        ),
        (
            "geometry_msgs/msg/PointStamped",
            "std_msgs/Header header\nPoint point\n",
        ),
        ("geometry_msgs/msg/Polygon", "Point32[] points\n"),
        (
            "geometry_msgs/msg/Twist",
            "Vector3 linear\nVector3 angular\n",
        ),
        (
            "geometry_msgs/msg/TwistStamped",
            "std_msgs/Header header\nTwist twist\n",
        ),
        (
            "geometry_msgs/msg/TwistWithCovariance",
            "Twist twist\nfloat64[36] covariance\n",
        ),
        (
            "geometry_msgs/msg/Accel",
            "Vector3 linear\nVector3 angular\n",
        ),
        (
            "geometry_msgs/msg/Wrench",
            "Vector3 force\nVector3 torque\n",
        ),
        (
            "geometry_msgs/msg/Transform",
            "Vector3 translation\nQuaternion rotation\n",
        ),
        (
            "geometry_msgs/msg/TransformStamped",
            "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
        ),
        (
            "geometry_msgs/msg/Vector3Stamped",
            "std_msgs/Header header\nVector3 vector\n",
        ),
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str, kind: InterfaceKind) -> Result<InterfaceDef, Vec<Diagnostic>> {
        let mut sm = SourceMap::new();
        let f = sm.add("p/x", text.to_string());
        parse_interface(&sm, f, "p", "X", kind)
    }

    fn err(text: &str, kind: InterfaceKind) -> String {
        parse(text, kind).unwrap_err()[0].to_string()
    }

    #[test]
    fn lines_parse() {
        let d = parse(
            "# c\nint8 A=1 # x\nstring S = \"a#b\"\nint32 x 5\nfloat64[3] v [1, 2, 3.5]\nstring<=4[<=2] s ['ab', \"c,d\"]\nInternal i\nq/T[] ts\n",
            InterfaceKind::Message,
        )
        .unwrap();
        let p = &d.parts[0];
        assert_eq!(p.constants[0].value, "1");
        assert_eq!(p.constants[1].value, "'a#b'");
        assert_eq!(p.fields[0].default.as_deref(), Some("5"));
        assert_eq!(p.fields[1].default.as_deref(), Some("[1.0, 2.0, 3.5]"));
        assert_eq!(p.fields[1].ty.array, ArraySize::Fixed(3));
        assert_eq!(p.fields[2].ty.array, ArraySize::Bounded(2));
        assert_eq!(p.fields[2].default.as_deref(), Some("['ab', 'c,d']"));
        assert_eq!(
            p.fields[3].ty.base,
            BaseType::Message {
                package: "p".into(),
                name: "Internal".into()
            }
        );
        assert_eq!(p.fields[4].ty.array, ArraySize::Unbounded);
    }

    #[test]
    fn bad_lines() {
        assert!(err("int32", InterfaceKind::Message).contains("p/x:1:6"));
        assert!(err("int33 x", InterfaceKind::Message).contains("p/x:1:1"));
        assert!(err("int8 x 300", InterfaceKind::Message).contains("out of range"));
        assert!(err("int32[2] x [1]", InterfaceKind::Message).contains("exactly 2"));
        assert!(err("int32 Bad", InterfaceKind::Message).contains("p/x:1:7"));
        assert!(err("int32 x\n---\n", InterfaceKind::Message).contains("p/x:2:1"));
        assert!(err("int32 x\n", InterfaceKind::Service).contains("2 parts"));
        assert!(err("int32 x\nint32 x\n", InterfaceKind::Message).contains("twice"));
        assert!(err("string s abc", InterfaceKind::Message).contains("quoted"));
        assert!(err("int32[<=x] s", InterfaceKind::Message).contains("length"));
        assert!(err("int32[2][3] s", InterfaceKind::Message).contains("array"));
        assert!(err("int32<=3 s", InterfaceKind::Message).contains("bounded"));
    }

    #[test]
    fn builtins_parse_and_resolve() {
        let ifs = Interfaces::with_builtins();
        assert_eq!(ifs.iter().count(), builtin::DEFS.len());
        assert_eq!(ifs.check(&SourceMap::new()), Ok(()));
        for d in ifs.iter() {
            let name = format!("{}/{}", d.package, d.name);
            let r = match d.kind {
                InterfaceKind::Message => ifs.message(&name).map(|_| ()),
                InterfaceKind::Service => ifs.service(&name).map(|_| ()),
                InterfaceKind::Action => ifs.action(&name).map(|_| ()),
            };
            assert_eq!(r, Ok(()), "{name}");
        }
    }

    #[test]
    fn no_input_panics() {
        let tokens = [
            "int32", "x", "X", "=", "[", "]", "[<=", "<=", "'", "\"", "é", "#", "---", " ", "\n",
            "3", "-1", "string", "p/T", "\\", ",", "\u{feff}", "1e999", "\r\n", "[]", "T",
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let (mut oks, mut errs) = (0, 0);
        for _ in 0..20_000 {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state
            };
            let mut text = String::new();
            for _ in 0..(next() % 9) {
                text.push_str(tokens[(next() % tokens.len() as u64) as usize]);
            }
            for kind in [
                InterfaceKind::Message,
                InterfaceKind::Service,
                InterfaceKind::Action,
            ] {
                match parse(&text, kind) {
                    Ok(_) => oks += 1,
                    Err(_) => errs += 1,
                }
            }
        }
        assert!(
            oks > 1_000 && errs > 10_000,
            "{oks} parsed, {errs} rejected"
        );
        assert_eq!(
            parse(
                "\u{feff}int32 x\r\nstring<=3 s 'é'\r\n",
                InterfaceKind::Message
            )
            .unwrap()
            .parts[0]
                .fields
                .len(),
            2
        );
    }

    #[test]
    fn folders_above() {
        assert_eq!(up(Path::new("a/b")), Path::new("a"));
        assert_eq!(up(Path::new("a")), Path::new("."));
        assert_eq!(up(Path::new(".")), Path::new("./.."));
        assert_eq!(up(Path::new("./..")), Path::new("./../.."));
        assert_eq!(up(Path::new("/")), Path::new("/.."));
    }

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance("int32", "int33"), 1);
        assert_eq!(edit_distance("", "ab"), 2);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }

    #[test]
    fn defaults_of_nested_arrays() {
        assert_eq!(array_default(&[ArraySize::Fixed(2)], "0"), "[0, 0]");
        assert_eq!(
            array_default(&[ArraySize::Fixed(2), ArraySize::Unbounded], "0"),
            "[[], []]"
        );
        assert_eq!(array_default(&[ArraySize::Bounded(2)], "0"), "[]");
    }
}
