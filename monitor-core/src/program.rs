//! The compiled form of a specification: variables, atom bytecode and temporal networks.
//!
//! A [`Program`] is a borrowed view over plain slices, so the same value can be
//! built by `codegen` on the host (from `Vec`s), loaded from a postcard table in
//! firmware (from `heapless::Vec`s borrowing the bytes) or written out as
//! `static` arrays by generated code. Nothing here is trusted: [`crate::Monitor::try_new`]
//! checks every index, type, stack depth and state offset before anything runs.
//!
//! Main types:
//! - [`Var`]: a declared input variable (event or state, typed, with its initial value).
//! - [`Instr`] / [`Atom`]: stack bytecode computing each atom from the variables.
//! - [`Node`] / [`Op`]: one node of a sequential network; children always come first.
//! - [`Property`]: one formula, a contiguous run of nodes whose last node is the root.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Index of a node in [`Program::nodes`].
pub type NodeId = u16;

/// The type of a variable or of an expression value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Ty {
    /// `true` / `false`.
    Bool,
    /// Signed 64-bit integer (every declared integer width is widened to this).
    Int,
    /// 64-bit IEEE float.
    Float,
    /// A string, interned: the value is an index into [`Program::strings`].
    Str,
}

/// A run-time value of a variable or of an expression.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Value {
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
    /// An interned string; ids at or past `strings.len()` equal no declared constant.
    Str(u32),
}

impl Value {
    /// The type of this value.
    pub const fn ty(&self) -> Ty {
        match self {
            Value::Bool(_) => Ty::Bool,
            Value::Int(_) => Ty::Int,
            Value::Float(_) => Ty::Float,
            Value::Str(_) => Ty::Str,
        }
    }
}

/// Whether a variable is an event (true only at the point of its message) or a state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum VarKind {
    /// True exactly at the point where its message is sent, false at every other point.
    /// Always of type [`Ty::Bool`] with initial value `false`.
    Event,
    /// Holds the last value sent, starting from [`Var::init`].
    State,
}

/// A declared input variable.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Var<'a> {
    /// The name used in the specification.
    pub name: &'a str,
    /// The value type; [`Value::ty`] of every value given for it must match.
    pub ty: Ty,
    /// Event or state variable.
    pub kind: VarKind,
    /// The value before any message sets it (`Bool(false)` for events).
    pub init: Value,
}

/// Numeric operand type of an arithmetic instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum NumTy {
    /// Checked `i64` arithmetic: overflow and division by zero are errors.
    Int,
    /// IEEE `f64` arithmetic.
    Float,
}

/// A comparison operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum CmpOp {
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

/// One instruction of the atom stack machine.
///
/// Operands are popped right first; every instruction names the types it
/// expects so that validation can type the whole program once.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Instr {
    /// Push a constant.
    Push(Value),
    /// Push the current value of variable `n`.
    Load(u16),
    /// Boolean negation.
    Not,
    /// Boolean conjunction of the two top values.
    And,
    /// Boolean disjunction of the two top values.
    Or,
    /// Arithmetic negation.
    Neg(NumTy),
    /// Addition.
    Add(NumTy),
    /// Subtraction.
    Sub(NumTy),
    /// Multiplication.
    Mul(NumTy),
    /// Division (integer division truncates toward zero).
    Div(NumTy),
    /// Remainder (sign of the dividend).
    Rem(NumTy),
    /// Compare two values of the given type; strings and booleans only by `Eq`/`Ne`.
    Cmp(CmpOp, Ty),
    /// Convert the integer on top of the stack to a float.
    ToFloat,
}

/// An atom: a range of [`Program::instrs`] that leaves exactly one boolean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Atom {
    /// First instruction.
    pub start: u16,
    /// Number of instructions (at least one).
    pub len: u16,
}

/// The operation of a network node. Children are node ids smaller than the node's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub enum Op {
    /// A constant.
    Const(bool),
    /// The value of atom `n` at this point.
    Atom(u16),
    /// `!a`
    Not(NodeId),
    /// `a && b`
    And(NodeId, NodeId),
    /// `a || b`
    Or(NodeId, NodeId),
    /// `a -> b`
    Implies(NodeId, NodeId),
    /// `a <-> b`
    Iff(NodeId, NodeId),
    /// `Y a`: false at the first point, else `a` at the previous point.
    Yesterday(NodeId),
    /// `Z a`: true at the first point, else `a` at the previous point.
    WeakYesterday(NodeId),
    /// `lhs S[lo:hi] rhs`; `hi == None` is unbounded. Invariant: `lo <= hi`.
    Since {
        /// The formula that must hold after the witness.
        lhs: NodeId,
        /// The witness formula.
        rhs: NodeId,
        /// Lower bound of `tau_i - tau_j`, inclusive.
        lo: u64,
        /// Upper bound of `tau_i - tau_j`, inclusive; `None` for no bound.
        hi: Option<u64>,
    },
}

/// One node of a network: its operation and where its state starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Node {
    /// What the node computes.
    pub op: Op,
    /// Index of the node's first state word; must equal the layout that
    /// [`crate::layout::node_words`] gives (checked on load). 0 for stateless nodes.
    pub slot: u32,
}

/// One compiled formula.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct Property<'a> {
    /// The property's name, as given in the specification.
    pub name: &'a str,
    /// First node of this property's network.
    pub first: NodeId,
    /// Root node: the last node of the network. Invariant: `first <= root`.
    pub root: NodeId,
}

/// A whole compiled specification, borrowed. Validate it with [`crate::Monitor::try_new`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize))]
pub struct Program<'a> {
    /// Length of one time unit in nanoseconds (informational: inputs are in units).
    pub tick_ns: u64,
    /// Declared variables, in input order.
    pub vars: &'a [Var<'a>],
    /// String constants; `Value::Str(i)` is `strings[i]`.
    pub strings: &'a [&'a str],
    /// Atom bytecode.
    pub instrs: &'a [Instr],
    /// Atoms, each a range of `instrs`.
    pub atoms: &'a [Atom],
    /// Nodes of every property, each property's nodes contiguous.
    pub nodes: &'a [Node],
    /// Properties, in order; their node ranges tile `nodes` in order.
    pub props: &'a [Property<'a>],
}
