//! `hindsight sweep`'s library side: a guarantee's time bounds swept over a grid of
//! values, each value a variant of the guarantee judged on the same runs, and the
//! threshold from which every run succeeds.
//!
//! A bound value is codegen's [`StepsOrDuration`] (model steps, or an exact duration):
//! [`grid`] reads the range, [`variants`] writes one guarantee per value with every
//! nonzero bound end of its formula replaced ([`set_bounds`]), [`sweep`] judges each
//! guarantee's variants on one study's runs (or [`sweep_recorded`] on recorded runs, the
//! logs of `sweep --online`), and [`threshold_index`] finds each curve's threshold.
//!
//! ```
//! use hindsight_verify::codegen::duration::StepsOrDuration;
//! use hindsight_verify::sweep::{bound_text, grid, set_bounds};
//!
//! let values = grid("0.1s", "0.3s", None).unwrap();
//! assert_eq!(values.iter().map(|v| bound_text(*v)).collect::<Vec<_>>(), ["0.1s", "0.2s", "0.3s"]);
//! assert_eq!(grid("58", "62", Some("2")).unwrap()[2], StepsOrDuration::Steps(62));
//! assert!(grid("1", "2s", None).is_err());
//! assert_eq!(set_bounds("once[2:5] {a}", "7"), ("once[7:7] {a}".to_string(), 2));
//! // A window that starts now keeps its start: only the deadline moves.
//! assert_eq!(set_bounds("once[0:5] {a}", "7"), ("once[0:7] {a}".to_string(), 1));
//! assert_eq!(set_bounds("once[0s:5s] {a}", "7s").1, 1);
//! ```

use std::fmt;
use std::path::Path;

use codegen::duration::{parse_steps_or_duration, DurationError, StepsOrDuration};

use codegen::diag::Diagnostics;

use crate::load::{Loaded, MaxTimeError};
use crate::observe::PropertySet;
use crate::options::VerifyOptions;
use crate::props::{self, SourceText};
use crate::sim::{CompiledModel, RunConfig};
use crate::smc::runner::{widened_interval, PropertyCounts, RunCounts};
use crate::smc::stats::{RuleConfig, RuleKind, StatsError};
use crate::smc::{Progress, StudyConfig};
use crate::study::{study, StudyError};

/// Why a sweep cannot start: its range, or the guarantees it names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SweepError {
    /// A bound value that is neither steps nor a duration.
    Bound(DurationError),
    /// `--from`, `--to` and `--step` mix steps and durations.
    Mixed,
    /// `--from` above `--to`, or a step of zero.
    Empty,
    /// More values than `MAX_VALUES`.
    TooMany(u64),
    /// A duration of the range that is no whole number of the model's time steps.
    NotWholeSteps {
        /// The value, as the table writes it.
        value: String,
        /// The model's time step.
        unit: String,
    },
    /// No guarantee of that name in the property file.
    NoGuarantee {
        /// The property file.
        file: String,
        /// The name asked for.
        id: String,
        /// The guarantees there are.
        known: Vec<String>,
    },
    /// The guarantee named has no time bound.
    NoBound {
        /// The property file.
        file: String,
        /// The guarantee.
        id: String,
    },
    /// No guarantee of the file has a time bound.
    NothingToSweep {
        /// The property file.
        file: String,
    },
}

impl fmt::Display for SweepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SweepError::Bound(m) => write!(f, "bad bound: {m}"),
            SweepError::Mixed => {
                f.write_str("--from, --to and --step must all be plain numbers or all durations")
            }
            SweepError::Empty => f.write_str("need --from <= --to and a step above zero"),
            SweepError::NotWholeSteps { value, unit } => write!(
                f,
                "{value} is not a whole number of the model's time steps ({unit}): give --from, \
                 --to and --step in multiples of {unit}"
            ),
            SweepError::TooMany(n) => {
                write!(
                    f,
                    "{n} bound values: at most {MAX_VALUES} (use a larger --step)"
                )
            }
            SweepError::NoGuarantee { file, id, known } => write!(
                f,
                "{file}: no guarantee `{id}` (there are: {})",
                known.join(", ")
            ),
            SweepError::NoBound { file, id } => {
                write!(f, "{file}: guarantee `{id}` has no time bound to sweep")
            }
            SweepError::NothingToSweep { file } => {
                write!(f, "{file}: no guarantee has a time bound to sweep")
            }
        }
    }
}

impl std::error::Error for SweepError {}

/// The most values one sweep takes.
pub(crate) const MAX_VALUES: u64 = 1000;

/// Parses a bound value: `62` (steps), `6.2s`, `100ms`, `1.5min`, `250us`, `10ns`
/// ([`parse_steps_or_duration`]).
pub(crate) fn parse_bound(text: &str) -> Result<StepsOrDuration, SweepError> {
    parse_steps_or_duration(text).map_err(SweepError::Bound)
}

/// The value as people read it: `62`, `6.2s`.
pub fn bound_text(v: StepsOrDuration) -> String {
    match v {
        StepsOrDuration::Steps(v) => v.to_string(),
        StepsOrDuration::Nanos(v) => codegen::duration::seconds(v),
    }
}

/// The value on a chart's x axis: steps, or seconds.
pub fn axis(v: StepsOrDuration) -> f64 {
    match v {
        StepsOrDuration::Steps(v) => v as f64,
        StepsOrDuration::Nanos(v) => v as f64 / 1e9,
    }
}

fn raw(v: StepsOrDuration) -> u64 {
    match v {
        StepsOrDuration::Steps(v) | StepsOrDuration::Nanos(v) => v,
    }
}

fn with_raw(like: StepsOrDuration, v: u64) -> StepsOrDuration {
    match like {
        StepsOrDuration::Steps(_) => StepsOrDuration::Steps(v),
        StepsOrDuration::Nanos(_) => StepsOrDuration::Nanos(v),
    }
}

/// The default step for a range starting at `text`: one unit of its last digit.
fn default_step(text: &str) -> Result<StepsOrDuration, SweepError> {
    let t = text.trim();
    match t.split_once('.') {
        None => match parse_bound(t)? {
            StepsOrDuration::Steps(_) => Ok(StepsOrDuration::Steps(1)),
            StepsOrDuration::Nanos(_) => {
                let unit = t.trim_start_matches(|c: char| c.is_ascii_digit());
                parse_bound(&format!("1{unit}"))
            }
        },
        Some((_, rest)) => {
            let digits = rest.chars().take_while(char::is_ascii_digit).count();
            let unit = &rest[digits..];
            parse_bound(&format!(
                "0.{}1{unit}",
                "0".repeat(digits.saturating_sub(1))
            ))
        }
    }
}

/// The values from `from` to `to` (inclusive) in steps of `step` (default: one unit of
/// `from`'s last digit); all three of one kind, at most `MAX_VALUES`.
pub fn grid(from: &str, to: &str, step: Option<&str>) -> Result<Vec<StepsOrDuration>, SweepError> {
    grid_in(from, to, step, None)
}

/// [`grid`] for a model whose time step is `unit_ns` nanoseconds (`None`: no time unit):
/// a default step of durations that is not a whole number of model steps is rounded up
/// to one (`--from 0.2s` on a 200 ms model steps by 0.2 s, not 0.1 s, whose odd values
/// no bound can take). A step given is kept as given.
pub fn grid_in(
    from: &str,
    to: &str,
    step: Option<&str>,
    unit_ns: Option<u64>,
) -> Result<Vec<StepsOrDuration>, SweepError> {
    let a = parse_bound(from)?;
    let b = parse_bound(to)?;
    let s = match step {
        Some(s) => parse_bound(s)?,
        None => match (default_step(from)?, unit_ns) {
            (StepsOrDuration::Nanos(s), Some(unit)) if unit > 0 && s % unit != 0 => {
                StepsOrDuration::Nanos(s.div_ceil(unit).saturating_mul(unit))
            }
            (s, _) => s,
        },
    };
    let same = |x: StepsOrDuration, y: StepsOrDuration| {
        std::mem::discriminant(&x) == std::mem::discriminant(&y)
    };
    if !same(a, b) || !same(a, s) {
        return Err(SweepError::Mixed);
    }
    if raw(s) == 0 || raw(a) > raw(b) {
        return Err(SweepError::Empty);
    }
    let count = (raw(b) - raw(a)) / raw(s) + 1;
    if count > MAX_VALUES {
        return Err(SweepError::TooMany(count));
    }
    let values: Vec<StepsOrDuration> = (0..count)
        .map(|i| with_raw(a, raw(a) + i * raw(s)))
        .collect();
    if let Some(unit) = unit_ns.filter(|&u| u > 0) {
        let odd = values
            .iter()
            .find(|v| matches!(v, StepsOrDuration::Nanos(n) if n % unit != 0));
        if let Some(&v) = odd {
            return Err(SweepError::NotWholeSteps {
                value: bound_text(v),
                unit: codegen::duration::format(unit),
            });
        }
    }
    Ok(values)
}

/// Replaces every bound end of `formula` (with its unit, if any: `62`, `2.5s`) by `value`
/// ([`codegen::bounds::map_bounds`]: an edit of the parsed tree, atoms are left alone),
/// except an end that is zero: the `0` of `once[0:2s]` says the window starts now, it
/// is not a bound (sweeping it too turned the deadline `once[0:2s]` into `once[2s:2s]`,
/// "exactly 2 s ago"). Returns the new formula and how many ends were replaced.
pub fn set_bounds(formula: &str, value: &str) -> (String, usize) {
    let mut replaced = 0;
    let Ok((text, _)) = codegen::bounds::map_bounds(formula, |end| {
        if codegen::bounds::is_zero_end(end) {
            return Ok::<_, std::convert::Infallible>(end.to_string());
        }
        replaced += 1;
        Ok(value.to_string())
    });
    (text, replaced)
}

/// The guarantees to sweep: those named in `ids` (each must have a time bound), or, with
/// none named, every guarantee with one. `props_path` names the file in errors.
pub fn targets(
    file: &props::PropertyFile,
    ids: &[String],
    props_path: &Path,
) -> Result<Vec<props::Property>, SweepError> {
    let path = || props_path.display().to_string();
    let has_bound = |g: &props::Property| set_bounds(g.formula.as_str(), "0").1 > 0;
    let targets: Vec<props::Property> = if ids.is_empty() {
        file.guarantees
            .iter()
            .filter(|g| has_bound(g))
            .cloned()
            .collect()
    } else {
        let mut out = Vec::new();
        for id in ids {
            let Some(g) = file.guarantees.iter().find(|g| &g.id == id) else {
                return Err(SweepError::NoGuarantee {
                    file: path(),
                    id: id.clone(),
                    known: file.guarantees.iter().map(|g| g.id.clone()).collect(),
                });
            };
            if !has_bound(g) {
                return Err(SweepError::NoBound {
                    file: path(),
                    id: id.clone(),
                });
            }
            out.push(g.clone());
        }
        out
    };
    if targets.is_empty() {
        return Err(SweepError::NothingToSweep { file: path() });
    }
    Ok(targets)
}

/// The stopping rule of a sweep: Clopper-Pearson intervals at `confidence`, never done
/// before the study's run cap (every bound gets the same runs).
pub fn rule(confidence: f64) -> RuleConfig {
    RuleConfig {
        kind: RuleKind::ClopperPearson,
        confidence,
        precision: 1e-9,
    }
}

/// One bound's counts for one property (a row of `sweep`'s CSV and JSON, read back by
/// the report).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SweepPoint {
    /// The bound value as people read it.
    pub bound: String,
    /// Runs that satisfied the variant.
    pub successes: u64,
    /// Runs that did not.
    pub failures: u64,
    /// Runs without a final verdict.
    pub unknown: u64,
    /// The estimate (`null` with no judged run).
    pub probability: Option<f64>,
    /// Lower end of the interval.
    pub lower: f64,
    /// Upper end of the interval.
    pub upper: f64,
}

/// One property's sweep.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SweepCurve {
    /// The guarantee.
    pub property: String,
    /// The smallest bound from which every run succeeded at every larger bound.
    pub threshold: Option<String>,
    /// One point per bound value, in increasing order.
    pub points: Vec<SweepPoint>,
}

impl SweepCurve {
    /// The curve of `property` through `points`, its threshold found.
    pub fn new(property: &str, points: Vec<SweepPoint>) -> SweepCurve {
        let threshold = threshold_index(&points).map(|i| points[i].bound.clone());
        SweepCurve {
            property: property.to_string(),
            threshold,
            points,
        }
    }
}

/// The smallest index from which every point has only successes (and at least one).
pub fn threshold_index(points: &[SweepPoint]) -> Option<usize> {
    let all_ok = |p: &SweepPoint| p.failures == 0 && p.unknown == 0 && p.successes > 0;
    let first_bad_from_end = points.iter().rposition(|p| !all_ok(p));
    match first_bad_from_end {
        None if points.is_empty() => None,
        None => Some(0),
        Some(i) if i + 1 < points.len() => Some(i + 1),
        Some(_) => None,
    }
}

/// The property file with `target`'s variants, one per bound value, as its guarantees
/// (named `ID@BOUND`).
pub fn variants(
    file: &props::PropertyFile,
    target: &props::Property,
    values: &[StepsOrDuration],
) -> props::PropertyFile {
    let mut one = file.clone();
    one.guarantees = values
        .iter()
        .map(|v| {
            let mut g = target.clone();
            g.id = format!("{}@{}", target.id, bound_text(*v));
            g.formula = SourceText::generated(
                // The bound as the table writes it (exact: seconds with up to nine
                // decimals), so an error in a variant names it as the user did.
                set_bounds(target.formula.as_str(), &bound_text(*v)).0,
                target.at,
            );
            g
        })
        .collect();
    one
}

/// Judges `set` (the [`variants`] of one guarantee, compiled) on one study of
/// `study_cfg.max_runs` runs: one point per value of `values`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep_study(
    model: &CompiledModel,
    set: &PropertySet,
    values: &[StepsOrDuration],
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> Result<(Vec<SweepPoint>, RunCounts), StudyError> {
    let r = study(model, set, run_cfg, study_cfg, rule, progress)?;
    let points = values
        .iter()
        .zip(&r.properties)
        .map(|(v, p)| SweepPoint {
            bound: bound_text(*v),
            successes: p.counts.successes,
            failures: p.counts.failures,
            unknown: p.counts.unknown,
            probability: p.estimate.estimate,
            lower: p.interval.lower,
            upper: p.interval.upper,
        })
        .collect();
    Ok((points, r.runs))
}

/// One point per value from counts found without a study (`sweep --online`: one run per
/// recorded log), with `rule`'s estimate and interval (widened over unknown runs).
pub(crate) fn points_from_counts(
    values: &[StepsOrDuration],
    counts: &[PropertyCounts],
    rule: &RuleConfig,
) -> Result<Vec<SweepPoint>, StatsError> {
    let rules = rule.build()?;
    Ok(values
        .iter()
        .zip(counts)
        .map(|(v, c)| {
            let interval = widened_interval(rules.as_ref(), c);
            SweepPoint {
                bound: bound_text(*v),
                successes: c.successes,
                failures: c.failures,
                unknown: c.unknown,
                probability: rules.estimate(c.successes, c.judged()).estimate,
                lower: interval.lower,
                upper: interval.upper,
            }
        })
        .collect())
}

/// What a running sweep reports, in order, for each property.
pub enum SweepEvent<'a> {
    /// The property's variants were compiled, with these warnings.
    Warnings(&'a Diagnostics),
    /// Runs of its study done so far (simulated sweeps).
    Runs(&'a Progress<'a>),
    /// The property's curve.
    Curve(&'a SweepCurve),
    /// How the runs of its study (simulated sweeps) ended, when some of them show a
    /// deadlock: [`Loaded::deadlock_note`]'s note.
    Deadlock(&'a str),
}

/// Why a sweep stopped once started.
#[derive(Debug)]
pub enum SweepFailure {
    /// The run length (`--max-time`) does not fit the model.
    MaxTime(MaxTimeError),
    /// A property's variants do not compile.
    Variants(Diagnostics),
    /// The study of a property's variants (the model failed during a run).
    Study(StudyError),
    /// The intervals' rule.
    Stats(StatsError),
    /// A recorded run could not be judged (`sweep --online`): what the judge said.
    Recorded(RecordedError),
}

impl fmt::Display for SweepFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SweepFailure::MaxTime(e) => write!(f, "--max-time: {e}"),
            SweepFailure::Variants(d) => write!(f, "{d}"),
            SweepFailure::Study(e) => write!(f, "{e}"),
            SweepFailure::Stats(e) => write!(f, "statistics: {e}"),
            SweepFailure::Recorded(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for SweepFailure {}

/// What judging the recorded runs in [`sweep_recorded`] failed on, as its judge says it.
pub type RecordedError = Box<dyn std::error::Error + Send + Sync>;

/// The judge of [`sweep_recorded`]: given the variants compiled, per recorded run, each
/// variant's outcome (`Some(true)` satisfied, `Some(false)` not, `None` unknown).
pub type Recorded<'a> =
    dyn FnMut(&codegen::Compiled) -> Result<Vec<Vec<Option<bool>>>, RecordedError> + 'a;

/// The sweep `hindsight sweep` runs: per guarantee of `targets`, its [`variants`] over
/// `values` judged on one study of `opts.max_runs` runs (the same seed for every
/// guarantee), each curve reported to `event` as it is done.
pub fn sweep(
    loaded: &Loaded,
    targets: &[props::Property],
    values: &[StepsOrDuration],
    opts: &VerifyOptions,
    event: &mut dyn FnMut(SweepEvent<'_>),
) -> Result<Vec<SweepCurve>, SweepFailure> {
    let run_cfg = opts.run_config(loaded).map_err(SweepFailure::MaxTime)?;
    let study_cfg = opts.study_config();
    let mut curves = Vec::new();
    for target in targets {
        let one = variants(&loaded.file, target, values);
        let set = PropertySet::with_unit(&one, &loaded.model, loaded.unit_ns)
            .map_err(SweepFailure::Variants)?;
        event(SweepEvent::Warnings(set.warnings()));
        let (points, ends) = sweep_study(
            &loaded.model,
            &set,
            values,
            &run_cfg,
            &study_cfg,
            &opts.rule,
            &mut |p| event(SweepEvent::Runs(p)),
        )
        .map_err(SweepFailure::Study)?;
        if let Some(note) =
            loaded.deadlock_note(run_cfg.max_time, ends.quiescent, ends.runs, opts.seed)
        {
            event(SweepEvent::Deadlock(&note));
        }
        let curve = SweepCurve::new(&target.id, points);
        event(SweepEvent::Curve(&curve));
        curves.push(curve);
    }
    Ok(curves)
}

/// `sweep --online`: the same curves from recorded runs instead of simulated ones. Per
/// guarantee of `targets`, its variants over `values` (guarantees only: the sidecar
/// monitors no assumption) are compiled and given to `judge`, which returns, per
/// recorded run, each variant's last verdict (`Some(true)`: the run satisfied it,
/// `Some(false)`: it did not, `None`: unknown); intervals by `rule`.
pub fn sweep_recorded(
    loaded: &Loaded,
    targets: &[props::Property],
    values: &[StepsOrDuration],
    rule: &RuleConfig,
    judge: &mut Recorded<'_>,
    event: &mut dyn FnMut(SweepEvent<'_>),
) -> Result<Vec<SweepCurve>, SweepFailure> {
    let mut curves = Vec::new();
    for target in targets {
        let mut one = variants(&loaded.file, target, values);
        one.assumptions.clear();
        let set = PropertySet::with_unit(&one, &loaded.model, loaded.unit_ns)
            .map_err(SweepFailure::Variants)?;
        event(SweepEvent::Warnings(set.warnings()));
        let mut counts = vec![PropertyCounts::default(); values.len()];
        for finals in judge(set.compiled()).map_err(SweepFailure::Recorded)? {
            for (c, v) in counts.iter_mut().zip(&finals) {
                match v {
                    Some(true) => c.successes += 1,
                    Some(false) => c.failures += 1,
                    None => c.unknown += 1,
                }
            }
        }
        let points = points_from_counts(values, &counts, rule).map_err(SweepFailure::Stats)?;
        let curve = SweepCurve::new(&target.id, points);
        event(SweepEvent::Curve(&curve));
        curves.push(curve);
    }
    Ok(curves)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bound_is_replaced_and_nothing_else() {
        let f = "historically((once[10:] true) -> once[:10] {x == 10})";
        assert_eq!(
            set_bounds(f, "7"),
            (
                "historically((once[7:] true) -> once[:7] {x == 10})".to_string(),
                2
            )
        );
        assert_eq!(
            set_bounds("{a} since[2:40] {b}", "5").0,
            "{a} since[5:5] {b}"
        );
        assert_eq!(set_bounds("once {a}", "5").1, 0);
        assert_eq!(
            set_bounds("once[3:] {a == \"[2]\"}", "5").0,
            "once[5:] {a == \"[2]\"}"
        );
        assert_eq!(
            set_bounds("once[2.5s:] {a}", "100ns"),
            ("once[100ns:] {a}".to_string(), 1)
        );
    }

    #[test]
    fn bound_values_parse_exactly() {
        assert_eq!(parse_bound("62"), Ok(StepsOrDuration::Steps(62)));
        assert_eq!(
            parse_bound("6.2s"),
            Ok(StepsOrDuration::Nanos(6_200_000_000))
        );
        assert_eq!(
            parse_bound("100ms"),
            Ok(StepsOrDuration::Nanos(100_000_000))
        );
        assert_eq!(
            parse_bound("1.5min"),
            Ok(StepsOrDuration::Nanos(90_000_000_000))
        );
        assert!(parse_bound("0.5ns").is_err());
        assert!(parse_bound("2.5").is_err());
        assert!(parse_bound("s").is_err());
        assert!(parse_bound("1.2.3s").is_err());
        assert!(parse_bound("3parsecs").is_err());
        assert!(parse_bound("99999999999999999999s").is_err());
        assert_eq!(bound_text(StepsOrDuration::Nanos(6_200_000_000)), "6.2s");
        assert_eq!(bound_text(StepsOrDuration::Nanos(2_000_000_000)), "2s");
    }

    #[test]
    fn grids_step_exactly_and_default_to_the_last_digit() {
        // A default step that is no whole number of model steps is rounded up to one.
        let g = grid_in("0.2s", "1s", None, Some(200_000_000)).unwrap();
        let texts: Vec<String> = g.iter().map(|v| bound_text(*v)).collect();
        assert_eq!(texts, ["0.2s", "0.4s", "0.6s", "0.8s", "1s"]);
        // A range off the model's steps is refused at its first value, and a step given
        // that is no whole number of steps at the first value it makes so.
        assert!(matches!(
            grid_in("0.25s", "0.5s", None, Some(100_000_000)),
            Err(SweepError::NotWholeSteps { value, .. }) if value == "0.25s"
        ));
        assert_eq!(
            grid_in("0.2s", "1s", Some("0.1s"), Some(200_000_000)),
            Err(SweepError::NotWholeSteps {
                value: "0.3s".into(),
                unit: "200ms".into()
            })
        );
        // A whole step, and steps, stay as they are.
        let five = |g: Result<Vec<StepsOrDuration>, SweepError>| g.map(|g| g.len());
        assert_eq!(
            five(grid_in("0.1s", "0.5s", None, Some(100_000_000))),
            Ok(5)
        );
        assert_eq!(five(grid_in("1", "5", None, Some(200_000_000))), Ok(5));
        assert_eq!(bound_text(StepsOrDuration::Nanos(300_000_000)), "0.3s");
        assert_eq!(bound_text(StepsOrDuration::Nanos(1)), "0.000000001s");
        let g = grid("0.1s", "0.5s", None).unwrap();
        assert_eq!(g.len(), 5);
        assert_eq!(g[4], StepsOrDuration::Nanos(500_000_000));
        let g = grid("58", "66", Some("2")).unwrap();
        assert_eq!(g, [58, 60, 62, 64, 66].map(StepsOrDuration::Steps).to_vec());
        assert_eq!(grid("1", "2s", None), Err(SweepError::Mixed));
        assert_eq!(grid("5", "1", None), Err(SweepError::Empty));
        assert_eq!(grid("0", "100000", None), Err(SweepError::TooMany(100_001)));
    }

    fn point(successes: u64, failures: u64) -> SweepPoint {
        SweepPoint {
            bound: String::new(),
            successes,
            failures,
            unknown: 0,
            probability: None,
            lower: 0.0,
            upper: 1.0,
        }
    }

    #[test]
    fn threshold_is_where_failures_stop_for_good() {
        let ps = [
            point(0, 5),
            point(5, 0),
            point(4, 1),
            point(5, 0),
            point(5, 0),
        ];
        assert_eq!(threshold_index(&ps), Some(3));
        assert_eq!(threshold_index(&[point(5, 0)]), Some(0));
        assert_eq!(threshold_index(&[point(5, 0), point(0, 5)]), None);
        assert_eq!(threshold_index(&[]), None);
    }
}
