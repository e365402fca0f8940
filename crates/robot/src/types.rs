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
/// is a one-line message (`no interface std_msgs/Int33 (known: ...)`); the caller adds
/// the span of the tag that named the type.
pub trait InterfaceLookup {
    /// A message type's leaf fields, in declaration order.
    fn message(&self, type_name: &str) -> Result<Vec<FlatField>, String>;
    /// A service type's request and response fields.
    fn service(&self, type_name: &str) -> Result<ServiceFields, String>;
    /// An action type's goal, result and feedback fields.
    fn action(&self, type_name: &str) -> Result<ActionFields, String>;
}
