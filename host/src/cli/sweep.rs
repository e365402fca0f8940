//! `hindsight sweep`: one property's success rate as every time bound in it takes each value of a range.

use std::path::PathBuf;

use super::verify::{load, max_time_error, progress_bar};
use super::CliError;
use crate::codegen::duration::StepsOrDuration;
use crate::live::{self, engine::Verdict};
use crate::props;
use crate::report::plot;
use crate::smc::runner::PropertyCounts;
use crate::verify::observe::PropertySet;
use crate::verify::options::VerifyOptions;
use crate::verify::sweep::{
    axis, bound_text, grid, points_from_counts, sweep_study, targets, threshold_index, variants,
    SweepCurve, SweepPoint,
};

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

/// Runs `hindsight sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    let values = grid(&args.from, &args.to, args.step.as_deref())
        .map_err(|e| CliError::Input(e.to_string()))?;
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
    let targets =
        targets(file, &args.properties, props_path).map_err(|e| CliError::Input(e.to_string()))?;
    let rule = crate::verify::sweep::rule(args.confidence);
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
            let points = points_from_counts(&values, &counts, &rule)
                .map_err(|e| CliError::Input(format!("statistics: {e}")))?;
            curves.push(curve(args, target, points));
        }
        return finish(args, &values, curves);
    }
    let opts = VerifyOptions {
        rule,
        seed: args.seed,
        threads: args.threads,
        max_runs: Some(args.runs),
        max_time: args.max_time.clone(),
        scheduler: args.scheduler,
        ..VerifyOptions::default()
    };
    let run_cfg = opts.run_config(&loaded).map_err(max_time_error)?;
    let study_cfg = opts.study_config();
    if !args.json {
        println!("property,bound,successes,failures,unknown,probability,lower,upper");
    }
    let mut curves = Vec::new();
    for target in &targets {
        let one = variants(file, target, &values);
        let set = PropertySet::with_unit(&one, model, loaded.unit_ns)?;
        crate::cli::print_new_warnings(set.warnings(), &mut said);
        let mut bar = progress_bar(!args.json);
        let points = sweep_study(
            model,
            &set,
            &values,
            &run_cfg,
            &study_cfg,
            &opts.rule,
            &mut |p| bar.update(p),
        )
        .map_err(|e| CliError::Input(e.to_string()))?;
        curves.push(curve(args, target, points));
    }
    finish(args, &values, curves)
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
    SweepCurve::new(&target.id, points)
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
    values: &[StepsOrDuration],
    curves: Vec<SweepCurve>,
) -> Result<(), CliError> {
    let unit_label = match values.first() {
        Some(StepsOrDuration::Nanos(_)) => "bound (s)",
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
                        x: axis(*v),
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
                    threshold: found.map(|i| axis(values[i])),
                    threshold_text: found.map(|i| bound_text(values[i])),
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
