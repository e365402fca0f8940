//! Errors of property files: every one carries the file, line and column it is about.
//!
//! A [`PropsError`] is the project's one diagnostic ([`codegen::diag::Diagnostic`])
//! with a [`PropsErrorKind`] as its payload, so callers can match on what is wrong
//! while positions and rendering stay codegen's.

use std::fmt;

use super::source::{Location, SourceFile};

/// What is wrong, without the position.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum PropsErrorKind {
    /// The file could not be read.
    Io(String),
    /// The file is not UTF-8.
    Encoding,
    /// The file is not well-formed XML.
    Xml(String),
    /// An element that has no meaning where it stands.
    UnknownElement {
        /// The element's name.
        name: String,
        /// Its parent's name (empty for the root).
        parent: String,
        /// What the parent accepts.
        expected: &'static str,
    },
    /// An attribute the element does not have.
    UnknownAttribute {
        /// The element's name.
        element: String,
        /// The attribute's name.
        name: String,
    },
    /// A required attribute is missing.
    MissingAttribute {
        /// The element's name.
        element: String,
        /// The attribute's name.
        name: &'static str,
    },
    /// A required child element is missing.
    MissingElement {
        /// The element's name.
        element: String,
        /// The missing child's name.
        name: &'static str,
    },
    /// A child element that may appear only once appears again.
    RepeatedElement {
        /// The element's name.
        element: String,
        /// The repeated child's name.
        name: String,
    },
    /// An operator with the wrong number of operands.
    Arity {
        /// The operator's element name.
        element: String,
        /// How many it takes, in words.
        expected: &'static str,
        /// How many it has.
        found: usize,
    },
    /// An attribute value that is not valid.
    BadValue {
        /// The attribute's name.
        attribute: String,
        /// The value given.
        value: String,
        /// What it should be.
        expected: String,
    },
    /// An id declared twice.
    Duplicate {
        /// What kind of id (variable, property, predicate).
        what: &'static str,
        /// The id.
        id: String,
        /// Where it was first declared.
        first: Location,
    },
    /// A reference to a variable or predicate that is not declared.
    UnknownReference {
        /// The id referred to.
        id: String,
    },
    /// A predicate that refers to itself.
    Cycle {
        /// The predicate's id.
        id: String,
    },
    /// An expression used where its type does not fit.
    Type {
        /// What does not fit.
        message: String,
    },
    /// Text content where none is allowed.
    UnexpectedText {
        /// The element containing it.
        element: String,
    },
    /// The file is not well-formed JSON.
    Json(String),
    /// A JANI construct that is wrong or not supported here.
    Jani(String),
}

impl fmt::Display for PropsErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PropsErrorKind::Io(message) => write!(f, "cannot read the file: {message}"),
            PropsErrorKind::Encoding => write!(f, "the file is not valid UTF-8"),
            PropsErrorKind::Xml(message) => write!(f, "malformed XML: {message}"),
            PropsErrorKind::UnknownElement {
                name,
                parent,
                expected,
            } => {
                if parent.is_empty() {
                    write!(f, "unknown root element <{name}>: expected {expected}")
                } else {
                    write!(
                        f,
                        "unknown element <{name}> in <{parent}>: expected {expected}"
                    )
                }
            }
            PropsErrorKind::UnknownAttribute { element, name } => {
                write!(f, "unknown attribute `{name}` on <{element}>")
            }
            PropsErrorKind::MissingAttribute { element, name } => {
                write!(f, "<{element}> needs the attribute `{name}`")
            }
            PropsErrorKind::MissingElement { element, name } => {
                write!(f, "<{element}> needs a <{name}> element")
            }
            PropsErrorKind::RepeatedElement { element, name } => {
                write!(f, "<{element}> has more than one <{name}>")
            }
            PropsErrorKind::Arity {
                element,
                expected,
                found,
            } => write!(f, "<{element}> takes {expected}, found {found}"),
            PropsErrorKind::BadValue {
                attribute,
                value,
                expected,
            } => write!(f, "`{attribute}=\"{value}\"`: expected {expected}"),
            PropsErrorKind::Duplicate { what, id, first } => {
                write!(f, "{what} `{id}` is declared twice (first at {first})")
            }
            PropsErrorKind::UnknownReference { id } => {
                write!(f, "`{id}` is neither a declared variable nor a predicate")
            }
            PropsErrorKind::Cycle { id } => write!(f, "predicate `{id}` refers to itself"),
            PropsErrorKind::Type { message } => f.write_str(message),
            PropsErrorKind::UnexpectedText { element } => {
                write!(f, "unexpected text inside <{element}>")
            }
            PropsErrorKind::Json(message) => write!(f, "malformed JSON: {message}"),
            PropsErrorKind::Jani(message) => f.write_str(message),
        }
    }
}

/// One error in a property file: file, line, column, source line and caret, and the
/// kind of problem as its `message`.
pub type PropsError = codegen::diag::Diagnostic<PropsErrorKind>;

/// Every error found in a property file (at least one), in file order.
pub type Diagnostics = codegen::diag::Diagnostics<PropsErrorKind>;

/// An error at `at` of the file `path` whose text `lines` indexes, showing its line.
pub(crate) fn error_at(
    path: &std::path::Path,
    lines: &SourceFile<'_>,
    at: Location,
    kind: PropsErrorKind,
) -> PropsError {
    PropsError::error(path.display().to_string(), (at.line, at.column), kind)
        .with_snippet(lines.snippet(at))
}

/// Where a property error is, as a [`Location`].
pub fn location(error: &PropsError) -> Location {
    Location::new(error.line, error.col)
}
