//! `defmt::Format` for the runtime's error values (feature `defmt`), for firmware logs.

use crate::error::{StepError, TableError};

impl defmt::Format for StepError {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            StepError::TimeWentBackwards { last, now } => {
                defmt::write!(f, "time went backwards: {=u64} < {=u64}", now, last)
            }
            StepError::TimeOutOfRange => defmt::write!(f, "timestamp out of range"),
            StepError::StateSize { expected, found } => {
                defmt::write!(f, "state size {=usize}, expected {=usize}", found, expected)
            }
            StepError::InputSize { expected, found } => {
                defmt::write!(f, "input size {=usize}, expected {=usize}", found, expected)
            }
            StepError::VarType { var } => defmt::write!(f, "variable {=u16}: wrong type", var),
            StepError::Arithmetic { atom } => {
                defmt::write!(f, "atom {=u16}: arithmetic error", atom)
            }
        }
    }
}

impl defmt::Format for TableError {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            TableError::Decode => defmt::write!(f, "table: decode error"),
            TableError::Version { found } => defmt::write!(f, "table: version {=u32}", found),
            TableError::Var { var } => defmt::write!(f, "table: variable {=u16}", var),
            TableError::Atom { atom } => defmt::write!(f, "table: atom {=u16}", atom),
            TableError::Feature { atom } => {
                defmt::write!(f, "table: atom {=u16} needs float or int-div", atom)
            }
            TableError::Node { node } => defmt::write!(f, "table: node {=u16}", node),
            TableError::Layout { node } => defmt::write!(f, "table: layout of node {=u16}", node),
            TableError::Property { prop } => defmt::write!(f, "table: property {=u16}", prop),
            TableError::TooLarge => defmt::write!(f, "table: too large"),
        }
    }
}
