//! Loading a postcard-serialised program into fixed-capacity storage, validated (feature `postcard`).
//!
//! The wire format is `(TABLE_VERSION: u32, Program)` in postcard encoding: the
//! host writes it with `postcard::to_allocvec(&(TABLE_VERSION, program))`
//! (`codegen` does this). Two loaders read it back without allocating,
//! borrowing names and strings from the bytes, and run every check of
//! [`Monitor::try_new`] before handing out a program:
//!
//! - [`Store`]: one `heapless` vector per program vector, each with its own
//!   capacity (const parameters: build scripts size them exactly for one
//!   table), filled in place: the RAM of the decoded program and nothing
//!   more, and a decode that keeps one element on the stack at a time. For
//!   firmware: put the `Store` in a `static` and call [`Store::load`].
//! - [`Table`]: a `Store` with one capacity `N` for every vector, returned by
//!   value from [`Store::from_bytes`], for hosts that do not know the table's
//!   shape in advance.
//!
//! Both read the program as a stream: the header, then each vector as its
//! length and its elements one at a time ([`read_program`]), never the whole
//! program as one serde value (which would build it in stack temporaries).

use heapless::Vec;
use serde::Deserialize;

use crate::error::TableError;
use crate::monitor::Monitor;
use crate::program::{Atom, Instr, Node, Program, Property, Var};

/// Version of the table wire format; bump on any change to the program types.
pub const TABLE_VERSION: u32 = 1;

/// One postcard value from the front of `rest`, advancing it.
fn take<'a, T: Deserialize<'a>>(rest: &mut &'a [u8]) -> Result<T, TableError> {
    let (value, tail) = postcard::take_from_bytes::<T>(rest).map_err(|_| TableError::Decode)?;
    *rest = tail;
    Ok(value)
}

/// One postcard sequence (length, then elements) from the front of `rest`,
/// handing element `i` to `put(i, element)`; `put` returns `false` when there
/// is no room for it, which is a [`TableError::Decode`] like any other corrupt input.
fn take_seq<'a, T: Deserialize<'a>>(
    rest: &mut &'a [u8],
    mut put: impl FnMut(usize, T) -> bool,
) -> Result<usize, TableError> {
    // postcard writes a sequence length as a varint `usize`; for lengths below
    // 2^32 its bytes are those of a varint `u32` (postcard's wire spec, "varint").
    let len = take::<u32>(rest)? as usize;
    for i in 0..len {
        let element = take::<T>(rest)?;
        if !put(i, element) {
            return Err(TableError::Decode);
        }
    }
    Ok(len)
}

/// Where [`read_program`] puts each element of a table, as it reads it.
///
/// Each method gets the element's index and the element, and returns `false`
/// when it has no room for it.
pub trait Sink<'a> {
    /// The program's `tick_ns`.
    fn tick_ns(&mut self, tick_ns: u64);
    /// Variable `i`.
    fn var(&mut self, i: usize, v: Var<'a>) -> bool;
    /// String constant `i`.
    fn string(&mut self, i: usize, s: &'a str) -> bool;
    /// Instruction `i`.
    fn instr(&mut self, i: usize, ins: Instr) -> bool;
    /// Atom `i`.
    fn atom(&mut self, i: usize, a: Atom) -> bool;
    /// Node `i`.
    fn node(&mut self, i: usize, n: Node) -> bool;
    /// Property `i`.
    fn prop(&mut self, i: usize, p: Property<'a>) -> bool;
}

/// The number of elements of each vector of a decoded program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    /// Variables.
    pub vars: usize,
    /// String constants.
    pub strings: usize,
    /// Instructions.
    pub instrs: usize,
    /// Atoms.
    pub atoms: usize,
    /// Nodes.
    pub nodes: usize,
    /// Properties.
    pub props: usize,
}

/// Reads a whole table from `bytes` into `sink`, element by element: the
/// version, then the program's fields in declaration order (postcard encodes a
/// struct as its fields in order, a sequence as a varint length and its
/// elements). Corrupt, truncated or trailing bytes, a foreign version or an
/// element the sink has no room for give an error; nothing is validated
/// beyond the encoding (that is [`Monitor::try_new`]'s job).
pub fn read_program<'a>(bytes: &'a [u8], sink: &mut impl Sink<'a>) -> Result<Counts, TableError> {
    let mut rest = bytes;
    let version = take::<u32>(&mut rest)?;
    if version != TABLE_VERSION {
        return Err(TableError::Version { found: version });
    }
    sink.tick_ns(take::<u64>(&mut rest)?);
    let counts = Counts {
        vars: take_seq(&mut rest, |i, v| sink.var(i, v))?,
        strings: take_seq(&mut rest, |i, s| sink.string(i, s))?,
        instrs: take_seq(&mut rest, |i, ins| sink.instr(i, ins))?,
        atoms: take_seq(&mut rest, |i, a| sink.atom(i, a))?,
        nodes: take_seq(&mut rest, |i, n| sink.node(i, n))?,
        props: take_seq(&mut rest, |i, p| sink.prop(i, p))?,
    };
    if !rest.is_empty() {
        return Err(TableError::Decode);
    }
    Ok(counts)
}

/// Storage for one decoded program: `heapless` vectors with room for `V`
/// variables, `S` strings, `I` instructions, `A` atoms, `N` nodes and `P`
/// properties. [`Store::new`] is `const` and leaves the room uninitialised, so
/// a store can live in a `static` with no image in flash; [`Store::load`]
/// decodes into it in place. With each capacity exactly what one table needs,
/// the store is the RAM of the decoded program and nothing more.
#[derive(Debug)]
pub struct Store<
    'a,
    const V: usize,
    const S: usize,
    const I: usize,
    const A: usize,
    const N: usize,
    const P: usize,
> {
    tick_ns: u64,
    vars: Vec<Var<'a>, V>,
    strings: Vec<&'a str, S>,
    instrs: Vec<Instr, I>,
    atoms: Vec<Atom, A>,
    nodes: Vec<Node, N>,
    props: Vec<Property<'a>, P>,
}

/// A store with one capacity `N` for every vector, for hosts that do not know
/// a table's shape in advance ([`Store::from_bytes`]).
pub type Table<'a, const N: usize> = Store<'a, N, N, N, N, N, N>;

impl<
        'a,
        const V: usize,
        const S: usize,
        const I: usize,
        const A: usize,
        const N: usize,
        const P: usize,
    > Store<'a, V, S, I, A, N, P>
{
    /// An empty store.
    pub const fn new() -> Self {
        Store {
            tick_ns: 0,
            vars: Vec::new(),
            strings: Vec::new(),
            instrs: Vec::new(),
            atoms: Vec::new(),
            nodes: Vec::new(),
            props: Vec::new(),
        }
    }

    /// Decodes `bytes` into this store, in place, and validates the program
    /// with [`Monitor::try_new`]. Corrupt or truncated bytes, trailing bytes,
    /// a foreign version or more elements of some kind than the store has room
    /// for give an error, never a panic. After an error, [`Store::program`]
    /// shows whatever was decoded, unvalidated.
    pub fn load(&mut self, bytes: &'a [u8]) -> Result<Monitor<'_>, TableError> {
        self.vars.clear();
        self.strings.clear();
        self.instrs.clear();
        self.atoms.clear();
        self.nodes.clear();
        self.props.clear();
        read_program(bytes, self)?;
        Monitor::try_new(self.program())
    }

    /// Decodes and validates a table into a new store, returned by value (on
    /// a host; firmware should [`Store::load`] into a `static` instead).
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, TableError> {
        let mut store = Self::new();
        store.load(bytes)?;
        Ok(store)
    }

    /// The program, borrowed from this store (empty before [`Store::load`]).
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

    /// The validated monitor for this store's program.
    pub fn monitor(&self) -> Result<Monitor<'_>, TableError> {
        Monitor::try_new(self.program())
    }
}

impl<
        'a,
        const V: usize,
        const S: usize,
        const I: usize,
        const A: usize,
        const N: usize,
        const P: usize,
    > Default for Store<'a, V, S, I, A, N, P>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<
        'a,
        const V: usize,
        const S: usize,
        const I: usize,
        const A: usize,
        const N: usize,
        const P: usize,
    > Sink<'a> for Store<'a, V, S, I, A, N, P>
{
    fn tick_ns(&mut self, tick_ns: u64) {
        self.tick_ns = tick_ns;
    }
    fn var(&mut self, _: usize, v: Var<'a>) -> bool {
        self.vars.push(v).is_ok()
    }
    fn string(&mut self, _: usize, s: &'a str) -> bool {
        self.strings.push(s).is_ok()
    }
    fn instr(&mut self, _: usize, ins: Instr) -> bool {
        self.instrs.push(ins).is_ok()
    }
    fn atom(&mut self, _: usize, a: Atom) -> bool {
        self.atoms.push(a).is_ok()
    }
    fn node(&mut self, _: usize, n: Node) -> bool {
        self.nodes.push(n).is_ok()
    }
    fn prop(&mut self, _: usize, p: Property<'a>) -> bool {
        self.props.push(p).is_ok()
    }
}
