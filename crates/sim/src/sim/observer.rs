//! What a run shows the outside world: the [`Observer`] callbacks at every trace point.
//!
//! The points are those of `docs/SEMANTICS.md` section 1: one after every message sent
//! ([`Observer::on_send`]) or received ([`Observer::on_receive`]), and one at
//! every time advance ([`Observer::on_time`]). The initial state is the point
//! before [`super::Simulator::run`] calls anything. Each delivery is its own
//! send step: a send without a target to three machines is three sends.

use super::compiled::CompiledModel;
use super::ids::{EventId, MachineId};
use crate::expr::value::Cell;
use crate::expr::Value;

/// Whether the run goes on after a callback.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Keep running.
    Continue,
    /// End the run now ([`super::EndReason::Stopped`]).
    Stop,
}

/// A message at the moment it is sent or received.
///
/// Parameters are indexed by the event's parameter list
/// ([`CompiledModel::event_params`]), so a property layer resolves names to
/// indices once ([`CompiledModel::param_index`]) and reads values by index.
/// A parameter that a particular `<send>` did not give holds its type's default.
#[derive(Clone, Copy, Debug)]
pub struct SentMessage<'a> {
    pub(crate) model: &'a CompiledModel,
    pub(crate) event: EventId,
    pub(crate) origin: MachineId,
    pub(crate) target: Option<MachineId>,
    pub(crate) params: &'a [Cell],
}

impl<'a> SentMessage<'a> {
    /// The event.
    pub fn event(&self) -> EventId {
        self.event
    }

    /// The sending machine.
    pub fn origin(&self) -> MachineId {
        self.origin
    }

    /// The receiving machine; `None` for the `NONE` sink (a send to `target="NONE"`
    /// when no machine is called `NONE`: observable, never delivered).
    pub fn target(&self) -> Option<MachineId> {
        self.target
    }

    /// Parameter `i` of the event's parameter list.
    pub fn param(&self, i: usize) -> Option<Value<'a>> {
        self.params.get(i).map(Value::of)
    }

    /// All parameters, in the event's parameter order.
    pub fn params(&self) -> impl Iterator<Item = Value<'a>> + 'a {
        self.params.iter().map(Value::of)
    }

    /// Number of parameters.
    pub fn param_count(&self) -> usize {
        self.params.len()
    }

    /// The event's name.
    pub fn event_name(&self) -> &'a str {
        self.model.event_name(self.event)
    }

    /// The sender's name.
    pub fn origin_name(&self) -> &'a str {
        self.model.machine_name(self.origin)
    }

    /// The receiver's name (`"NONE"` for the sink).
    pub fn target_name(&self) -> &'a str {
        match self.target {
            Some(m) => self.model.machine_name(m),
            None => "NONE",
        }
    }

    /// The model the message belongs to (string table, names).
    pub fn model(&self) -> &'a CompiledModel {
        self.model
    }
}

/// Callbacks at every trace point of a run. Every method has a no-op default.
pub trait Observer {
    /// A message was sent (the point after the send step), at `time`.
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let _ = (time, msg);
        Flow::Continue
    }

    /// A machine took a message from its external queue (the point after the receive step).
    fn on_receive(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let _ = (time, msg);
        Flow::Continue
    }

    /// Time advanced by one unit to `time` (a point where no message is sent).
    fn on_time(&mut self, time: u64) -> Flow {
        let _ = time;
        Flow::Continue
    }

    /// A `<log>` was executed (not a trace point).
    fn on_log(&mut self, time: u64, machine: MachineId, label: &str, value: Option<Value<'_>>) {
        let _ = (time, machine, label, value);
    }

    /// Messages from outside the model to post now, right after [`Observer::on_time`]
    /// (a component replaced by a real process). The simulator posts what it can as if
    /// a machine had sent it (an [`Observer::on_send`] point with [`SentMessage::origin`]
    /// [`EXTERNAL`]) and leaves in `inbox` what cannot be posted yet (its event is still
    /// pending under [`super::EventSemantics::As2fm`]), to try again as soon as the model
    /// is idle at this instant. Only runs under [`super::EventSemantics::As2fm`] call it.
    fn inputs(&mut self, time: u64, inbox: &mut Inbox) {
        let _ = (time, inbox);
    }
}

/// The origin of a message posted from outside the model ([`Observer::inputs`]).
pub const EXTERNAL: MachineId = MachineId(u32::MAX);

/// Messages waiting to enter a run from outside ([`Observer::inputs`]), oldest first.
#[derive(Debug, Default)]
pub struct Inbox {
    pub(crate) items: std::collections::VecDeque<(EventId, Vec<(usize, Scalar)>)>,
}

/// A scalar parameter value of an external message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scalar {
    /// A boolean.
    Bool(bool),
    /// An integer.
    Int(i64),
    /// A float.
    Float(f64),
}

impl Inbox {
    /// Queues a message of `event` whose parameters `(index, value)` are given; the
    /// others keep their declared defaults.
    pub fn push(&mut self, event: EventId, params: Vec<(usize, Scalar)>) {
        self.items.push_back((event, params));
    }

    /// Messages not posted yet.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether nothing waits.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

/// Observes nothing.
impl Observer for () {}

impl<O: Observer + ?Sized> Observer for &mut O {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        (**self).on_send(time, msg)
    }
    fn on_receive(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        (**self).on_receive(time, msg)
    }
    fn on_time(&mut self, time: u64) -> Flow {
        (**self).on_time(time)
    }
    fn on_log(&mut self, time: u64, machine: MachineId, label: &str, value: Option<Value<'_>>) {
        (**self).on_log(time, machine, label, value)
    }
    fn inputs(&mut self, time: u64, inbox: &mut Inbox) {
        (**self).inputs(time, inbox)
    }
}

fn both(a: Flow, b: Flow) -> Flow {
    if a == Flow::Stop || b == Flow::Stop {
        Flow::Stop
    } else {
        Flow::Continue
    }
}

/// Two observers side by side (e.g. monitors and a trace recorder); stops when either stops.
impl<A: Observer, B: Observer> Observer for (A, B) {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let a = self.0.on_send(time, msg);
        both(a, self.1.on_send(time, msg))
    }
    fn on_receive(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let a = self.0.on_receive(time, msg);
        both(a, self.1.on_receive(time, msg))
    }
    fn on_time(&mut self, time: u64) -> Flow {
        let a = self.0.on_time(time);
        both(a, self.1.on_time(time))
    }
    fn on_log(&mut self, time: u64, machine: MachineId, label: &str, value: Option<Value<'_>>) {
        self.0.on_log(time, machine, label, value);
        self.1.on_log(time, machine, label, value);
    }
    fn inputs(&mut self, time: u64, inbox: &mut Inbox) {
        self.0.inputs(time, inbox);
        self.1.inputs(time, inbox);
    }
}
