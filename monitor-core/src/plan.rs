//! What a validated program does at every point, decided once: [`Step`]s for the nodes and one [`AtomStep`] per atom.
//!
//! [`crate::Monitor::try_step`] on a `Monitor<'_, N>` with `N > 0` runs these
//! instead of re-deriving them from [`Op`] and the atom bytecode at every point:
//! every connective and unbounded `S` is a 16-bit truth table over its children,
//! its own last value and "first point" (no dispatch per operator); a bounded
//! `Since` node's kind comes from [`layout::since_kind`], its window capacity
//! computed here and not per point; children and state slots are plain
//! indices; the atoms of the common shapes (a boolean variable, its negation,
//! an integer variable compared with a constant) are read without the atom
//! machine, after one pass over the variables has checked their types and
//! gathered the booleans as bits ([`Plan::FAST`]). In a program of at most 64
//! nodes and atoms the literal nodes (constants, atoms and `Not`s of them) are
//! no steps at all but bits set by the atoms, and a `Not` of a step's node is
//! written by that step ([`Plan::FOLDED`]); when every step is then a truth
//! table, or a timed `Since` over literals and other timed steps, and the
//! atoms, timed steps and memory bits are few, a transition table steps a
//! point by the timed steps and one lookup ([`Plan::TABLE`], [`timed_first`],
//! [`build_table`]). The plan lives in
//! the monitor itself, in arrays of `N` entries (const generics: no
//! allocation); a program with more than `N` nodes or atoms runs the unplanned
//! interpreter.

use crate::error::StepError;
use crate::layout::{self, SinceKind};
use crate::program::{Atom, CmpOp, Instr, Op, Program, Ty, Value};

mod lookup;

pub(crate) use lookup::{build_literals, build_table, gather, index_bit, timed_first};

/// The kind of a planned step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A boolean function of `a`, `b`, the node's own last value and the first
    /// point, read from [`Step::table`]: constants, every connective, unbounded `S`
    /// (also an unused plan entry: `table` 0 is `false`).
    Logic,
    /// `Y a` / `Z a`: [`Step::table`] of the child's last value (the node's
    /// own word) and the first point; the word then takes `a`'s value.
    Latch,
    /// Atom `a` (only when atoms are not folded, see [`Plan::FOLDED`]).
    Atom,
    /// `a S[0:hi] b`.
    SinceUpTo,
    /// `a S[lo:] b`, `lo > 0`.
    SinceAtLeast,
    /// `a S[lo:hi] b`, `0 < lo <= hi`, with `cap` runs.
    SinceWindow,
}

/// Bit positions of a [`Step::table`] index.
pub(crate) const A: u16 = 1;
/// Bit of the second child.
pub(crate) const B: u16 = 2;
/// Bit of the node's own value at the last point (`Logic`) or of its word (`Latch`).
pub(crate) const C: u16 = 4;
/// Bit set at the first point.
pub(crate) const D: u16 = 8;

/// The children a truth table depends on: [`A`] if flipping `a` changes some
/// entry, [`B`] likewise.
const fn table_reads(table: u16) -> u8 {
    let mut reads = 0u16;
    let mut x = 0u16;
    while x < 16 {
        let v = (table >> x) & 1;
        if (table >> (x ^ A)) & 1 != v {
            reads |= A;
        }
        if (table >> (x ^ B)) & 1 != v {
            reads |= B;
        }
        x += 1;
    }
    reads as u8
}

/// The truth table of `f` over the four inputs of a [`Step::table`] index:
/// bit `x` of the result is `f(x & A != 0, x & B != 0, x & C != 0, x & D != 0)`.
fn table(f: impl Fn(bool, bool, bool, bool) -> bool) -> u16 {
    let mut t = 0u16;
    for x in 0..16u16 {
        t |= (f(x & A != 0, x & B != 0, x & C != 0, x & D != 0) as u16) << x;
    }
    t
}

/// One step of the plan: one node (and, fused into it, the `Not` of it, see
/// [`Step::negate`]), its kind, children, state slot and bounds.
///
/// Every boolean node and unbounded `S` is a 16-bit truth table over its two
/// children's values at this point, its own value at the last point and "first
/// point" (`kind` `Logic`): one table lookup, no dispatch per operator.
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
    /// The node this step computes.
    pub dest: u16,
    /// The node that is `Not(dest)`, computed by this step too when `negate` is 1.
    pub neg: u16,
    /// `Logic`, `Latch`: the value for each index `A | B | C | D` ([`table`]).
    pub table: u16,
    /// 1 when this step also writes `!value` to node `neg`, else 0.
    pub negate: u8,
    /// A transition table's timed step ([`Plan::timed`]): where its children's
    /// values are in the table's index, as [`index_bit`] reads them.
    pub ia: u8,
    /// Likewise for `b`.
    pub ib: u8,
    /// A transition table's timed step: the index bit it sets to its value.
    pub at: u8,
    /// Which children the unfolded step reads: [`A`] for `a`, [`B`] for `b` (a
    /// constant reads neither, `Not` and `Y`/`Z` only `a`), so that a large
    /// program's step, where a child's bit may be in a stored word, reads no more
    /// than the operator needs.
    pub reads: u8,
    /// What the node computes.
    pub kind: Kind,
}

impl Step {
    /// An unused entry.
    pub(crate) const NONE: Step = Step {
        lo: 0,
        hi: 0,
        slot: 0,
        cap: 1,
        a: 0,
        b: 0,
        dest: 0,
        neg: 0,
        table: 0,
        negate: 0,
        ia: 0,
        ib: 0,
        at: 0,
        reads: 0,
        kind: Kind::Logic,
    };

    /// The plan of validated node `dest` whose own words start at `slot`, or
    /// `None` for bounds [`layout::since_kind`] rejects (validation already did).
    fn of(op: &Op, dest: u16, slot: u32) -> Option<Step> {
        let s = |kind, a, b, table| Step {
            slot,
            a,
            b,
            dest,
            table,
            reads: match kind {
                Kind::Logic => table_reads(table),
                Kind::Latch => A as u8,
                Kind::Atom => 0,
                _ => (A | B) as u8,
            },
            kind,
            ..Step::NONE
        };
        let logic = |a, b, f: fn(bool, bool, bool, bool) -> bool| s(Kind::Logic, a, b, table(f));
        Some(match *op {
            Op::Const(c) => s(Kind::Logic, 0, 0, if c { u16::MAX } else { 0 }),
            Op::Atom(a) => s(Kind::Atom, a, 0, 0),
            Op::Not(a) => logic(a, a, |a, _, _, _| !a),
            Op::And(a, b) => logic(a, b, |a, b, _, _| a && b),
            Op::Or(a, b) => logic(a, b, |a, b, _, _| a || b),
            Op::Implies(a, b) => logic(a, b, |a, b, _, _| !a || b),
            Op::Iff(a, b) => logic(a, b, |a, b, _, _| a == b),
            // `Y a`: false at the first point, else a's last value (the own word).
            Op::Yesterday(a) => s(Kind::Latch, a, a, table(|_, _, c, d| c && !d)),
            // `Z a`: true at the first point.
            Op::WeakYesterday(a) => s(Kind::Latch, a, a, table(|_, _, c, d| c || d)),
            Op::Since { lhs, rhs, lo, hi } => match layout::since_kind(lo, hi)? {
                // g || (f && own last value), the last value being false at the first point.
                SinceKind::Unbounded => logic(lhs, rhs, |f, g, c, d| g || (f && c && !d)),
                SinceKind::UpTo(hi) => Step {
                    hi,
                    ..s(Kind::SinceUpTo, lhs, rhs, 0)
                },
                SinceKind::AtLeast(lo) => Step {
                    lo,
                    ..s(Kind::SinceAtLeast, lhs, rhs, 0)
                },
                SinceKind::Window { lo, hi, cap } => Step {
                    lo,
                    hi,
                    cap: cap.max(1),
                    ..s(Kind::SinceWindow, lhs, rhs, 0)
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
    /// The constant of the `Int*` kinds; 1 for `NotBool` (the bit that flips
    /// the variable's), 0 for `Bool`.
    pub c: i64,
    /// The variable read (every kind but `General`) or the first instruction (`General`).
    pub var: u16,
    /// The number of instructions (`General`).
    pub len: u16,
    /// The shape.
    pub kind: AtomKind,
    /// Folded plans ([`Plan::FOLDED`]): the nodes that are true when this atom is
    /// (the atom's nodes, an even number of `Not`s over them).
    pub pos: u64,
    /// Folded plans: the nodes that are true when this atom is false.
    pub neg: u64,
}

impl AtomStep {
    /// An unused entry.
    pub(crate) const NONE: AtomStep = AtomStep {
        c: 0,
        var: 0,
        len: 0,
        kind: AtomKind::General,
        pos: 0,
        neg: 0,
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
            kind,
            ..AtomStep::NONE
        };
        match *code {
            [Instr::Load(n)] if ty(n) == Some(Ty::Bool) => var(n, AtomKind::Bool, 0),
            [Instr::Load(n), Instr::Not] if ty(n) == Some(Ty::Bool) => var(n, AtomKind::NotBool, 1),
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

    /// This atom's value when it has one of the shapes read directly and its
    /// variable has the type declared; `None` otherwise (a value of another type,
    /// or `General`).
    #[inline(always)]
    pub(crate) fn fast(&self, vals: &[Value]) -> Option<bool> {
        // The value's variant first (one compare): a boolean variable, the most
        // common atom, is then one test of the kind away.
        let c = self.c;
        Some(match (vals.get(self.var as usize)?, self.kind) {
            (Value::Bool(b), AtomKind::Bool) => *b,
            (Value::Bool(b), AtomKind::NotBool) => !*b,
            (Value::Int(x), AtomKind::IntEq) => *x == c,
            (Value::Int(x), AtomKind::IntNe) => *x != c,
            (Value::Int(x), AtomKind::IntLt) => *x < c,
            (Value::Int(x), AtomKind::IntLe) => *x <= c,
            (Value::Int(x), AtomKind::IntGt) => *x > c,
            (Value::Int(x), AtomKind::IntGe) => *x >= c,
            _ => return None,
        })
    }

    /// This atom's value; `atom` is its index (for errors): [`AtomStep::fast`],
    /// else the atom machine (`General`) or, for a value of another type than
    /// declared (the caller checked, so never), the machine's error.
    #[inline(always)]
    pub(crate) fn eval(
        &self,
        instrs: &[Instr],
        vals: &[Value],
        atom: usize,
    ) -> Result<bool, StepError> {
        match self.fast(vals) {
            Some(v) => Ok(v),
            None => self.general(instrs, vals, atom),
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

/// What [`build`] decided for the whole program: six bytes, so that an
/// unplanned `Monitor<'_>` (firmware) stays as small as before plans.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Plan {
    /// The number of steps in the plan's node array.
    pub steps: u16,
    /// [`Plan::PLANNED`] .. [`Plan::LITS`].
    pub flags: u8,
    /// [`Plan::RUN`]: the variable of atom 0.
    pub shift: u8,
    /// [`Plan::TABLE`] with a gathering multiplier ([`build_table`]): 64 less
    /// the number of index bits above the atoms.
    pub top: u8,
    /// [`Plan::TABLE`]: the number of timed steps, first in the plan, that run
    /// before the lookup ([`timed_first`]); 0 when every step is `Logic`.
    pub timed: u8,
}

impl Plan {
    /// The plan arrays hold the program (at most `N` nodes and atoms).
    pub(crate) const PLANNED: u8 = 1;
    /// 1 to 64 nodes and 1 to 64 atoms, not `compact`: the
    /// literal nodes (constants, atoms and `Not`s of literals) are not steps but
    /// bits, in each atom's [`AtomStep::pos`]/[`AtomStep::neg`] (a `true`
    /// constant in both masks of atom 0); a `Not` of a step is fused into it
    /// ([`Step::negate`]); the steps are the other nodes, in node order.
    /// Otherwise there is one step per node, in node order, and none is fused.
    pub(crate) const FOLDED: u8 = 2;
    /// Every atom has a shape [`AtomStep::fast`] reads, at most 64 atoms and 64
    /// variables, not `compact`: one pass over the variables checks their
    /// types and gathers the boolean ones as bits, then the atoms are read
    /// without a type check.
    pub(crate) const FAST: u8 = 4;
    /// `FAST` and every atom is a boolean variable or its negation
    /// ([`AtomKind::Bool`], [`AtomKind::NotBool`]): a bit of the variables' bits.
    pub(crate) const BOOLS: u8 = 8;
    /// At most 64 atoms and 64 nodes (planned or not, see `Monitor::advance`).
    pub(crate) const SMALL: u8 = 16;
    /// `FOLDED`, every step is `Logic` or a timed `Since` over literals and
    /// other timed steps ([`timed_first`]), with at most [`lookup::TABLE_BITS`] atoms,
    /// timed steps and memory bits together: after the first point, the value
    /// word is the timed steps ([`Plan::timed`] of them) and one lookup in the
    /// monitor's transition table ([`build_table`]).
    pub(crate) const TABLE: u8 = 32;
    /// `BOOLS`, and atom `k` is boolean variable `shift + k` (not negated): the
    /// atoms are one shift and mask of the variables' bits.
    pub(crate) const RUN: u8 = 64;
    /// `FOLDED`, not `TABLE`, and at most [`lookup::TABLE_BITS`] atoms: the monitor's
    /// table holds the literal nodes' bits of every value of the atoms
    /// ([`build_literals`]), one lookup instead of a loop over the atoms.
    pub(crate) const LITS: u8 = 128;

    /// Whether every flag of `f` is set.
    #[inline(always)]
    pub(crate) const fn has(&self, f: u8) -> bool {
        self.flags & f == f
    }
}

/// A node's value when it does not depend on the network: a constant, or
/// atom `k` (`true`) or its negation (`false`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Lit {
    /// Not a literal: a step computes it.
    No,
    /// A constant.
    Const(bool),
    /// Atom `.0`, negated when `.1` is false.
    Atom(u16, bool),
}

/// The plan of a validated `program` into `nodes` and `atoms`, `nodes_at` being
/// [`layout::first_node_word`]; `None` (and nothing planned) when the program
/// has more nodes or atoms than the arrays hold.
pub(crate) fn build(
    p: &Program<'_>,
    nodes_at: usize,
    nodes: &mut [Step],
    atoms: &mut [AtomStep],
) -> Option<Plan> {
    if p.nodes.len() > nodes.len() || p.atoms.len() > atoms.len() {
        return None;
    }
    for (step, a) in atoms.iter_mut().zip(p.atoms) {
        *step = AtomStep::of(a, p);
    }
    let compact = cfg!(feature = "compact");
    // One atom word and one value word: the state opens with exactly three words.
    let folded = !compact && (1..=64).contains(&p.nodes.len()) && (1..=64).contains(&p.atoms.len());
    let mut plan = Plan {
        steps: 0,
        flags: Plan::PLANNED | if folded { Plan::FOLDED } else { 0 },
        shift: 0,
        top: 0,
        timed: 0,
    };
    let planned = atoms.get(..p.atoms.len()).unwrap_or(&[]);
    if !compact
        && p.atoms.len() <= 64
        && p.vars.len() <= 64
        && planned.iter().all(|a| a.kind != AtomKind::General)
    {
        plan.flags |= Plan::FAST;
        if planned
            .iter()
            .all(|a| matches!(a.kind, AtomKind::Bool | AtomKind::NotBool))
        {
            plan.flags |= Plan::BOOLS;
            let shift = planned.first().map_or(0, |a| a.var);
            if planned
                .iter()
                .enumerate()
                .all(|(k, a)| a.kind == AtomKind::Bool && a.var as usize == shift as usize + k)
            {
                plan.flags |= Plan::RUN;
                plan.shift = shift as u8;
            }
        }
    }
    // Folded: each node's literal value, and the step computing each non-literal node.
    let mut lit = [Lit::No; 64];
    let mut step_of = [u8::MAX; 64];
    let mut n = 0usize;
    for (i, node) in p.nodes.iter().enumerate() {
        let slot = (node.slot as usize).saturating_sub(nodes_at) as u32;
        let step = Step::of(&node.op, i as u16, slot)?;
        if folded {
            let bit = 1u64 << (i & 63);
            let of = |c: u16| lit.get(c as usize).copied().unwrap_or(Lit::No);
            let l = match node.op {
                Op::Const(c) => Lit::Const(c),
                Op::Atom(k) => Lit::Atom(k, true),
                Op::Not(c) => match of(c) {
                    Lit::Const(v) => Lit::Const(!v),
                    Lit::Atom(k, pol) => Lit::Atom(k, !pol),
                    Lit::No => Lit::No,
                },
                _ => Lit::No,
            };
            match l {
                // True whatever atom 0 is (folded plans have one).
                Lit::Const(v) => {
                    let a = atoms.first_mut()?;
                    if v {
                        a.pos |= bit;
                        a.neg |= bit;
                    }
                }
                Lit::Atom(k, pol) => {
                    let a = atoms.get_mut(k as usize)?;
                    if pol {
                        a.pos |= bit;
                    } else {
                        a.neg |= bit;
                    }
                }
                Lit::No => {}
            }
            if let Some(x) = lit.get_mut(i) {
                *x = l;
            }
            if l != Lit::No {
                continue;
            }
            // `Not` of a step's node: that step writes it too.
            if let Op::Not(c) = node.op {
                let at = step_of.get(c as usize).copied().unwrap_or(u8::MAX) as usize;
                if let Some(s) = nodes.get_mut(..n).and_then(|s| s.get_mut(at)) {
                    if s.negate == 0 {
                        s.negate = 1;
                        s.neg = i as u16;
                        continue;
                    }
                }
            }
            if let Some(x) = step_of.get_mut(i) {
                *x = n as u8;
            }
        }
        *nodes.get_mut(n)? = step;
        n += 1;
    }
    plan.steps = n as u16;
    Some(plan)
}

/// One `Logic` step of a folded plan: `new` is this point's value word so far
/// (the literal nodes and the steps before `s`), `old` the last point's, `d`
/// [`D`] at the first point (else 0); `new` with this step's node (and its
/// fused `Not`) added. The one copy of it: `Monitor`'s folded step and
/// [`build_table`] both call it.
#[inline(always)]
pub(crate) fn logic_step(s: &Step, old: u64, new: u64, d: u16) -> u64 {
    // Shifts by `wrapping_shl`/`wrapping_shr`: every index is below 64.
    let i = s.dest as u32;
    let f = new.wrapping_shr(s.a as u32) & 1;
    let g = new.wrapping_shr(s.b as u32) & 1;
    let c = old.wrapping_shr(i) & 1;
    let v = (s.table as u64).wrapping_shr((f | g << 1 | c << 2) as u32 | d as u32) & 1;
    with_value(s, new, v)
}

/// `new` with step `s`'s node set to `v` (0 or 1) and its fused `Not` to `!v`.
#[inline(always)]
pub(crate) fn with_value(s: &Step, new: u64, v: u64) -> u64 {
    let mut new = new | v.wrapping_shl(s.dest as u32);
    if s.negate != 0 {
        new |= (v ^ 1).wrapping_shl(s.neg as u32);
    }
    new
}

/// The literal nodes' bits of a folded plan for the atoms `bits` (bit `k`:
/// atom `k`).
#[inline(always)]
pub(crate) fn literal_bits(atoms: &[AtomStep], bits: u64) -> u64 {
    let mut nodes = 0u64;
    for (k, a) in atoms.iter().enumerate() {
        nodes |= if bits >> (k & 63) & 1 == 1 {
            a.pos
        } else {
            a.neg
        };
    }
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_reads_only_the_children_its_operator_needs() {
        let reads = |op: Op| Step::of(&op, 9, 0).map(|s| s.reads);
        assert_eq!(reads(Op::Const(true)), Some(0));
        assert_eq!(reads(Op::Const(false)), Some(0));
        assert_eq!(reads(Op::Not(3)), Some(A as u8));
        assert_eq!(reads(Op::Yesterday(3)), Some(A as u8));
        for op in [
            Op::And(1, 2),
            Op::Or(1, 2),
            Op::Implies(1, 2),
            Op::Iff(1, 2),
        ] {
            assert_eq!(reads(op), Some((A | B) as u8));
        }
        let since = |lo, hi| Op::Since {
            lhs: 1,
            rhs: 2,
            lo,
            hi,
        };
        assert_eq!(reads(since(0, None)), Some((A | B) as u8));
        assert_eq!(reads(since(0, Some(5))), Some((A | B) as u8));
        assert_eq!(reads(since(2, Some(5))), Some((A | B) as u8));
        assert_eq!(table_reads(table(|_, b, _, _| b)), B as u8);
    }
}
