//! Records a run's message trace (time, event, origin, target, parameters) and writes it as CSV.

use super::compiled::CompiledModel;
use super::ids::{EventId, MachineId};
use super::observer::{Flow, Observer, SentMessage};
use crate::expr::OwnedValue;
use std::io::{self, Write};

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

    /// Forgets the recorded rows (keeps the buffer).
    pub fn clear(&mut self) {
        self.rows.clear();
    }

    /// Writes `time,event,origin,target,params` rows; `params` is `name=value;...`.
    pub fn write_csv(&self, model: &CompiledModel, mut w: impl Write) -> io::Result<()> {
        writeln!(w, "time,event,origin,target,params")?;
        let mut buf = String::new();
        for r in &self.rows {
            buf.clear();
            for (i, ((name, _), v)) in model
                .event_params(r.event)
                .iter()
                .zip(&r.params)
                .enumerate()
            {
                if i > 0 {
                    buf.push(';');
                }
                buf.push_str(name);
                buf.push('=');
                v.write_to(model.strings(), &mut buf);
            }
            let target = match r.target {
                Some(t) => model.machine_name(t),
                None => "NONE",
            };
            writeln!(
                w,
                "{},{},{},{},{}",
                r.time,
                csv_field(model.event_name(r.event)),
                csv_field(model.machine_name(r.origin)),
                csv_field(target),
                csv_field(&buf)
            )?;
        }
        Ok(())
    }
}

fn csv_field(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) {
        std::borrow::Cow::Owned(format!("\"{}\"", s.replace('"', "\"\"")))
    } else {
        std::borrow::Cow::Borrowed(s)
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
