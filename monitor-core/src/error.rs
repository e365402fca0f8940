//! Error values of the runtime: a rejected program and a step that could not be judged.

use core::fmt;

/// Why a [`crate::Program`] was rejected by [`crate::Monitor::try_new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum TableError {
    /// The bytes are not a postcard table of this format (or the capacity is too small).
    Decode,
    /// The table was written by an incompatible format version.
    Version {
        /// Version found in the table.
        found: u32,
    },
    /// A variable's initial value does not have its type, or an event is not a `false` boolean.
    Var {
        /// Index of the variable.
        var: u16,
    },
    /// An atom's bytecode is out of range, ill-typed, too deep or does not leave one boolean.
    Atom {
        /// Index of the atom.
        atom: u16,
    },
    /// An atom needs what this build of monitor-core left out: floating point
    /// (feature `float`) or integer division (feature `int-div`).
    Feature {
        /// Index of the atom.
        atom: u16,
    },
    /// A node refers to a later node, a node outside its property, or a missing atom.
    Node {
        /// Index of the node.
        node: u16,
    },
    /// A node's bounds are empty or its state offset is not the canonical layout.
    Layout {
        /// Index of the node.
        node: u16,
    },
    /// Property node ranges do not tile the nodes in order.
    Property {
        /// Index of the property.
        prop: u16,
    },
    /// More nodes, atoms or state words than the formats can address.
    TooLarge,
}

/// Why a point was not judged; the monitor state is unchanged when this is returned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum StepError {
    /// The point's timestamp is earlier than the previous point's.
    TimeWentBackwards {
        /// Timestamp of the previous point.
        last: u64,
        /// The rejected timestamp.
        now: u64,
    },
    /// `u64::MAX` is reserved and cannot be a timestamp.
    TimeOutOfRange,
    /// The state buffer does not have [`crate::Monitor::state_words`] words.
    StateSize {
        /// Words required.
        expected: usize,
        /// Words given.
        found: usize,
    },
    /// The variable or verdict slice has the wrong length.
    InputSize {
        /// Length required.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// A variable's value does not have its declared type.
    VarType {
        /// Index of the variable.
        var: u16,
    },
    /// Integer overflow or division by zero while computing an atom.
    Arithmetic {
        /// Index of the atom.
        atom: u16,
    },
}

impl TableError {
    /// The kind of error as one number, for logs that have no room for the
    /// messages (firmware): 1 [`TableError::Decode`], 2 `Version`, 3 `Var`,
    /// 4 `Atom`, 5 `Feature`, 6 `Node`, 7 `Layout`, 8 `Property`, 9 `TooLarge`.
    /// The host's `Display` of the same table says which element.
    pub const fn code(&self) -> u8 {
        match self {
            TableError::Decode => 1,
            TableError::Version { .. } => 2,
            TableError::Var { .. } => 3,
            TableError::Atom { .. } => 4,
            TableError::Feature { .. } => 5,
            TableError::Node { .. } => 6,
            TableError::Layout { .. } => 7,
            TableError::Property { .. } => 8,
            TableError::TooLarge => 9,
        }
    }
}

impl StepError {
    /// The kind of error as one number, for logs that have no room for the
    /// messages (firmware): 1 [`StepError::TimeWentBackwards`], 2
    /// `TimeOutOfRange`, 3 `StateSize`, 4 `InputSize`, 5 `VarType`, 6 `Arithmetic`.
    pub const fn code(&self) -> u8 {
        match self {
            StepError::TimeWentBackwards { .. } => 1,
            StepError::TimeOutOfRange => 2,
            StepError::StateSize { .. } => 3,
            StepError::InputSize { .. } => 4,
            StepError::VarType { .. } => 5,
            StepError::Arithmetic { .. } => 6,
        }
    }
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableError::Decode => write!(f, "not a valid monitor table"),
            TableError::Version { found } => write!(f, "unsupported table version {found}"),
            TableError::Var { var } => write!(f, "variable {var}: bad type or initial value"),
            TableError::Atom { atom } => write!(f, "atom {atom}: invalid bytecode"),
            TableError::Feature { atom } => write!(
                f,
                "atom {atom}: needs floating point or integer division, which this build leaves out (monitor-core features `float`, `int-div`)"
            ),
            TableError::Node { node } => write!(f, "node {node}: invalid operand"),
            TableError::Layout { node } => write!(f, "node {node}: invalid bounds or state slot"),
            TableError::Property { prop } => write!(f, "property {prop}: invalid node range"),
            TableError::TooLarge => write!(f, "program too large to address"),
        }
    }
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::TimeWentBackwards { last, now } => {
                write!(f, "timestamp {now} is before the previous point's {last}")
            }
            StepError::TimeOutOfRange => write!(f, "timestamp u64::MAX is reserved"),
            StepError::StateSize { expected, found } => {
                write!(f, "state buffer has {found} words, needs {expected}")
            }
            StepError::InputSize { expected, found } => {
                write!(f, "input slice has {found} elements, needs {expected}")
            }
            StepError::VarType { var } => write!(f, "variable {var}: value of the wrong type"),
            StepError::Arithmetic { atom } => {
                write!(f, "atom {atom}: integer overflow or division by zero")
            }
        }
    }
}

impl core::error::Error for TableError {}
impl core::error::Error for StepError {}

#[cfg(test)]
mod tests {
    use super::{StepError, TableError};

    #[test]
    fn codes_tell_every_kind_apart() {
        let table = [
            TableError::Decode,
            TableError::Version { found: 2 },
            TableError::Var { var: 1 },
            TableError::Atom { atom: 1 },
            TableError::Feature { atom: 1 },
            TableError::Node { node: 1 },
            TableError::Layout { node: 1 },
            TableError::Property { prop: 1 },
            TableError::TooLarge,
        ];
        let codes: [u8; 9] = table.map(|e| e.code());
        assert_eq!(codes, [1, 2, 3, 4, 5, 6, 7, 8, 9]);
        let step = [
            StepError::TimeWentBackwards { last: 2, now: 1 },
            StepError::TimeOutOfRange,
            StepError::StateSize {
                expected: 1,
                found: 2,
            },
            StepError::InputSize {
                expected: 1,
                found: 2,
            },
            StepError::VarType { var: 0 },
            StepError::Arithmetic { atom: 0 },
        ];
        let codes: [u8; 6] = step.map(|e| e.code());
        assert_eq!(codes, [1, 2, 3, 4, 5, 6]);
    }
}
