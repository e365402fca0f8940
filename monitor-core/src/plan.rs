//! What a validated program does at every point, decided once: one [`Step`] per node and one [`AtomStep`] per atom.
//!
//! [`crate::Monitor::try_step`] on a `Monitor<'_, N>` with `N > 0` runs these
//! instead of re-deriving them from [`Op`] and the atom bytecode at every point:
//! a node's kind is one byte (a `Since` node's kind from [`layout::since_kind`],
//! its window capacity computed here and not per point), its children and its
//! state slot are plain indices, and the atoms of the common shapes (a boolean
//! variable, its negation, an integer variable compared with a constant) are
//! read without the atom machine. The plan lives in the monitor itself, in
//! arrays of `N` entries (const generics: no allocation); a program with more
//! than `N` nodes or atoms runs the unplanned interpreter.

use crate::error::StepError;
use crate::layout::{self, SinceKind};
use crate::program::{Atom, CmpOp, Instr, Op, Program, Ty, Value};

/// The kind of a planned node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A constant `false` (also an unused plan entry).
    False,
    /// A constant `true`.
    True,
    /// Atom `a`.
    Atom,
    /// `!a`
    Not,
    /// `a && b`
    And,
    /// `a || b`
    Or,
    /// `a -> b`
    Implies,
    /// `a <-> b`
    Iff,
    /// `Y a`
    Yesterday,
    /// `Z a`
    WeakYesterday,
    /// `a S b`, no bound.
    Since,
    /// `a S[0:hi] b`.
    SinceUpTo,
    /// `a S[lo:] b`, `lo > 0`.
    SinceAtLeast,
    /// `a S[lo:hi] b`, `0 < lo <= hi`, with `cap` runs.
    SinceWindow,
}

/// One node, planned: kind, children, state slot and bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Step {
    /// Lower bound (`SinceAtLeast`, `SinceWindow`).
    pub lo: u64,
    /// Upper bound (`SinceUpTo`, `SinceWindow`).
    pub hi: u64,
    /// The node's first own word, counted from [`layout::first_node_word`].
    pub slot: u32,
    /// Window capacity (`SinceWindow`), at least 1.
    pub cap: u32,
    /// First child (the atom for `Atom`; `lhs` for `Since`).
    pub a: u16,
    /// Second child (`rhs` for `Since`).
    pub b: u16,
    /// What the node computes.
    pub kind: Kind,
}

impl Step {
    /// An unused entry.
    pub const NONE: Step = Step {
        lo: 0,
        hi: 0,
        slot: 0,
        cap: 1,
        a: 0,
        b: 0,
        kind: Kind::False,
    };

    /// The plan of a validated node whose own words start at `slot`, or `None`
    /// for bounds [`layout::since_kind`] rejects (validation already did).
    fn of(op: &Op, slot: u32) -> Option<Step> {
        let s = |kind, a, b| Step {
            slot,
            a,
            b,
            kind,
            ..Step::NONE
        };
        Some(match *op {
            Op::Const(false) => s(Kind::False, 0, 0),
            Op::Const(true) => s(Kind::True, 0, 0),
            Op::Atom(a) => s(Kind::Atom, a, 0),
            Op::Not(a) => s(Kind::Not, a, 0),
            Op::And(a, b) => s(Kind::And, a, b),
            Op::Or(a, b) => s(Kind::Or, a, b),
            Op::Implies(a, b) => s(Kind::Implies, a, b),
            Op::Iff(a, b) => s(Kind::Iff, a, b),
            Op::Yesterday(a) => s(Kind::Yesterday, a, 0),
            Op::WeakYesterday(a) => s(Kind::WeakYesterday, a, 0),
            Op::Since { lhs, rhs, lo, hi } => match layout::since_kind(lo, hi)? {
                SinceKind::Unbounded => s(Kind::Since, lhs, rhs),
                SinceKind::UpTo(hi) => Step {
                    hi,
                    ..s(Kind::SinceUpTo, lhs, rhs)
                },
                SinceKind::AtLeast(lo) => Step {
                    lo,
                    ..s(Kind::SinceAtLeast, lhs, rhs)
                },
                SinceKind::Window { lo, hi, cap } => Step {
                    lo,
                    hi,
                    cap: cap.max(1),
                    ..s(Kind::SinceWindow, lhs, rhs)
                },
            },
        })
    }
}

/// How a planned atom is computed: one byte, no payload (a direct jump).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum AtomKind {
    /// Boolean variable `var`.
    Bool,
    /// `!var` for a boolean variable.
    NotBool,
    /// Integer variable `var == c`.
    IntEq,
    /// `var != c`.
    IntNe,
    /// `var < c`.
    IntLt,
    /// `var <= c`.
    IntLe,
    /// `var > c`.
    IntGt,
    /// `var >= c`.
    IntGe,
    /// Through the atom machine: `instrs[start .. start + len]`.
    General,
}

/// The kind of `var op c`.
const fn int_kind(op: CmpOp) -> AtomKind {
    match op {
        CmpOp::Eq => AtomKind::IntEq,
        CmpOp::Ne => AtomKind::IntNe,
        CmpOp::Lt => AtomKind::IntLt,
        CmpOp::Le => AtomKind::IntLe,
        CmpOp::Gt => AtomKind::IntGt,
        CmpOp::Ge => AtomKind::IntGe,
    }
}

/// One atom, planned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct AtomStep {
    /// The constant of the `Int*` kinds.
    pub c: i64,
    /// The variable read (every kind but `General`) or the first instruction (`General`).
    pub var: u16,
    /// The number of instructions (`General`).
    pub len: u16,
    /// The shape.
    pub kind: AtomKind,
}

impl AtomStep {
    /// An unused entry.
    pub const NONE: AtomStep = AtomStep {
        c: 0,
        var: 0,
        len: 0,
        kind: AtomKind::General,
    };

    /// The plan of a validated atom: its shape, matched on its code and the variable types.
    fn of(a: &Atom, p: &Program<'_>) -> AtomStep {
        let general = AtomStep {
            var: a.start,
            len: a.len,
            ..AtomStep::NONE
        };
        let start = a.start as usize;
        let Some(code) = p.instrs.get(start..start + a.len as usize) else {
            return general;
        };
        let ty = |n: u16| p.vars.get(n as usize).map(|v| v.ty);
        let var = |var, kind, c| AtomStep {
            c,
            var,
            len: 0,
            kind,
        };
        match *code {
            [Instr::Load(n)] if ty(n) == Some(Ty::Bool) => var(n, AtomKind::Bool, 0),
            [Instr::Load(n), Instr::Not] if ty(n) == Some(Ty::Bool) => var(n, AtomKind::NotBool, 0),
            [Instr::Load(n), Instr::Push(Value::Int(c)), Instr::Cmp(op, Ty::Int)]
                if ty(n) == Some(Ty::Int) =>
            {
                var(n, int_kind(op), c)
            }
            [Instr::Push(Value::Int(c)), Instr::Load(n), Instr::Cmp(op, Ty::Int)]
                if ty(n) == Some(Ty::Int) =>
            {
                var(n, int_kind(flip(op)), c)
            }
            _ => general,
        }
    }

    /// This atom's value; `atom` is its index (for errors).
    #[inline(always)]
    pub fn eval(&self, instrs: &[Instr], vals: &[Value], atom: usize) -> Result<bool, StepError> {
        // The variables' types were checked by the caller, so the fallbacks only
        // keep this total; they give the general machine's result and error.
        let c = self.c;
        match (self.kind, vals.get(self.var as usize)) {
            (AtomKind::Bool, Some(Value::Bool(b))) => Ok(*b),
            (AtomKind::NotBool, Some(Value::Bool(b))) => Ok(!*b),
            (AtomKind::IntEq, Some(Value::Int(x))) => Ok(*x == c),
            (AtomKind::IntNe, Some(Value::Int(x))) => Ok(*x != c),
            (AtomKind::IntLt, Some(Value::Int(x))) => Ok(*x < c),
            (AtomKind::IntLe, Some(Value::Int(x))) => Ok(*x <= c),
            (AtomKind::IntGt, Some(Value::Int(x))) => Ok(*x > c),
            (AtomKind::IntGe, Some(Value::Int(x))) => Ok(*x >= c),
            _ => self.general(instrs, vals, atom),
        }
    }

    #[inline(never)]
    fn general(&self, instrs: &[Instr], vals: &[Value], atom: usize) -> Result<bool, StepError> {
        let start = self.var as usize;
        match self.kind {
            AtomKind::General => {
                let code = instrs.get(start..start + self.len as usize).unwrap_or(&[]);
                crate::expr::eval(code, vals, atom as u16)
            }
            // A value of another type than declared: the caller checked, so never.
            _ => Err(StepError::VarType { var: self.var }),
        }
    }
}

/// `c op x` as `x op' c`.
const fn flip(op: CmpOp) -> CmpOp {
    match op {
        CmpOp::Eq => CmpOp::Eq,
        CmpOp::Ne => CmpOp::Ne,
        CmpOp::Lt => CmpOp::Gt,
        CmpOp::Le => CmpOp::Ge,
        CmpOp::Gt => CmpOp::Lt,
        CmpOp::Ge => CmpOp::Le,
    }
}

/// The plan of a validated `program` into `nodes` and `atoms`, `nodes_at` being
/// [`layout::first_node_word`]; `false` (and nothing planned) when the program
/// has more nodes or atoms than the arrays hold.
pub(crate) fn build(
    p: &Program<'_>,
    nodes_at: usize,
    nodes: &mut [Step],
    atoms: &mut [AtomStep],
) -> bool {
    if p.nodes.len() > nodes.len() || p.atoms.len() > atoms.len() {
        return false;
    }
    for (step, n) in nodes.iter_mut().zip(p.nodes) {
        let slot = (n.slot as usize).saturating_sub(nodes_at) as u32;
        match Step::of(&n.op, slot) {
            Some(s) => *step = s,
            None => return false,
        }
    }
    for (step, a) in atoms.iter_mut().zip(p.atoms) {
        *step = AtomStep::of(a, p);
    }
    true
}
