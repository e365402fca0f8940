//! The simulator: compiles a model once into flat tables and runs it as SCAN's channel system.
//!
//! # Pipeline
//!
//! 1. [`CompiledModel::compile`] (or [`CompiledModel::load`]) type-checks a
//!    [`crate::model::ModelSource`] and compiles it: machines, states and
//!    events become dense indices ([`MachineId`], [`StateId`], [`EventId`]),
//!    variables become typed slots, executable content becomes per-machine
//!    bytecode whose expressions are closures ([`crate::expr`]).
//! 2. [`Simulator::new`] allocates the run-time buffers once;
//!    [`Simulator::run`] executes one run from a seeded random stream and
//!    calls an [`Observer`] at every trace point. Runs reuse every buffer:
//!    a run in steady state does not allocate.
//! 3. [`TraceRecorder`] is an observer that keeps the message trace (time,
//!    event, origin, target, parameters) for tests and tools; it costs
//!    nothing when not used (`verify --record` writes the CSV a replay reads).
//!
//! # Semantics (SCAN's channel system)
//!
//! - Each machine has a FIFO external queue (`<send>`) and a FIFO internal
//!   queue (`<raise>`); it processes one event at a time (run to completion).
//! - Entering a state runs its `<onentry>`, then the first enabled eventless
//!   transition fires (document order). Otherwise the machine takes the next
//!   internal event, else the next external one; the first enabled transition
//!   on it fires (its source's `<onexit>`, its content, then entry into the
//!   target); an event no transition takes is dropped. After an event that
//!   fired nothing, eventless transitions are not re-checked (SCAN).
//! - A `<send>` without target goes to every machine with a transition on its
//!   event, one delivery (one step) each, in machine order. `target="NONE"`
//!   when no machine is called `NONE` is a sink: the message is observed, not
//!   delivered.
//! - `delay="n"` blocks the sending machine for `n` time units, then sends
//!   (SCAN's timed location); parameters are evaluated when the message is
//!   sent.
//! - Scheduling: uniformly at random among machines that can move (or as the run's
//!   [`Scheduler`] says: one sampled deterministic scheduler, see `run/sched.rs`); a step
//!   runs one machine up to and including its next communication (send or
//!   receive). Time advances by one unit only when no machine can move and a
//!   delayed send is pending; with nothing pending the run is quiescent.
//! - [`RunConfig::events`] = [`EventSemantics::As2fm`] replaces the queues with the
//!   semantics of AS2FM's JANI translation, for the plain SCXML AS2FM generates: one
//!   pending message per event, delivered to all its receivers at once, senders
//!   blocking while it is pending (details on [`EventSemantics::As2fm`]).
//! - Runs end at quiescence, `max_time`, `max_steps`, when an observer stops
//!   them, at a run-time error, or when a loop is detected: too many
//!   eventless transitions in one step, or too many steps at one instant
//!   ([`SpinReport`] names the machine and state).

pub mod as2fm;
mod compiled;
mod ids;
mod observer;
mod run;
mod trace;

pub use compiled::CompiledModel;
pub use ids::{EventId, MachineId, StateId};
pub use observer::{Flow, Inbox, Observer, Scalar, SentMessage, EXTERNAL};
pub use run::{
    mix, BadScheduler, EndReason, EventSemantics, Memory, PutBack, Quiescence, RunConfig, RunError,
    RunOutcome, Sampled, Scheduler, SchedulerWhy, Simulator, SpinKind, SpinReport,
    TransitionChoice,
};
pub use trace::{TraceRecorder, TraceRow};
