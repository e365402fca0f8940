//! The contract between the ROS lowering and the interface reader: messages as flat fields.
//!
//! AS2FM's translation sends every message, request, response, goal, result and feedback
//! as one event whose parameters are the message's leaf fields, named
//! `ros_fields__<a>__<b>` for the path `a.b`. The ROS lowering only needs that flat
//! view, so it asks an [`InterfaceLookup`] for it and never reads `.msg` files itself.

/// One leaf field of a (possibly nested) ROS message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlatField {
    /// The path from the message root, `["pose", "position", "x"]`.
    pub path: Vec<String>,
    /// The field's type as our SCXML reader spells it (`int32`, `float64`, `bool`,
    /// `string`, `int32[]`, `float64[3]`, ...), see [`crate::model::types::TypeExpr`].
    pub scxml_type: String,
    /// The value an unset field has, as an ECMAScript literal (`0`, `0.0`, `false`,
    /// `''`, `[]`).
    pub default: String,
}

impl FlatField {
    /// The event parameter that carries this field: `ros_fields__pose__position__x`.
    pub fn param_name(&self) -> String {
        format!("ros_fields__{}", self.path.join("__"))
    }

    /// The field as written in a model expression: `pose.position.x`.
    pub fn dotted(&self) -> String {
        self.path.join(".")
    }
}

/// The two halves of a service type (`.srv`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ServiceFields {
    /// The request's leaf fields.
    pub request: Vec<FlatField>,
    /// The response's leaf fields.
    pub response: Vec<FlatField>,
}

/// The three parts of an action type (`.action`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ActionFields {
    /// The goal's leaf fields.
    pub goal: Vec<FlatField>,
    /// The result's leaf fields.
    pub result: Vec<FlatField>,
    /// The feedback's leaf fields.
    pub feedback: Vec<FlatField>,
}

/// Where the ROS lowering finds message layouts. Type names are as written in models:
/// `std_msgs/Int32`, `std_msgs/msg/Int32`, `example_interfaces/srv/AddTwoInts`. An error
/// is a [`LookupError`] (its message: no message type `std_msgs/Int33`, why, and close
/// names); the caller adds the span of the tag that named the type.
pub trait InterfaceLookup {
    /// A message type's leaf fields, in declaration order.
    fn message(&self, type_name: &str) -> Result<Vec<FlatField>, LookupError>;
    /// A service type's request and response fields.
    fn service(&self, type_name: &str) -> Result<ServiceFields, LookupError>;
    /// An action type's goal, result and feedback fields.
    fn action(&self, type_name: &str) -> Result<ActionFields, LookupError>;
}

/// Why an [`InterfaceLookup`] has no layout for a type name. Displayed as one message
/// (the unknown-package case adds the places searched on lines of their own); the
/// caller puts it at the span of the tag that named the type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LookupError {
    /// The name is not `package/Type` or `package/<kind>/Type`: the folder the kind
    /// wanted uses, and what follows the message (close names), if anything.
    NotATypeName {
        /// The name as written.
        type_name: String,
        /// The kind's folder (`msg`, `srv`, `action`).
        dir: &'static str,
        /// Close names, or how many there are to choose from.
        suggestion: Option<String>,
    },
    /// The name is of an interface of another kind.
    WrongKind {
        /// The name as written.
        type_name: String,
        /// What it names (`message`, `service`, `action`).
        found: &'static str,
        /// What was needed here.
        wanted: &'static str,
        /// Whether the kind came from the name's folder (`pkg/msg/Type`) rather than
        /// from the interfaces known.
        by_folder: bool,
    },
    /// No interface of that kind and name: why (the package missing, broken or without
    /// such a type), with close names or the places searched.
    Unknown {
        /// `package/Type`.
        type_name: String,
        /// What was looked for (`message`, `service`, `action`).
        kind: &'static str,
        /// The rest of the message.
        why: String,
    },
    /// Messages nest deeper than `limit` levels at the field path `at`.
    TooDeep {
        /// The dotted field path reached.
        at: String,
        /// The deepest nesting followed.
        limit: usize,
    },
    /// The flattened message has more than `limit` leaf fields (at the path `at`).
    TooManyLeaves {
        /// The dotted field path reached.
        at: String,
        /// The most leaf fields one message may have.
        limit: usize,
    },
}

impl std::fmt::Display for LookupError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LookupError::NotATypeName {
                type_name,
                dir,
                suggestion,
            } => {
                write!(
                    f,
                    "`{type_name}` is not a type name (expected `package/Type` or `package/{dir}/Type`)"
                )?;
                match suggestion {
                    Some(s) => write!(f, "; {s}"),
                    None => Ok(()),
                }
            }
            LookupError::WrongKind {
                type_name,
                found,
                wanted,
                by_folder,
            } => {
                let verb = if *by_folder { "names" } else { "is" };
                write!(
                    f,
                    "`{type_name}` {verb} a {found}, but a {wanted} type is needed here"
                )
            }
            LookupError::Unknown {
                type_name,
                kind,
                why,
            } => write!(f, "no {kind} type `{type_name}`: {why}"),
            LookupError::TooDeep { at, limit } => write!(
                f,
                "messages nest deeper than {limit} levels at `{at}` (a message contains itself?)"
            ),
            LookupError::TooManyLeaves { at, limit } => write!(
                f,
                "the message has more than {limit} leaf fields (at `{at}`)"
            ),
        }
    }
}

impl std::error::Error for LookupError {}
