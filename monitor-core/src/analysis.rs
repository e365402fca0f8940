//! Static and per-point analyses of a [`Program`]: finality, repeat-idempotence, reads, horizon and arithmetic.
//!
//! These are facts about the semantics of the network, so they live beside it:
//! every function here matches [`Op`] exhaustively, and a new operator does not
//! compile until each analysis has a rule for it. None allocates, so firmware can
//! use them too (for example to stop on a final verdict).
//!
//! - [`settle`]: for the state after a point, which nodes have a value no later
//!   point can change (sound, not complete), and [`settled`] for a property's root.
//! - [`repeat_is_noop`]: whether stepping the same point twice (same time, same
//!   values) always leaves the state unchanged, so a caller may skip the repeat.
//! - [`for_each_read`]: the variables a property's atoms load.
//! - [`horizon`]: the largest time bound in a property's formula.
//! - [`arithmetic`]: whether the atoms need floating point or integer division
//!   (the `float` / `int-div` features of this crate).
//! - [`culprit`]: at a point where a property is false, the deepest subformula whose
//!   value at that point explains it (what a report points at).
//!
//! The conformance tests (`tests/tests/analysis.rs`) check [`settle`] and
//! [`repeat_is_noop`] against the reference oracle on the corpus and on random
//! formulas.

use crate::program::{Instr, NodeId, NumTy, Op, Program, Property, Ty, Var};

/// The final value of one node, if its value can no longer change, from its
/// operation, its value `now` after the last point and its children's finality.
///
/// The rules:
/// - a constant is final; an atom never is;
/// - `!`, `&&`, `||`, `->`, `<->` are final when their final operands decide them
///   (`false && _` is final as soon as one side is final `false`);
/// - `Y a` / `Z a` is final `v` when `a` is final `v` and the node is `v` now
///   (its next value is `a`'s value now, which is `v` forever);
/// - `f S[a:] g` with no upper bound is final `true` once it is true while `f` is
///   final `true`: its witness never expires and is never reset;
/// - `f S g` (no bounds at all) is final `false` once it is false while `g` is
///   final `false`: nothing can start a witness again;
/// - any other `S` (a bounded window) is never final.
pub fn node_final(op: Op, now: bool, child: impl Fn(NodeId) -> Option<bool>) -> Option<bool> {
    match op {
        Op::Const(c) => Some(c),
        Op::Atom(_) => None,
        Op::Not(a) => child(a).map(|a| !a),
        Op::And(a, b) => match (child(a), child(b)) {
            (Some(false), _) | (_, Some(false)) => Some(false),
            (Some(true), Some(true)) => Some(true),
            _ => None,
        },
        Op::Or(a, b) => match (child(a), child(b)) {
            (Some(true), _) | (_, Some(true)) => Some(true),
            (Some(false), Some(false)) => Some(false),
            _ => None,
        },
        Op::Implies(a, b) => match (child(a), child(b)) {
            (Some(false), _) | (_, Some(true)) => Some(true),
            (Some(true), Some(false)) => Some(false),
            _ => None,
        },
        Op::Iff(a, b) => match (child(a), child(b)) {
            (Some(x), Some(y)) => Some(x == y),
            _ => None,
        },
        Op::Yesterday(a) | Op::WeakYesterday(a) => match child(a) {
            Some(v) if v == now => Some(v),
            _ => None,
        },
        Op::Since { lhs, rhs, lo, hi } => {
            if hi.is_none() && now && child(lhs) == Some(true) {
                Some(true)
            } else if lo == 0 && hi.is_none() && !now && child(rhs) == Some(false) {
                Some(false)
            } else {
                None
            }
        }
    }
}

/// Computes every node's final value (`None`: may still change) into `finals`,
/// given each node's value `now` after the last point (for example
/// [`crate::Monitor::node_value`]). Nodes are visited in order, children first;
/// `finals` should have one entry per node (extra nodes are left out).
pub fn settle(program: &Program<'_>, now: impl Fn(NodeId) -> bool, finals: &mut [Option<bool>]) {
    for (i, node) in program.nodes.iter().enumerate().take(finals.len()) {
        let (done, rest) = finals.split_at_mut(i);
        let child = |n: NodeId| done.get(n as usize).copied().flatten();
        rest[0] = node_final(node.op, now(i as NodeId), child);
    }
}

/// The final verdict of property `prop` in `finals` as [`settle`] left it, if final.
pub fn settled(program: &Program<'_>, finals: &[Option<bool>], prop: usize) -> Option<bool> {
    let root = program.props.get(prop)?.root;
    finals.get(root as usize).copied().flatten()
}

/// Whether a second step at the same time with the same values always leaves every
/// node's state as the first step left it.
///
/// True without `Y` / `Z`: atoms are pure, `S` keeps or resets the same witness,
/// windows expire nothing more and extend their newest run to the same time. `Y` /
/// `Z` shift their operand's value by one point, so a repeat moves them.
pub fn repeat_is_noop(program: &Program<'_>) -> bool {
    program.nodes.iter().all(|n| match n.op {
        Op::Yesterday(_) | Op::WeakYesterday(_) => false,
        Op::Const(_)
        | Op::Atom(_)
        | Op::Not(_)
        | Op::And(..)
        | Op::Or(..)
        | Op::Implies(..)
        | Op::Iff(..)
        | Op::Since { .. } => true,
    })
}

/// The nodes of `prop`, or none if its range is out of the program.
fn nodes<'p>(program: &Program<'p>, prop: &Property<'_>) -> &'p [crate::program::Node] {
    program
        .nodes
        .get(prop.first as usize..=prop.root as usize)
        .unwrap_or(&[])
}

/// Calls `read` with every variable index that an atom of `prop` loads (in
/// bytecode order, possibly more than once).
pub fn for_each_read(program: &Program<'_>, prop: &Property<'_>, mut read: impl FnMut(u16)) {
    for node in nodes(program, prop) {
        let atom = match node.op {
            Op::Atom(a) => a,
            Op::Const(_)
            | Op::Not(_)
            | Op::And(..)
            | Op::Or(..)
            | Op::Implies(..)
            | Op::Iff(..)
            | Op::Yesterday(_)
            | Op::WeakYesterday(_)
            | Op::Since { .. } => continue,
        };
        let Some(atom) = program.atoms.get(atom as usize) else {
            continue;
        };
        let (start, len) = (atom.start as usize, atom.len as usize);
        for instr in program.instrs.get(start..start + len).unwrap_or(&[]) {
            match *instr {
                Instr::Load(v) => read(v),
                Instr::Push(_)
                | Instr::Not
                | Instr::And
                | Instr::Or
                | Instr::Neg(_)
                | Instr::Add(_)
                | Instr::Sub(_)
                | Instr::Mul(_)
                | Instr::Div(_)
                | Instr::Rem(_)
                | Instr::Cmp(..)
                | Instr::ToFloat => {}
            }
        }
    }
}

/// The largest time bound (lower or upper) of any `S` in `prop`, 0 if none.
///
/// After a restart, a property's windows are full again once this much time has
/// passed (`Y` / `Z` look back one point, not a time, and add nothing).
pub fn horizon(program: &Program<'_>, prop: &Property<'_>) -> u64 {
    nodes(program, prop)
        .iter()
        .map(|node| match node.op {
            Op::Since { lo, hi, .. } => lo.max(hi.unwrap_or(0)),
            Op::Const(_)
            | Op::Atom(_)
            | Op::Not(_)
            | Op::And(..)
            | Op::Or(..)
            | Op::Implies(..)
            | Op::Iff(..)
            | Op::Yesterday(_)
            | Op::WeakYesterday(_) => 0,
        })
        .max()
        .unwrap_or(0)
}

/// What a program's atoms compute beyond booleans, comparisons and integer
/// `+ - *`: each is a feature of this crate that a firmware build may leave out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Arithmetic {
    /// Some instruction loads, pushes, computes or compares a float (feature `float`).
    pub float: bool,
    /// Some instruction divides integers, `/` or `%` (feature `int-div`).
    pub int_div: bool,
}

/// Scans every instruction of `program` for floats and integer division.
pub fn arithmetic(program: &Program<'_>) -> Arithmetic {
    program
        .instrs
        .iter()
        .map(|ins| instr_arithmetic(ins, program.vars))
        .fold(Arithmetic::default(), |a, b| Arithmetic {
            float: a.float || b.float,
            int_div: a.int_div || b.int_div,
        })
}

/// What one instruction needs, over variables `vars`.
pub(crate) fn instr_arithmetic(ins: &Instr, vars: &[Var<'_>]) -> Arithmetic {
    let float = match *ins {
        Instr::Push(v) => v.ty() == Ty::Float,
        Instr::Load(n) => vars.get(n as usize).is_some_and(|v| v.ty == Ty::Float),
        Instr::Neg(t) | Instr::Add(t) | Instr::Sub(t) | Instr::Mul(t) => t == NumTy::Float,
        Instr::Div(t) | Instr::Rem(t) => t == NumTy::Float,
        Instr::Cmp(_, ty) => ty == Ty::Float,
        Instr::ToFloat => true,
        Instr::Not | Instr::And | Instr::Or => false,
    };
    Arithmetic {
        float,
        int_div: matches!(ins, Instr::Div(NumTy::Int) | Instr::Rem(NumTy::Int)),
    }
}

/// The subformula that explains a node's value `value(node)` at this point: from `node`,
/// descend while one child's value at this point alone decides the node's, with the
/// polarity that decides it:
/// - `!a` is explained by `a` (with the opposite value);
/// - a false `a && b` by its first false operand, a true `a || b` by its first true one;
/// - a false `a -> b` by `b` (false; `a` is true);
/// - a true unbounded `a S b` by `b` when `b` is true now (the witness is this point);
/// - anything else (a constant, an atom, `<->`, `Y`, `Z`, a bounded `S`, a node whose
///   operands both decide it) is its own explanation.
///
/// `value` gives a node's value after the point (`None` if unknown, which stops the
/// descent). A node stays within its property's run of nodes, so this ends.
pub fn culprit(
    program: &Program<'_>,
    node: NodeId,
    value: impl Fn(NodeId) -> Option<bool>,
) -> NodeId {
    let mut n = node;
    loop {
        let Some(op) = program.nodes.get(n as usize).map(|x| x.op) else {
            return n;
        };
        let Some(v) = value(n) else {
            return n;
        };
        let next = match op {
            Op::Not(a) => Some(a),
            Op::And(a, b) if !v => [a, b].into_iter().find(|&c| value(c) == Some(false)),
            Op::Or(a, b) if v => [a, b].into_iter().find(|&c| value(c) == Some(true)),
            Op::Implies(_, b) if !v => Some(b),
            Op::Since {
                rhs,
                lo: 0,
                hi: None,
                ..
            } if v && value(rhs) == Some(true) => Some(rhs),
            Op::Const(_)
            | Op::Atom(_)
            | Op::And(..)
            | Op::Or(..)
            | Op::Implies(..)
            | Op::Iff(..)
            | Op::Yesterday(_)
            | Op::WeakYesterday(_)
            | Op::Since { .. } => None,
        };
        match next {
            // Children come before their parent: the descent always moves down.
            Some(c) if c < n => n = c,
            _ => return n,
        }
    }
}
