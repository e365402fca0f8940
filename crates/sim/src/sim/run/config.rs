//! What a run is asked to do ([`RunConfig`] and its choices) and how it ended ([`RunOutcome`]).

use super::*;

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
    /// End the run ([`EndReason::Quiescent`]; [`EndReason::MaxTime`] at the horizon).
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

impl EventSemantics {
    /// The name on the command line (`--events`): `queues` or `as2fm`.
    pub fn label(self) -> &'static str {
        match self {
            EventSemantics::Queues => "queues",
            EventSemantics::As2fm => "as2fm",
        }
    }

    /// The semantics [`EventSemantics::label`] names (`None`: no such label).
    pub fn from_label(label: &str) -> Option<Self> {
        [EventSemantics::Queues, EventSemantics::As2fm]
            .into_iter()
            .find(|e| e.label() == label)
    }
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
    /// Who resolves the choices the model leaves open (uniformly at random by default).
    pub scheduler: Scheduler,
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
            scheduler: Scheduler::Uniform,
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
            self.location.file,
            self.location.line,
            self.location.col,
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
    /// Nothing can ever happen again, before the horizon: every machine waits for an
    /// event that no one will send and no delayed send is pending.
    Quiescent,
    /// The clock reached [`RunConfig::max_time`] and everything due then was done
    /// (whether or not anything could still happen later).
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
