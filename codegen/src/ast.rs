//! The checked AST: what a specification means once names, types and time bounds are resolved.
//!
//! This is the level a reference evaluator works on (the tests crate has one):
//! no syntax left, every name an index, every bound in ticks of the spec's unit.
//!
//! Main types:
//! - [`CheckedSpec`]: time unit, variables, interned strings and properties.
//! - [`VarDecl`]: one input variable, with its [`monitor_core::Ty`] and initial value.
//! - [`Formula`] / [`FormulaKind`]: Past-MTL over atoms, with [`Interval`]s in ticks.
//!   `O`/`P` and `H` are kept as written ([`FormulaKind::Once`], [`FormulaKind::Historically`]);
//!   the lowering to `S` happens later, when networks are built.
//! - [`Expr`] / [`ExprKind`]: an atom, a typed expression. Every node carries its
//!   type; int/float mixes have an explicit [`ExprKind::ToFloat`].
//!
//! Invariants (established by the checker): atoms have type `Bool`; the operands
//! of an arithmetic operator both have the operator's result type (`Int` or
//! `Float`); the operands of a comparison have the same type, and `Bool`/`Str`
//! are only compared by `==`/`!=`; `Var(i)` indexes [`CheckedSpec::vars`];
//! `Value::Str(i)` indexes [`CheckedSpec::strings`]; every interval has `lo <= hi`.
//!
//! Every node keeps the [`Span`] it was written at; a node that the checker
//! inserted (a `ToFloat`) gets the span of the operand it converts.

use monitor_core::{CmpOp, Ty, Value, VarKind};

use crate::diag::Span;

/// A whole checked specification.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedSpec {
    /// Length of one time unit (tick) in nanoseconds; every timestamp and bound is in ticks.
    pub tick_ns: u64,
    /// Input variables, in declaration order; [`ExprKind::Var`] indexes this.
    pub vars: Vec<VarDecl>,
    /// String constants, interned; `Value::Str(i)` is `strings[i]`.
    pub strings: Vec<String>,
    /// The properties, in declaration order.
    pub properties: Vec<PropertyDef>,
}

/// A declared input variable.
#[derive(Clone, Debug, PartialEq)]
pub struct VarDecl {
    /// The variable's name.
    pub name: String,
    /// Its run-time type (every integer width is `Int`, every float width `Float`).
    pub ty: Ty,
    /// Event (true only at its point) or state (keeps its last value).
    pub kind: VarKind,
    /// The value before any message sets it (`Bool(false)` for events).
    pub init: Value,
    /// The type as written (`u8`, `f32`, `string`, ...; `bool` for events), for emitters.
    pub type_name: String,
    /// Where it was declared.
    pub span: Span,
}

/// A named property.
#[derive(Clone, Debug, PartialEq)]
pub struct PropertyDef {
    /// The property's name, unique in the spec.
    pub name: String,
    /// Its formula.
    pub formula: Formula,
    /// The whole declaration.
    pub span: Span,
}

/// A closed interval of ticks `[lo, hi]`; `hi == None` means no upper bound.
///
/// Invariant: `lo <= hi` when `hi` is `Some`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Interval {
    /// Smallest distance allowed, inclusive.
    pub lo: u64,
    /// Largest distance allowed, inclusive; `None` for unbounded.
    pub hi: Option<u64>,
}

impl Interval {
    /// `[0, inf)`: no constraint.
    pub const ALWAYS: Interval = Interval { lo: 0, hi: None };

    /// `true` when the distance `d` (in ticks) lies in the interval.
    pub fn contains(&self, d: u64) -> bool {
        d >= self.lo && self.hi.is_none_or(|hi| d <= hi)
    }

    /// `true` for `[0, inf)`.
    pub(crate) fn is_unbounded(&self) -> bool {
        *self == Self::ALWAYS
    }
}

/// A checked Past-MTL formula with its span.
#[derive(Clone, Debug, PartialEq)]
pub struct Formula {
    /// What the formula is.
    pub kind: FormulaKind,
    /// Where it was written.
    pub span: Span,
}

/// The operators of Past-MTL (semantics: `docs/SEMANTICS.md` section 4).
#[derive(Clone, Debug, PartialEq)]
pub enum FormulaKind {
    /// `true` / `false`.
    Const(bool),
    /// `{expr}`: a boolean expression over the variables at this point.
    Atom(Expr),
    /// `!f`
    Not(Box<Formula>),
    /// `f && g`
    And(Box<Formula>, Box<Formula>),
    /// `f || g`
    Or(Box<Formula>, Box<Formula>),
    /// `f -> g`
    Implies(Box<Formula>, Box<Formula>),
    /// `f <-> g`
    Iff(Box<Formula>, Box<Formula>),
    /// `Y f`: false at the first point, else `f` at the previous point.
    Yesterday(Box<Formula>),
    /// `Z f`: true at the first point, else `f` at the previous point.
    WeakYesterday(Box<Formula>),
    /// `P[I] f` (also `O`, `once`): `f` at some earlier-or-current point at a distance in `I`.
    Once(Interval, Box<Formula>),
    /// `H[I] f` (also `historically`): `f` at every earlier-or-current point at a distance in `I`.
    Historically(Interval, Box<Formula>),
    /// `f S[I] g` (also `since`): some point j at a distance in `I` has `g`,
    /// and `f` holds at every point after j up to and including this one.
    Since(Interval, Box<Formula>, Box<Formula>),
}

/// A unary operator of atom expressions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum UnaryOp {
    /// Arithmetic negation `-e` (type `Int` or `Float`).
    Neg,
    /// Boolean negation `!e` / `not e`.
    Not,
}

/// A binary operator of atom expressions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/` (integer division truncates toward zero)
    Div,
    /// `%` (sign of the dividend)
    Rem,
    /// A comparison `== != < <= > >=`.
    Cmp(CmpOp),
    /// `&&` / `and` (both sides are evaluated)
    And,
    /// `||` / `or` (both sides are evaluated)
    Or,
}

impl BinaryOp {
    /// The operator as written in the surface syntax.
    pub fn symbol(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
            BinaryOp::Rem => "%",
            BinaryOp::Cmp(CmpOp::Eq) => "==",
            BinaryOp::Cmp(CmpOp::Ne) => "!=",
            BinaryOp::Cmp(CmpOp::Lt) => "<",
            BinaryOp::Cmp(CmpOp::Le) => "<=",
            BinaryOp::Cmp(CmpOp::Gt) => ">",
            BinaryOp::Cmp(CmpOp::Ge) => ">=",
            BinaryOp::And => "&&",
            BinaryOp::Or => "||",
        }
    }
}

/// A typed atom expression with its span.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// What the expression computes.
    pub kind: ExprKind,
    /// Its type.
    pub ty: Ty,
    /// Where it was written.
    pub span: Span,
}

/// The forms of an atom expression.
#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// A constant (strings are interned: `Value::Str(i)` is [`CheckedSpec::strings`]`[i]`).
    Const(Value),
    /// The current value of variable `i` of [`CheckedSpec::vars`].
    Var(u16),
    /// `op e`; `Neg` has the operand's numeric type, `Not` is `Bool`.
    Unary(UnaryOp, Box<Expr>),
    /// `a op b`; see the module invariants for operand types.
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// An `Int` operand converted to `Float` (inserted by the checker).
    ToFloat(Box<Expr>),
}
