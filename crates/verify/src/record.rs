//! Failing runs as CSV: every point of a replayed run with its message and every property variable.
//!
//! Columns: `time`, `step` (`init`, `send`, `receive`, `time`), `event`, `origin`,
//! `target`, `params` (`name=value` separated by `;`), then one column per property
//! variable (its value after the point) and one `verdict_NAME` per property (its verdict at
//! the point). A field holding `,`, `"` or a line break is quoted as RFC 4180 says (a
//! `"` doubled inside), so no value is altered; [`records`] reads such a file back.

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
    /// Per property that turned false, why, at its first false point.
    pub culprits: Vec<Culprit>,
}

/// Why a property turned false: at its first false point, the subformula whose value
/// there explains it ([`Judge::culprit`]).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Culprit {
    /// The property.
    pub property: String,
    /// The subformula, in surface syntax with bounds in ticks.
    pub formula: String,
    /// Its value at that point.
    pub value: bool,
}

impl<'j, 'a> Recorder<'j, 'a> {
    /// A recorder writing the header; call [`Recorder::start`] next.
    pub fn new(judge: &'j mut Judge<'a>, model: &'a CompiledModel) -> Self {
        // A model with a time unit says it first (a comment the CSV readers skip), so
        // that `replay` reads bounds in seconds over the times of this trace rightly.
        let mut csv = match model.time_unit_ns() {
            Some(ns) => format!("# time unit: {}\n", codegen::duration::format(ns)),
            None => String::new(),
        };
        csv.push_str("time,step,event,origin,target,params");
        let compiled = judge.set().compiled();
        // Names are quoted like every other field (ids are checked where declared and
        // never need it; a spec's own names are identifiers): one grammar for the file.
        for v in compiled.vars() {
            csv.push(',');
            field(&mut csv, &v.name);
        }
        for p in compiled.property_names() {
            csv.push(',');
            field(&mut csv, &format!("verdict_{p}"));
        }
        csv.push('\n');
        Recorder {
            judge,
            model,
            csv,
            culprits: Vec::new(),
        }
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
                let mut params = String::new();
                for (i, v) in m.params().enumerate() {
                    if i > 0 {
                        params.push(';');
                    }
                    params.push_str(names.get(i).map_or("?", |(n, _)| n.as_str()));
                    params.push('=');
                    v.write_to(self.model.strings(), &mut params);
                }
                field(&mut self.csv, &params);
            }
            None => self.csv.push_str(",,,,"),
        }
        let compiled = self.judge.set().compiled();
        for v in self.judge.values() {
            let _ = match v {
                Value::Bool(b) => write!(self.csv, ",{b}"),
                Value::Int(i) => write!(self.csv, ",{i}"),
                Value::Float(f) => write!(self.csv, ",{f}"),
                Value::Str(s) => {
                    self.csv.push(',');
                    let text = compiled.strings().get(*s as usize);
                    field(&mut self.csv, text.map_or("?", String::as_str));
                    Ok(())
                }
            };
        }
        for v in self.judge.verdicts() {
            let _ = write!(self.csv, ",{v}");
        }
        self.csv.push('\n');
        let names: Vec<&str> = compiled.property_names().collect();
        for (i, &v) in self.judge.verdicts().iter().enumerate() {
            let name = names.get(i).copied().unwrap_or("?");
            if !v && !self.culprits.iter().any(|c| c.property == name) {
                if let Some((formula, value)) = self.judge.culprit(i) {
                    self.culprits.push(Culprit {
                        property: name.to_string(),
                        formula,
                        value,
                    });
                }
            }
        }
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

/// The project's one CSV grammar (RFC 4180 quoting), shared with `hindsight replay`'s
/// trace reader and the report's reader: see [`codegen::csv`].
pub use codegen::csv::{field, records, Record};
