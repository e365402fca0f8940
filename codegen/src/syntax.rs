//! The parsed (unchecked) syntax tree: what was written, with spans, before names and types are resolved.

use monitor_core::VarKind;

use crate::ast::{BinaryOp, UnaryOp};
use crate::diag::Span;

/// The deepest tree the parser builds (formula or expression); deeper input is an error,
/// so that every later recursive pass stays far from the stack limit.
pub(crate) const MAX_DEPTH: u32 = 200;

/// A name with its span.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Ident {
    pub name: String,
    pub span: Span,
}

pub(crate) use crate::duration::TimeUnit;

/// A time literal as written: `62`, `2.5s`, `100ms`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TimeLit {
    /// Digits before the point.
    pub int: String,
    /// Digits after the point (empty when there is no point).
    pub frac: String,
    /// The unit suffix, if any.
    pub unit: Option<TimeUnit>,
    pub span: Span,
}

/// `[lo:hi]` as written; a missing end is `None`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Bound {
    pub lo: Option<TimeLit>,
    pub hi: Option<TimeLit>,
    pub span: Span,
}

/// A prefix temporal or boolean operator.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum PrefixOp {
    Not,
    Yesterday,
    WeakYesterday,
    Once(Option<Bound>),
    Historically(Option<Bound>),
}

/// A binary formula operator.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum InfixOp {
    And,
    Or,
    Implies,
    Iff,
    Since(Option<Bound>),
}

impl InfixOp {
    /// Binding strength: higher binds tighter.
    pub(crate) fn precedence(&self) -> u8 {
        match self {
            InfixOp::Iff => 1,
            InfixOp::Implies => 2,
            InfixOp::Or => 3,
            InfixOp::And => 4,
            InfixOp::Since(_) => 5,
        }
    }

    /// `->` groups to the right, every other operator to the left.
    pub(crate) fn right_assoc(&self) -> bool {
        matches!(self, InfixOp::Implies)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum FormulaKind {
    Const(bool),
    Atom(Expr),
    Prefix(PrefixOp, Box<Formula>),
    Infix(InfixOp, Box<Formula>, Box<Formula>),
}

/// A formula: a [`Node`] of [`FormulaKind`].
pub(crate) type Formula = Node<FormulaKind>;

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum ExprKind {
    Bool(bool),
    /// An integer literal as written (no sign); may exceed `i64::MAX`.
    Int(u64),
    Float(f64),
    Str(String),
    Var(String),
    Unary(UnaryOp, Box<Expr>),
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
}

/// An expression inside an atom: a [`Node`] of [`ExprKind`].
pub(crate) type Expr = Node<ExprKind>;

/// A node of a parsed formula or expression: what it is, where it was written, and the
/// height of its tree (a leaf is 1), which the parser bounds.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Node<K> {
    pub kind: K,
    pub span: Span,
    /// Height of the tree (a leaf is 1).
    pub depth: u32,
}

/// `event name;` or `state name: type = init;`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Decl {
    pub kind: VarKind,
    pub name: Ident,
    /// The type name (`None` for events).
    pub ty: Option<Ident>,
    pub init: Option<Expr>,
    pub span: Span,
}

/// `property name = formula;`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Prop {
    pub name: Ident,
    pub formula: Formula,
    pub span: Span,
}

/// A parsed specification.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SpecSyntax {
    /// Every `unit` statement (more than one is an error, reported by the checker).
    pub units: Vec<TimeLit>,
    /// Ticks have no duration: bounds with a unit are errors.
    pub untimed: bool,
    pub decls: Vec<Decl>,
    pub props: Vec<Prop>,
}
