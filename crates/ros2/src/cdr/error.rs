//! The CDR reader's errors: a message that does not decode ([`CdrError`]) and a field
//! path a port or a writer names that its type does not have as asked ([`FieldError`]).

/// A problem decoding one message (the caller adds the topic and the message index).
/// Byte offsets count from the start of the message, its 4-byte header included.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CdrError {
    /// Shorter than the encapsulation header (`len` bytes).
    NoHeader {
        /// The message's length.
        len: usize,
    },
    /// An encapsulation kind other than plain CDR.
    Encapsulation {
        /// The header's first two bytes.
        kind: [u8; 2],
    },
    /// The message ends (at byte `end`) before `need` bytes at byte `at`.
    Truncated {
        /// Its length.
        end: usize,
        /// Bytes needed.
        need: usize,
        /// Where.
        at: usize,
    },
    /// A sequence or string claims more elements than the bytes left could hold.
    Count {
        /// The claimed count.
        count: usize,
        /// Bytes left.
        left: usize,
    },
    /// A `bool` byte other than 0 or 1.
    Bool(u8),
    /// A string without its terminating NUL.
    NoNul,
    /// Bytes after the end of the message's type (another type's message).
    Trailing {
        /// Bytes left over.
        left: usize,
        /// The type decoded.
        ty: String,
    },
    /// A bounded sequence with more elements than its bound.
    PastBound {
        /// The field.
        field: String,
        /// Its message type.
        ty: String,
        /// Elements in the message.
        count: usize,
        /// The bound.
        bound: u32,
    },
    /// An unsigned value past the largest integer a property holds (`i64`).
    TooLarge {
        /// The field path.
        path: String,
        /// The value.
        value: u64,
    },
    /// A value of another kind than the slot's type.
    Mismatch {
        /// The field path.
        path: String,
    },
}

impl std::fmt::Display for CdrError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CdrError::NoHeader { len } => write!(
                f,
                "{len} bytes: too short for the 4-byte CDR encapsulation header"
            ),
            CdrError::Encapsulation { kind: [a, b] } => write!(
                f,
                "encapsulation kind 0x{a:02x}{b:02x} is not plain CDR (0x0000 big endian or 0x0001 little endian)"
            ),
            CdrError::Truncated { end, need, at } => write!(
                f,
                "the message ends at byte {end} but {need} more byte(s) are needed at byte {at}"
            ),
            CdrError::Count { count, left } => write!(
                f,
                "a sequence claims {count} element(s) but only {left} byte(s) are left"
            ),
            CdrError::Bool(v) => write!(f, "a bool is {v}, not 0 or 1"),
            CdrError::NoNul => f.write_str("a string does not end with a NUL byte"),
            CdrError::Trailing { left, ty } => write!(
                f,
                "{left} byte(s) follow the end of a `{ty}` (is this the message's type?)"
            ),
            CdrError::PastBound {
                field,
                ty,
                count,
                bound,
            } => write!(
                f,
                "field `{field}` of `{ty}` has {count} elements, more than its bound {bound}"
            ),
            CdrError::TooLarge { path, value } => write!(
                f,
                "`{path}` is {value}, past the largest integer a property holds"
            ),
            CdrError::Mismatch { path } => write!(f, "`{path}`: type mismatch"),
        }
    }
}

impl std::error::Error for CdrError {}

/// A field path a property (or a writer) names that the message type does not have as
/// asked: every variant names the path and the types involved.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FieldError {
    /// Not a field path (`a.b[2].c`): the path and why.
    Syntax {
        /// The text given.
        path: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A step names a field the message does not have.
    NoField {
        /// The message type that lacks it.
        ty: String,
        /// The field named.
        field: String,
        /// The whole path.
        path: String,
        /// The root type of the path.
        root: String,
        /// The fields `ty` has.
        known: Vec<String>,
    },
    /// `here` indexes field `field` of `ty`, which is not an array.
    NotAnArray {
        /// The path up to this step.
        here: String,
        /// The field.
        field: String,
        /// Its message type.
        ty: String,
    },
    /// `here` indexes past the `bound` elements field `field` of `ty` can have.
    PastBound {
        /// The path up to this step.
        here: String,
        /// The field.
        field: String,
        /// Its message type.
        ty: String,
        /// Its fixed size or bound.
        bound: usize,
    },
    /// `here` is an array: one element must be named.
    IsAnArray {
        /// The path up to this step.
        here: String,
        /// The field.
        field: String,
        /// Its message type.
        ty: String,
    },
    /// `here` is a primitive (`prim`, a `.msg` type name) of `ty`, yet the path goes on.
    NoFields {
        /// The path up to this step.
        here: String,
        /// The primitive's `.msg` name.
        prim: &'static str,
        /// Its message type.
        ty: String,
    },
    /// `here` is a message (of type `ty`): the path must name one of its fields.
    IsAMessage {
        /// The whole path.
        here: String,
        /// The nested message's type.
        ty: String,
    },
    /// The field is a `prim`, which is not read as the property's type (`want`).
    Convert {
        /// The whole path.
        path: String,
        /// The root type.
        root: String,
        /// The field's `.msg` type.
        prim: &'static str,
        /// What the property reads (`bool`, `an integer`, `a number`, `string`).
        want: &'static str,
    },
}

impl std::fmt::Display for FieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FieldError::Syntax { path, why } => {
                write!(f, "`{path}` is not a field path ({why})")
            }
            FieldError::NoField {
                ty,
                field,
                path,
                root,
                known,
            } => write!(
                f,
                "message `{ty}` has no field `{field}` (field path `{path}` of `{root}`; its fields: {})",
                known.join(", ")
            ),
            FieldError::NotAnArray { here, field, ty } => write!(
                f,
                "`{here}` indexes field `{field}` of `{ty}`, which is not an array"
            ),
            FieldError::PastBound {
                here,
                field,
                ty,
                bound,
            } => write!(
                f,
                "`{here}`: field `{field}` of `{ty}` has at most {bound} element(s)"
            ),
            FieldError::IsAnArray { here, field, ty } => write!(
                f,
                "`{here}` is an array (field `{field}` of `{ty}`): name one element, `{here}[0]`"
            ),
            FieldError::NoFields { here, prim, ty } => {
                write!(f, "`{here}` is a {prim} of `{ty}`, it has no fields")
            }
            FieldError::IsAMessage { here, ty } => write!(
                f,
                "`{here}` is a message (`{ty}`): name one of its fields"
            ),
            FieldError::Convert {
                path,
                root,
                prim,
                want,
            } => write!(
                f,
                "field `{path}` of `{root}` is a {prim}, which is not read as {want}"
            ),
        }
    }
}

impl std::error::Error for FieldError {}
