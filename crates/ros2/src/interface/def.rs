//! The parsed form of a ROS 2 interface file: kinds, primitive types, fields, constants,
//! and the normalised text each prints as.

use codegen::diag::{FileId, Span};
use codegen::scalar::Scalar;

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

    /// The word for this kind in messages: `message`, `service`, `action`.
    pub fn noun(self) -> &'static str {
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
    /// The primitive called `name` in a `.msg` file: ROS's `byte`, `char` and `wstring`,
    /// or a name of the one scalar table (`codegen::scalar`).
    pub fn from_name(name: &str) -> Option<Primitive> {
        Some(match name {
            "byte" => Primitive::Byte,
            "char" => Primitive::Char,
            "wstring" => Primitive::WString,
            _ => match Scalar::from_exact_name(name)? {
                Scalar::Bool => Primitive::Bool,
                Scalar::F32 => Primitive::Float32,
                Scalar::F64 => Primitive::Float64,
                Scalar::I8 => Primitive::Int8,
                Scalar::U8 => Primitive::UInt8,
                Scalar::I16 => Primitive::Int16,
                Scalar::U16 => Primitive::UInt16,
                Scalar::I32 => Primitive::Int32,
                Scalar::U32 => Primitive::UInt32,
                Scalar::I64 => Primitive::Int64,
                Scalar::U64 => Primitive::UInt64,
                Scalar::Str => Primitive::String,
            },
        })
    }

    /// The scalar the SCXML reader takes it as (`byte`/`char` -> `uint8`, `wstring` ->
    /// `string`).
    pub fn scalar(self) -> Scalar {
        match self {
            Primitive::Bool => Scalar::Bool,
            Primitive::Byte | Primitive::Char | Primitive::UInt8 => Scalar::U8,
            Primitive::Float32 => Scalar::F32,
            Primitive::Float64 => Scalar::F64,
            Primitive::Int8 => Scalar::I8,
            Primitive::Int16 => Scalar::I16,
            Primitive::UInt16 => Scalar::U16,
            Primitive::Int32 => Scalar::I32,
            Primitive::UInt32 => Scalar::U32,
            Primitive::Int64 => Scalar::I64,
            Primitive::UInt64 => Scalar::U64,
            Primitive::String | Primitive::WString => Scalar::Str,
        }
    }

    /// The type as the SCXML reader spells it (`byte`/`char` -> `uint8`, `wstring` -> `string`).
    pub fn scxml_name(self) -> &'static str {
        self.scalar().name()
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

    /// Whether it is `string` or `wstring`.
    pub(crate) fn is_string(self) -> bool {
        matches!(self, Primitive::String | Primitive::WString)
    }

    /// Inclusive range of an integer type (its scalar's).
    pub fn int_range(self) -> Option<(i128, i128)> {
        self.scalar().int_range()
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
    pub(crate) fn msg_name(self) -> &'static str {
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
