//! A compiled property program cut into one monitor program per property, with the
//! facts the [`super::observe::Judge`] needs to step a property only at the points
//! where stepping it can change its state.
//!
//! A [`Program`]'s properties are independent networks: each property's nodes are a
//! contiguous run whose children stay inside it (checked by `Monitor::try_new`), and
//! only its atoms read the variables. So a property's network, with its atoms renumbered
//! and its state slots laid out again, is a program of its own whose verdicts at every
//! point are the whole program's verdicts for that property. Stepping it alone lets the
//! judge skip it at a point where, by `docs/SEMANTICS.md` section 1's rules, the step
//! would leave its state bit for bit as it is (see [`Part`]'s fields).

use monitor_core::program::{Atom, Instr, Node, NodeId, NumTy, Op, Program, Property};
use monitor_core::{layout, StepError};

/// One property's program (or, in [`Split::whole`], every property's), owned.
#[derive(Clone, Debug)]
pub(super) struct Part {
    /// The nodes, children renumbered from 0, slots laid out for `atoms`.
    nodes: Vec<Node>,
    /// The atoms its nodes read, in the whole program's order.
    atoms: Vec<Atom>,
    /// Local atom index -> the whole program's.
    atom_ids: Vec<u16>,
    /// Its properties, nodes renumbered.
    props: Vec<Property<'static>>,
    /// The whole program's index of its first property and of its first node.
    pub first_prop: usize,
    pub first_node: usize,
    /// It has a bounded `S` (`S[a:b]`, `S[a:]` with a > 0, `S[0:b]`), whose value may
    /// change when only time passes: it is stepped at every new time.
    pub timed: bool,
    /// It has a `Y` / `Z`, which shifts its operand by one point, so that even a repeated
    /// point moves it: it is stepped at every point.
    pub shifts: bool,
}

impl Part {
    /// This part as a program over the whole program's variables, strings and
    /// instructions (an atom is still a range of the whole `instrs`).
    pub(crate) fn program<'a>(&'a self, whole: &Program<'a>) -> Program<'a> {
        Program {
            nodes: &self.nodes,
            atoms: &self.atoms,
            props: &self.props,
            ..*whole
        }
    }

    /// The error a step of this part returned, with its atom numbered as in the whole
    /// program (what `Compiled::describe` reads).
    pub(crate) fn global_error(&self, e: StepError) -> StepError {
        match e {
            StepError::Arithmetic { atom } => StepError::Arithmetic {
                atom: self.atom_ids.get(atom as usize).copied().unwrap_or(atom),
            },
            e => e,
        }
    }

    /// The number of nodes.
    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

/// The parts of a program, and which parts read each variable.
#[derive(Clone, Debug)]
pub(super) struct Split {
    pub parts: Vec<Part>,
    /// Per variable, the parts whose atoms load it: bit `p % 64` for part `p`.
    pub readers: Vec<u64>,
    /// The parts stepped at every new time ([`Part::timed`]), same bits.
    pub timed: u64,
    /// The parts stepped at every point ([`Part::shifts`]), same bits.
    pub always: u64,
}

/// At most this many parts: one bit each in a `u64`.
const MAX_PARTS: usize = 64;

impl Split {
    /// One part per property; one part for the whole program when it has more than 64
    /// properties or when some atom can fail (integer arithmetic: an overflow or a
    /// division by zero stops the run, and a whole-program step is what leaves every
    /// verdict unchanged at the point that fails, as `Monitor::try_step` promises).
    pub(crate) fn new(program: &Program<'_>) -> Split {
        let can_fail = program.instrs.iter().any(|i| {
            matches!(
                i,
                Instr::Neg(NumTy::Int)
                    | Instr::Add(NumTy::Int)
                    | Instr::Sub(NumTy::Int)
                    | Instr::Mul(NumTy::Int)
                    | Instr::Div(NumTy::Int)
                    | Instr::Rem(NumTy::Int)
            )
        });
        let n = program.props.len();
        let ranges: Vec<(usize, usize)> = if n == 0 {
            Vec::new()
        } else if can_fail || n > MAX_PARTS {
            vec![(0, n)]
        } else {
            (0..n).map(|k| (k, k + 1)).collect()
        };
        let parts: Vec<Part> = ranges.iter().map(|&r| part(program, r)).collect();
        let mut readers = vec![0u64; program.vars.len()];
        let (mut timed, mut always) = (0u64, 0u64);
        for (p, (part, &(a, b))) in parts.iter().zip(&ranges).enumerate() {
            let bit = 1u64 << (p % MAX_PARTS);
            for prop in &program.props[a..b] {
                monitor_core::analysis::for_each_read(program, prop, |v| {
                    if let Some(r) = readers.get_mut(v as usize) {
                        *r |= bit;
                    }
                });
            }
            if part.timed {
                timed |= bit;
            }
            if part.shifts {
                always |= bit;
            }
        }
        Split {
            parts,
            readers,
            timed,
            always,
        }
    }

    /// All parts' bits.
    pub(crate) fn all(&self) -> u64 {
        match self.parts.len() {
            0 => 0,
            n => u64::MAX >> (64 - n.min(MAX_PARTS)),
        }
    }

    /// The part holding node `node` of the whole program, and the node's index in it.
    pub(crate) fn locate(&self, node: NodeId) -> Option<(usize, NodeId)> {
        let n = node as usize;
        let p = self.parts.partition_point(|part| part.first_node <= n);
        let part = self.parts.get(p.checked_sub(1)?)?;
        let local = n - part.first_node;
        (local < part.nodes.len()).then_some((p - 1, local as NodeId))
    }
}

/// The part of `program` holding properties `a .. b`.
fn part(program: &Program<'_>, (a, b): (usize, usize)) -> Part {
    let first_node = program.props[a].first as usize;
    let last = program.props[b - 1].root as usize;
    let whole = &program.nodes[first_node..=last];
    // The atoms read, in the whole program's order (so a failing atom found first
    // here is the one the whole program finds first).
    let mut atom_ids: Vec<u16> = whole
        .iter()
        .filter_map(|n| match n.op {
            Op::Atom(k) => Some(k),
            _ => None,
        })
        .collect();
    atom_ids.sort_unstable();
    atom_ids.dedup();
    let local_atom = |k: u16| atom_ids.binary_search(&k).unwrap_or(0) as u16;
    let shift = |c: NodeId| c - first_node as NodeId;
    let mut slot = layout::first_node_word(atom_ids.len(), whole.len()) as u64;
    let (mut timed, mut shifts) = (false, false);
    let nodes = whole
        .iter()
        .map(|n| {
            let op = match n.op {
                Op::Const(c) => Op::Const(c),
                Op::Atom(k) => Op::Atom(local_atom(k)),
                Op::Not(x) => Op::Not(shift(x)),
                Op::And(x, y) => Op::And(shift(x), shift(y)),
                Op::Or(x, y) => Op::Or(shift(x), shift(y)),
                Op::Implies(x, y) => Op::Implies(shift(x), shift(y)),
                Op::Iff(x, y) => Op::Iff(shift(x), shift(y)),
                Op::Yesterday(x) => {
                    shifts = true;
                    Op::Yesterday(shift(x))
                }
                Op::WeakYesterday(x) => {
                    shifts = true;
                    Op::WeakYesterday(shift(x))
                }
                Op::Since { lhs, rhs, lo, hi } => {
                    timed |= lo != 0 || hi.is_some();
                    Op::Since {
                        lhs: shift(lhs),
                        rhs: shift(rhs),
                        lo,
                        hi,
                    }
                }
            };
            // A layout the whole program passed: never `None`.
            let words = layout::node_words(&op).unwrap_or(0);
            let node = Node {
                op,
                slot: if words == 0 { 0 } else { slot as u32 },
            };
            slot += words;
            node
        })
        .collect();
    let props = program.props[a..b]
        .iter()
        .map(|p| Property {
            name: "",
            first: shift(p.first),
            root: shift(p.root),
        })
        .collect();
    Part {
        atoms: atom_ids
            .iter()
            .map(|&k| program.atoms[k as usize])
            .collect(),
        atom_ids,
        nodes,
        props,
        first_prop: a,
        first_node,
        timed,
        shifts,
    }
}
