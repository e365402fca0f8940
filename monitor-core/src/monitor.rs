//! The table interpreter: a validated [`Program`] stepped over a caller-provided state buffer.

use crate::error::{StepError, TableError};
use crate::expr;
use crate::layout::{self, SinceKind};
use crate::program::{Op, Program, Value, VarKind};

/// A [`Program`] that passed every check: it can be stepped without panicking.
///
/// Build one with [`Monitor::try_new`]; allocate `state_words()` words (statically
/// or on the stack), [`Monitor::reset`] them, then call [`Monitor::try_step`]
/// once per point.
#[derive(Clone, Copy, Debug)]
pub struct Monitor<'a> {
    program: Program<'a>,
    state_words: usize,
    values_at: usize,
}

/// The most nodes, atoms or variables a program may have (ids are `u16`).
pub const MAX_IDS: usize = u16::MAX as usize;

impl<'a> Monitor<'a> {
    /// Checks every invariant of `program`: indices, types, bounds, state slots.
    pub fn try_new(program: Program<'a>) -> Result<Self, TableError> {
        let p = &program;
        if p.vars.len() > MAX_IDS
            || p.atoms.len() > MAX_IDS
            || p.nodes.len() > MAX_IDS
            || p.props.len() > MAX_IDS
            || p.instrs.len() > MAX_IDS
        {
            return Err(TableError::TooLarge);
        }
        for (i, v) in p.vars.iter().enumerate() {
            let ok =
                v.init.ty() == v.ty && (v.kind == VarKind::State || v.init == Value::Bool(false));
            if !ok {
                return Err(TableError::Var { var: i as u16 });
            }
        }
        for (i, a) in p.atoms.iter().enumerate() {
            let err = TableError::Atom { atom: i as u16 };
            let end = a.start as usize + a.len as usize;
            let code = p.instrs.get(a.start as usize..end).ok_or(err)?;
            if !expr::check(code, p.vars) {
                return Err(err);
            }
        }
        let mut next_word = layout::first_node_word(p.atoms.len(), p.nodes.len()) as u64;
        let mut prop_of_next = 0usize;
        let mut first = 0usize;
        for (i, n) in p.nodes.iter().enumerate() {
            // The property owning node i: the first whose root is >= i.
            while p
                .props
                .get(prop_of_next)
                .is_some_and(|pr| (pr.root as usize) < i)
            {
                prop_of_next += 1;
                first = i;
            }
            let node_err = TableError::Node { node: i as u16 };
            let child_ok = |c: u16| (c as usize) < i && (c as usize) >= first;
            let ok = match n.op {
                Op::Const(_) => true,
                Op::Atom(a) => (a as usize) < p.atoms.len(),
                Op::Not(a) | Op::Yesterday(a) | Op::WeakYesterday(a) => child_ok(a),
                Op::And(a, b) | Op::Or(a, b) | Op::Implies(a, b) | Op::Iff(a, b) => {
                    child_ok(a) && child_ok(b)
                }
                Op::Since { lhs, rhs, .. } => child_ok(lhs) && child_ok(rhs),
            };
            if !ok {
                return Err(node_err);
            }
            let layout_err = TableError::Layout { node: i as u16 };
            let words = layout::node_words(&n.op).ok_or(layout_err)?;
            let expected_slot = if words == 0 { 0 } else { next_word };
            if n.slot as u64 != expected_slot {
                return Err(layout_err);
            }
            next_word = next_word.checked_add(words).ok_or(TableError::TooLarge)?;
            if next_word > u32::MAX as u64 {
                return Err(TableError::TooLarge);
            }
        }
        let mut expect_first = 0usize;
        for (i, pr) in p.props.iter().enumerate() {
            let err = TableError::Property { prop: i as u16 };
            if pr.first as usize != expect_first || pr.root < pr.first {
                return Err(err);
            }
            if pr.root as usize >= p.nodes.len() {
                return Err(err);
            }
            expect_first = pr.root as usize + 1;
        }
        if expect_first != p.nodes.len() {
            return Err(TableError::Property {
                prop: p.props.len() as u16,
            });
        }
        Ok(Monitor {
            program,
            state_words: next_word as usize,
            values_at: layout::HEADER_WORDS + layout::bit_words(p.atoms.len()),
        })
    }

    /// The program this monitor runs.
    pub fn program(&self) -> &Program<'a> {
        &self.program
    }

    /// The number of `u64` words the state buffer must have.
    pub fn state_words(&self) -> usize {
        self.state_words
    }

    /// The state size in bytes (`8 * state_words()`).
    pub fn state_bytes(&self) -> usize {
        self.state_words * 8
    }

    /// The number of properties, and so of verdicts per step.
    pub fn properties(&self) -> usize {
        self.program.props.len()
    }

    /// Puts `state` before the first point.
    pub fn reset(&self, state: &mut [u64]) -> Result<(), StepError> {
        self.check_state(state)?;
        state.fill(0);
        Ok(())
    }

    fn check_state(&self, state: &[u64]) -> Result<(), StepError> {
        if state.len() != self.state_words {
            return Err(StepError::StateSize {
                expected: self.state_words,
                found: state.len(),
            });
        }
        Ok(())
    }

    /// Judges one point: computes every atom from `vars` (one value per declared
    /// variable, of its type), updates every network and writes each property's
    /// verdict at this point into `verdicts`. On error nothing is changed.
    pub fn try_step(
        &self,
        state: &mut [u64],
        time: u64,
        vars: &[Value],
        verdicts: &mut [bool],
    ) -> Result<(), StepError> {
        self.check_point(state, time, verdicts)?;
        let p = &self.program;
        if vars.len() != p.vars.len() {
            return Err(StepError::InputSize {
                expected: p.vars.len(),
                found: vars.len(),
            });
        }
        for (i, (v, d)) in vars.iter().zip(p.vars).enumerate() {
            if v.ty() != d.ty {
                return Err(StepError::VarType { var: i as u16 });
            }
        }
        let atom_words = self.values_at - layout::HEADER_WORDS;
        let mut atoms_done = 0usize;
        // Atoms first, into the scratch words: an error leaves the temporal state untouched.
        for w in 0..atom_words {
            let mut bits = 0u64;
            for b in 0..64 {
                let Some(a) = p.atoms.get(atoms_done) else {
                    break;
                };
                let code = &p.instrs[a.start as usize..a.start as usize + a.len as usize];
                if expr::eval(code, vars, atoms_done as u16)? {
                    bits |= 1 << b;
                }
                atoms_done += 1;
            }
            state[layout::HEADER_WORDS + w] = bits;
        }
        self.advance(state, time, verdicts);
        Ok(())
    }

    /// Like [`Monitor::try_step`] for a caller that computes the atoms itself:
    /// bit `k % 64` of `atoms[k / 64]` is atom `k`.
    pub fn try_step_atoms(
        &self,
        state: &mut [u64],
        time: u64,
        atoms: &[u64],
        verdicts: &mut [bool],
    ) -> Result<(), StepError> {
        self.check_point(state, time, verdicts)?;
        let words = self.values_at - layout::HEADER_WORDS;
        if atoms.len() != words {
            return Err(StepError::InputSize {
                expected: words,
                found: atoms.len(),
            });
        }
        state[layout::HEADER_WORDS..self.values_at].copy_from_slice(atoms);
        self.advance(state, time, verdicts);
        Ok(())
    }

    fn check_point(&self, state: &[u64], time: u64, verdicts: &[bool]) -> Result<(), StepError> {
        self.check_state(state)?;
        if verdicts.len() != self.program.props.len() {
            return Err(StepError::InputSize {
                expected: self.program.props.len(),
                found: verdicts.len(),
            });
        }
        if time == u64::MAX {
            return Err(StepError::TimeOutOfRange);
        }
        if state[0] != 0 && time < state[0] - 1 {
            return Err(StepError::TimeWentBackwards {
                last: state[0] - 1,
                now: time,
            });
        }
        Ok(())
    }

    /// The verdict of property `prop` at the last point (false before any point).
    pub fn verdict(&self, state: &[u64], prop: usize) -> Option<bool> {
        let root = self.program.props.get(prop)?.root as usize;
        let w = state.get(self.values_at + root / 64)?;
        Some(w >> (root % 64) & 1 == 1)
    }

    /// Updates every node; the state length and the time were checked by the caller.
    fn advance(&self, state: &mut [u64], t: u64, verdicts: &mut [bool]) {
        let first_point = state[0] == 0;
        let vals = self.values_at;
        let get = |state: &[u64], base: usize, i: u16| -> bool {
            let i = i as usize;
            state[base + i / 64] >> (i % 64) & 1 == 1
        };
        for (i, node) in self.program.nodes.iter().enumerate() {
            let slot = node.slot as usize;
            let v = match node.op {
                Op::Const(c) => c,
                Op::Atom(a) => get(state, layout::HEADER_WORDS, a),
                Op::Not(a) => !get(state, vals, a),
                Op::And(a, b) => get(state, vals, a) && get(state, vals, b),
                Op::Or(a, b) => get(state, vals, a) || get(state, vals, b),
                Op::Implies(a, b) => !get(state, vals, a) || get(state, vals, b),
                Op::Iff(a, b) => get(state, vals, a) == get(state, vals, b),
                Op::Yesterday(a) => {
                    let out = !first_point && state[slot] != 0;
                    state[slot] = get(state, vals, a) as u64;
                    out
                }
                Op::WeakYesterday(a) => {
                    let out = first_point || state[slot] != 0;
                    state[slot] = get(state, vals, a) as u64;
                    out
                }
                Op::Since { lhs, rhs, lo, hi } => {
                    let f = get(state, vals, lhs);
                    let g = get(state, vals, rhs);
                    match layout::since_kind(lo, hi) {
                        Some(SinceKind::Unbounded) => {
                            let prev = !first_point && get(state, vals, i as u16);
                            g || (f && prev)
                        }
                        Some(SinceKind::UpTo(b)) => {
                            let w = &mut state[slot];
                            if !f {
                                *w = 0;
                            }
                            if g {
                                *w = t + 1;
                            }
                            *w != 0 && t - (*w - 1) <= b
                        }
                        Some(SinceKind::AtLeast(a)) => {
                            let w = &mut state[slot];
                            if !f {
                                *w = 0;
                            }
                            if g && *w == 0 {
                                *w = t + 1;
                            }
                            *w != 0 && t - (*w - 1) >= a
                        }
                        Some(SinceKind::Window { lo, hi, cap }) => {
                            window_step(&mut state[slot..], cap as usize, lo, hi, t, f, g)
                        }
                        // Rejected by `try_new`.
                        None => false,
                    }
                }
            };
            let w = &mut state[vals + i / 64];
            *w = (*w & !(1 << (i % 64))) | ((v as u64) << (i % 64));
        }
        state[0] = t + 1;
        for (out, pr) in verdicts.iter_mut().zip(self.program.props) {
            *out = get(state, vals, pr.root);
        }
    }
}

/// One point of `f S[lo:hi] g` with `0 < lo <= hi`, over a ring of witness runs.
///
/// `w[0]` packs `head | len << 32`; run `k` is `w[1 + 2k] = first`, `w[2 + 2k] = last`.
/// Amortised constant work: each run is pushed and expired once, and only the
/// oldest run decides the verdict (it has the smallest `first`, and every live
/// run still has `last + hi >= t`).
fn window_step(w: &mut [u64], cap: usize, lo: u64, hi: u64, t: u64, f: bool, g: bool) -> bool {
    let mut head = (w[0] & 0xffff_ffff) as usize;
    let mut len = (w[0] >> 32) as usize;
    if !f {
        len = 0;
    }
    while len > 0 && w[2 + 2 * head].saturating_add(hi) < t {
        head = if head + 1 == cap { 0 } else { head + 1 };
        len -= 1;
    }
    if len == 0 {
        head = 0;
    }
    if g {
        let newest = (head + len + cap - 1) % cap;
        if len > 0 && t - w[2 + 2 * newest] <= hi - lo {
            w[2 + 2 * newest] = t;
        } else if len < cap {
            let k = (head + len) % cap;
            w[1 + 2 * k] = t;
            w[2 + 2 * k] = t;
            len += 1;
        }
        // len == cap cannot happen: at most floor(hi / (hi - lo + 1)) + 1 runs are live.
    }
    w[0] = head as u64 | (len as u64) << 32;
    len > 0 && w[1 + 2 * head].saturating_add(lo) <= t
}
