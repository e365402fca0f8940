//! The table interpreter: a validated [`Program`] stepped over a caller-provided state buffer.

use crate::error::{StepError, TableError};
use crate::expr;
use crate::layout;
use crate::plan::{self, AtomStep, Kind, Plan, Step};
use crate::program::{Atom, Instr, Op, Program, Ty, Value, VarKind};

mod node;

use node::{rd, special, wr, NodeStep};

/// A [`Program`] that passed every check: it can be stepped without panicking.
///
/// Build one with [`Monitor::try_new`]; allocate `state_words()` words (statically
/// or on the stack), [`Monitor::reset`] them, then call [`Monitor::try_step`]
/// once per point.
///
/// `N` is the room for a plan (`plan.rs`): a `Monitor<'_, N>` built with
/// [`Monitor::try_new_planned`] decides each node's kind, children, state slot
/// and window capacity and each atom's shape once, for programs of at most `N`
/// nodes and `N` atoms, and steps faster. It holds `N` entries of 40 bytes,
/// `N` of 32 and `N` of 8 (const generics: no allocation); the default `N = 0`
/// plans nothing and holds nothing more.
#[derive(Clone, Copy, Debug)]
pub struct Monitor<'a, const N: usize = 0> {
    program: Program<'a>,
    state_words: usize,
    values_at: usize,
    /// First word of the nodes' own state ([`layout::first_node_word`]), decided once.
    nodes_at: usize,
    /// At most 64 atoms and 64 nodes, decided once: the atoms and the node values
    /// of a point each fit one register ([`Monitor::advance`]).
    /// Whether `plan` and `atom_plan` hold the program (`info.planned`) and what
    /// the plan decided for the whole program ([`Plan`]).
    info: Plan,
    /// The plan's steps, the first `info.steps` used, when planned.
    plan: [Step; N],
    /// Atom `k`'s plan, for `k < program.atoms.len()` when planned.
    atom_plan: [AtomStep; N],
    /// [`Plan::TABLE`]: the value word after a point that is not the first, by
    /// atoms, timed steps' values and memory bits ([`plan::build_table`]); [`Plan::LITS`]: the
    /// literal nodes' bits by atoms ([`plan::build_literals`]).
    table: [u64; N],
}

/// [`Monitor::advance_folded`]'s shape, when the caller knows it: any folded
/// plan (decided by its flags at each point), a transition table
/// ([`Plan::TABLE`]) or one step.
const SHAPE_ANY: u8 = 0;
/// A transition table: see [`SHAPE_ANY`].
const SHAPE_TABLE: u8 = 1;
/// A plan of one step: see [`SHAPE_ANY`].
const SHAPE_ONE: u8 = 2;

/// The most nodes, atoms or variables a program may have (ids are `u16`).
pub const MAX_IDS: usize = u16::MAX as usize;

impl<'a> Monitor<'a> {
    /// Checks every invariant of `program`: indices, types, bounds, state slots.
    pub fn try_new(program: Program<'a>) -> Result<Self, TableError> {
        Self::try_new_planned(program)
    }
}

impl<'a, const N: usize> Monitor<'a, N> {
    /// [`Monitor::try_new`], and the plan of a program of at most `N` nodes and
    /// `N` atoms (a larger one is stepped unplanned, with the same results).
    pub fn try_new_planned(program: Program<'a>) -> Result<Self, TableError> {
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
            let Some(needs) = expr::check(code, p.vars) else {
                return Err(err);
            };
            if !expr::enabled(needs) {
                return Err(TableError::Feature { atom: i as u16 });
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
        let nodes_at = layout::first_node_word(p.atoms.len(), p.nodes.len());
        let mut monitor = Monitor {
            program,
            state_words: next_word as usize,
            values_at: layout::HEADER_WORDS + layout::bit_words(p.atoms.len()),
            nodes_at,
            info: Plan {
                steps: 0,
                flags: if p.atoms.len() <= 64 && p.nodes.len() <= 64 {
                    Plan::SMALL
                } else {
                    0
                },
                shift: 0,
                top: 0,
                timed: 0,
            },
            plan: [Step::NONE; N],
            atom_plan: [AtomStep::NONE; N],
            table: [0; N],
        };
        if N > 0 {
            if let Some(info) = plan::build(
                &program,
                nodes_at,
                &mut monitor.plan,
                &mut monitor.atom_plan,
            ) {
                monitor.info = Plan {
                    flags: info.flags | monitor.info.flags,
                    ..info
                };
                if info.has(Plan::FOLDED) {
                    let steps = monitor
                        .plan
                        .get_mut(..info.steps as usize)
                        .unwrap_or(&mut []);
                    let timed = plan::timed_first(steps);
                    let atoms = monitor.atom_plan.get(..p.atoms.len()).unwrap_or(&[]);
                    let table = timed.and_then(|timed| {
                        plan::build_table(steps, timed, atoms, &mut monitor.table)
                            .map(|m| (timed, m))
                    });
                    if let Some((timed, m)) = table {
                        monitor.info.flags |= Plan::TABLE;
                        monitor.info.top = 64 - m as u8;
                        monitor.info.timed = timed as u8;
                    } else if plan::build_literals(atoms, &mut monitor.table).is_some() {
                        monitor.info.flags |= Plan::LITS;
                    }
                }
            }
        }
        Ok(monitor)
    }

    /// Whether this monitor steps through its plan: `N > 0` and the program has
    /// at most `N` nodes and `N` atoms (see [`Monitor::try_new_planned`]).
    pub fn is_planned(&self) -> bool {
        N > 0 && self.info.has(Plan::PLANNED)
    }

    /// `Some(k)` when this monitor steps every point but the first by a
    /// transition table, after `k` timed steps (`P[a:b] p`, `p S[a:b] q` over
    /// atoms and other timed steps); `None` otherwise (an observation for
    /// tests and benchmarks: the verdicts are the same either way).
    pub fn table_after_timed_steps(&self) -> Option<usize> {
        self.info
            .has(Plan::TABLE)
            .then_some(self.info.timed as usize)
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
        let p = &self.program;
        if cfg!(feature = "compact") {
            // The checks one after the other: the smallest code (firmware).
            self.check_point(state, time, verdicts)?;
            if vars.len() != p.vars.len() {
                return Err(StepError::InputSize {
                    expected: p.vars.len(),
                    found: vars.len(),
                });
            }
        } else {
            // Every check of the point's shape in one test, the error built out of line.
            let last = state.first().copied().unwrap_or(0);
            let ok = (state.len() == self.state_words)
                & (verdicts.len() == p.props.len())
                & (vars.len() == p.vars.len())
                & (time.wrapping_add(1) >= last)
                & (time != u64::MAX);
            if !ok {
                return Err(self.point_error(state, time, vars.len(), verdicts));
            }
        }
        if N > 0 && self.info.has(Plan::PLANNED) {
            return self.step_planned(state, time, vars, verdicts);
        }
        check_types(p, vars)?;
        // Atoms first: an error leaves the temporal state untouched.
        let first = atom_words(p.atoms, p.instrs, vars, state)?;
        self.advance(p.nodes, state, time, first, verdicts);
        Ok(())
    }

    /// [`Monitor::try_step`] through the plan, once the point's shape is checked.
    #[inline(always)]
    fn step_planned(
        &self,
        state: &mut [u64],
        time: u64,
        vars: &[Value],
        verdicts: &mut [bool],
    ) -> Result<(), StepError> {
        let (p, info) = (&self.program, &self.info);
        if info.has(Plan::FAST) {
            // The two commonest shapes first, each stepped with its flags known:
            // atoms that are a run of boolean variables, and a transition table or
            // one step (no test of the other flags, the literals only where read).
            const RUN: u8 = Plan::FAST | Plan::BOOLS | Plan::RUN | Plan::FOLDED;
            if info.flags & (RUN | Plan::TABLE) == RUN | Plan::TABLE {
                return self.step_run::<SHAPE_TABLE>(state, time, vars, verdicts);
            }
            if info.flags & (RUN | Plan::TABLE) == RUN && info.steps == 1 {
                return self.step_run::<SHAPE_ONE>(state, time, vars, verdicts);
            }
            let vb = var_bits(p, vars)?;
            let mut bits = 0u64;
            if info.has(Plan::RUN) {
                bits = self.run_bits(vb);
            } else if info.has(Plan::BOOLS) {
                for (k, a) in self.plan_atoms().iter().enumerate() {
                    let v = (vb.wrapping_shr(a.var as u32) ^ a.c as u64) & 1;
                    bits |= v << (k & 63);
                }
            } else {
                for (k, a) in self.plan_atoms().iter().enumerate() {
                    // The types were checked: never `None`.
                    let v = a.fast(vars).unwrap_or(false);
                    bits |= (v as u64) << (k & 63);
                }
            }
            if info.has(Plan::FOLDED) {
                let lits = || self.literals(bits);
                self.advance_folded::<SHAPE_ANY>(state, time, bits, bits, lits, verdicts);
            } else {
                if !p.atoms.is_empty() {
                    wr(state, layout::HEADER_WORDS, bits);
                }
                self.advance(self.plan_nodes(), state, time, bits, verdicts);
            }
            return Ok(());
        }
        check_types(p, vars)?;
        // Atoms first: an error leaves the temporal state untouched.
        let first = atom_words(self.plan_atoms(), p.instrs, vars, state)?;
        self.advance_plan(state, time, first, verdicts);
        Ok(())
    }

    /// [`Monitor::step_planned`] of a folded plan whose atoms are a run of
    /// boolean variables ([`Plan::RUN`]) and whose shape is `SHAPE`
    /// ([`Monitor::advance_folded`]).
    #[inline(always)]
    fn step_run<const SHAPE: u8>(
        &self,
        state: &mut [u64],
        time: u64,
        vars: &[Value],
        verdicts: &mut [bool],
    ) -> Result<(), StepError> {
        let bits = self.run_bits(var_bits(&self.program, vars)?);
        let lits = || self.literals(bits);
        self.advance_folded::<SHAPE>(state, time, bits, bits, lits, verdicts);
        Ok(())
    }

    /// [`Plan::RUN`]: the atoms from the boolean variables' bits `vb`.
    #[inline(always)]
    fn run_bits(&self, vb: u64) -> u64 {
        // At most 64 variables: `shift + atoms <= 64`. With no atom the mask is
        // all ones and the bits are read by nothing.
        let n = self.program.atoms.len() as u32;
        vb >> (self.info.shift & 63) & u64::MAX >> (64u32.wrapping_sub(n) & 63)
    }

    /// A transition table's first point: the whole plan, out of line.
    #[cold]
    #[inline(never)]
    fn fold_first(&self, body: &mut [u64], t: u64, old: u64, nodes: u64) -> u64 {
        self.fold(body, t, old, nodes, true)
    }

    /// The network step of a planned monitor, from the atoms of this point
    /// (stored in the state's scratch words, the first of them in `first`).
    #[inline(always)]
    fn advance_plan(&self, state: &mut [u64], time: u64, first: u64, verdicts: &mut [bool]) {
        if self.info.has(Plan::FOLDED) {
            // Only the atoms' bits index the tables: a caller's word
            // (`try_step_atoms`) may have more set.
            let n = self.program.atoms.len() as u32;
            let exact = first & u64::MAX.checked_shr(64u32.wrapping_sub(n)).unwrap_or(0);
            let lits = || self.literals(exact);
            self.advance_folded::<SHAPE_ANY>(state, time, first, exact, lits, verdicts);
        } else {
            self.advance(self.plan_nodes(), state, time, first, verdicts);
        }
    }

    /// Folded plans: the literal nodes' bits for the atoms `atoms`.
    #[inline(always)]
    fn literals(&self, atoms: u64) -> u64 {
        if self.info.has(Plan::LITS) {
            return self.table.get(atoms as usize).copied().unwrap_or(0);
        }
        plan::literal_bits(self.plan_atoms(), atoms)
    }

    /// The network step of a folded plan ([`Plan::FOLDED`]): `atoms` is this
    /// point's atom word as given, `exact` its bits of the atoms alone (the
    /// tables' index), `nodes` gives the literal nodes' bits; each step adds its
    /// node's (and its fused `Not`'s). One to 64 atoms and at most 64 nodes: the
    /// state opens with exactly three words (time, atoms, values; [`layout`]),
    /// and the values of this point and the last each fit one register. With a
    /// transition table ([`Plan::TABLE`]) every point but the first is the timed
    /// steps, if any, and one lookup. `SHAPE` is the plan's shape when the
    /// caller knows it ([`SHAPE_TABLE`], [`SHAPE_ONE`]), else [`SHAPE_ANY`].
    #[inline(always)]
    fn advance_folded<const SHAPE: u8>(
        &self,
        state: &mut [u64],
        t: u64,
        atoms: u64,
        exact: u64,
        nodes: impl FnOnce() -> u64,
        verdicts: &mut [bool],
    ) {
        // The state length was checked (it covers every node's words): never `None`.
        let Some(([time_word, atom_word, value_word], body)) = state.split_first_chunk_mut::<3>()
        else {
            return;
        };
        let first_point = *time_word == 0;
        let old = *value_word;
        let new = if SHAPE == SHAPE_ONE {
            self.fold_one(body, t, old, nodes(), first_point)
        } else if SHAPE == SHAPE_TABLE && first_point {
            self.fold_first(body, t, old, nodes())
        } else if (SHAPE == SHAPE_TABLE || self.info.has(Plan::TABLE)) && !first_point {
            self.table_step(body, t, old, exact)
        } else if self.info.steps != 1 {
            self.fold(body, t, old, nodes(), first_point)
        } else {
            // One step (`P[a:b] p`, `p S[a:b] q`, `P[0:b] p`: a timed node over
            // literals): no step loop.
            self.fold_one(body, t, old, nodes(), first_point)
        };
        *atom_word = atoms;
        *value_word = new;
        *time_word = t + 1;
        for (out, pr) in verdicts.iter_mut().zip(self.program.props) {
            *out = new >> (pr.root & 63) & 1 == 1;
        }
    }

    /// A transition table's step ([`Plan::TABLE`]) at a point that is not the
    /// first: the timed steps, then one lookup whose index is the atoms `exact`,
    /// above them the memory bits of `old` and above those the timed steps'
    /// values ([`plan::build_table`]).
    #[inline(always)]
    fn table_step(&self, body: &mut [u64], t: u64, old: u64, exact: u64) -> u64 {
        let n = self.program.atoms.len();
        let mut idx = match self.table.as_slice() {
            // One multiply gathers the memory bits (most tables).
            [.., k, mem] if *k != 0 => {
                exact | (old & mem).wrapping_mul(*k) >> (self.info.top & 63) << (n & 63)
            }
            [.., mem] => plan::gather(exact, n, old, *mem),
            [] => 0,
        };
        if self.info.timed != 0 {
            idx = self.timed_steps(body, t, idx);
        }
        self.table.get(idx as usize).copied().unwrap_or(0)
    }

    /// The timed steps of a transition table's plan ([`Plan::timed`]) at a
    /// point that is not the first: each reads its children from the table's
    /// index `idx` and sets its own bit there ([`plan::build_table`]). Out of
    /// line, so that `try_step` stays small enough to inline into its caller's
    /// loop.
    #[inline(never)]
    fn timed_steps(&self, body: &mut [u64], t: u64, mut idx: u64) -> u64 {
        let timed = self.plan.get(..self.info.timed as usize).unwrap_or(&[]);
        for s in timed {
            let f = plan::index_bit(idx, s.ia);
            let g = plan::index_bit(idx, s.ib);
            let v = special::<false>(s, body, t, f, g, 0) as u64;
            idx |= v.wrapping_shl(s.at as u32);
        }
        idx
    }

    /// [`Monitor::fold`] of a plan of one step, out of line: the loop's
    /// registers stay as they are for the other plans.
    #[inline(never)]
    fn fold_one(&self, body: &mut [u64], t: u64, old: u64, nodes: u64, first_point: bool) -> u64 {
        let d = if first_point { plan::D } else { 0 };
        match self.plan.first() {
            Some(s) => fold_step::<true>(s, body, t, old, nodes, d),
            None => 0,
        }
    }

    /// The folded steps at one point, from the literal nodes' bits `nodes` and
    /// the last point's value word `old`: this point's value word.
    #[inline(always)]
    fn fold(&self, body: &mut [u64], t: u64, old: u64, nodes: u64, first_point: bool) -> u64 {
        let d = if first_point { plan::D } else { 0 };
        let mut new = nodes;
        for s in self.plan_nodes() {
            new = fold_step::<false>(s, body, t, old, new, d);
        }
        new
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
        for (k, a) in atoms.iter().enumerate() {
            wr(state, layout::HEADER_WORDS + k, *a);
        }
        let first = atoms.first().copied().unwrap_or(0);
        if N > 0 && self.info.has(Plan::PLANNED) {
            self.advance_plan(state, time, first, verdicts);
        } else {
            self.advance(self.program.nodes, state, time, first, verdicts);
        }
        Ok(())
    }

    /// The error of a point [`Monitor::try_step`] found of the wrong shape: the
    /// first of [`Monitor::check_point`]'s, else the variables' count.
    #[cold]
    #[inline(never)]
    fn point_error(&self, state: &[u64], time: u64, vars: usize, verdicts: &[bool]) -> StepError {
        match self.check_point(state, time, verdicts) {
            Err(e) => e,
            Ok(()) => StepError::InputSize {
                expected: self.program.vars.len(),
                found: vars,
            },
        }
    }

    fn check_point(&self, state: &[u64], time: u64, verdicts: &[bool]) -> Result<(), StepError> {
        self.check_state(state)?;
        if verdicts.len() != self.program.props.len() {
            return Err(StepError::InputSize {
                expected: self.program.props.len(),
                found: verdicts.len(),
            });
        }
        // `last` is 1 + the last time (0 before the first point): `time + 1 < last`
        // is "time went backwards", and a `time` of `u64::MAX` wraps to 0.
        let last = rd(state, 0);
        if time.wrapping_add(1) < last || time == u64::MAX {
            if time == u64::MAX {
                return Err(StepError::TimeOutOfRange);
            }
            return Err(StepError::TimeWentBackwards {
                last: last.wrapping_sub(1),
                now: time,
            });
        }
        Ok(())
    }

    /// The verdict of property `prop` at the last point (false before any point).
    pub fn verdict(&self, state: &[u64], prop: usize) -> Option<bool> {
        self.node_value(state, self.program.props.get(prop)?.root)
    }

    /// The value of node `node` at the last point (false before any point).
    ///
    /// Lets a host-side analysis (for example "this verdict can no longer change")
    /// read the network without knowing the state layout.
    pub fn node_value(&self, state: &[u64], node: u16) -> Option<bool> {
        if node as usize >= self.program.nodes.len() {
            return None;
        }
        let w = state.get(self.values_at + node as usize / 64)?;
        Some(w >> (node % 64) & 1 == 1)
    }

    /// The timestamp of the last point, `None` before the first point.
    pub fn last_time(&self, state: &[u64]) -> Option<u64> {
        state.first().and_then(|t| t.checked_sub(1))
    }

    /// The plan's atoms (empty unless planned).
    #[inline(always)]
    fn plan_atoms(&self) -> &[AtomStep] {
        self.atom_plan
            .get(..self.program.atoms.len())
            .unwrap_or(&[])
    }

    /// The plan's steps (empty unless planned).
    #[inline(always)]
    fn plan_nodes(&self) -> &[Step] {
        self.plan.get(..self.info.steps as usize).unwrap_or(&[])
    }

    /// Updates every node, planned ([`Step`]) or not ([`Node`](crate::program::Node)): one loop for
    /// both; the state length and the time were checked by the caller, and the
    /// atoms of this point are in the scratch words, the first of them also in
    /// `atoms`.
    ///
    /// Every access goes through `get`/`get_mut` (the slots were validated, so the
    /// fallbacks never run): the step links no panic path into firmware. The value
    /// bits of the nodes being updated are built in a register and stored once per
    /// 64 nodes; a node's children come before it, so their values at this point
    /// are either in that register or in a word already stored. A program of at
    /// most 64 atoms and 64 nodes (most of them) takes a loop without the word
    /// bookkeeping, unless the `compact` feature keeps only the general loop.
    #[inline(always)]
    fn advance<S: NodeStep>(
        &self,
        nodes: &[S],
        state: &mut [u64],
        t: u64,
        atoms: u64,
        verdicts: &mut [bool],
    ) {
        // Header, atom and value words before `off`; nodes' own words from `off` on.
        let (off, vals) = (self.nodes_at, self.values_at);
        // The state length was checked (it covers every node's words): never `None`.
        let Some((head, body)) = state.split_at_mut_checked(off) else {
            return;
        };
        let first_point = rd(head, 0) == 0;
        if !cfg!(feature = "compact") && self.info.has(Plan::SMALL) {
            let old = rd(head, vals);
            let mut new = 0u64;
            for (i, node) in nodes.iter().enumerate() {
                let now = new;
                let v = node.value(
                    off,
                    body,
                    t,
                    first_point,
                    |a| atoms >> (a & 63) & 1 == 1,
                    |c| now >> (c & 63) & 1 == 1,
                    old >> (i & 63) & 1 == 1,
                );
                new |= (v as u64) << (i & 63);
            }
            wr(head, vals, new);
            wr(head, 0, t + 1);
            for (out, pr) in verdicts.iter_mut().zip(self.program.props) {
                *out = new >> (pr.root & 63) & 1 == 1;
            }
            return;
        }
        let mut old = rd(head, vals);
        let mut new = 0u64;
        let mut base = 0usize;
        for (i, node) in nodes.iter().enumerate() {
            if i - base >= 64 {
                wr(head, vals + base / 64, new);
                base = i;
                old = rd(head, vals + base / 64);
                new = 0;
            }
            let (now, h): (u64, &[u64]) = (new, head);
            let v = node.value(
                off,
                body,
                t,
                first_point,
                |a| rd(h, layout::HEADER_WORDS + a as usize / 64) >> (a % 64) & 1 == 1,
                |c| {
                    let c = c as usize;
                    let w = if c >= base {
                        now >> ((c - base) & 63)
                    } else {
                        rd(h, vals + c / 64) >> (c % 64)
                    };
                    w & 1 == 1
                },
                old >> ((i - base) & 63) & 1 == 1,
            );
            new |= (v as u64) << ((i - base) & 63);
        }
        wr(head, vals + base / 64, new);
        wr(head, 0, t + 1);
        for (out, pr) in verdicts.iter_mut().zip(self.program.props) {
            let r = pr.root as usize;
            *out = rd(head, vals + r / 64) >> (r % 64) & 1 == 1;
        }
    }
}

/// One folded step: `new` is this point's value word so far (the literal nodes
/// and the steps before `s`), `old` the last point's, `d` [`plan::D`] at the
/// first point (else 0); `new` with this step's node (and its fused `Not`) added.
#[inline(always)]
fn fold_step<const ONE: bool>(
    s: &Step,
    body: &mut [u64],
    t: u64,
    old: u64,
    new: u64,
    d: u16,
) -> u64 {
    if s.kind == Kind::Logic {
        return plan::logic_step(s, old, new, d);
    }
    let f = new.wrapping_shr(s.a as u32) & 1 == 1;
    let g = new.wrapping_shr(s.b as u32) & 1 == 1;
    plan::with_value(s, new, special::<ONE>(s, body, t, f, g, d) as u64)
}

/// [`Plan::FAST`]: one pass over the variables (at most 64): each value's type
/// against the declared one (a mismatch gives the first variable of another
/// type, before anything is written) and the booleans' bits.
#[inline(always)]
fn var_bits(p: &Program<'_>, vars: &[Value]) -> Result<u64, StepError> {
    let (mut bad, mut vb) = (false, 0u64);
    for (i, (v, d)) in vars.iter().zip(p.vars).enumerate() {
        let (ty, b) = match *v {
            Value::Bool(b) => (Ty::Bool, b),
            Value::Int(_) => (Ty::Int, false),
            Value::Float(_) => (Ty::Float, false),
            Value::Str(_) => (Ty::Str, false),
        };
        bad |= ty != d.ty;
        vb |= (b as u64) << (i & 63);
    }
    if bad {
        return Err(type_error(p, vars));
    }
    Ok(vb)
}

/// Every value of `vars` has its variable's declared type (same length, checked before).
#[inline(always)]
fn check_types(p: &Program<'_>, vars: &[Value]) -> Result<(), StepError> {
    for (i, (v, d)) in vars.iter().zip(p.vars).enumerate() {
        if v.ty() != d.ty {
            return Err(StepError::VarType { var: i as u16 });
        }
    }
    Ok(())
}

/// The error of a point whose shape a planned atom read found wrong: the first
/// variable of another type than declared, as [`check_types`] reports it.
#[cold]
#[inline(never)]
fn type_error(p: &Program<'_>, vars: &[Value]) -> StepError {
    match check_types(p, vars) {
        Err(e) => e,
        // Not reached: the read that failed saw a value of another type.
        Ok(()) => StepError::VarType { var: 0 },
    }
}

/// One atom at one point: a program's [`Atom`] or its plan ([`AtomStep`]).
trait AtomValue {
    /// The atom's value from the variables; `atom` is its index (for errors).
    fn value(&self, instrs: &[Instr], vars: &[Value], atom: usize) -> Result<bool, StepError>;
}

impl AtomValue for Atom {
    /// A boolean variable (one `Load`, the most common atom) is read directly; any
    /// other atom, or a value of another type, goes through [`expr::eval`], so
    /// results and errors are those of the general machine.
    #[inline(always)]
    fn value(&self, instrs: &[Instr], vars: &[Value], atom: usize) -> Result<bool, StepError> {
        let start = self.start as usize;
        match (self.len, instrs.get(start)) {
            (1, Some(Instr::Load(n))) => match vars.get(*n as usize) {
                Some(Value::Bool(v)) => Ok(*v),
                _ => general_atom(instrs, start, self.len, vars, atom),
            },
            _ => general_atom(instrs, start, self.len, vars, atom),
        }
    }
}

impl AtomValue for AtomStep {
    #[inline(always)]
    fn value(&self, instrs: &[Instr], vars: &[Value], atom: usize) -> Result<bool, StepError> {
        self.eval(instrs, vars, atom)
    }
}

/// Computes every atom of this point into the scratch words of `state`, 64 at a
/// time, and returns the first word (0 without atoms).
#[inline(always)]
fn atom_words<A: AtomValue>(
    atoms: &[A],
    instrs: &[Instr],
    vars: &[Value],
    state: &mut [u64],
) -> Result<u64, StepError> {
    if !cfg!(feature = "compact") && atoms.len() <= 64 {
        // One word in a register (most programs): no chunk bookkeeping.
        let mut bits = 0u64;
        for (b, a) in atoms.iter().enumerate() {
            bits |= (a.value(instrs, vars, b)? as u64) << (b & 63);
        }
        // No scratch word without atoms: the value word comes next.
        if !atoms.is_empty() {
            wr(state, layout::HEADER_WORDS, bits);
        }
        return Ok(bits);
    }
    let mut first = 0u64;
    for (w, chunk) in atoms.chunks(64).enumerate() {
        let mut bits = 0u64;
        for (b, a) in chunk.iter().enumerate() {
            bits |= (a.value(instrs, vars, w * 64 + b)? as u64) << (b & 63);
        }
        if w == 0 {
            first = bits;
        }
        wr(state, layout::HEADER_WORDS + w, bits);
    }
    Ok(first)
}

/// Atom number `atom`, `len` instructions from `start`, through the atom machine.
#[inline(never)]
fn general_atom(
    instrs: &[Instr],
    start: usize,
    len: u16,
    vars: &[Value],
    atom: usize,
) -> Result<bool, StepError> {
    let code = instrs.get(start..start + len as usize).unwrap_or(&[]);
    expr::eval(code, vars, atom as u16)
}
