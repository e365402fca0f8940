//! The simulator: runs a [`CompiledModel`] as a channel system, step by step, without allocating.

use super::as2fm::{event_flags, may_discard, never_discards, EV_BB_REQ, EV_BB_SET, EV_TIMER};
use super::compiled::{CompiledModel, DelayDef, Instr, MachineDef, SendDef, SendTo};
use super::ids::{EventId, MachineId, StateId};
use super::observer::{Flow, Inbox, Observer, Scalar, SentMessage, EXTERNAL};
use crate::expr::compile::{Code, Entropy, Env, EvalError, EvalErrorKind, MAX_PATH};
use crate::expr::value::{Cell, StrId, Strings};
use crate::expr::Value;
use crate::model::Diagnostic;
use std::collections::VecDeque;

mod config;
mod deliver;
mod sched;
mod send;
mod stop;

pub use config::{
    EndReason, EventSemantics, Quiescence, RunConfig, RunError, RunOutcome, SpinKind, SpinReport,
    TransitionChoice,
};
pub use sched::{mix, Memory, PutBack, Sampled, Scheduler};

const IDLE: u32 = u32::MAX;
const NO_MSG: u32 = u32::MAX;
const NOT_RUNNABLE: u32 = u32::MAX;

#[derive(Clone, Debug)]
struct Slot {
    event: u32,
    origin: u32,
    /// `u32::MAX`: the `NONE` sink.
    target: u32,
    params: Vec<Cell>,
}

#[derive(Debug)]
struct MachineRt {
    state: u32,
    pc: u32,
    /// Blocked by a delayed send until `wake`.
    waiting: bool,
    /// [`EventSemantics::As2fm`]: blocked at a send (its event is pending) or waiting
    /// for a timer event it sent to be delivered (`awaiting`).
    blocked: bool,
    /// The timer event this machine waits to see delivered (`NO_MSG`: none).
    awaiting: u32,
    wake: u64,
    /// Index of the next target of a send without target.
    bcast: u32,
    /// The current send's delay has elapsed.
    delay_done: bool,
    /// Message being processed (`_event`), a pool slot.
    cur: u32,
    cur_event: StrId,
    cur_origin: StrId,
    intq: VecDeque<u32>,
    extq: VecDeque<u32>,
    vars: Vec<Cell>,
    /// Position in [`Simulator::runnable`] (`NOT_RUNNABLE`: not there).
    rpos: u32,
    /// Steps taken at the current instant.
    moves: u32,
    /// The scheduler iteration it last changed in (state, variables, position, flags).
    changed: u64,
    /// Its cached state hash is stale (it is in [`Simulator::dirty`]); see `run/sched.rs`.
    dirty: bool,
}

/// Runs a compiled model; reuse one simulator for many runs (buffers are kept).
///
/// Scheduling (SCAN's channel-system semantics): at each step one machine is
/// chosen uniformly at random among those that can move; it runs until it
/// completes one communication (a send, or taking a message from its external
/// queue) or until it has nothing left to do. Assignments, conditions,
/// eventless transitions and raised events are internal to that step.
/// When no machine can move, time advances by one unit (waking machines whose
/// delayed send is due).
pub struct Simulator<'m> {
    model: &'m CompiledModel,
    ms: Vec<MachineRt>,
    pool: Vec<Slot>,
    /// Free message slots, per event.
    free: Vec<Vec<u32>>,
    runnable: Vec<u32>,
    delayed: Vec<u32>,
    enabled: Vec<u32>,
    time: u64,
    steps: u64,
    instant_steps: u64,
    /// Per machine, one scratch cell per instruction that builds arrays or structs,
    /// so each keeps its buffers' shape from step to step and run to run.
    scratch: Vec<Vec<Cell>>,
    idx: [i64; MAX_PATH],
    /// The current run uses [`EventSemantics::As2fm`].
    as2fm: bool,
    /// Per event: [`EV_TIMER`], [`EV_SYNCHED`], [`EV_BB_REQ`], [`EV_BB_SET`] flags.
    ev_flags: Vec<u8>,
    /// Per machine: never discards events (BT roots and ROS interface handlers).
    no_discard: Vec<bool>,
    /// Per event: pending (as2fm).
    pending: Vec<bool>,
    /// Pending events, in the order they were sent.
    pending_list: Vec<u32>,
    /// Pending events other than timer events.
    pending_regular: u32,
    /// Pending `bt_blackboard_set_*` events.
    pending_bb_set: u32,
    /// Scratch: events deliverable at this step.
    deliverable: Vec<u32>,
    /// Messages from outside the model not posted yet ([`Observer::inputs`]).
    inbox: Inbox,
    /// Machines blocked at a send.
    blocked_list: Vec<u32>,
    /// Per event: parameters being evaluated before they replace the global ones.
    ev_scratch: Vec<Vec<Cell>>,
    /// Per event: the pool slot of its first receiver's copy of a delivered message.
    rx_base: Vec<u32>,
    /// Pool slots reserved for [`EventSemantics::As2fm`] (never freed).
    reserved: usize,
    /// No transition condition draws random numbers: with [`TransitionChoice::DocumentOrder`]
    /// a receiver's choice depends only on its own state, so it can be kept.
    pure_guards: bool,
    /// The current run keeps receivers' choices ([`EventSemantics::As2fm`], pure guards,
    /// document order).
    keep_choices: bool,
    /// Scheduler iterations so far (never reset): the stamps below are its values.
    clock: u64,
    /// Per receiver of each event (indexed like the receivers' pool slots past the
    /// events' buffers): the iteration its choice was computed in (0: not computed).
    checked: Vec<u64>,
    /// Per receiver of each event: the transition it fires on the pending event
    /// (`NO_TRANS`: it discards it, `CANNOT_TAKE`: not now), as of `checked`.
    choice_kept: Vec<u32>,
    /// [`Memory::History`]: the hash of the run's states and choices so far.
    history: u64,
    /// The current run is under a sampled scheduler: the state hash is kept up to date.
    sampled: bool,
    /// Machines whose cached hash ([`Simulator::mhash`]) is stale. Under the uniform
    /// scheduler every machine stays stale all run, so marking one costs one test.
    dirty: Vec<u32>,
    /// Per machine: the hash of its record (all but the time left on its delay), as of
    /// the last choice it was not stale at.
    mhash: Vec<u64>,
    /// The wrapping sum of `mhash`: the machines' part of the state hash.
    mhash_sum: u64,
}

const NO_TRANS: u32 = u32::MAX;
const CANNOT_TAKE: u32 = u32::MAX - 1;

impl std::fmt::Debug for Simulator<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Simulator")
            .field("time", &self.time)
            .field("steps", &self.steps)
            .finish()
    }
}

/// The expression environment of machine `m`: its variables and its current event.
/// A function over the two fields (not a method) so callers may hold other fields mutably.
#[inline(always)]
fn env<'s>(
    ms: &'s [MachineRt],
    pool: &'s [Slot],
    m: usize,
    rng: &'s mut dyn Entropy,
    strings: &'s Strings,
) -> Env<'s> {
    let r = &ms[m];
    let params: &[Cell] = if r.cur == NO_MSG {
        &[]
    } else {
        &pool[r.cur as usize].params
    };
    env_of(r, params, rng, strings)
}

/// Machine record `r`'s environment, `params` being its current message's parameters.
#[inline(always)]
fn env_of<'s>(
    r: &'s MachineRt,
    params: &'s [Cell],
    rng: &'s mut dyn Entropy,
    strings: &'s Strings,
) -> Env<'s> {
    Env {
        vars: &r.vars,
        params,
        event: r.cur_event,
        origin: r.cur_origin,
        rng,
        strings,
    }
}

/// Machine `m`'s scratch cell `sc` (`None` only if the compiled model is inconsistent).
/// A function over the field, like [`env`], so callers may borrow the others meanwhile.
#[inline]
fn scratch_cell(scratch: &mut [Vec<Cell>], m: usize, sc: u32) -> Option<&mut Cell> {
    scratch.get_mut(m).and_then(|v| v.get_mut(sc as usize))
}

/// Evaluates a send's parameter expressions into `out` (the message's cells), stopping at
/// the first error.
fn eval_params(sd: &SendDef, env: &mut Env<'_>, out: &mut [Cell]) -> Result<(), EvalError> {
    for (i, f) in &sd.params {
        if let Some(dst) = out.get_mut(*i as usize) {
            f(env, dst)?;
        }
    }
    Ok(())
}

/// Unbiased uniform integer in `0..n` (`n > 0`), Lemire's multiply-and-reject
/// (the division is only needed in the rare case the low half is small).
fn below(rng: &mut dyn Entropy, n: u32) -> u32 {
    let n = n as u64;
    let mut m = (rng.next_u64() as u128) * (n as u128);
    if (m as u64) < n {
        let threshold = n.wrapping_neg() % n;
        while (m as u64) < threshold {
            m = (rng.next_u64() as u128) * (n as u128);
        }
    }
    (m >> 64) as u32
}

/// Why a run stops early: a run-time error or a spin, boxed so that the `Result`s of
/// the step functions stay small (the diagnostic inside carries its source line).
enum Stop {
    End(Box<EndReason>),
}

/// Evaluates `code`: a scalar is returned, an array or struct is written into `scratch`.
fn eval_code(
    code: &Code,
    env: &mut Env<'_>,
    scratch: &mut Cell,
) -> Result<Option<Cell>, EvalError> {
    Ok(Some(match code {
        Code::Bool(f) => Cell::Bool(f(env)?),
        Code::Int(f) => Cell::Int(f(env)?),
        Code::Float(f) => Cell::Float(f(env)?),
        Code::Str(f) => Cell::Str(f(env)?),
        Code::Comp(f) => {
            f(env, scratch)?;
            return Ok(None);
        }
    }))
}

impl<'m> Simulator<'m> {
    /// A simulator for `model` (allocates its buffers once).
    pub fn new(model: &'m CompiledModel) -> Self {
        let n = model.machines.len();
        Simulator {
            model,
            ms: model
                .machines
                .iter()
                .map(|d| MachineRt {
                    state: d.initial,
                    pc: IDLE,
                    waiting: false,
                    blocked: false,
                    awaiting: NO_MSG,
                    wake: 0,
                    bcast: 0,
                    delay_done: false,
                    cur: NO_MSG,
                    cur_event: StrId(0),
                    cur_origin: StrId(0),
                    intq: VecDeque::new(),
                    extq: VecDeque::new(),
                    vars: d.defaults.clone(),
                    rpos: NOT_RUNNABLE,
                    moves: 0,
                    changed: 0,
                    dirty: false,
                })
                .collect(),
            // Under EventSemantics::As2fm, slot `e` is event `e`'s global buffer, and
            // each receiver of `e` has its own copy at `rx_base[e] + position`.
            pool: model
                .events
                .iter()
                .enumerate()
                .map(|(e, d)| Slot {
                    event: e as u32,
                    origin: 0,
                    target: u32::MAX,
                    params: d.defaults.clone(),
                })
                .chain(model.events.iter().enumerate().flat_map(|(e, d)| {
                    d.receivers.iter().map(move |&r| Slot {
                        event: e as u32,
                        origin: 0,
                        target: r,
                        params: d.defaults.clone(),
                    })
                }))
                .collect(),
            rx_base: model
                .events
                .iter()
                .scan(model.events.len() as u32, |next, d| {
                    let base = *next;
                    *next += d.receivers.len() as u32;
                    Some(base)
                })
                .collect(),
            reserved: model.events.len()
                + model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>(),
            free: vec![Vec::new(); model.events.len()],
            runnable: Vec::with_capacity(n),
            delayed: Vec::with_capacity(n),
            enabled: Vec::new(),
            time: 0,
            steps: 0,
            instant_steps: 0,
            scratch: model
                .machines
                .iter()
                .map(|d| vec![Cell::Int(0); d.n_scratch as usize])
                .collect(),
            idx: [0; MAX_PATH],
            as2fm: false,
            ev_flags: model.events.iter().map(|e| event_flags(&e.name)).collect(),
            no_discard: model
                .machines
                .iter()
                .map(|d| never_discards(&d.name))
                .collect(),
            pending: vec![false; model.events.len()],
            pending_list: Vec::with_capacity(model.events.len()),
            pending_regular: 0,
            pending_bb_set: 0,
            deliverable: Vec::with_capacity(model.events.len()),
            inbox: Inbox::default(),
            blocked_list: Vec::with_capacity(n),
            ev_scratch: model.events.iter().map(|d| d.defaults.clone()).collect(),
            pure_guards: model
                .machines
                .iter()
                .all(|d| d.trans.iter().all(|t| !t.cond_draws)),
            keep_choices: false,
            clock: 0,
            checked: vec![
                0;
                model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>()
            ],
            choice_kept: vec![
                NO_TRANS;
                model
                    .events
                    .iter()
                    .map(|d| d.receivers.len())
                    .sum::<usize>()
            ],
            history: 0,
            sampled: false,
            dirty: Vec::with_capacity(n),
            mhash: vec![0; n],
            mhash_sum: 0,
        }
    }

    /// Current model time.
    pub fn time(&self) -> u64 {
        self.time
    }

    /// Communication steps taken so far in the current (or last) run.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The current state of a machine.
    pub fn state_of(&self, m: MachineId) -> StateId {
        StateId(self.ms.get(m.0 as usize).map_or(0, |r| r.state))
    }

    /// The current value of a machine's variable.
    pub fn var(&self, m: MachineId, name: &str) -> Option<Value<'_>> {
        let def = self.model.machines.get(m.0 as usize)?;
        let slot = def.vars.iter().position(|(n, _)| n == name)?;
        self.ms.get(m.0 as usize)?.vars.get(slot).map(Value::of)
    }

    /// Keeps machine `m`'s place in [`Simulator::runnable`] true to whether it can move.
    /// Called after nearly every step and delivery (on UC3 about 4 times per step), so
    /// always inlined: the call itself cost a third of it.
    #[inline(always)]
    fn refresh(&mut self, m: usize) {
        let r = &self.ms[m];
        let can =
            !r.waiting && !r.blocked && (r.pc != IDLE || !r.intq.is_empty() || !r.extq.is_empty());
        let pos = r.rpos;
        if can && pos == NOT_RUNNABLE {
            self.ms[m].rpos = self.runnable.len() as u32;
            self.runnable.push(m as u32);
        } else if !can && pos != NOT_RUNNABLE {
            let last = self.runnable.len() - 1;
            self.runnable.swap(pos as usize, last);
            let moved = self.runnable[pos as usize] as usize;
            self.ms[moved].rpos = pos;
            self.runnable.pop();
            self.ms[m].rpos = NOT_RUNNABLE;
        }
    }

    fn free_slot(&mut self, slot: u32) {
        // The first slots are the events' global buffers and receiver copies: never free.
        if (slot as usize) < self.reserved {
            return;
        }
        let ev = self.pool.get(slot as usize).map_or(0, |s| s.event as usize);
        if let Some(f) = self.free.get_mut(ev) {
            f.push(slot);
        }
    }

    fn release(&mut self, m: usize) {
        let cur = self.ms[m].cur;
        if cur != NO_MSG && !self.as2fm {
            self.free_slot(cur);
            self.ms[m].cur = NO_MSG;
        }
    }

    /// Resets every machine to its initial state and evaluates the datamodel.
    fn reset(&mut self, rng: &mut dyn Entropy) -> Result<(), Stop> {
        self.time = 0;
        self.steps = 0;
        self.instant_steps = 0;
        self.history = 0;
        for f in &mut self.free {
            f.clear();
        }
        for i in (self.reserved..self.pool.len()).rev() {
            let ev = self.pool[i].event as usize;
            if let Some(f) = self.free.get_mut(ev) {
                f.push(i as u32);
            }
        }
        self.runnable.clear();
        self.dirty.clear();
        for (m, r) in self.ms.iter_mut().enumerate() {
            r.rpos = NOT_RUNNABLE;
            r.moves = 0;
            r.dirty = true;
            self.dirty.push(m as u32);
        }
        self.mhash.iter_mut().for_each(|h| *h = 0);
        self.mhash_sum = 0;
        self.delayed.clear();
        let model = self.model;
        for (m, def) in model.machines.iter().enumerate() {
            let r = &mut self.ms[m];
            r.state = def.initial;
            r.pc = def
                .states
                .get(def.initial as usize)
                .map_or(IDLE, |s| s.entry);
            r.waiting = false;
            r.blocked = false;
            r.awaiting = NO_MSG;
            r.wake = 0;
            r.bcast = 0;
            r.delay_done = false;
            r.cur = NO_MSG;
            r.cur_event = StrId(0);
            r.cur_origin = StrId(0);
            r.intq.clear();
            r.extq.clear();
            // Variables with an initial value are overwritten below; resetting them to the
            // default first would throw their buffers away.
            for (i, (v, d)) in r.vars.iter_mut().zip(&def.defaults).enumerate() {
                if !def.init.iter().any(|x| x.0 as usize == i) {
                    v.clone_from(d);
                }
            }
            for (slot, f, bound, span, sc) in &def.init {
                let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                    continue;
                };
                let res = {
                    let r = &self.ms[m];
                    let mut env = Env {
                        vars: &r.vars,
                        params: &[],
                        event: StrId(0),
                        origin: StrId(0),
                        rng: &mut *rng,
                        strings: &model.strings,
                    };
                    f(&mut env, scratch)
                };
                if let Err(e) = res {
                    return Err(self.diag_error(m, None, e));
                }
                let scratch = &self.scratch[m][*sc as usize];
                if let (Some(b), Cell::List(v)) = (bound, scratch) {
                    if v.len() > *b as usize {
                        return Err(Stop::End(Box::new(EndReason::Error(RunError {
                            machine: MachineId(m as u32),
                            time: 0,
                            diagnostic: model.sources.diag(
                                *span,
                                format!(
                                    "initial value has {} elements, more than the declared {b}",
                                    v.len()
                                ),
                            ),
                        }))));
                    }
                }
                if let Some(dst) = self.ms[m].vars.get_mut(*slot as usize) {
                    dst.clone_from(scratch);
                }
            }
        }
        self.pending.iter_mut().for_each(|p| *p = false);
        self.checked.iter_mut().for_each(|c| *c = 0);
        self.pending_list.clear();
        self.inbox.items.clear();
        self.pending_regular = 0;
        self.pending_bb_set = 0;
        self.blocked_list.clear();
        for (slot, d) in self.pool.iter_mut().zip(&model.events) {
            for (c, dc) in slot.params.iter_mut().zip(&d.defaults) {
                c.clone_from(dc);
            }
            slot.origin = 0;
        }
        for m in 0..self.ms.len() {
            self.refresh(m);
        }
        Ok(())
    }

    /// Runs the model once from its initial state, calling `obs` at every trace point.
    ///
    /// The same model, configuration and random stream give the same run.
    pub fn run<R: rand_core::Rng, O: Observer + ?Sized>(
        &mut self,
        rng: &mut R,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> RunOutcome {
        let rng: &mut dyn Entropy = rng;
        let end = match self.run_inner(rng, cfg, obs) {
            Ok(e) => e,
            Err(Stop::End(e)) => *e,
        };
        RunOutcome {
            end,
            time: self.time,
            steps: self.steps,
        }
    }

    fn run_inner<O: Observer + ?Sized>(
        &mut self,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> Result<EndReason, Stop> {
        self.as2fm = cfg.events == EventSemantics::As2fm;
        self.keep_choices =
            self.as2fm && self.pure_guards && cfg.transitions == TransitionChoice::DocumentOrder;
        self.sampled = matches!(cfg.scheduler, Scheduler::Sampled(_));
        self.reset(rng)?;
        loop {
            self.clock += 1;
            if self.as2fm {
                self.deliverable.clear();
                for i in 0..self.pending_list.len() {
                    let e = self.pending_list[i];
                    let now = if self.keep_choices {
                        self.deliverable_kept(e, rng, cfg)?
                    } else {
                        self.deliverable_now(e, rng, cfg)?
                    };
                    if now {
                        self.deliverable.push(e);
                    }
                }
                if self.runnable.is_empty()
                    && self.deliverable.is_empty()
                    && !self.pending_list.is_empty()
                    && cfg.quiescence == Quiescence::Stop
                {
                    // An event nobody can ever take blocks time: JANI's deadlock. A live
                    // run (`Quiescence::AdvanceTime`) goes on: a process playing a node may
                    // still answer and unblock it, as any external message may.
                    return Ok(EndReason::Quiescent);
                }
            }
            if self.runnable.is_empty() && self.deliverable.is_empty() {
                // Messages from outside that waited for their event's previous message go
                // in at this instant, before time moves: the model takes them as fast as
                // it can, and a fast process is never left further and further behind.
                if self.as2fm && !self.inbox.is_empty() {
                    let before = self.inbox.len();
                    if self.post_inputs(obs) == Flow::Stop {
                        return Ok(EndReason::Stopped);
                    }
                    if self.inbox.len() < before {
                        continue;
                    }
                }
                if self.delayed.is_empty() && cfg.quiescence == Quiescence::Stop {
                    return Ok(EndReason::Quiescent);
                }
                if self.time >= cfg.max_time {
                    return Ok(EndReason::MaxTime);
                }
                self.time += 1;
                self.instant_steps = 0;
                self.ms.iter_mut().for_each(|r| r.moves = 0);
                let flow = obs.on_time(self.time);
                let mut i = 0;
                while i < self.delayed.len() {
                    let m = self.delayed[i] as usize;
                    if self.ms[m].wake <= self.time {
                        self.ms[m].waiting = false;
                        self.ms[m].changed = self.clock;
                        self.touch(m);
                        self.delayed.swap_remove(i);
                        self.refresh(m);
                    } else {
                        i += 1;
                    }
                }
                if flow == Flow::Stop {
                    return Ok(EndReason::Stopped);
                }
                if self.as2fm {
                    obs.inputs(self.time, &mut self.inbox);
                    if !self.inbox.is_empty() && self.post_inputs(obs) == Flow::Stop {
                        return Ok(EndReason::Stopped);
                    }
                }
                continue;
            }
            if self.steps >= cfg.max_steps {
                return Ok(EndReason::MaxSteps);
            }
            if self.instant_steps >= cfg.max_steps_per_instant {
                let busiest = (0..self.ms.len())
                    .max_by_key(|&m| self.ms[m].moves)
                    .unwrap_or(0);
                return Err(self.spin(busiest, SpinKind::NoTimeProgress));
            }
            let n_deliver = if self.as2fm {
                self.deliverable.len()
            } else {
                0
            };
            let k = self.choose_step((self.runnable.len() + n_deliver) as u32, rng, cfg) as usize;
            if k >= self.runnable.len() {
                let e = self.deliverable[k - self.runnable.len()];
                if self.deliver(e, rng, cfg, obs)? == Flow::Stop {
                    return Ok(EndReason::Stopped);
                }
                continue;
            }
            let m = self.runnable[k] as usize;
            let r = &mut self.ms[m];
            r.changed = self.clock;
            r.moves = r.moves.saturating_add(1);
            let flow = self.step(m, rng, cfg, obs)?;
            self.touch(m);
            if flow == Flow::Stop {
                return Ok(EndReason::Stopped);
            }
        }
    }

    /// Evaluates the guards of `list` (transitions of machine `m`) and picks one.
    fn select(
        &mut self,
        m: usize,
        def: &MachineDef,
        list: &[u32],
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<Option<u32>, Stop> {
        if list.is_empty() {
            return Ok(None);
        }
        self.enabled.clear();
        for &t in list {
            let Some(td) = def.trans.get(t as usize) else {
                continue;
            };
            let ok = match &td.cond {
                None => true,
                Some(c) => {
                    let mut env = env(&self.ms, &self.pool, m, &mut *rng, &self.model.strings);
                    match c(&mut env) {
                        Ok(b) => b,
                        Err(e) => return Err(self.diag_error(m, Some(td.pc as usize), e)),
                    }
                }
            };
            if ok {
                if cfg.transitions == TransitionChoice::DocumentOrder {
                    return Ok(Some(t));
                }
                self.enabled.push(t);
            }
        }
        match self.enabled.len() {
            0 => Ok(None),
            1 => Ok(Some(self.enabled[0])),
            n => {
                let k = self.choose_transition(m, n as u32, rng, cfg);
                Ok(Some(self.enabled[k as usize]))
            }
        }
    }

    /// The transitions of machine `m` in its current state on `event`, or its eventless
    /// ones (`None`), in document order.
    fn candidates<'d>(&self, m: usize, def: &'d MachineDef, event: Option<u32>) -> &'d [u32] {
        match (def.states.get(self.ms[m].state as usize), event) {
            (Some(st), Some(e)) => st.transitions(e, &def.dispatch),
            (Some(st), None) => &st.eventless,
            (None, _) => &[],
        }
    }

    /// One step of machine `m`: runs until it communicates once or has nothing to do.
    fn step<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let def = &model.machines[m];
        let mut internal = 0u32;
        loop {
            let pc = self.ms[m].pc;
            if pc == IDLE {
                match self.take_event(m, rng, cfg, obs, &mut internal)? {
                    Some(flow) => return Ok(flow),
                    None => continue,
                }
            }
            let Some(instr) = def.code.get(pc as usize) else {
                return Err(self.diag_error(
                    m,
                    None,
                    EvalError {
                        at: 0,
                        kind: EvalErrorKind::Internal,
                    },
                ));
            };
            match instr {
                Instr::AssignVar {
                    slot,
                    value,
                    bound,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        eval_code(value, &mut env, scratch)
                    };
                    let scratch = &self.scratch[m][*sc as usize];
                    let scalar = match res {
                        Ok(v) => v,
                        Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                    };
                    let Some(dst) = self.ms[m].vars.get_mut(*slot as usize) else {
                        return Err(self.internal(m, pc));
                    };
                    match scalar {
                        Some(v) => *dst = v,
                        None => {
                            if let (Some(b), Cell::List(v)) = (bound, scratch) {
                                if v.len() > *b as usize {
                                    return Err(self.too_long(m, pc, *b));
                                }
                            }
                            dst.clone_from(scratch);
                        }
                    }
                    self.ms[m].pc = pc + 1;
                }
                Instr::AssignPlace {
                    place,
                    value,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        place
                            .eval_indices(&mut env, &mut self.idx)
                            .and_then(|()| eval_code(value, &mut env, scratch))
                    };
                    let scratch = &self.scratch[m][*sc as usize];
                    let stored = match res {
                        Ok(Some(v)) => place.store(&mut self.ms[m].vars, &self.idx, &v),
                        Ok(None) => place.store(&mut self.ms[m].vars, &self.idx, scratch),
                        Err(e) => Err(e),
                    };
                    if let Err(e) = stored {
                        return Err(self.diag_error(m, Some(pc as usize), e));
                    }
                    self.ms[m].pc = pc + 1;
                }
                Instr::If { cond, else_pc } => {
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        cond(&mut env)
                    };
                    match res {
                        Ok(true) => self.ms[m].pc = pc + 1,
                        Ok(false) => self.ms[m].pc = *else_pc,
                        Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                    }
                }
                Instr::Jump(t) => self.ms[m].pc = *t,
                Instr::Raise(ev) => {
                    self.ms[m].intq.push_back(*ev);
                    self.ms[m].pc = pc + 1;
                }
                Instr::Log {
                    label,
                    value,
                    scratch: sc,
                } => {
                    let Some(scratch) = scratch_cell(&mut self.scratch, m, *sc) else {
                        return Err(self.internal(m, pc));
                    };
                    let mut has = false;
                    if let Some(f) = value {
                        let res = {
                            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                            f(&mut env, scratch)
                        };
                        if let Err(e) = res {
                            return Err(self.diag_error(m, Some(pc as usize), e));
                        }
                        has = true;
                    }
                    let scratch = &self.scratch[m][*sc as usize];
                    let v = if has { Some(Value::of(scratch)) } else { None };
                    obs.on_log(self.time, MachineId(m as u32), label, v);
                    self.ms[m].pc = pc + 1;
                }
                Instr::Goto(s) => {
                    let r = &mut self.ms[m];
                    r.state = *s;
                    r.pc = match def.states.get(*s as usize) {
                        // What its entry code would do: check no eventless transition.
                        Some(st) if st.idle_on_entry => IDLE,
                        Some(st) => st.entry,
                        None => IDLE,
                    };
                }
                Instr::CheckEventless => {
                    match self.select(m, def, self.candidates(m, def, None), rng, cfg)? {
                        Some(t) => {
                            internal += 1;
                            if internal > cfg.max_eventless {
                                return Err(self.spin(m, SpinKind::EventlessLoop));
                            }
                            self.ms[m].pc = def.trans[t as usize].pc;
                        }
                        None => self.ms[m].pc = IDLE,
                    }
                }
                Instr::Send(sd) => {
                    // A delayed send blocks its machine for the delay (as in SCAN), then sends.
                    if self.start_delay(m, pc, sd, rng)? {
                        return Ok(Flow::Continue);
                    }
                    if self.as2fm {
                        if sd.expanded_copy {
                            self.ms[m].pc = pc + 1;
                            continue;
                        }
                        return self.as2fm_send(m, pc, sd, rng, obs);
                    }
                    match self.queue_send(m, pc, sd, rng, obs)? {
                        Some(flow) => return Ok(flow),
                        None => continue,
                    }
                }
            }
        }
    }
}
