//! Loading a postcard-serialised program into fixed-capacity storage, validated (feature `postcard`).
//!
//! The wire format is `(TABLE_VERSION: u32, Program)` in postcard encoding: the
//! host writes it with `postcard::to_allocvec(&(TABLE_VERSION, program))`
//! (`codegen` does this); [`Table::from_bytes`] reads it back without
//! allocating, borrowing names and strings from the bytes, and runs every
//! check of [`Monitor::try_new`] before handing out a monitor.

use heapless::Vec;
use serde::Deserialize;

use crate::error::TableError;
use crate::monitor::Monitor;
use crate::program::{Atom, Instr, Node, Program, Property, Var};

/// Version of the table wire format; bump on any change to the program types.
pub const TABLE_VERSION: u32 = 1;

/// A deserialised program in fixed-capacity vectors of at most `N` elements each.
#[derive(Debug, Deserialize)]
pub struct Table<'a, const N: usize> {
    tick_ns: u64,
    #[serde(borrow)]
    vars: Vec<Var<'a>, N>,
    #[serde(borrow)]
    strings: Vec<&'a str, N>,
    instrs: Vec<Instr, N>,
    atoms: Vec<Atom, N>,
    nodes: Vec<Node, N>,
    #[serde(borrow)]
    props: Vec<Property<'a>, N>,
}

impl<'a, const N: usize> Table<'a, N> {
    /// Decodes and validates a table. Corrupt or truncated bytes, trailing bytes,
    /// a foreign version or a table larger than `N` give an error, never a panic.
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, TableError> {
        let (version, rest) =
            postcard::take_from_bytes::<u32>(bytes).map_err(|_| TableError::Decode)?;
        if version != TABLE_VERSION {
            return Err(TableError::Version { found: version });
        }
        // A vector longer than `N` fails to decode like any other corrupt input.
        let (table, rest) =
            postcard::take_from_bytes::<Self>(rest).map_err(|_| TableError::Decode)?;
        if !rest.is_empty() {
            return Err(TableError::Decode);
        }
        Monitor::try_new(table.program())?;
        Ok(table)
    }

    /// The program, borrowed from this table.
    pub fn program(&self) -> Program<'_> {
        Program {
            tick_ns: self.tick_ns,
            vars: &self.vars,
            strings: &self.strings,
            instrs: &self.instrs,
            atoms: &self.atoms,
            nodes: &self.nodes,
            props: &self.props,
        }
    }

    /// The validated monitor for this table.
    pub fn monitor(&self) -> Result<Monitor<'_>, TableError> {
        Monitor::try_new(self.program())
    }
}
