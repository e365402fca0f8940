//! The sidecar's two JSON-lines streams: verdict lines out, and the input log that `--replay` reads back.
//!
//! Verdict line: `{"property":"battery_recurrence","time":42,"verdict":"currently_false","event":"museum/battery"}`.
//!
//! Input log, one record per line, every time in ticks of the spec's unit:
//! - `{"kind":"start","unit_ns":N,"speed":S}`: the first line the sidecar writes: the
//!   tick's length in nanoseconds and the system's speed (a log without it is accepted;
//!   one with another unit than the replaying spec's is rejected);
//! - `{"kind":"sample","time":T,"source":S,"sets":{VAR:VALUE,..}}`: a tapped sample;
//! - `{"kind":"request","time":T,"source":S,"sets":{..},"filter":[PROP,..]|null}`: a proxied request;
//! - `{"kind":"tick","time":T}`: a heartbeat point with no sample;
//! - `{"kind":"loss","time":T,"source":S,"vars":[VAR,..],"count":N,"reason":R}`: lost or
//!   malformed samples, or (reason `late`) a sample that arrived after later points were
//!   judged; its `unknown` verdicts name the event `lost S` (`late S`);
//! - `{"kind":"restart","time":T,"source":S,"gap":TICKS}`: a new publisher (informational).
//!
//! Values are JSON booleans, integers and floats, typed by the spec's variables.

use std::collections::BTreeMap;

use codegen::Compiled;
use monitor_core::{Ty, Value};
use serde::{Deserialize, Serialize};

use super::engine::{Change, Engine, EngineError, Verdict};

/// What makes one record unjudgeable by a spec ([`apply`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RecordError {
    /// A variable the spec does not have.
    UnknownVariable(String),
    /// A `filter` property the spec does not have.
    UnknownProperty(String),
    /// A value that is not of its variable's type.
    BadValue {
        /// The value as JSON.
        value: String,
        /// The variable.
        var: String,
        /// Its type in the spec.
        ty: String,
    },
    /// The log was recorded with another tick than the spec's.
    Unit {
        /// The log's tick, in nanoseconds.
        log_ns: u64,
        /// The spec's.
        spec_ns: u64,
    },
    /// The monitors refused the point (time going backwards), as the spec describes it.
    Step(String),
}

impl std::fmt::Display for RecordError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RecordError::UnknownVariable(n) => write!(f, "`{n}` is not a variable of the spec"),
            RecordError::UnknownProperty(n) => write!(f, "`{n}` is not a property of the spec"),
            RecordError::BadValue { value, var, ty } => {
                write!(f, "`{value}` is not a value of type `{ty}` for `{var}`")
            }
            RecordError::Unit { log_ns, spec_ns } => write!(
                f,
                "the log's ticks are {} long, the spec's are {}: record and replay with the \
                 same unit",
                codegen::duration::format(*log_ns),
                codegen::duration::format(*spec_ns)
            ),
            RecordError::Step(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for RecordError {}

/// Why an input log does not replay: where (`file:line:col`) and what.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LogError {
    /// A line that is not a record.
    Syntax {
        /// The log's name.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the JSON reader says.
        message: String,
    },
    /// A record the spec cannot judge.
    Record {
        /// The log's name.
        file: String,
        /// 1-based line.
        line: usize,
        /// What is wrong with it.
        error: RecordError,
    },
    /// The spec's monitors could not be built (before any record).
    Engine(EngineError),
}

impl std::fmt::Display for LogError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LogError::Syntax {
                file,
                line,
                column,
                message,
            } => write!(f, "{file}:{line}:{column}: {message}"),
            LogError::Record { file, line, error } => write!(f, "{file}:{line}:1: {error}"),
            LogError::Engine(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for LogError {}

/// One record of the input log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Input {
    /// What the log's times mean; the sidecar writes it first.
    Start {
        /// Nanoseconds of model time in one tick: the spec's unit.
        unit_ns: u64,
        /// How many times faster than real time the system ran (informational).
        speed: f64,
    },
    /// A tapped sample.
    Sample {
        /// Quantised time.
        time: u64,
        /// The service it came from.
        source: String,
        /// Variable name to value.
        sets: BTreeMap<String, serde_json::Value>,
    },
    /// A proxied request.
    Request {
        /// Quantised time.
        time: u64,
        /// The service it came from.
        source: String,
        /// Variable name to value.
        sets: BTreeMap<String, serde_json::Value>,
        /// The properties it may not falsify (`filter`), `None` for `log`.
        filter: Option<Vec<String>>,
    },
    /// A heartbeat point.
    Tick {
        /// Quantised time.
        time: u64,
    },
    /// Samples lost or unreadable.
    Loss {
        /// Quantised time.
        time: u64,
        /// The service.
        source: String,
        /// The variables its samples set.
        vars: Vec<String>,
        /// How many samples (at least; 1 when unknown).
        count: u64,
        /// Why: `sequence gap`, `buffer full`, `malformed: ...`.
        reason: String,
    },
    /// A new publisher appeared on a topic after another one.
    Restart {
        /// Quantised time.
        time: u64,
        /// The service.
        source: String,
        /// Ticks since the previous publisher's last sample.
        gap: u64,
    },
}

/// Value to JSON.
pub(crate) fn value_json(spec: &Compiled, v: Value) -> serde_json::Value {
    match v {
        Value::Bool(b) => b.into(),
        Value::Int(i) => i.into(),
        Value::Float(f) => {
            serde_json::Number::from_f64(f).map_or(serde_json::Value::Null, Into::into)
        }
        Value::Str(s) => spec
            .strings()
            .get(s as usize)
            .cloned()
            .unwrap_or_default()
            .into(),
    }
}

/// Variable sets to a JSON object keyed by variable name.
pub(crate) fn sets_json(
    spec: &Compiled,
    sets: &[(usize, Value)],
) -> BTreeMap<String, serde_json::Value> {
    sets.iter()
        .map(|&(v, x)| (spec.vars()[v].name.clone(), value_json(spec, x)))
        .collect()
}

fn sets_back(
    spec: &Compiled,
    sets: &BTreeMap<String, serde_json::Value>,
) -> Result<Vec<(usize, Value)>, RecordError> {
    let mut out = Vec::with_capacity(sets.len());
    for (name, j) in sets {
        let var = spec
            .var_index(name)
            .ok_or_else(|| RecordError::UnknownVariable(name.clone()))?;
        let v = match (spec.vars()[var].ty, j) {
            (Ty::Bool, serde_json::Value::Bool(b)) => Value::Bool(*b),
            (Ty::Int, serde_json::Value::Number(n)) if n.is_i64() => {
                Value::Int(n.as_i64().unwrap_or(0))
            }
            (Ty::Float, serde_json::Value::Number(n)) => Value::Float(n.as_f64().unwrap_or(0.0)),
            _ => {
                return Err(RecordError::BadValue {
                    value: j.to_string(),
                    var: name.clone(),
                    ty: spec.vars()[var].type_name.clone(),
                })
            }
        };
        out.push((var, v));
    }
    Ok(out)
}

fn vars_back(spec: &Compiled, names: &[String]) -> Result<Vec<usize>, RecordError> {
    names
        .iter()
        .map(|n| {
            spec.var_index(n)
                .ok_or_else(|| RecordError::UnknownVariable(n.clone()))
        })
        .collect()
}

/// The verdict line of `c`.
pub fn verdict_line(spec: &Compiled, c: &Change) -> String {
    let line = serde_json::json!({
        "property": spec.properties()[c.property].name,
        "time": c.time,
        "verdict": c.verdict.as_str(),
        "event": c.event,
    });
    line.to_string()
}

/// A parsed verdict line.
#[derive(Clone, Debug, PartialEq, Eq, Deserialize)]
pub struct VerdictLine {
    /// Property name.
    pub property: String,
    /// Time in ticks.
    pub time: u64,
    /// `true`, `false`, `currently_true`, `currently_false` or `unknown`.
    pub verdict: String,
    /// What made the point.
    pub event: String,
}

impl VerdictLine {
    /// The verdict, parsed.
    pub fn verdict(&self) -> Option<Verdict> {
        Verdict::parse(&self.verdict)
    }
}

/// Feeds one input record to `engine`; the same call serves the live loop and replay.
pub fn apply(
    spec: &Compiled,
    engine: &mut Engine<'_>,
    input: &Input,
    out: &mut Vec<Change>,
) -> Result<Option<bool>, RecordError> {
    let step = |e: monitor_core::StepError| RecordError::Step(spec.describe(&e));
    match input {
        Input::Sample { time, source, sets } => {
            let sets = sets_back(spec, sets)?;
            engine.point(*time, &sets, source, out).map_err(step)?;
        }
        Input::Request {
            time,
            source,
            sets,
            filter,
        } => {
            let sets = sets_back(spec, sets)?;
            let props = match filter {
                None => None,
                Some(names) => Some(
                    names
                        .iter()
                        .map(|n| {
                            spec.property_names()
                                .position(|p| p == n)
                                .ok_or_else(|| RecordError::UnknownProperty(n.clone()))
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                ),
            };
            let ok = engine
                .request(*time, &sets, source, props.as_deref(), out)
                .map_err(step)?;
            return Ok(Some(ok));
        }
        Input::Tick { time } => engine.point(*time, &[], "tick", out).map_err(step)?,
        Input::Loss {
            time,
            source,
            vars,
            reason,
            ..
        } => {
            let vars = vars_back(spec, vars)?;
            engine
                .loss(*time, &vars, &loss_event(reason, source), out)
                .map_err(step)?;
        }
        Input::Restart { .. } => {}
        Input::Start { unit_ns, .. } => {
            if *unit_ns != spec.tick_ns() {
                return Err(RecordError::Unit {
                    log_ns: *unit_ns,
                    spec_ns: spec.tick_ns(),
                });
            }
        }
    }
    Ok(None)
}

/// The event a loss's `unknown` verdicts name: `late SOURCE` for a sample that came
/// after later points were judged ([`LATE`]), `lost SOURCE` otherwise.
fn loss_event(reason: &str, source: &str) -> String {
    if reason == LATE {
        format!("late {source}")
    } else {
        format!("lost {source}")
    }
}

/// The reason of a [`Input::Loss`] for a late sample.
pub(crate) const LATE: &str = "late";

/// Parses an input log: every record with its line number (1-based); blank lines are
/// skipped. Errors name `file:line:col`.
pub fn parse_log(text: &str, file: &str) -> Result<Vec<(usize, Input)>, LogError> {
    let mut out = Vec::new();
    for (i, l) in text.lines().enumerate() {
        if l.trim().is_empty() {
            continue;
        }
        let input: Input = serde_json::from_str(l).map_err(|e| LogError::Syntax {
            file: file.to_string(),
            line: i + 1,
            column: e.column(),
            message: e.to_string(),
        })?;
        out.push((i + 1, input));
    }
    Ok(out)
}

/// The warning [`complete_records`] returns: the log's last line is a partial record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CutRecord {
    /// The log's name.
    pub file: String,
    /// The 1-based line of the partial record.
    pub line: usize,
}

impl std::fmt::Display for CutRecord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}:1: warning: the last record is cut short (the recorder stopped \
             mid-line): replaying the complete records before it",
            self.file, self.line
        )
    }
}

/// The complete records of a log whose recorder may have been stopped mid-line (killed,
/// out of disk): the text up to its last line break, and a warning naming the cut tail
/// when the text ends in a partial record (no line break, not a record). A last record
/// that is whole but lacks its line break is kept.
pub fn complete_records<'t>(text: &'t str, file: &str) -> (&'t str, Option<CutRecord>) {
    let start = text.rfind('\n').map_or(0, |i| i + 1);
    let tail = &text[start..];
    if tail.trim().is_empty() || serde_json::from_str::<Input>(tail).is_ok() {
        return (text, None);
    }
    let line = text[..start].matches('\n').count() + 1;
    (
        &text[..start],
        Some(CutRecord {
            file: file.to_string(),
            line,
        }),
    )
}

/// Replays an input log: every verdict line, in order. Errors name `file:line`.
pub fn replay(
    spec: &Compiled,
    text: &str,
    file: &str,
    every_point: bool,
) -> Result<Vec<String>, LogError> {
    let mut engine = Engine::new(spec, every_point).map_err(LogError::Engine)?;
    let mut lines = Vec::new();
    let mut out = Vec::new();
    for (line, input) in parse_log(text, file)? {
        out.clear();
        apply(spec, &mut engine, &input, &mut out).map_err(|error| LogError::Record {
            file: file.to_string(),
            line,
            error,
        })?;
        lines.extend(out.iter().map(|c| verdict_line(spec, c)));
    }
    Ok(lines)
}

/// The records of a run: without the heartbeats before the first sample or request and
/// after the last one, when the monitor was waiting for the system or outlived it.
///
/// A sidecar started before the system, or stopped after it, records heartbeats in
/// which nothing can arrive; judged, they would make every recurrence fail at both ends.
/// `hindsight sweep --online` judges a log as one run from its first message to its last,
/// as the off-line sweep judges a simulated run from its start to its end. A log with no
/// sample or request is returned whole.
pub fn run_span(records: &[(usize, Input)]) -> Vec<(usize, Input)> {
    let message_time = |r: &Input| match r {
        Input::Sample { time, .. } | Input::Request { time, .. } => Some(*time),
        _ => None,
    };
    let mut times = records.iter().filter_map(|(_, r)| message_time(r));
    let Some(first) = times.next() else {
        return records.to_vec();
    };
    let last = times.next_back().unwrap_or(first);
    records
        .iter()
        .filter(|(_, r)| !matches!(r, Input::Tick { time } if *time < first || *time > last))
        .cloned()
        .collect()
}

/// Replays parsed log records (from [`parse_log`] on `file`) and returns every
/// property's verdict after the last one (`None`: no point was judged).
///
/// This judges what the log records, against properties that may differ from the ones
/// it was recorded with (`hindsight sweep --online` replays each log against every bound
/// of a property): a request is judged as the point it would have been had it passed,
/// and its `filter` list is not applied (the names are those of the recording's
/// properties). Every variable a record sets must be a variable of `spec`, or the error
/// names `file:line`.
pub fn final_verdicts(
    spec: &Compiled,
    records: &[(usize, Input)],
    file: &str,
) -> Result<Vec<Option<Verdict>>, LogError> {
    let mut engine = Engine::new(spec, false).map_err(LogError::Engine)?;
    let mut out = Vec::new();
    for (line, input) in records {
        out.clear();
        let as_point;
        let input = match input {
            Input::Request {
                time, source, sets, ..
            } => {
                as_point = Input::Sample {
                    time: *time,
                    source: source.clone(),
                    sets: sets.clone(),
                };
                &as_point
            }
            other => other,
        };
        apply(spec, &mut engine, input, &mut out).map_err(|error| LogError::Record {
            file: file.to_string(),
            line: *line,
            error,
        })?;
    }
    Ok(engine.verdicts().to_vec())
}
