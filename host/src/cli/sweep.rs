//! `hindsight sweep`: one property's success rate as every time bound in it takes each value of a range.

use std::path::PathBuf;
use std::time::Duration;

use super::verify::{load, study};
use super::CliError;
use crate::live::{self, engine::Verdict};
use crate::props::{self, SourceText};
use crate::report::plot;
use crate::sim::RunConfig;
use crate::smc::runner::{widened_interval, PropertyCounts};
use crate::smc::stats::{RuleConfig, RuleKind};
use crate::smc::StudyConfig;
use crate::verify::observe::PropertySet;

/// Arguments of `hindsight sweep`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Every time bound in a property's formula ([a:], [:b], [a:b]) takes each value from
--from to --to in steps of --step. Bounds are model time units (integers), or durations
with a unit (100ms, 2.5s) when the model has a time unit (robot models do).

Each property's variants are judged on the same runs (one study per property, --runs
runs, Clopper-Pearson intervals). The threshold is the smallest bound from which every
run satisfied the property at every larger bound of the range.

Output: CSV `property,bound,successes,failures,unknown,probability,lower,upper` on stdout,
the thresholds on stderr (or everything as one JSON object with --json), and with --svg
a chart of success rate against the bound.

On-line (--online LOG, repeatable): instead of simulating, each input log that
`hindsight monitor --model MODEL --record LOG` wrote is one run. Every bound's variant is
replayed over it, from the log's first sample or request to its last (heartbeats while
the monitor waited for the system, or outlived it, are not the run), and the run succeeds
when the variant's last verdict is true or currently_true (false or currently_false: a
failure; unknown, after a lost sample: unknown). Requests are judged as the points they
would have been; a `filter` is not applied. The output is the off-line one, so the two
thresholds compare (the paper's Tables II and III). A log in another unit than the
model's, or setting a variable that is not a port of the property file, is an error
naming the file and line.

Examples:
  hindsight sweep examples/museum-scxml --property battery_recurrence --from 5 --to 15 --svg sweep.svg
  hindsight sweep examples/museum-guide --online run1.jsonl --online run2.jsonl --from 0.5s --to 7s")]
pub struct SweepArgs {
    /// The model and its properties, as for `verify`.
    #[command(flatten)]
    pub input: super::verify::ModelArgs,
    /// A guarantee to sweep (repeat for several); default: every guarantee with a time bound.
    #[arg(long = "property")]
    pub properties: Vec<String>,
    /// First bound value (`62`, or `6.2s` with a unit).
    #[arg(long)]
    pub from: String,
    /// Last bound value, inclusive.
    #[arg(long)]
    pub to: String,
    /// Step between values; default: one unit of `--from`'s last digit (`1`, `0.1s`).
    #[arg(long)]
    pub step: Option<String>,
    /// Runs per property (every bound of a property is judged on the same runs; at least 1).
    #[arg(long, default_value_t = 200, value_parser = super::run_count)]
    pub runs: u64,
    /// Confidence of the intervals.
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    /// Study seed (the same for every property).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// A run ends when model time reaches this, as for `verify`.
    #[arg(long, value_name = "T")]
    pub max_time: Option<String>,
    /// Run every run under this scheduler (a witness `verify --schedulers` printed).
    #[arg(long, value_name = "ID", value_parser = super::verify::parse_scheduler)]
    pub scheduler: Option<crate::sim::Scheduler>,
    /// Also write an SVG chart of success rate against the bound to this file.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Print one JSON object instead of CSV and the threshold summary.
    #[arg(long)]
    pub json: bool,
    /// Also write one self-contained HTML page with the curves, their intervals and
    /// thresholds, and every bound's counts (see `hindsight report --help`).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// On-line: judge input logs recorded by `hindsight monitor --record` instead of
    /// simulating; each log is one run (repeat for several). Their variables are the
    /// property file's port ids and their times ticks of the model's time unit, as
    /// `monitor --model MODEL --record LOG` writes them.
    #[arg(
        long = "online",
        value_name = "LOG",
        conflicts_with_all = ["runs", "seed", "threads", "max_time"]
    )]
    pub online: Vec<PathBuf>,
}

/// A bound value as written: model time units, or an exact duration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum BoundValue {
    /// A plain integer: model time units.
    Units(u64),
    /// A duration with a unit, in nanoseconds.
    Nanos(u64),
}

impl BoundValue {
    /// Parses `62`, `6.2s`, `100ms`, `1.5min`, `250us`, `10ns`
    /// ([`codegen::duration::parse_steps_or_duration`]).
    pub fn parse(text: &str) -> Result<BoundValue, String> {
        use codegen::duration::StepsOrDuration;
        match codegen::duration::parse_steps_or_duration(text) {
            Ok(StepsOrDuration::Steps(v)) => Ok(BoundValue::Units(v)),
            Ok(StepsOrDuration::Nanos(v)) => Ok(BoundValue::Nanos(v)),
            Err(m) => Err(format!("bad bound: {m}")),
        }
    }

    /// The default step for a range starting at `text`: one unit of its last digit.
    fn default_step(text: &str) -> Result<BoundValue, String> {
        let t = text.trim();
        match t.split_once('.') {
            None => match BoundValue::parse(t)? {
                BoundValue::Units(_) => Ok(BoundValue::Units(1)),
                BoundValue::Nanos(_) => {
                    let unit = t.trim_start_matches(|c: char| c.is_ascii_digit());
                    BoundValue::parse(&format!("1{unit}"))
                }
            },
            Some((_, rest)) => {
                let digits = rest.chars().take_while(char::is_ascii_digit).count();
                let unit = &rest[digits..];
                BoundValue::parse(&format!(
                    "0.{}1{unit}",
                    "0".repeat(digits.saturating_sub(1))
                ))
            }
        }
    }

    fn raw(self) -> u64 {
        match self {
            BoundValue::Units(v) | BoundValue::Nanos(v) => v,
        }
    }

    fn with_raw(self, v: u64) -> BoundValue {
        match self {
            BoundValue::Units(_) => BoundValue::Units(v),
            BoundValue::Nanos(_) => BoundValue::Nanos(v),
        }
    }

    /// The text put into the formula (exact: nanoseconds for durations).
    fn formula_text(self) -> String {
        match self {
            BoundValue::Units(v) => v.to_string(),
            BoundValue::Nanos(v) => format!("{v}ns"),
        }
    }

    /// The value on the chart's x axis: units, or seconds.
    fn axis(self) -> f64 {
        match self {
            BoundValue::Units(v) => v as f64,
            BoundValue::Nanos(v) => v as f64 / 1e9,
        }
    }

    /// The value as people read it: `62`, `6.2s`.
    pub fn display(self) -> String {
        match self {
            BoundValue::Units(v) => v.to_string(),
            BoundValue::Nanos(v) => codegen::duration::seconds(v),
        }
    }
}

/// The values from `from` to `to` (inclusive) in steps of `step`; all three of one kind.
pub fn grid(from: &str, to: &str, step: Option<&str>) -> Result<Vec<BoundValue>, String> {
    let a = BoundValue::parse(from)?;
    let b = BoundValue::parse(to)?;
    let s = match step {
        Some(s) => BoundValue::parse(s)?,
        None => BoundValue::default_step(from)?,
    };
    let same = |x: BoundValue, y: BoundValue| {
        matches!(
            (x, y),
            (BoundValue::Units(_), BoundValue::Units(_))
                | (BoundValue::Nanos(_), BoundValue::Nanos(_))
        )
    };
    if !same(a, b) || !same(a, s) {
        return Err("--from, --to and --step must all be plain numbers or all durations".into());
    }
    if s.raw() == 0 || a.raw() > b.raw() {
        return Err("need --from <= --to and a step above zero".into());
    }
    let count = (b.raw() - a.raw()) / s.raw() + 1;
    if count > 1000 {
        return Err(format!(
            "{count} bound values: at most 1000 (use a larger --step)"
        ));
    }
    Ok((0..count)
        .map(|i| a.with_raw(a.raw() + i * s.raw()))
        .collect())
}

/// Replaces every bound end of `formula` (with its unit, if any: `62`, `2.5s`) by `value`
/// ([`codegen::bounds::map_bounds`]: an edit of the parsed tree, atoms are left alone).
/// Returns the new formula and how many ends were replaced.
pub fn set_bounds(formula: &str, value: &str) -> (String, usize) {
    codegen::bounds::map_bounds(formula, |_| Ok::<_, ()>(value.to_string())).unwrap_or_default()
}

/// One bound's counts for one property.
#[derive(Clone, Debug, serde::Serialize)]
struct SweepPoint {
    bound: String,
    successes: u64,
    failures: u64,
    unknown: u64,
    probability: Option<f64>,
    lower: f64,
    upper: f64,
}

/// One property's sweep.
#[derive(Clone, Debug, serde::Serialize)]
struct SweepCurve {
    property: String,
    /// The smallest bound from which every run succeeded at every larger bound.
    threshold: Option<String>,
    points: Vec<SweepPoint>,
}

/// The smallest index from which every point has only successes (and at least one).
fn threshold_index(points: &[SweepPoint]) -> Option<usize> {
    let all_ok = |p: &SweepPoint| p.failures == 0 && p.unknown == 0 && p.successes > 0;
    let first_bad_from_end = points.iter().rposition(|p| !all_ok(p));
    match first_bad_from_end {
        None if points.is_empty() => None,
        None => Some(0),
        Some(i) if i + 1 < points.len() => Some(i + 1),
        Some(_) => None,
    }
}

/// Runs `hindsight sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    let values = grid(&args.from, &args.to, args.step.as_deref()).map_err(CliError::Input)?;
    if args.runs == 0 {
        return Err(CliError::Input("sweep: --runs must be at least 1".into()));
    }
    let loaded = load(&args.input)?;
    // Each property is compiled again below: the load printed the file's warnings.
    let mut said: std::collections::BTreeSet<String> = loaded
        .warnings
        .iter()
        .map(crate::cli::warning_text)
        .collect();
    let (model, file, props_path) = (&loaded.model, &loaded.file, &loaded.props_path);
    let targets: Vec<props::Property> = if args.properties.is_empty() {
        file.guarantees
            .iter()
            .filter(|g| set_bounds(g.formula.as_str(), "0").1 > 0)
            .cloned()
            .collect()
    } else {
        let mut out = Vec::new();
        for id in &args.properties {
            let Some(g) = file.guarantees.iter().find(|g| &g.id == id) else {
                let known: Vec<&str> = file.guarantees.iter().map(|g| g.id.as_str()).collect();
                return Err(CliError::Input(format!(
                    "{}: no guarantee `{id}` (there are: {})",
                    props_path.display(),
                    known.join(", ")
                )));
            };
            if set_bounds(g.formula.as_str(), "0").1 == 0 {
                return Err(CliError::Input(format!(
                    "{}: guarantee `{id}` has no time bound to sweep",
                    props_path.display()
                )));
            }
            out.push(g.clone());
        }
        out
    };
    if targets.is_empty() {
        return Err(CliError::Input(format!(
            "{}: no guarantee has a time bound to sweep",
            props_path.display()
        )));
    }
    let rule = RuleConfig {
        kind: RuleKind::ClopperPearson,
        confidence: args.confidence,
        // Never done before `--runs`: every bound gets the same runs.
        precision: 1e-9,
    };
    if !args.online.is_empty() {
        let logs = read_logs(&args.online)?;
        if !args.json {
            println!("property,bound,successes,failures,unknown,probability,lower,upper");
        }
        let mut curves = Vec::new();
        for target in &targets {
            let mut one = variants(file, target, &values);
            // The sidecar monitors guarantees only.
            one.assumptions.clear();
            let set = PropertySet::with_unit(&one, model, loaded.unit_ns)?;
            crate::cli::print_new_warnings(set.warnings(), &mut said);
            let mut counts = vec![PropertyCounts::default(); values.len()];
            for (name, records) in &logs {
                let finals = live::record::final_verdicts(set.compiled(), records, name)
                    .map_err(|e| CliError::Input(e.to_string()))?;
                for (c, v) in counts.iter_mut().zip(&finals) {
                    match v {
                        Some(Verdict::True | Verdict::CurrentlyTrue) => c.successes += 1,
                        Some(Verdict::False | Verdict::CurrentlyFalse) => c.failures += 1,
                        Some(Verdict::Unknown) | None => c.unknown += 1,
                    }
                }
            }
            let rules = rule
                .build()
                .map_err(|e| CliError::Input(format!("statistics: {e}")))?;
            let points: Vec<SweepPoint> = values
                .iter()
                .zip(&counts)
                .map(|(v, c)| {
                    let interval = widened_interval(rules.as_ref(), c);
                    SweepPoint {
                        bound: v.display(),
                        successes: c.successes,
                        failures: c.failures,
                        unknown: c.unknown,
                        probability: rules.estimate(c.successes, c.judged()).estimate,
                        lower: interval.lower,
                        upper: interval.upper,
                    }
                })
                .collect();
            curves.push(curve(args, target, points));
        }
        return finish(args, &values, curves);
    }
    let run_cfg = RunConfig {
        max_time: loaded
            .max_time(args.max_time.as_deref())
            .map_err(|m| CliError::Input(format!("--max-time: {m}")))?,
        events: loaded.events,
        scheduler: args.scheduler.unwrap_or_default(),
        ..RunConfig::default()
    };
    let study_cfg = StudyConfig {
        seed: args.seed,
        threads: args.threads,
        max_runs: Some(args.runs),
        keep_failing: 0,
        progress_every: Duration::from_millis(200),
    };
    let show_progress = !args.json;
    if !args.json {
        println!("property,bound,successes,failures,unknown,probability,lower,upper");
    }
    let mut curves = Vec::new();
    for target in &targets {
        let one = variants(file, target, &values);
        let set = PropertySet::with_unit(&one, model, loaded.unit_ns)?;
        crate::cli::print_new_warnings(set.warnings(), &mut said);
        let r = study(model, &set, &run_cfg, &study_cfg, &rule, show_progress)?;
        let points: Vec<SweepPoint> = values
            .iter()
            .zip(&r.properties)
            .map(|(v, p)| SweepPoint {
                bound: v.display(),
                successes: p.counts.successes,
                failures: p.counts.failures,
                unknown: p.counts.unknown,
                probability: p.estimate.estimate,
                lower: p.interval.lower,
                upper: p.interval.upper,
            })
            .collect();
        curves.push(curve(args, target, points));
    }
    finish(args, &values, curves)
}

/// The property file with `target`'s variants, one per bound value, as its guarantees
/// (named `ID@BOUND`).
fn variants(
    file: &props::PropertyFile,
    target: &props::Property,
    values: &[BoundValue],
) -> props::PropertyFile {
    let mut one = file.clone();
    one.guarantees = values
        .iter()
        .map(|v| {
            let mut g = target.clone();
            g.id = format!("{}@{}", target.id, v.display());
            g.formula = SourceText::generated(
                set_bounds(target.formula.as_str(), &v.formula_text()).0,
                target.at,
            );
            g
        })
        .collect();
    one
}

/// Prints a property's CSV rows (unless --json) and finds its threshold.
fn curve(args: &SweepArgs, target: &props::Property, points: Vec<SweepPoint>) -> SweepCurve {
    if !args.json {
        for p in &points {
            println!(
                "{},{},{},{},{},{},{:.4},{:.4}",
                target.id,
                p.bound,
                p.successes,
                p.failures,
                p.unknown,
                p.probability.map_or("".into(), |x| format!("{x:.4}")),
                p.lower,
                p.upper
            );
        }
    }
    let threshold = threshold_index(&points).map(|i| points[i].bound.clone());
    SweepCurve {
        property: target.id.clone(),
        threshold,
        points,
    }
}

/// A parsed `--online` log: its name and its records with their line numbers.
type Log = (String, Vec<(usize, live::record::Input)>);

/// Reads and parses every `--online` log.
fn read_logs(paths: &[PathBuf]) -> Result<Vec<Log>, CliError> {
    paths
        .iter()
        .map(|p| {
            let name = p.display().to_string();
            let text = super::read_file(p)?;
            let records = live::record::parse_log(&text, &name)
                .map_err(|e| CliError::Input(e.to_string()))?;
            Ok((name, live::record::run_span(&records)))
        })
        .collect()
}

/// Prints the thresholds (or the JSON object) and writes the chart.
fn finish(
    args: &SweepArgs,
    values: &[BoundValue],
    curves: Vec<SweepCurve>,
) -> Result<(), CliError> {
    let unit_label = match values.first() {
        Some(BoundValue::Nanos(_)) => "bound (s)",
        _ => "bound (model time units)",
    };
    let doc = if args.online.is_empty() {
        serde_json::json!({
            "runs": args.runs,
            "seed": args.seed,
            "confidence": args.confidence,
            "properties": curves,
        })
    } else {
        let logs: Vec<String> = args
            .online
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        serde_json::json!({
            "runs": logs.len(),
            "logs": logs,
            "confidence": args.confidence,
            "properties": curves,
        })
    };
    if let Some(path) = &args.report {
        super::report::from_sweep(path, &args.input.model, &doc)?;
    }
    if args.json {
        println!("{doc}");
    }
    if !args.json {
        for c in &curves {
            match &c.threshold {
                Some(t) => eprintln!("{}: every run succeeds from bound {t} on", c.property),
                None => eprintln!(
                    "{}: no bound in the range makes every run succeed",
                    c.property
                ),
            }
        }
    }
    if let Some(path) = &args.svg {
        let plot_curves: Vec<plot::Curve> = curves
            .iter()
            .map(|c| {
                let points: Vec<plot::Point> = values
                    .iter()
                    .zip(&c.points)
                    .map(|(v, p)| plot::Point {
                        x: v.axis(),
                        rate: p.probability.unwrap_or(f64::NAN),
                        lower: p.lower,
                        upper: p.upper,
                    })
                    .filter(|p| p.rate.is_finite())
                    .collect();
                let found = threshold_index(&c.points);
                plot::Curve {
                    name: c.property.clone(),
                    points,
                    threshold: found.map(|i| values[i].axis()),
                    threshold_text: found.map(|i| values[i].display()),
                }
            })
            .collect();
        let title = if args.online.is_empty() {
            format!(
                "{}: success rate against the bound ({} runs each)",
                args.input.model.display(),
                args.runs
            )
        } else {
            let n = args.online.len();
            format!(
                "{}: success rate against the bound ({n} recorded run{})",
                args.input.model.display(),
                if n == 1 { "" } else { "s" }
            )
        };
        std::fs::write(path, plot::svg(&title, unit_label, &plot_curves))
            .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", path.display())))?;
        if !args.json {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
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
        assert_eq!(BoundValue::parse("62"), Ok(BoundValue::Units(62)));
        assert_eq!(
            BoundValue::parse("6.2s"),
            Ok(BoundValue::Nanos(6_200_000_000))
        );
        assert_eq!(
            BoundValue::parse("100ms"),
            Ok(BoundValue::Nanos(100_000_000))
        );
        assert_eq!(
            BoundValue::parse("1.5min"),
            Ok(BoundValue::Nanos(90_000_000_000))
        );
        assert!(BoundValue::parse("0.5ns").is_err());
        assert!(BoundValue::parse("2.5").is_err());
        assert!(BoundValue::parse("s").is_err());
        assert!(BoundValue::parse("1.2.3s").is_err());
        assert!(BoundValue::parse("3parsecs").is_err());
        assert!(BoundValue::parse("99999999999999999999s").is_err());
        assert_eq!(BoundValue::Nanos(6_200_000_000).display(), "6.2s");
        assert_eq!(BoundValue::Nanos(2_000_000_000).display(), "2s");
    }

    #[test]
    fn grids_step_exactly_and_default_to_the_last_digit() {
        let g = grid("0.1s", "0.5s", None).unwrap();
        assert_eq!(g.len(), 5);
        assert_eq!(g[4], BoundValue::Nanos(500_000_000));
        let g = grid("58", "66", Some("2")).unwrap();
        assert_eq!(g, [58, 60, 62, 64, 66].map(BoundValue::Units).to_vec());
        assert!(grid("1", "2s", None).is_err());
        assert!(grid("5", "1", None).is_err());
        assert!(grid("0", "100000", None).is_err());
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
