//! A recorded trace judged by a compiled spec, point by point (`hindsight replay`): one
//! `monitor_core` monitor over the spec's variables, its verdicts kept at every point or
//! only where one changes.
//!
//! The points come from a CSV trace ([`crate::tracefile::parse_csv`], judged by
//! [`TraceJudge::judge_csv`]) or from any other source that calls [`TraceJudge::step`]
//! (`hindsight-live`'s recordings). Nothing here prints: the kept rows are returned.
//!
//! ```
//! use hindsight_verify::codegen::compile_spec;
//! use hindsight_verify::trace_judge::{Keep, TraceJudge};
//! use hindsight_verify::tracefile::parse_csv;
//!
//! let spec = compile_spec("unit 1s;\nevent b;\nproperty seen = P {b};\n", "t.hspec").unwrap();
//! let trace = parse_csv("time,b\n0,false\n1,true\n2,false\n", "t.csv", &spec).unwrap();
//! let mut judge = TraceJudge::new(&spec, Keep::Changes).unwrap();
//! judge.judge_csv(&trace, "t.csv").unwrap();
//! assert_eq!(judge.points(), 3);
//! assert_eq!(judge.rows(), &[(0, vec![false]), (1, vec![true])]);
//! ```

use std::fmt;

use codegen::Compiled;
use monitor_core::{valuation, Monitor, StepError, TableError, Value};

use crate::tracefile::TracePoint;

/// Which points' verdicts a [`TraceJudge`] keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// Every point's.
    All,
    /// The first point's and those where some verdict changes (`replay --changes`).
    Changes,
    /// None: only the points are counted (`replay --quiet`).
    Nothing,
}

/// One monitor judging a trace of a compiled spec, with the verdict rows it keeps.
pub struct TraceJudge<'c> {
    monitor: Monitor<'c>,
    state: Vec<u64>,
    vals: Vec<Value>,
    verdicts: Vec<bool>,
    keep: Keep,
    rows: Vec<(u64, Vec<bool>)>,
    points: usize,
}

impl<'c> TraceJudge<'c> {
    /// A monitor for `compiled`'s properties, every variable at its initial value; an
    /// error only if the compiled program is rejected (an internal fault).
    pub fn new(compiled: &'c Compiled, keep: Keep) -> Result<Self, TableError> {
        let program = compiled.program();
        let monitor = Monitor::try_new(program)?;
        let mut vals = vec![Value::Bool(false); program.vars.len()];
        valuation::init(program.vars, &mut vals);
        Ok(TraceJudge {
            state: vec![0u64; monitor.state_words()],
            verdicts: vec![false; monitor.properties()],
            monitor,
            vals,
            keep,
            rows: Vec::new(),
            points: 0,
        })
    }

    /// Judges one point at `time` (in the spec's unit) where the variables `sets` names
    /// take their values (event variables not set are false); keeps its verdicts as
    /// [`Keep`] says.
    pub fn step(&mut self, time: u64, sets: &[(usize, Value)]) -> Result<(), StepError> {
        let vars = self.monitor.program().vars;
        valuation::begin_point(vars, &mut self.vals);
        for &(var, v) in sets {
            self.vals[var] = v;
        }
        self.monitor
            .try_step(&mut self.state, time, &self.vals, &mut self.verdicts)?;
        self.points += 1;
        let keep = match self.keep {
            Keep::All => true,
            Keep::Changes => self.rows.last().is_none_or(|(_, v)| *v != self.verdicts),
            Keep::Nothing => false,
        };
        if keep {
            self.rows.push((time, self.verdicts.clone()));
        }
        Ok(())
    }

    /// Judges the points of a CSV trace read from `file` in order; the first point the
    /// monitor refuses (a time going backwards, an atom that cannot be evaluated) stops
    /// it, named by its line and number.
    pub fn judge_csv(&mut self, trace: &[TracePoint], file: &str) -> Result<(), PointError> {
        for (i, p) in trace.iter().enumerate() {
            self.step(p.time, &p.sets).map_err(|error| PointError {
                file: file.to_string(),
                line: p.line,
                point: i + 1,
                error,
            })?;
        }
        Ok(())
    }

    /// How many points were judged.
    pub fn points(&self) -> usize {
        self.points
    }

    /// The kept rows: each point's time and every property's verdict there.
    pub fn rows(&self) -> &[(u64, Vec<bool>)] {
        &self.rows
    }

    /// The monitor's state in bytes.
    pub fn state_bytes(&self) -> usize {
        self.monitor.state_bytes()
    }
}

/// A point of a CSV trace that the monitor refused.
#[derive(Debug)]
pub struct PointError {
    /// The trace file as named.
    pub file: String,
    /// The point's line in the file, from 1.
    pub line: usize,
    /// The point's number, from 1.
    pub point: usize,
    /// The monitor's refusal.
    pub error: StepError,
}

impl PointError {
    /// The message: `file:line: point N: ` and the refusal, with the atom it names
    /// spelled as `compiled` wrote it ([`Compiled::describe`]).
    pub fn describe(&self, compiled: &Compiled) -> String {
        format!(
            "{}:{}: point {}: {}",
            self.file,
            self.line,
            self.point,
            compiled.describe(&self.error)
        )
    }
}

impl fmt::Display for PointError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}: point {}: {}",
            self.file, self.line, self.point, self.error
        )
    }
}

impl std::error::Error for PointError {}
