//! The judging core of the sidecar: points in, five-valued verdict changes out, with the loss rule.
//!
//! The engine does no I/O and knows nothing of iceoryx2, so the live loop and
//! `--replay` feed it the same inputs and get the same verdicts.
//!
//! # Verdicts
//! - `true` / `false`: the monitor's verdict, and it can no longer change
//!   (decided by [`monitor_core::analysis::settle`]);
//! - `currently_true` / `currently_false`: the verdict at this point, which later points may change;
//! - `unknown`: a sample that a property reads was lost (or malformed) recently.
//!
//! # The loss rule
//! A loss on a source at time `t` affects every property whose formula reads a
//! variable that the source sets. An affected property whose verdict was already a
//! final `false` keeps it (the violation was seen; nothing lost can undo it). Every
//! other affected property is reported `unknown` at `t` and its temporal state is
//! restarted as if monitoring began at `t`: it reports `unknown` until `t + h`,
//! where `h` is the largest time bound in its formula (at least 1 tick), and judges
//! again from then on. Its later verdicts speak about the run since `t`.
//! Unaffected properties are never disturbed.

use codegen::Compiled;
use monitor_core::{analysis, valuation, Monitor, StepError, TableError, Value};

/// Why [`Engine::new`] could not build the monitors of a spec: the compiled program was
/// refused by [`Monitor::try_new_planned`] (a compiler bug: `codegen` validates what it
/// emits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineError(pub TableError);

impl std::fmt::Display for EngineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "internal: compiled program rejected: {}", self.0)
    }
}

impl std::error::Error for EngineError {}

/// A property's verdict as the sidecar reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// True, and no later point can change it.
    True,
    /// False, and no later point can change it.
    False,
    /// True at this point.
    CurrentlyTrue,
    /// False at this point.
    CurrentlyFalse,
    /// Not judged: a sample this property reads was lost recently.
    Unknown,
}

impl Verdict {
    /// The JSON spelling: `true`, `false`, `currently_true`, `currently_false`, `unknown`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::True => "true",
            Verdict::False => "false",
            Verdict::CurrentlyTrue => "currently_true",
            Verdict::CurrentlyFalse => "currently_false",
            Verdict::Unknown => "unknown",
        }
    }

    /// Parses [`Verdict::as_str`]'s spelling.
    pub fn parse(s: &str) -> Option<Verdict> {
        [
            Verdict::True,
            Verdict::False,
            Verdict::CurrentlyTrue,
            Verdict::CurrentlyFalse,
            Verdict::Unknown,
        ]
        .into_iter()
        .find(|v| v.as_str() == s)
    }

    /// True for `true` and `currently_true`.
    pub fn holds(self) -> bool {
        matches!(self, Verdict::True | Verdict::CurrentlyTrue)
    }
}

/// One reported verdict: property `property` has `verdict` at `time`, caused by `event`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Change {
    /// Property index (declaration order).
    pub property: usize,
    /// Time in ticks of the spec's unit.
    pub time: u64,
    /// The new verdict.
    pub verdict: Verdict,
    /// What made the point: a service name, `tick`, or `lost SERVICE`.
    pub event: String,
}

/// A temporal state that some properties read their verdicts from.
#[derive(Clone, Debug)]
struct Slot {
    state: Vec<u64>,
    verdicts: Vec<bool>,
    /// Per node, its final value as of the last point ([`analysis::settle`]).
    finals: Vec<Option<bool>>,
}

/// The monitors of one spec with the loss rule applied.
#[derive(Debug)]
pub struct Engine<'c> {
    /// Planned for up to 256 nodes and atoms (a larger spec is stepped unplanned).
    monitor: Monitor<'c, 256>,
    vals: Vec<Value>,
    slots: Vec<Slot>,
    prop_slot: Vec<usize>,
    unknown_until: Vec<Option<u64>>,
    prop_vars: Vec<Vec<usize>>,
    horizon: Vec<u64>,
    last: Vec<Option<Verdict>>,
    last_time: Option<u64>,
    every_point: bool,
}

impl<'c> Engine<'c> {
    /// An engine for `spec`; `every_point` reports every verdict at every point,
    /// otherwise only changes (and every property's first verdict).
    pub fn new(spec: &'c Compiled, every_point: bool) -> Result<Self, EngineError> {
        let program = spec.program();
        let monitor = Monitor::try_new_planned(program).map_err(EngineError)?;
        let mut vals = vec![Value::Bool(false); program.vars.len()];
        valuation::init(program.vars, &mut vals);
        let n = monitor.properties();
        let mut prop_vars = Vec::with_capacity(n);
        let mut horizon = Vec::with_capacity(n);
        for p in program.props {
            let mut vars = Vec::new();
            analysis::for_each_read(&program, p, |v| vars.push(v as usize));
            vars.sort_unstable();
            vars.dedup();
            prop_vars.push(vars);
            horizon.push(analysis::horizon(&program, p).max(1));
        }
        let slot = Self::fresh(&monitor);
        Ok(Engine {
            monitor,
            vals,
            slots: vec![slot],
            prop_slot: vec![0; n],
            unknown_until: vec![None; n],
            prop_vars,
            horizon,
            last: vec![None; n],
            last_time: None,
            every_point,
        })
    }

    fn fresh<const N: usize>(monitor: &Monitor<'_, N>) -> Slot {
        Slot {
            state: vec![0; monitor.state_words()],
            verdicts: vec![false; monitor.properties()],
            finals: vec![None; monitor.program().nodes.len()],
        }
    }

    /// The number of properties.
    pub fn properties(&self) -> usize {
        self.last.len()
    }

    /// The last reported verdict of every property (`None` before the first point).
    pub fn verdicts(&self) -> &[Option<Verdict>] {
        &self.last
    }

    /// The time of the last point or loss.
    pub fn last_time(&self) -> Option<u64> {
        self.last_time
    }

    fn check_time(&self, time: u64) -> Result<(), StepError> {
        match self.last_time {
            Some(last) if time < last => Err(StepError::TimeWentBackwards { last, now: time }),
            _ => Ok(()),
        }
    }

    /// Judges one point at `time` where `sets` are the variables it sets
    /// (event/state semantics), appending the verdicts to report to `out`.
    pub fn point(
        &mut self,
        time: u64,
        sets: &[(usize, Value)],
        event: &str,
        out: &mut Vec<Change>,
    ) -> Result<(), StepError> {
        self.check_time(time)?;
        // Types first, so an error changes nothing (the config makes this a bug check).
        for &(v, x) in sets {
            if self.vals.get(v).is_none_or(|cur| cur.ty() != x.ty()) {
                return Err(StepError::VarType { var: v as u16 });
            }
        }
        valuation::begin_point(self.monitor.program().vars, &mut self.vals);
        for &(v, x) in sets {
            self.vals[v] = x;
        }
        for s in &mut self.slots {
            // Cannot fail: state sizes, the time and every type were checked.
            self.monitor
                .try_step(&mut s.state, time, &self.vals, &mut s.verdicts)?;
            let m = &self.monitor;
            let st = &s.state;
            analysis::settle(
                m.program(),
                |n| m.node_value(st, n).unwrap_or(false),
                &mut s.finals,
            );
        }
        self.last_time = Some(time);
        self.report(time, event, out);
        Ok(())
    }

    fn judged(&self, prop: usize, time: u64) -> Verdict {
        if self.unknown_until[prop].is_some_and(|u| time < u) {
            return Verdict::Unknown;
        }
        let s = &self.slots[self.prop_slot[prop]];
        match (
            analysis::settled(self.monitor.program(), &s.finals, prop),
            s.verdicts[prop],
        ) {
            (Some(true), _) => Verdict::True,
            (Some(false), _) => Verdict::False,
            (None, true) => Verdict::CurrentlyTrue,
            (None, false) => Verdict::CurrentlyFalse,
        }
    }

    fn report(&mut self, time: u64, event: &str, out: &mut Vec<Change>) {
        for p in 0..self.last.len() {
            let v = self.judged(p, time);
            if self.unknown_until[p].is_some_and(|u| time >= u) {
                self.unknown_until[p] = None;
            }
            if self.every_point || self.last[p] != Some(v) {
                out.push(Change {
                    property: p,
                    time,
                    verdict: v,
                    event: event.to_string(),
                });
            }
            self.last[p] = Some(v);
        }
    }

    /// Records that samples setting any of `vars` were lost (or unreadable) at
    /// `time`, applying the loss rule; reports the properties that turn `unknown`.
    pub fn loss(
        &mut self,
        time: u64,
        vars: &[usize],
        event: &str,
        out: &mut Vec<Change>,
    ) -> Result<(), StepError> {
        self.check_time(time)?;
        let affected: Vec<usize> = (0..self.last.len())
            .filter(|&p| self.prop_vars[p].iter().any(|v| vars.contains(v)))
            .filter(|&p| self.last[p] != Some(Verdict::False))
            .collect();
        if affected.is_empty() {
            return Ok(());
        }
        self.last_time = Some(time);
        let slot = self.slots.len();
        self.slots.push(Self::fresh(&self.monitor));
        for &p in &affected {
            self.prop_slot[p] = slot;
            self.unknown_until[p] = Some(time + self.horizon[p]);
            if self.last[p] != Some(Verdict::Unknown) || self.every_point {
                out.push(Change {
                    property: p,
                    time,
                    verdict: Verdict::Unknown,
                    event: event.to_string(),
                });
            }
            self.last[p] = Some(Verdict::Unknown);
        }
        // Drop the slots no property reads any more (never the main slot 0).
        let mut keep: Vec<bool> = vec![false; self.slots.len()];
        keep[0] = true;
        for &s in &self.prop_slot {
            keep[s] = true;
        }
        let mut map = vec![0usize; self.slots.len()];
        let mut next = 0;
        for (i, k) in keep.iter().enumerate() {
            if *k {
                map[i] = next;
                next += 1;
            }
        }
        let mut i = 0;
        self.slots.retain(|_| {
            i += 1;
            keep[i - 1]
        });
        for s in &mut self.prop_slot {
            *s = map[*s];
        }
        Ok(())
    }

    /// Judges a request tentatively: with `filter`, a request that turns any of
    /// `props` from holding to not holding is refused and leaves no trace (returns
    /// `false`); otherwise it is a point like [`Engine::point`] (returns `true`).
    pub fn request(
        &mut self,
        time: u64,
        sets: &[(usize, Value)],
        event: &str,
        props: Option<&[usize]>,
        out: &mut Vec<Change>,
    ) -> Result<bool, StepError> {
        let Some(props) = props else {
            self.point(time, sets, event, out)?;
            return Ok(true);
        };
        let before: Vec<bool> = props
            .iter()
            .map(|&p| self.last[p].is_none_or(|v| v.holds()))
            .collect();
        let saved = (
            self.vals.clone(),
            self.slots.clone(),
            self.last.clone(),
            self.unknown_until.clone(),
            self.last_time,
        );
        let mut tentative = Vec::new();
        self.point(time, sets, event, &mut tentative)?;
        let refused = props.iter().zip(&before).any(|(&p, &held)| {
            held && matches!(self.last[p], Some(Verdict::False | Verdict::CurrentlyFalse))
        });
        if refused {
            (
                self.vals,
                self.slots,
                self.last,
                self.unknown_until,
                self.last_time,
            ) = saved;
            return Ok(false);
        }
        out.extend(tentative);
        Ok(true)
    }
}
