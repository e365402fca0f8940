//! SCAN property files: ports (state and event variables) and Past-MTL guarantees and
//! assumptions, read from both formats SCAN has used.
//!
//! # Formats
//!
//! **Current** (SCAN today):
//!
//! ```xml
//! <properties>
//!   <ports>
//!     <scxml_event_send event="E" origin="M" target="T">
//!       <state_var id="x" param="p" type="int32" expr="0"/>
//!       <event_var id="e"/>
//!     </scxml_event_send>
//!   </ports>
//!   <guarantees><property id="P1" logic="pmtl" expr="historically({ x &lt; 3 })"/></guarantees>
//!   <assumes>...same as guarantees...</assumes>
//! </properties>
//! ```
//!
//! `logic` is optional and must be `pmtl` when given. The formula is the unescaped `expr`
//! (tabs and line breaks become spaces, as XML attribute normalisation says).
//!
//! **Tree form** (older SCAN, used by the museum case study):
//! `<port id type>` with `<origin refid/>`, `<target refid/>` and
//! `<message event [param_name expr]/>` (a port with `param_name` is a state variable
//! with initial value `expr`, one without is an event variable and must be `boolean`);
//! `<predicates>` of `<predicate id>` holding one value expression; `<guarantees>` of
//! `<guarantee id>` (and, as an extension, `<assumes>` of `<assume id>`) holding one
//! formula. Elements:
//!
//! | element | Rye text |
//! | --- | --- |
//! | `<true/>`, `<false/>` | `true`, `false` |
//! | `<var refid/>` | `{x}` for a boolean variable, the predicate's body for a predicate |
//! | `<not>`, `<and>`, `<or>`, `<implies>` | `(!f)`, `(f && g ...)`, `(f \|\| g ...)`, `(f -> g)` |
//! | `<historically lower_bound upper_bound>` | `(historically[a:b] f)` |
//! | `<previously ...>` (also `<once>`) | `(once[a:b] f)` |
//! | `<since ...>` f g | `(f since[a:b] g)` (f must hold since the last g) |
//! | `<equal>`, `<less>`, `<leq>`, `<greater>`, `<geq>` | `{a == b}` etc., one atom |
//! | `<sum>`, `<mult>`, `<opposite>` | `a + b`, `a * b`, `-a`, inside an atom |
//! | `<const type expr/>` | the literal (strings in single quotes) |
//!
//! Bounds are optional non-negative integers (`[a:]`, `[:b]`, `[a:b]`). Inside an atom
//! (an argument of a comparison or arithmetic) boolean operators become `&&`, `||`, `!`
//! and `!a || b`. The whole formula loses its outermost parentheses.
//!
//! # Output
//!
//! A [`PropertyFile`]: one [`Port`] per variable, and [`Property`]s whose formula is a
//! [`SourceText`] that maps every byte offset back to a file [`Location`], so an error
//! the formula compiler reports at an offset can name the line and column in the file
//! (exactly for the current format, at the generating element for the tree form).
//!
//! # Errors
//!
//! Malformed XML (a bad reference in an attribute value included) stops reading at the
//! first error. Otherwise every problem is collected ([`Diagnostics`]): unknown elements
//! and attributes, missing attributes and elements, bad values and types, duplicate ids,
//! unknown references, predicate cycles, each with file, line and column.
//!
//! # Crate
//!
//! `hindsight-props` depends on `codegen` (source map, diagnostics), `hindsight-expr` (the
//! port types) and `hindsight-sim` (the XML tree, and a compiled model's events that
//! [`jani`] resolves names against), on no other crate of the project; `hindsight`'s
//! `verify` compiles its formulas with codegen and binds its ports to a model.
//!
//! ```
//! use hindsight_props::{parse_str, PortKind};
//! use std::path::Path;
//!
//! let text = r#"<properties>
//!   <ports>
//!     <scxml_event_send event="E" origin="M" target="T">
//!       <state_var id="x" param="p" type="int32" expr="0"/>
//!     </scxml_event_send>
//!   </ports>
//!   <guarantees><property id="P1" logic="pmtl" expr="historically({ x &lt; 3 })"/></guarantees>
//! </properties>"#;
//! let file = parse_str(text, Path::new("props.xml")).unwrap();
//! assert_eq!(file.ports[0].id, "x");
//! assert!(matches!(file.ports[0].kind, PortKind::State { .. }));
//! let p1 = &file.guarantees[0];
//! assert_eq!(p1.formula.as_str(), "historically({ x < 3 })"); // `&lt;` unescaped
//! assert_eq!((p1.at.line, p1.at.column), (7, 15));
//!
//! // Every problem is collected, with its file, line and column.
//! let bad = text.replace("state_var id=\"x\"", "state_var");
//! let errors = parse_str(&bad, Path::new("props.xml")).unwrap_err();
//! assert!(errors.to_string().contains("props.xml:4:"), "{errors}");
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

// Inside this crate the model layer is `crate::model` / `crate::sim` and the expression
// language `crate::expr`, as they were inside `hindsight`.
use hindsight_expr as expr;
use hindsight_sim::{model, sim};

mod error;
pub mod jani;
mod read;
pub mod ros;
mod source;

use std::path::{Path, PathBuf};

pub use error::{location, Diagnostics, PropsError, PropsErrorKind};
pub use source::{Location, SourceText};

/// A property file, read and checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PropertyFile {
    /// The file, as given.
    pub path: PathBuf,
    /// The variables formulas may use, in file order; ids are unique.
    pub ports: Vec<Port>,
    /// Properties to verify, in file order; ids are unique among all properties.
    pub guarantees: Vec<Property>,
    /// Properties that restrict runs (a run violating one is discarded), in file order.
    pub assumptions: Vec<Property>,
    /// The ROS interface types the ports name, where each is written: checked against a
    /// robot model's interfaces when the file is loaded with one (`verify::load`).
    pub ros_types: Vec<RosTypeUse>,
}

/// A ROS interface type named by a port (`<ros_topic type>`, `<ros_service type>`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RosTypeUse {
    /// The type as written (`std_msgs/Int32`).
    pub type_name: String,
    /// `true` for a service type (`.srv`), `false` for a message type (`.msg`).
    pub service: bool,
    /// The `type` attribute.
    pub at: Location,
    /// The QoS a `<ros_topic>` names (`("durability", "transient_local")`, checked
    /// against [`ros::QOS_SETTINGS`]), in that list's order; empty: ROS 2's default.
    pub qos: Vec<(String, String)>,
}

/// One variable of a property file, observed on one message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Port {
    /// The variable's name in formulas.
    pub id: String,
    /// State or event variable.
    pub kind: PortKind,
    /// The SCXML event (message) observed.
    pub event: String,
    /// The machine that sends it ([`ANY`]: every sender).
    pub origin: String,
    /// The machine it is sent to ([`ANY`]: every target, the `NONE` sink included).
    pub target: String,
    /// Where the variable is declared (`<state_var>`, `<event_var>` or `<port>`).
    pub at: Location,
}

/// A port's origin or target that matches every machine (JANI properties observe an
/// event whoever sends it).
pub const ANY: &str = "*";

/// What a variable holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PortKind {
    /// True exactly at the point where the message is sent.
    Event,
    /// False until the message is first sent, true from then on (JANI's `E.valid`).
    Sent,
    /// Part of an array or string parameter as last sent (JANI's `aa` and `.d1_len`):
    /// the element at `path` (indices from the outside in; inside a string, a
    /// character's code) or, with `length`, the number of elements (characters) there.
    /// An element the message does not have reads as `0`, `false` or `0.0`.
    Part {
        /// The message parameter.
        param: String,
        /// Indices into it.
        path: Vec<u32>,
        /// The length at `path` instead of the element.
        length: bool,
        /// The element's type, as for [`PortKind::State`].
        ty: String,
    },
    /// The value of a message parameter as last sent.
    State {
        /// The message parameter.
        param: String,
        /// The declared type, as written: `bool`/`boolean`, `int`, `int8`..`int64`,
        /// `uint8`..`uint64`, `float`, `double`, `float32`, `float64` or `string`.
        ty: String,
        /// The initial value expression, as written (unescaped).
        init: SourceText,
    },
}

/// A guarantee or assumption.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Property {
    /// The property's id.
    pub id: String,
    /// The Past-MTL formula in Rye syntax.
    pub formula: SourceText,
    /// Where the property's element starts.
    pub at: Location,
    /// Whether the formula was converted from the tree form (its locations then point at
    /// the elements that generated each piece).
    pub converted: bool,
}

impl PropertyFile {
    /// The port declaring variable `id`.
    pub fn port(&self, id: &str) -> Option<&Port> {
        self.ports.iter().find(|port| port.id == id)
    }
}

/// The longest property or port id, in characters: with `-run<k>.csv` after it, a
/// `--save-failing` file name stays under the 255 bytes file systems allow.
pub const MAX_ID_LEN: usize = 200;

/// What an id may hold, as the error at a bad one says it.
pub(crate) const ID_RULE: &str =
    "an id of ASCII letters, digits, `_`, `-` and `.`, starting with a \
     letter, digit or `_`, at most 200 characters (ids name CSV columns and the files of \
     `verify --save-failing`)";

/// Whether `id` may name a property or a port: ASCII letters, digits, `_`, `-` and `.`,
/// starting with a letter, digit or `_`, at most [`MAX_ID_LEN`] characters. Checked
/// where every id is declared (SCAN, ROS and tree-form property files, JANI property
/// names), because ids become CSV header cells and file names (`<id>-run<k>.csv`):
/// with this rule a name is never a path (`/`, `..`), never needs CSV quoting (`,`,
/// `"`), and means the same on every file system. Every id of the corpus (SCAN names,
/// JANI names such as `alarm-follows-battery-low`) fits.
pub fn is_valid_id(id: &str) -> bool {
    let mut chars = id.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
        && id.len() <= MAX_ID_LEN
}

/// Reads and checks the property file at `path`.
pub fn parse_file(path: &Path) -> Result<PropertyFile, Diagnostics> {
    let fail = |at: Location, kind| {
        Diagnostics::from(vec![PropsError::error(
            path.display().to_string(),
            (at.line, at.column),
            kind,
        )])
    };
    // The one reader of source files: a folder, FIFO or device is refused unopened, a
    // byte order mark dropped, a byte that is not UTF-8 located.
    match codegen::diag::read_source(path) {
        Ok(text) => parse_str(&text, path),
        Err(d) if d.line == 0 => Err(fail(Location::new(1, 1), PropsErrorKind::Io(d.message))),
        Err(d) => Err(fail(Location::new(d.line, d.col), PropsErrorKind::Encoding)),
    }
}

/// Reads and checks a property file's text; `path` is only used in errors.
pub fn parse_str(text: &str, path: &Path) -> Result<PropertyFile, Diagnostics> {
    // Not even the start of XML: not the property file it was named as (a path that
    // reaches `/etc/passwd`); its text, maybe a secret, is not shown.
    // (At 1:1, with no excerpt; an empty file is "no root element" as before.)
    let start = text.trim_start();
    if !start.is_empty() && !start.starts_with('<') {
        return Err(Diagnostics::from(vec![PropsError::error(
            path.display().to_string(),
            (1, 1),
            PropsErrorKind::Xml("it does not start with `<` (its text is not shown)".into()),
        )]));
    }
    let lines = source::SourceFile::new(path, text);
    let root = crate::model::xml::parse_text(text, crate::model::FileId(0)).map_err(|e| {
        let at = lines.location(e.offset as usize);
        Diagnostics::from(vec![error::error_at(
            path,
            &lines,
            at,
            PropsErrorKind::Xml(e.message),
        )])
    })?;
    let mut reader = read::FileReader::new(path, &lines);
    let mut file = reader.read(&root);
    file.ros_types = std::mem::take(&mut reader.ros_types);
    let mut errors = reader.into_errors();
    if errors.is_empty() {
        Ok(file)
    } else {
        errors.sort_by_key(|error| (error.line, error.col));
        errors.dedup();
        Err(Diagnostics::from(errors))
    }
}
