//! The simulator: runs a [`CompiledModel`] as a channel system, step by step, without allocating.

use super::as2fm::{event_flags, may_discard, never_discards, EV_BB_REQ, EV_BB_SET, EV_TIMER};
use super::compiled::{CompiledModel, DelayDef, Instr, MachineDef, SendDef, SendTo};
use super::ids::{MachineId, StateId};
use super::observer::{Flow, Inbox, Observer, Scalar, SentMessage, EXTERNAL};
use crate::expr::compile::{Code, Entropy, Env, EvalError, EvalErrorKind, MAX_PATH};
use crate::expr::value::{Cell, StrId, Strings};
use crate::expr::Value;
use crate::model::{Diagnostic, Span};
use std::collections::VecDeque;

/// How a machine picks among several enabled transitions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TransitionChoice {
    /// The first enabled transition in document order (SCXML and SCAN).
    #[default]
    DocumentOrder,
    /// Uniformly at random among the enabled transitions.
    Random,
}

/// What happens when nothing can move and no delayed send is pending.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Quiescence {
    /// End the run ([`EndReason::Quiescent`]).
    #[default]
    Stop,
    /// Keep advancing time (one [`Observer::on_time`] per unit) until `max_time`,
    /// as SCAN does; the run then ends with [`EndReason::MaxTime`].
    AdvanceTime,
}

/// How `<send>`s are delivered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EventSemantics {
    /// SCAN's channel system: each machine has a FIFO queue; a send goes to its target.
    #[default]
    Queues,
    /// AS2FM's JANI translation, for the plain SCXML AS2FM generates: one global
    /// one-place buffer per event, broadcast to every machine with a transition on it.
    ///
    /// - The `target` of a `<send>` is ignored. Sending `E` while `E` is pending blocks
    ///   the sender until `E` is delivered; an event no machine has a transition on is
    ///   observed and never pending.
    /// - Delivering a pending `E` is a step of its own, chosen at random among the
    ///   machine steps and the other deliverable events. It is possible only when every
    ///   receiver is idle in a state where it can take `E`: an enabled transition on `E`
    ///   (the first in document order fires), or a discard: the state has transitions
    ///   on `E` none of which is enabled, or it has none and `E` is not one of AS2FM's
    ///   synchronised events (BT `bt_N_tick` / `_halt` / `_response` /
    ///   `_halt_response`, services `srv_*_request` / `_response` / `_req_client*`,
    ///   actions `action_*_goal_*`, `action_*_result*`, `action_*_thread_start|free`).
    ///   BT roots (`bt_root_fsm*`) and ROS interface handlers (`srv_handler_*`,
    ///   `action_handler_*`) never discard. All receivers take `E` at once.
    /// - A send writes the event's global parameters (one that it leaves out keeps its
    ///   previous value); each receiver copies them when it takes the event and reads
    ///   `_event.data` from its copy. (JANI reads the globals on each edge: the same
    ///   values up to the transition's first `<send>` or `<if>`, which execute on later
    ///   edges and could see a newer send of the event; the copy leaves out that race.)
    /// - AS2FM's plain export writes one broadcast `<send>` as one send per receiver
    ///   (same event, same parameters, targets exactly the event's receivers): such a
    ///   run of sends is sent once.
    /// - Timer events (`ros_time_rate.*`) are a rendezvous: the sender waits until the
    ///   event is delivered, which needs no other event pending.
    /// - `bt_blackboard_req` cannot be sent while a `bt_blackboard_set_*` is pending.
    /// - Time advances only when nothing else can move and no event is pending; with an
    ///   event pending that nobody can take, the run ends (JANI's deadlock). (JANI lets
    ///   the global timer tick as soon as no event is pending, even while a machine is
    ///   still inside a transition; here time waits for every machine, as in SCAN.)
    As2fm,
}

/// Limits and choices for one run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunConfig {
    /// The clock never goes past this time; the run ends when it would.
    ///
    /// SCAN's `--duration d` runs while the time is at most `d` and then adds one
    /// time point at `d + 1`; to reproduce it, use `max_time = d + 1` and return
    /// [`Flow::Stop`] from [`Observer::on_time`] at `d + 1`.
    pub max_time: u64,
    /// Maximum number of communication steps (sends plus receives).
    pub max_steps: u64,
    /// Eventless transitions (and raised events) one machine may take in a row
    /// without communicating before the run ends as an eventless loop.
    pub max_eventless: u32,
    /// Steps allowed at one instant before the run ends as a loop that never
    /// lets time advance.
    pub max_steps_per_instant: u64,
    /// How enabled transitions are chosen.
    pub transitions: TransitionChoice,
    /// What quiescence does.
    pub quiescence: Quiescence,
    /// How sends are delivered.
    pub events: EventSemantics,
}

impl Default for RunConfig {
    fn default() -> Self {
        RunConfig {
            max_time: 10_000,
            max_steps: 100_000_000,
            max_eventless: 100_000,
            max_steps_per_instant: 1_000_000,
            transitions: TransitionChoice::DocumentOrder,
            quiescence: Quiescence::Stop,
            events: EventSemantics::Queues,
        }
    }
}

/// Which kind of endless loop was detected.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpinKind {
    /// A machine kept taking eventless transitions without communicating.
    EventlessLoop,
    /// Machines kept exchanging messages without ever letting time advance.
    NoTimeProgress,
}

/// An endless loop: the machine and state that spin.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SpinReport {
    /// The kind of loop.
    pub kind: SpinKind,
    /// The machine that spins (for [`SpinKind::NoTimeProgress`]: the one that moved most).
    pub machine: MachineId,
    /// Its state when the loop was detected.
    pub state: StateId,
    /// The machine's name.
    pub machine_name: String,
    /// The state's id.
    pub state_name: String,
    /// Where the state is declared.
    pub location: Diagnostic,
}

impl std::fmt::Display for SpinReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.kind {
            SpinKind::EventlessLoop => "loops through eventless transitions without communicating",
            SpinKind::NoTimeProgress => "keeps the model busy without letting time advance",
        };
        write!(
            f,
            "{}:{}:{}: machine `{}` in state `{}` {what}",
            self.location.path.display(),
            self.location.line,
            self.location.column,
            self.machine_name,
            self.state_name
        )
    }
}

/// A run-time error (index out of bounds, remainder by zero, unknown `targetexpr`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunError {
    /// The machine executing.
    pub machine: MachineId,
    /// Model time of the error.
    pub time: u64,
    /// File, line, column and message.
    pub diagnostic: Diagnostic,
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} (at time {})", self.diagnostic, self.time)
    }
}

/// Why a run ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EndReason {
    /// Nothing can ever happen again: every machine waits for an event that no
    /// one will send and no delayed send is pending.
    Quiescent,
    /// The clock reached [`RunConfig::max_time`] and everything due then was done.
    MaxTime,
    /// [`RunConfig::max_steps`] steps were taken.
    MaxSteps,
    /// An observer returned [`Flow::Stop`].
    Stopped,
    /// An endless loop was detected.
    Spin(SpinReport),
    /// The model failed at run time.
    Error(RunError),
}

/// The result of one run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunOutcome {
    /// Why the run ended.
    pub end: EndReason,
    /// Model time at the end.
    pub time: u64,
    /// Communication steps taken (sends plus receives).
    pub steps: u64,
}

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
    rpos: Vec<u32>,
    delayed: Vec<u32>,
    enabled: Vec<u32>,
    time: u64,
    steps: u64,
    instant_steps: u64,
    instant_moves: Vec<u32>,
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
    /// Per machine: the iteration it last changed in (state, variables, position, flags).
    changed: Vec<u64>,
    /// Per receiver of each event (indexed like the receivers' pool slots past the
    /// events' buffers): the iteration its choice was computed in (0: not computed).
    checked: Vec<u64>,
    /// Per receiver of each event: the transition it fires on the pending event
    /// (`NO_TRANS`: it discards it, `CANNOT_TAKE`: not now), as of `checked`.
    choice_kept: Vec<u32>,
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

/// Unbiased uniform integer in `0..n` (`n > 0`), Lemire's multiply-and-reject
/// (the division is only needed in the rare case the low half is small).
/// The expression environment of machine `m`: its variables and its current event.
/// A function over the two fields (not a method) so callers may hold other fields mutably.
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
    Env {
        vars: &r.vars,
        params,
        event: r.cur_event,
        origin: r.cur_origin,
        rng,
        strings,
    }
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

enum Stop {
    End(EndReason),
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
            rpos: vec![NOT_RUNNABLE; n],
            delayed: Vec::with_capacity(n),
            enabled: Vec::new(),
            time: 0,
            steps: 0,
            instant_steps: 0,
            instant_moves: vec![0; n],
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
            changed: vec![0; n],
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

    fn refresh(&mut self, m: usize) {
        let r = &self.ms[m];
        let can =
            !r.waiting && !r.blocked && (r.pc != IDLE || !r.intq.is_empty() || !r.extq.is_empty());
        let pos = self.rpos[m];
        if can && pos == NOT_RUNNABLE {
            self.rpos[m] = self.runnable.len() as u32;
            self.runnable.push(m as u32);
        } else if !can && pos != NOT_RUNNABLE {
            let last = self.runnable.len() - 1;
            self.runnable.swap(pos as usize, last);
            let moved = self.runnable[pos as usize] as usize;
            self.rpos[moved] = pos;
            self.runnable.pop();
            self.rpos[m] = NOT_RUNNABLE;
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

    fn diag_error(&self, m: usize, pc: Option<usize>, e: EvalError) -> Stop {
        let def = &self.model.machines[m];
        let span = if e.at != 0 {
            Span {
                file: def.file,
                offset: e.at,
            }
        } else {
            pc.and_then(|p| def.code_spans.get(p).copied())
                .unwrap_or(Span {
                    file: def.file,
                    offset: 0,
                })
        };
        Stop::End(EndReason::Error(RunError {
            machine: MachineId(m as u32),
            time: self.time,
            diagnostic: self.model.sources.diag(span, e.message()),
        }))
    }

    fn spin(&self, m: usize, kind: SpinKind) -> Stop {
        let def = &self.model.machines[m];
        let s = self.ms[m].state;
        let state_name = def
            .states
            .get(s as usize)
            .map_or(String::new(), |st| st.name.clone());
        let span = def
            .states
            .get(s as usize)
            .map(|st| st.span)
            .unwrap_or(Span {
                file: def.file,
                offset: 0,
            });
        Stop::End(EndReason::Spin(SpinReport {
            kind,
            machine: MachineId(m as u32),
            state: StateId(s),
            machine_name: def.name.clone(),
            state_name: state_name.clone(),
            location: self
                .model
                .sources
                .diag(span, format!("state `{state_name}`")),
        }))
    }

    /// Resets every machine to its initial state and evaluates the datamodel.
    fn reset(&mut self, rng: &mut dyn Entropy) -> Result<(), Stop> {
        self.time = 0;
        self.steps = 0;
        self.instant_steps = 0;
        self.instant_moves.iter_mut().for_each(|c| *c = 0);
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
        self.rpos.iter_mut().for_each(|p| *p = NOT_RUNNABLE);
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
                let Some(scratch) = self
                    .scratch
                    .get_mut(m)
                    .and_then(|v| v.get_mut(*sc as usize))
                else {
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
                        return Err(Stop::End(EndReason::Error(RunError {
                            machine: MachineId(m as u32),
                            time: 0,
                            diagnostic: model.sources.diag(
                                *span,
                                format!(
                                    "initial value has {} elements, more than the declared {b}",
                                    v.len()
                                ),
                            ),
                        })));
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
            Ok(e) | Err(Stop::End(e)) => e,
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
                {
                    // An event nobody can ever take blocks time: JANI's deadlock.
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
                self.instant_moves.iter_mut().for_each(|c| *c = 0);
                let flow = obs.on_time(self.time);
                let mut i = 0;
                while i < self.delayed.len() {
                    let m = self.delayed[i] as usize;
                    if self.ms[m].wake <= self.time {
                        self.ms[m].waiting = false;
                        self.changed[m] = self.clock;
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
                    .max_by_key(|&m| self.instant_moves[m])
                    .unwrap_or(0);
                return Err(self.spin(busiest, SpinKind::NoTimeProgress));
            }
            let n_deliver = if self.as2fm {
                self.deliverable.len()
            } else {
                0
            };
            let k = below(rng, (self.runnable.len() + n_deliver) as u32) as usize;
            if k >= self.runnable.len() {
                let e = self.deliverable[k - self.runnable.len()];
                if self.deliver(e, rng, cfg, obs)? == Flow::Stop {
                    return Ok(EndReason::Stopped);
                }
                continue;
            }
            let m = self.runnable[k] as usize;
            self.changed[m] = self.clock;
            self.instant_moves[m] = self.instant_moves[m].saturating_add(1);
            if self.step(m, rng, cfg, obs)? == Flow::Stop {
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
                    let r = &self.ms[m];
                    let params: &[Cell] = if r.cur == NO_MSG {
                        &[]
                    } else {
                        &self.pool[r.cur as usize].params
                    };
                    let mut env = Env {
                        vars: &r.vars,
                        params,
                        event: r.cur_event,
                        origin: r.cur_origin,
                        rng: &mut *rng,
                        strings: &self.model.strings,
                    };
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
            n => Ok(Some(self.enabled[below(rng, n as u32) as usize])),
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
                if let Some(ev) = self.ms[m].intq.pop_front() {
                    self.release(m);
                    self.ms[m].cur_event = model
                        .events
                        .get(ev as usize)
                        .map_or(StrId(0), |e| e.name_str);
                    self.ms[m].cur_origin = def.name_str;
                    let list = self.candidates(m, def, Some(ev));
                    if let Some(t) = self.select(m, def, list, rng, cfg)? {
                        self.ms[m].pc = def.trans[t as usize].pc;
                    }
                    internal += 1;
                    if internal > cfg.max_eventless {
                        return Err(self.spin(m, SpinKind::EventlessLoop));
                    }
                    continue;
                }
                if let Some(slot) = self.ms[m].extq.pop_front() {
                    self.release(m);
                    let (event, origin, target) = {
                        let s = &self.pool[slot as usize];
                        (s.event, s.origin, s.target)
                    };
                    let r = &mut self.ms[m];
                    r.cur = slot;
                    r.cur_event = model
                        .events
                        .get(event as usize)
                        .map_or(StrId(0), |e| e.name_str);
                    r.cur_origin = model
                        .machines
                        .get(origin as usize)
                        .map_or(StrId(0), |d| d.name_str);
                    self.steps += 1;
                    self.instant_steps += 1;
                    let flow = obs.on_receive(
                        self.time,
                        &SentMessage {
                            model,
                            event: super::ids::EventId(event),
                            origin: MachineId(origin),
                            target: (target != u32::MAX).then_some(MachineId(target)),
                            params: &self.pool[slot as usize].params,
                        },
                    );
                    let list = self.candidates(m, def, Some(event));
                    if let Some(t) = self.select(m, def, list, rng, cfg)? {
                        self.ms[m].pc = def.trans[t as usize].pc;
                    }
                    self.refresh(m);
                    return Ok(flow);
                }
                self.refresh(m);
                return Ok(Flow::Continue);
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
                    let Some(scratch) = self
                        .scratch
                        .get_mut(m)
                        .and_then(|v| v.get_mut(*sc as usize))
                    else {
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
                    let Some(scratch) = self
                        .scratch
                        .get_mut(m)
                        .and_then(|v| v.get_mut(*sc as usize))
                    else {
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
                    let Some(scratch) = self
                        .scratch
                        .get_mut(m)
                        .and_then(|v| v.get_mut(*sc as usize))
                    else {
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
                    if let Some(d) = &sd.delay {
                        if !self.ms[m].delay_done {
                            let n = match d {
                                DelayDef::Const(n) => *n,
                                DelayDef::Expr(f) => {
                                    let res = {
                                        let mut env =
                                            env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                                        f(&mut env)
                                    };
                                    match res {
                                        Ok(v) => v.max(0) as u64,
                                        Err(e) => {
                                            return Err(self.diag_error(m, Some(pc as usize), e))
                                        }
                                    }
                                }
                            };
                            if n > 0 {
                                let r = &mut self.ms[m];
                                r.delay_done = true;
                                r.waiting = true;
                                r.wake = self.time.saturating_add(n);
                                self.delayed.push(m as u32);
                                self.refresh(m);
                                return Ok(Flow::Continue);
                            }
                        }
                    }
                    if self.as2fm {
                        if sd.expanded_copy {
                            self.ms[m].pc = pc + 1;
                            continue;
                        }
                        return self.as2fm_send(m, pc, sd, rng, obs);
                    }
                    let mut broadcast_len = 0usize;
                    let target: Option<u32> = match &sd.to {
                        SendTo::Machine(t) => Some(*t),
                        SendTo::Sink => None,
                        SendTo::Broadcast(list) => {
                            broadcast_len = list.len();
                            match list.get(self.ms[m].bcast as usize) {
                                Some(&t) => Some(t),
                                None => {
                                    // Nobody receives this event: nothing is sent.
                                    let r = &mut self.ms[m];
                                    r.bcast = 0;
                                    r.delay_done = false;
                                    r.pc = pc + 1;
                                    continue;
                                }
                            }
                        }
                        SendTo::Expr(f) => {
                            let res = {
                                let mut env =
                                    env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                                f(&mut env)
                            };
                            let s = match res {
                                Ok(s) => s,
                                Err(e) => return Err(self.diag_error(m, Some(pc as usize), e)),
                            };
                            match model.machine_of_str.get(s.0 as usize) {
                                Some(&t) if t != u32::MAX => Some(t),
                                _ if s == model.none_str => None,
                                _ => {
                                    let span =
                                        def.code_spans.get(pc as usize).copied().unwrap_or(Span {
                                            file: def.file,
                                            offset: 0,
                                        });
                                    return Err(Stop::End(EndReason::Error(RunError {
                                        machine: MachineId(m as u32),
                                        time: self.time,
                                        diagnostic: model.sources.diag(
                                            span,
                                            format!(
                                                "targetexpr evaluated to `{}`, which is not a machine",
                                                model.strings.get(s)
                                            ),
                                        ),
                                    })));
                                }
                            }
                        }
                    };
                    let Some(evdef) = model.events.get(sd.event as usize) else {
                        return Err(self.diag_error(
                            m,
                            Some(pc as usize),
                            EvalError {
                                at: 0,
                                kind: EvalErrorKind::Internal,
                            },
                        ));
                    };
                    // Slots are reused per event, so their cells keep their shapes (no allocation).
                    let slot = match self.free.get_mut(sd.event as usize).and_then(|f| f.pop()) {
                        Some(s) => s,
                        None => {
                            self.pool.push(Slot {
                                event: sd.event,
                                origin: 0,
                                target: 0,
                                params: evdef.defaults.clone(),
                            });
                            self.pool.len() as u32 - 1
                        }
                    };
                    let mut out = std::mem::take(&mut self.pool[slot as usize].params);
                    for &i in &sd.missing {
                        if let (Some(dst), Some(d)) =
                            (out.get_mut(i as usize), evdef.defaults.get(i as usize))
                        {
                            dst.clone_from(d);
                        }
                    }
                    let res = {
                        let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
                        eval_params(sd, &mut env, &mut out)
                    };
                    {
                        let s = &mut self.pool[slot as usize];
                        s.params = out;
                        s.event = sd.event;
                        s.origin = m as u32;
                        s.target = target.unwrap_or(u32::MAX);
                    }
                    if let Err(e) = res {
                        self.free_slot(slot);
                        return Err(self.diag_error(m, Some(pc as usize), e));
                    }
                    self.steps += 1;
                    self.instant_steps += 1;
                    let flow = obs.on_send(
                        self.time,
                        &SentMessage {
                            model,
                            event: super::ids::EventId(sd.event),
                            origin: MachineId(m as u32),
                            target: target.map(MachineId),
                            params: &self.pool[slot as usize].params,
                        },
                    );
                    match target {
                        Some(t) => {
                            self.ms[t as usize].extq.push_back(slot);
                            self.refresh(t as usize);
                        }
                        None => self.free_slot(slot),
                    }
                    let r = &mut self.ms[m];
                    if broadcast_len > 0 && (r.bcast as usize) + 1 < broadcast_len {
                        r.bcast += 1;
                    } else {
                        r.bcast = 0;
                        r.delay_done = false;
                        r.pc = pc + 1;
                    }
                    return Ok(flow);
                }
            }
        }
    }

    /// Whether a blocked machine's send (or awaited rendezvous) can go on now.
    fn send_possible(&self, m: usize) -> bool {
        let r = &self.ms[m];
        if r.awaiting != NO_MSG {
            return !self.pending[r.awaiting as usize];
        }
        match self.model.machines[m].code.get(r.pc as usize) {
            Some(Instr::Send(sd)) => self.send_enabled(sd.event),
            _ => true,
        }
    }

    /// [`EventSemantics::As2fm`]: whether event `e` may be sent now.
    fn send_enabled(&self, e: u32) -> bool {
        let bb_blocked = self.ev_flags[e as usize] & EV_BB_REQ != 0 && self.pending_bb_set > 0;
        !self.pending[e as usize] && !bb_blocked
    }

    /// What receiver `r` does with pending event `e` now: `Some(Some(t))` fires
    /// transition `t`, `Some(None)` discards it, `None` cannot take it yet.
    /// Points the receiver's `_event` at the event's global buffer.
    fn receive_choice(
        &mut self,
        r: u32,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<Option<Option<u32>>, Stop> {
        let model = self.model;
        let m = r as usize;
        let rt = &self.ms[m];
        if rt.pc != IDLE || rt.blocked || rt.waiting || !rt.intq.is_empty() {
            return Ok(None);
        }
        let def = &model.machines[m];
        let Some(st) = def.states.get(rt.state as usize) else {
            return Ok(None);
        };
        let list = st.transitions(e, &def.dispatch);
        let has = !list.is_empty();
        let origin = self.pool[e as usize].origin;
        {
            let rt = &mut self.ms[m];
            rt.cur = e;
            rt.cur_event = model
                .events
                .get(e as usize)
                .map_or(StrId(0), |d| d.name_str);
            rt.cur_origin = model
                .machines
                .get(origin as usize)
                .map_or(StrId(0), |d| d.name_str);
        }
        if let Some(t) = self.select(m, def, list, rng, cfg)? {
            return Ok(Some(Some(t)));
        }
        let discard = may_discard(self.no_discard[m], has, self.ev_flags[e as usize]);
        Ok(discard.then_some(None))
    }

    /// Whether pending event `e` can be delivered now (every receiver can take it).
    fn deliverable_now(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<bool, Stop> {
        if self.ev_flags[e as usize] & EV_TIMER != 0 && self.pending_regular > 0 {
            return Ok(false);
        }
        let model = self.model;
        for &r in &model.events[e as usize].receivers {
            if self.receive_choice(r, e, rng, cfg)?.is_none() {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// [`Simulator::deliverable_now`] for a run that keeps receivers' choices: a
    /// receiver's choice is computed again only when it changed since (or the event was
    /// sent again). Receivers are gone through in the same order up to the first that
    /// cannot take the event, so the same guards run at the same iterations, with the
    /// same results and errors: a guard reads only its machine and the event.
    fn deliverable_kept(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
    ) -> Result<bool, Stop> {
        let ei = e as usize;
        if self.ev_flags[ei] & EV_TIMER != 0 && self.pending_regular > 0 {
            return Ok(false);
        }
        let model = self.model;
        let base = self.rx_base[ei] as usize - model.events.len();
        for (k, &r) in model.events[ei].receivers.iter().enumerate() {
            let at = self.checked[base + k];
            let choice = if at != 0 && self.changed[r as usize] < at {
                self.choice_kept[base + k]
            } else {
                let c = match self.receive_choice(r, e, rng, cfg)? {
                    Some(Some(t)) => t,
                    Some(None) => NO_TRANS,
                    None => CANNOT_TAKE,
                };
                self.checked[base + k] = self.clock;
                self.choice_kept[base + k] = c;
                c
            };
            if choice == CANNOT_TAKE {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Delivers pending event `e` to all its receivers at once (one point each).
    fn deliver<O: Observer + ?Sized>(
        &mut self,
        e: u32,
        rng: &mut dyn Entropy,
        cfg: &RunConfig,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let mut flow = Flow::Continue;
        let origin = self.pool[e as usize].origin;
        for (k, &r) in model.events[e as usize].receivers.iter().enumerate() {
            let m = r as usize;
            let choice = if self.keep_choices {
                // Computed at this iteration by `deliverable_kept`; set `_event` as
                // `receive_choice` does.
                let kept =
                    self.choice_kept[self.rx_base[e as usize] as usize - model.events.len() + k];
                let rt = &mut self.ms[m];
                rt.cur_event = model.events[e as usize].name_str;
                rt.cur_origin = model
                    .machines
                    .get(origin as usize)
                    .map_or(StrId(0), |d| d.name_str);
                (kept != NO_TRANS).then_some(kept)
            } else {
                self.receive_choice(r, e, rng, cfg)?.flatten()
            };
            self.changed[m] = self.clock;
            // The receiver keeps its own copy: JANI assigns it with the receive itself.
            let rx = self.rx_base[e as usize] as usize + k;
            let (global, copy) = self.pool.split_at_mut(rx);
            copy[0].params.clone_from(&global[e as usize].params);
            copy[0].origin = origin;
            self.ms[m].cur = rx as u32;
            self.steps += 1;
            self.instant_steps += 1;
            self.instant_moves[m] = self.instant_moves[m].saturating_add(1);
            let f = obs.on_receive(
                self.time,
                &SentMessage {
                    model,
                    event: super::ids::EventId(e),
                    origin: MachineId(origin),
                    target: Some(MachineId(r)),
                    params: &self.pool[e as usize].params,
                },
            );
            if f == Flow::Stop {
                flow = Flow::Stop;
            }
            if let Some(t) = choice {
                self.ms[m].pc = model.machines[m].trans[t as usize].pc;
                self.refresh(m);
            }
        }
        self.pending[e as usize] = false;
        if let Some(i) = self.pending_list.iter().position(|&x| x == e) {
            self.pending_list.remove(i);
        }
        let flags = self.ev_flags[e as usize];
        if flags & EV_TIMER == 0 {
            self.pending_regular = self.pending_regular.saturating_sub(1);
        }
        if flags & EV_BB_SET != 0 {
            self.pending_bb_set = self.pending_bb_set.saturating_sub(1);
        }
        let mut i = 0;
        while i < self.blocked_list.len() {
            let m = self.blocked_list[i] as usize;
            if self.send_possible(m) {
                self.changed[m] = self.clock;
                self.ms[m].blocked = false;
                self.ms[m].awaiting = NO_MSG;
                self.blocked_list.swap_remove(i);
                self.refresh(m);
            } else {
                i += 1;
            }
        }
        Ok(flow)
    }

    /// Posts the messages of [`Self::inbox`] whose events are not pending, oldest first,
    /// as [`Self::as2fm_send`] does for a machine's send; the rest wait until the model is
    /// idle again at this instant, or for the next unit.
    fn post_inputs<O: Observer + ?Sized>(&mut self, obs: &mut O) -> Flow {
        let model = self.model;
        let mut flow = Flow::Continue;
        let mut left = std::mem::take(&mut self.inbox.items);
        let mut i = 0;
        while i < left.len() {
            let e = left[i].0 .0 as usize;
            if e >= model.events.len() {
                left.remove(i);
                continue;
            }
            if !self.send_enabled(e as u32) {
                i += 1;
                continue;
            }
            let Some((_, params)) = left.remove(i) else {
                break;
            };
            let slot = &mut self.pool[e];
            for (c, d) in slot.params.iter_mut().zip(&model.events[e].defaults) {
                c.clone_from(d);
            }
            for (k, v) in params {
                let Some(c) = slot.params.get_mut(k) else {
                    continue;
                };
                // Only a value of the parameter's own kind replaces its default.
                match (c, v) {
                    (Cell::Bool(b), Scalar::Bool(x)) => *b = x,
                    (Cell::Int(b), Scalar::Int(x)) => *b = x,
                    (Cell::Float(b), Scalar::Float(x)) => *b = x,
                    (Cell::Float(b), Scalar::Int(x)) => *b = x as f64,
                    _ => {}
                }
            }
            slot.origin = EXTERNAL.0;
            slot.target = u32::MAX;
            self.steps += 1;
            self.instant_steps += 1;
            let f = obs.on_send(
                self.time,
                &SentMessage {
                    model,
                    event: super::ids::EventId(e as u32),
                    origin: EXTERNAL,
                    target: None,
                    params: &self.pool[e].params,
                },
            );
            if f == Flow::Stop {
                flow = Flow::Stop;
            }
            if !model.events[e].receivers.is_empty() {
                self.pending[e] = true;
                let base = self.rx_base[e] as usize - model.events.len();
                self.checked[base..base + model.events[e].receivers.len()].fill(0);
                self.pending_list.push(e as u32);
                let flags = self.ev_flags[e];
                if flags & EV_TIMER == 0 {
                    self.pending_regular += 1;
                }
                if flags & EV_BB_SET != 0 {
                    self.pending_bb_set += 1;
                }
            }
        }
        self.inbox.items = left;
        flow
    }

    /// A `<send>` under [`EventSemantics::As2fm`]: blocks while its event is pending,
    /// else writes the event's global parameters and makes it pending.
    fn as2fm_send<O: Observer + ?Sized>(
        &mut self,
        m: usize,
        pc: u32,
        sd: &SendDef,
        rng: &mut dyn Entropy,
        obs: &mut O,
    ) -> Result<Flow, Stop> {
        let model = self.model;
        let e = sd.event as usize;
        if !self.send_enabled(sd.event) {
            self.ms[m].blocked = true;
            self.blocked_list.push(m as u32);
            self.refresh(m);
            return Ok(Flow::Continue);
        }
        let mut out = std::mem::take(&mut self.ev_scratch[e]);
        for &i in &sd.missing {
            if let (Some(dst), Some(cur)) =
                (out.get_mut(i as usize), self.pool[e].params.get(i as usize))
            {
                dst.clone_from(cur);
            }
        }
        let res = {
            let mut env = env(&self.ms, &self.pool, m, &mut *rng, &model.strings);
            eval_params(sd, &mut env, &mut out)
        };
        if let Err(err) = res {
            self.ev_scratch[e] = out;
            return Err(self.diag_error(m, Some(pc as usize), err));
        }
        std::mem::swap(&mut self.pool[e].params, &mut out);
        self.ev_scratch[e] = out;
        let declared = match &sd.to {
            SendTo::Machine(t) => *t,
            _ => u32::MAX,
        };
        self.pool[e].origin = m as u32;
        self.pool[e].target = declared;
        self.steps += 1;
        self.instant_steps += 1;
        let flow = obs.on_send(
            self.time,
            &SentMessage {
                model,
                event: super::ids::EventId(sd.event),
                origin: MachineId(m as u32),
                target: (declared != u32::MAX).then_some(MachineId(declared)),
                params: &self.pool[e].params,
            },
        );
        let r = &mut self.ms[m];
        r.bcast = 0;
        r.delay_done = false;
        r.pc = pc + 1;
        if !model.events[e].receivers.is_empty() {
            let flags = self.ev_flags[e];
            self.pending[e] = true;
            // New parameters: every receiver's choice is computed again.
            let base = self.rx_base[e] as usize - model.events.len();
            self.checked[base..base + model.events[e].receivers.len()].fill(0);
            self.pending_list.push(sd.event);
            if flags & EV_TIMER != 0 {
                r.blocked = true;
                r.awaiting = sd.event;
                self.blocked_list.push(m as u32);
            } else {
                self.pending_regular += 1;
            }
            if flags & EV_BB_SET != 0 {
                self.pending_bb_set += 1;
            }
            self.refresh(m);
        }
        Ok(flow)
    }

    fn internal(&self, m: usize, pc: u32) -> Stop {
        self.diag_error(
            m,
            Some(pc as usize),
            EvalError {
                at: 0,
                kind: EvalErrorKind::Internal,
            },
        )
    }

    fn too_long(&self, m: usize, pc: u32, bound: u32) -> Stop {
        self.diag_error(
            m,
            Some(pc as usize),
            EvalError {
                at: 0,
                kind: EvalErrorKind::TooLong { bound },
            },
        )
    }
}
