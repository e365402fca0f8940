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
//! program as one value (which serde would build in stack temporaries), and
//! with a reader of postcard's encoding written for these types rather than
//! serde's generic one (a fraction of its code size).

use heapless::Vec;

use crate::error::TableError;
use crate::monitor::Monitor;
use crate::program::{
    Atom, CmpOp, Instr, Node, NumTy, Op, Program, Property, Ty, Value, Var, VarKind,
};

/// Version of the table wire format; bump on any change to the program types.
pub const TABLE_VERSION: u32 = 1;

/// A cursor over table bytes that reads postcard's encoding of the program
/// types directly, without serde: the decoder of a firmware image is then a
/// few small functions instead of serde's generic visitors (several KiB).
///
/// The rules, from postcard's wire format (its `spec/` and
/// `postcard::de::deserializer::Deserializer`, read for the rules only):
/// - `u16`/`u32`/`u64` (and lengths, `usize`) are unsigned LEB128 varints of
///   at most 3/5/10 bytes whose last byte may not carry bits beyond the type
///   (`try_take_varint_u*`); `i64` is the varint of its zigzag encoding;
/// - `bool` is one byte, 0 or 1; `f64` 8 bytes little-endian; `Option` a
///   byte 0 (None) or 1 followed by the value;
/// - `&str` a varint length and that many bytes of UTF-8;
/// - an enum the varint `u32` index of its variant (in declaration order,
///   as serde derives it) followed by the variant's fields; a struct or tuple
///   its fields in order; a sequence a varint length and its elements.
///
/// Each `program.rs` type's derived `Serialize` writes exactly this;
/// `tests/validate.rs` checks the reader against postcard on every variant.
///
/// A corrupt or truncated input sets `bad` and the reader goes on with zeros
/// (each element reads at least one byte, and every sequence stops at the
/// first element read after that): one test per element and one at the end
/// instead of a branch after every field (code size), with the same result,
/// [`TableError::Decode`].
struct Reader<'a> {
    rest: &'a [u8],
    bad: bool,
}

impl<'a> Reader<'a> {
    /// Marks the input corrupt; returns `T`'s zero to go on with.
    #[cold]
    fn fail<T: Default>(&mut self) -> T {
        self.bad = true;
        T::default()
    }

    fn byte(&mut self) -> u8 {
        match self.rest.split_first() {
            Some((&b, rest)) => {
                self.rest = rest;
                b
            }
            None => self.fail(),
        }
    }

    /// A varint of a type of `bits` bits (16, 32 or 64).
    fn varint(&mut self, bits: u32) -> u64 {
        // `bits.div_ceil(7)` for the widths read (16, 32, 64): without a
        // division, a library routine on a Cortex-M0 (no divide instruction).
        let max_bytes = match bits {
            16 => 3,
            32 => 5,
            _ => 10,
        };
        let mut out = 0u64;
        for i in 0..max_bytes {
            let b = self.byte();
            let low = (b & 0x7f) as u64;
            if i == max_bytes - 1 && (b & 0x80 != 0 || low >> (bits - 7 * i) != 0) {
                break;
            }
            out |= low << (7 * i);
            if b & 0x80 == 0 {
                return out;
            }
        }
        self.fail()
    }

    fn u16(&mut self) -> u16 {
        self.varint(16) as u16
    }

    fn u32(&mut self) -> u32 {
        self.varint(32) as u32
    }

    fn u64(&mut self) -> u64 {
        self.varint(64)
    }

    fn i64(&mut self) -> i64 {
        let z = self.varint(64);
        (z >> 1) as i64 ^ -((z & 1) as i64)
    }

    fn bool(&mut self) -> bool {
        match self.byte() {
            0 => false,
            1 => true,
            _ => self.fail(),
        }
    }

    fn f64(&mut self) -> f64 {
        match self.rest.split_first_chunk::<8>() {
            Some((bytes, rest)) => {
                self.rest = rest;
                f64::from_le_bytes(*bytes)
            }
            None => self.fail(),
        }
    }

    fn str(&mut self) -> &'a str {
        let len = self.varint(usize::BITS) as usize;
        let Some((bytes, rest)) = self.rest.split_at_checked(len) else {
            return self.fail();
        };
        self.rest = rest;
        // Valid UTF-8 is one chunk with no invalid bytes after it: the same
        // answer as `str::from_utf8`, whose word-at-a-time validator is
        // larger in firmware (52-64 B of flash).
        let mut chunks = bytes.utf8_chunks();
        match chunks.next() {
            None => "",
            Some(c) if c.invalid().is_empty() && c.valid().len() == bytes.len() => c.valid(),
            Some(_) => self.fail(),
        }
    }

    /// A variant index (postcard writes it as a varint `u32`).
    fn variant(&mut self) -> u32 {
        self.u32()
    }

    /// A value, written into `out` where it will live: returned by value,
    /// its 15 bytes after the tag were copied through `memcpy` (not
    /// otherwise linked on a Cortex-M4F: 742 B of flash).
    fn value(&mut self, out: &mut Value) {
        *out = match self.variant() {
            0 => Value::Bool(self.bool()),
            1 => Value::Int(self.i64()),
            2 => Value::Float(self.f64()),
            3 => Value::Str(self.u32()),
            _ => Value::Bool(self.fail()),
        };
    }

    fn ty(&mut self) -> Ty {
        match self.variant() {
            0 => Ty::Bool,
            1 => Ty::Int,
            2 => Ty::Float,
            3 => Ty::Str,
            _ => {
                self.bad = true;
                Ty::Bool
            }
        }
    }

    fn num_ty(&mut self) -> NumTy {
        match self.variant() {
            0 => NumTy::Int,
            1 => NumTy::Float,
            _ => {
                self.bad = true;
                NumTy::Int
            }
        }
    }

    fn cmp_op(&mut self) -> CmpOp {
        match self.variant() {
            0 => CmpOp::Eq,
            1 => CmpOp::Ne,
            2 => CmpOp::Lt,
            3 => CmpOp::Le,
            4 => CmpOp::Gt,
            5 => CmpOp::Ge,
            _ => {
                self.bad = true;
                CmpOp::Eq
            }
        }
    }

    /// A variable, written into `out` field by field: returned by value it
    /// was copied once more through `memcpy` (code size).
    fn var(&mut self, out: &mut Var<'a>) {
        out.name = self.str();
        out.ty = self.ty();
        out.kind = match self.variant() {
            0 => VarKind::Event,
            1 => VarKind::State,
            _ => {
                self.bad = true;
                VarKind::Event
            }
        };
        self.value(&mut out.init);
    }

    fn instr(&mut self) -> Instr {
        let v = self.variant();
        // The arithmetic variants' one field is read at one call site (code size).
        let n = if matches!(v, 5..=10) {
            self.num_ty()
        } else {
            NumTy::Int
        };
        match v {
            0 => {
                let mut v = Value::Bool(false);
                self.value(&mut v);
                Instr::Push(v)
            }
            1 => Instr::Load(self.u16()),
            2 => Instr::Not,
            3 => Instr::And,
            4 => Instr::Or,
            5 => Instr::Neg(n),
            6 => Instr::Add(n),
            7 => Instr::Sub(n),
            8 => Instr::Mul(n),
            9 => Instr::Div(n),
            10 => Instr::Rem(n),
            11 => Instr::Cmp(self.cmp_op(), self.ty()),
            12 => Instr::ToFloat,
            _ => {
                self.bad = true;
                Instr::Not
            }
        }
    }

    fn atom(&mut self) -> Atom {
        Atom {
            start: self.u16(),
            len: self.u16(),
        }
    }

    fn node(&mut self) -> Node {
        let v = self.variant();
        // Every variant but `Const` starts with one or two ids, read at one call
        // site each (code size), in the order postcard writes them.
        let a = if matches!(v, 1..=9) { self.u16() } else { 0 };
        let b = if matches!(v, 3..=6 | 9) {
            self.u16()
        } else {
            0
        };
        let op = match v {
            0 => Op::Const(self.bool()),
            1 => Op::Atom(a),
            2 => Op::Not(a),
            3 => Op::And(a, b),
            4 => Op::Or(a, b),
            5 => Op::Implies(a, b),
            6 => Op::Iff(a, b),
            7 => Op::Yesterday(a),
            8 => Op::WeakYesterday(a),
            9 => Op::Since {
                lhs: a,
                rhs: b,
                lo: self.u64(),
                hi: match self.byte() {
                    0 => None,
                    1 => Some(self.u64()),
                    _ => self.fail(),
                },
            },
            _ => Op::Const(self.fail()),
        };
        Node {
            op,
            slot: self.u32(),
        }
    }

    fn prop(&mut self) -> Property<'a> {
        Property {
            name: self.str(),
            first: self.u16(),
            root: self.u16(),
        }
    }
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
    let mut r = Reader {
        rest: bytes,
        bad: false,
    };
    let version = r.u32();
    if r.bad {
        return Err(TableError::Decode);
    }
    if version != TABLE_VERSION {
        return Err(TableError::Version { found: version });
    }
    read_body(&mut r, sink).ok_or(TableError::Decode)
}

/// [`read_program`] after the version; `None`: corrupt bytes.
///
/// The six sequences are read by one loop, each as its length and its
/// elements, each element handed to the sink as soon as it is read (`false`
/// from the sink: no room, corrupt input like any other). No element read
/// after the input turned out corrupt is handed on. One loop rather than one
/// per element type (code size).
fn read_body<'a>(r: &mut Reader<'a>, sink: &mut impl Sink<'a>) -> Option<Counts> {
    let tick_ns = r.u64();
    if r.bad {
        return None;
    }
    sink.tick_ns(tick_ns);
    let mut counts = [0usize; 6];
    for (kind, count) in counts.iter_mut().enumerate() {
        let len = r.varint(usize::BITS) as usize;
        for i in 0..len {
            let room = match kind {
                0 => {
                    // Read in place: a `Var` returned by value was copied
                    // once more through `memcpy` (code size).
                    let mut v = Var {
                        name: "",
                        ty: Ty::Bool,
                        kind: VarKind::Event,
                        init: Value::Bool(false),
                    };
                    r.var(&mut v);
                    !r.bad && sink.var(i, v)
                }
                1 => {
                    let s = r.str();
                    !r.bad && sink.string(i, s)
                }
                2 => {
                    let ins = r.instr();
                    !r.bad && sink.instr(i, ins)
                }
                3 => {
                    let a = r.atom();
                    !r.bad && sink.atom(i, a)
                }
                4 => {
                    let n = r.node();
                    !r.bad && sink.node(i, n)
                }
                _ => {
                    let p = r.prop();
                    !r.bad && sink.prop(i, p)
                }
            };
            if !room {
                return None;
            }
        }
        if r.bad {
            return None;
        }
        *count = len;
    }
    let [vars, strings, instrs, atoms, nodes, props] = counts;
    r.rest.is_empty().then_some(Counts {
        vars,
        strings,
        instrs,
        atoms,
        nodes,
        props,
    })
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
        // Field by field: a copy of the whole `Var` went through `memcpy`
        // in pieces (its only calls on a Cortex-M0: 600 B of flash).
        self.vars
            .push(Var {
                name: v.name,
                ty: v.ty,
                kind: v.kind,
                init: match v.init {
                    Value::Bool(b) => Value::Bool(b),
                    Value::Int(i) => Value::Int(i),
                    Value::Float(f) => Value::Float(f),
                    Value::Str(s) => Value::Str(s),
                },
            })
            .is_ok()
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

#[cfg(test)]
mod tests {
    use super::Reader;

    #[test]
    fn strings_are_utf8_checked_like_from_utf8() {
        let cases: [&[u8]; 8] = [
            b"",
            b"battery_level",
            "caf\u{e9} \u{1f600}".as_bytes(),
            b"\xff",
            b"ab\xc3",
            b"\xc3\x28",
            b"ok\xed\xa0\x80",
            b"\xf4\x90\x80\x80",
        ];
        for bytes in cases {
            let mut encoded = [0u8; 16];
            encoded[0] = bytes.len() as u8;
            encoded[1..=bytes.len()].copy_from_slice(bytes);
            let mut r = Reader {
                rest: &encoded[..=bytes.len()],
                bad: false,
            };
            let s = r.str();
            let read = (!r.bad).then_some(s);
            assert_eq!(read, core::str::from_utf8(bytes).ok(), "{bytes:?}");
        }
    }
}
