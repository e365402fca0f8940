//! Failing runs as CSV: every point of a replayed run with its message and every property variable.
//!
//! Columns: `time`, `step` (`init`, `send`, `receive`, `time`), `event`, `origin`,
//! `target`, `params` (`name=value` separated by `;`), then one column per property
//! variable (its value after the point) and one `verdict_NAME` per property (its verdict at
//! the point).

use std::fmt::Write;

use monitor_core::Value;

use super::observe::Judge;
use crate::sim::{CompiledModel, Flow, Observer, SentMessage};

/// Wraps a [`Judge`] and writes one CSV row per point it judges.
pub struct Recorder<'j, 'a> {
    judge: &'j mut Judge<'a>,
    model: &'a CompiledModel,
    /// The CSV text so far, header included.
    pub csv: String,
}

impl<'j, 'a> Recorder<'j, 'a> {
    /// A recorder writing the header; call [`Recorder::start`] next.
    pub fn new(judge: &'j mut Judge<'a>, model: &'a CompiledModel) -> Self {
        let mut csv = String::from("time,step,event,origin,target,params");
        let compiled = judge.set().compiled();
        for v in compiled.vars() {
            csv.push(',');
            csv.push_str(&v.name);
        }
        for p in compiled.property_names() {
            csv.push_str(",verdict_");
            csv.push_str(p);
        }
        csv.push('\n');
        Recorder { judge, model, csv }
    }

    /// Judges and records the initial point.
    pub fn start(&mut self) -> Flow {
        let flow = self.judge.start();
        self.row(0, "init", None);
        flow
    }

    fn row(&mut self, time: u64, step: &str, msg: Option<&SentMessage<'_>>) {
        let _ = write!(self.csv, "{time},{step}");
        match msg {
            Some(m) => {
                let _ = write!(
                    self.csv,
                    ",{},{},{},",
                    m.event_name(),
                    m.origin_name(),
                    m.target_name()
                );
                let names = self.model.event_params(m.event());
                for (i, v) in m.params().enumerate() {
                    if i > 0 {
                        self.csv.push(';');
                    }
                    let name = names.get(i).map_or("?", |(n, _)| n.as_str());
                    let mut text = String::new();
                    v.write_to(self.model.strings(), &mut text);
                    let _ = write!(self.csv, "{name}={}", text.replace([',', '\n'], " "));
                }
            }
            None => self.csv.push_str(",,,,"),
        }
        let compiled = self.judge.set().compiled();
        for v in self.judge.values() {
            let _ = match v {
                Value::Bool(b) => write!(self.csv, ",{b}"),
                Value::Int(i) => write!(self.csv, ",{i}"),
                Value::Float(f) => write!(self.csv, ",{f}"),
                Value::Str(s) => write!(
                    self.csv,
                    ",{}",
                    compiled
                        .strings()
                        .get(*s as usize)
                        .map_or("?", String::as_str)
                ),
            };
        }
        for v in self.judge.verdicts() {
            let _ = write!(self.csv, ",{v}");
        }
        self.csv.push('\n');
    }
}

impl Observer for Recorder<'_, '_> {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let flow = self.judge.on_send(time, msg);
        self.row(time, "send", Some(msg));
        flow
    }

    fn on_receive(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        let flow = self.judge.on_receive(time, msg);
        self.row(time, "receive", Some(msg));
        flow
    }

    fn on_time(&mut self, time: u64) -> Flow {
        let flow = self.judge.on_time(time);
        self.row(time, "time", None);
        flow
    }
}
