//! Records a run's message trace: time, event, origin, target and parameters of every send.

use super::ids::{EventId, MachineId};
use super::observer::{Flow, Observer, SentMessage};
use crate::expr::OwnedValue;

/// One sent message.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceRow {
    /// Model time of the send.
    pub time: u64,
    /// The event.
    pub event: EventId,
    /// The sender.
    pub origin: MachineId,
    /// The receiver (`None`: the `NONE` sink).
    pub target: Option<MachineId>,
    /// Parameter values in the event's parameter order.
    pub params: Vec<OwnedValue>,
}

/// An [`Observer`] that records every send. Combine it with another observer as a
/// pair `(other, &mut recorder)`; when not used it costs nothing.
#[derive(Clone, Debug, Default)]
pub struct TraceRecorder {
    /// The recorded sends, in order.
    pub rows: Vec<TraceRow>,
}

impl TraceRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Observer for TraceRecorder {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        self.rows.push(TraceRow {
            time,
            event: msg.event(),
            origin: msg.origin(),
            target: msg.target(),
            params: msg.params().map(OwnedValue::from).collect(),
        });
        Flow::Continue
    }
}
