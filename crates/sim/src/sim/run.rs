//! The simulator: runs a [`CompiledModel`] as a channel system, step by step, without allocating.

use super::as2fm::{event_flags, may_discard, never_discards, EV_BB_REQ, EV_BB_SET, EV_TIMER};
use super::compiled::{CompiledModel, DelayDef, Instr, MachineDef, SendDef, SendTo};
use super::ids::{EventId, MachineId, StateId};
use super::observer::{Flow, Inbox, Observer, Scalar, SentMessage, EXTERNAL};
use crate::expr::compile::{Code, Entropy, Env, EvalError, EvalErrorKind, MAX_PATH};
use crate::expr::value::{assign_cells, Cell, StrId, Strings};
use crate::expr::Value;
use crate::model::Diagnostic;
use std::collections::VecDeque;

mod config;
mod deliver;
mod init;
mod receivers;
mod sched;
mod send;
mod step;
mod stop;

pub use config::{
    EndReason, EventSemantics, Quiescence, RunConfig, RunError, RunOutcome, SpinKind, SpinReport,
    TransitionChoice,
};
pub use sched::{mix, BadScheduler, Memory, PutBack, Sampled, Scheduler, SchedulerWhy};

const IDLE: u32 = u32::MAX;
const NO_MSG: u32 = u32::MAX;
const NOT_RUNNABLE: u32 = u32::MAX;

#[derive(Clone, Debug)]
struct Slot {
    event: u32,
    origin: u32,
    /// `u32::MAX`: the `NONE` sink.
    target: u32,
    /// The next message in its target's external queue (`NO_MSG`: the last).
    next: u32,
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
    /// The external queue: a list of pool slots linked through [`Slot::next`], oldest
    /// first (`NO_MSG`: empty). A queue costs two words and no buffer of its own.
    qhead: u32,
    qtail: u32,
    qlen: u32,
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
    /// Per receiver slot (pool slot past the events' buffers): where its states' cases
    /// start in [`Simulator::rx_cases`] (see `run/receivers.rs`).
    rx_first: Vec<u32>,
    /// Per receiver slot and state of the receiver: its transitions on the event and
    /// whether it may drop it.
    rx_cases: Vec<receivers::RxCase>,
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

/// The parameters of machine record `r`'s current message (empty: none).
#[inline(always)]
fn params_of<'p>(r: &MachineRt, pool: &'p [Slot]) -> &'p [Cell] {
    if r.cur == NO_MSG {
        &[]
    } else {
        pool.get(r.cur as usize).map_or(&[], |s| &s.params)
    }
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

/// Keeps machine `m`'s place in `runnable` true to whether it can move: a function over
/// the two fields so that a step holding others may call it. Called after nearly every
/// step and delivery (on UC3 about 4 times per step), so always inlined: the call itself
/// cost a third of it.
#[inline(always)]
fn refresh_in(ms: &mut [MachineRt], runnable: &mut Vec<u32>, m: usize) {
    let r = &ms[m];
    let can = !r.waiting && !r.blocked && (r.pc != IDLE || !r.intq.is_empty() || r.qhead != NO_MSG);
    let pos = r.rpos;
    if can && pos == NOT_RUNNABLE {
        ms[m].rpos = runnable.len() as u32;
        runnable.push(m as u32);
    } else if !can && pos != NOT_RUNNABLE {
        let last = runnable.len() - 1;
        runnable.swap(pos as usize, last);
        let moved = runnable[pos as usize] as usize;
        ms[moved].rpos = pos;
        runnable.pop();
        ms[m].rpos = NOT_RUNNABLE;
    }
}

/// Marks machine `m`'s cached state hash stale, as [`Simulator::touch`] does, over the
/// fields it needs (`sampled`: [`Simulator::sampled`]).
#[inline(always)]
fn touch_in(ms: &mut [MachineRt], dirty: &mut Vec<u32>, sampled: bool, m: usize) {
    if !sampled {
        return;
    }
    let r = &mut ms[m];
    if !r.dirty {
        r.dirty = true;
        dirty.push(m as u32);
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

impl<'m> Simulator<'m> {
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
    #[inline(always)]
    fn refresh(&mut self, m: usize) {
        refresh_in(&mut self.ms, &mut self.runnable, m);
    }

    /// How a run that can no longer move ends: at the horizon if the clock is there (a
    /// run that went quiet at its last instant lasted its whole length; a robot model's
    /// global timer stops at `max_time`, so every run of one would otherwise end quiescent
    /// and hide a real deadlock), else quiescent.
    fn quiet_end(&self, cfg: &RunConfig) -> EndReason {
        if self.time >= cfg.max_time {
            EndReason::MaxTime
        } else {
            EndReason::Quiescent
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
                    return Ok(self.quiet_end(cfg));
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
                    return Ok(self.quiet_end(cfg));
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
}
