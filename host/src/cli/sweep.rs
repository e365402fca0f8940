//! `hindsight sweep`: one property's success rate as every time bound in it takes each value of a range.

use std::path::PathBuf;

use super::verify::{load, progress_bar};
use super::CliError;
use crate::codegen::duration::StepsOrDuration;
use crate::live::{self, engine::Verdict};
use crate::report::plot;
use crate::verify::options::VerifyOptions;
use crate::verify::sweep::{grid, grid_in, sweep, sweep_recorded, targets, SweepCurve, SweepEvent};

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
    /// Step between values; default: one unit of `--from`'s last digit (`1`, `0.1s`),
    /// rounded up to a whole number of the model's time steps.
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
    /// Worker threads (0: all cores; at most 1024). The numbers do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::cli::thread_count)]
    pub threads: usize,
    /// A run ends when model time reaches this, as for `verify`.
    #[arg(long, value_name = "T")]
    pub max_time: Option<String>,
    /// Run every run under this scheduler (a witness `verify --schedulers` printed).
    #[arg(long, value_name = "ID", value_parser = super::verify::parse_scheduler)]
    pub scheduler: Option<crate::verify::options::Scheduler>,
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

/// Runs `hindsight sweep`: the library's [`sweep`] (or [`sweep_recorded`] over the logs
/// `live` reads and judges), each curve printed as CSV as it is done, then the
/// thresholds, the chart and the page.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    // The range is read before the model loads, so that a bad one is said at once; the
    // model's time step then rounds a default step up to whole steps.
    grid(&args.from, &args.to, args.step.as_deref()).map_err(|e| CliError::Input(e.to_string()))?;
    if args.runs == 0 {
        return Err(CliError::Input("sweep: --runs must be at least 1".into()));
    }
    // So is the rule, and before the CSV header goes out: a script reading standard
    // output sees no table of a sweep that never started.
    crate::verify::sweep::rule(args.confidence)
        .build()
        .map_err(|e| CliError::Input(format!("statistics: {e}")))?;
    let loaded = load(&args.input)?;
    let values = grid_in(&args.from, &args.to, args.step.as_deref(), loaded.unit_ns)
        .map_err(|e| CliError::Input(e.to_string()))?;
    // Each property is compiled again: the load printed the file's warnings.
    let mut said: std::collections::BTreeSet<String> = loaded
        .warnings
        .iter()
        .map(crate::cli::warning_text)
        .collect();
    let targets = targets(&loaded.file, &args.properties, &loaded.props_path)
        .map_err(|e| CliError::Input(e.to_string()))?;
    for t in &targets {
        for w in crate::codegen::bounds::two_sided_windows(t.formula.as_str()) {
            eprintln!(
                "warning: {}: guarantee `{}`: both ends of the window {w} take each swept value (it becomes [X:X]); a sweep moves a deadline written as [0:X], [:X] or [X:]",
                loaded.props_path.display(),
                t.id
            );
        }
    }
    let rule = crate::verify::sweep::rule(args.confidence);
    let logs = if args.online.is_empty() {
        Vec::new()
    } else {
        read_logs(&args.online)?
    };
    if !args.json {
        println!("property,bound,successes,failures,unknown,probability,lower,upper");
    }
    let mut bar = progress_bar(!args.json);
    let mut deadlock_said = false;
    let mut event = |e: SweepEvent<'_>| match e {
        SweepEvent::Warnings(w) => crate::cli::print_new_warnings(w, &mut said),
        SweepEvent::Runs(p) => bar.update(p),
        SweepEvent::Curve(c) if !args.json => print_rows(c),
        SweepEvent::Curve(_) => {}
        // Every guarantee is swept on the same seed's runs: one note says it.
        SweepEvent::Deadlock(note) if !deadlock_said => {
            deadlock_said = true;
            eprintln!("{note}");
        }
        SweepEvent::Deadlock(_) => {}
    };
    let curves = if args.online.is_empty() {
        let opts = VerifyOptions {
            rule,
            seed: args.seed,
            threads: args.threads,
            max_runs: Some(args.runs),
            max_time: args.max_time.clone(),
            scheduler: args.scheduler,
            ..VerifyOptions::default()
        };
        sweep(&loaded, &targets, &values, &opts, &mut event)
    } else {
        // Each log is one run: the last verdict of each variant over it.
        let mut judge = |spec: &crate::codegen::Compiled| {
            let mut runs = Vec::new();
            for (name, records) in &logs {
                let finals = live::record::final_verdicts(spec, records, name)?;
                runs.push(finals.iter().map(|v| passed(*v)).collect());
            }
            Ok(runs)
        };
        sweep_recorded(&loaded, &targets, &values, &rule, &mut judge, &mut event)
    }
    .map_err(|e| CliError::Input(e.to_string()))?;
    finish(args, &values, curves)
}

/// Whether a recorded run satisfied a variant, from its last verdict (unknown: `None`).
fn passed(last: Option<Verdict>) -> Option<bool> {
    match last? {
        Verdict::True | Verdict::CurrentlyTrue => Some(true),
        Verdict::False | Verdict::CurrentlyFalse => Some(false),
        Verdict::Unknown => None,
    }
}

/// A property's CSV rows.
fn print_rows(c: &SweepCurve) {
    let name = c.property.as_str();
    for p in &c.points {
        println!(
            "{name},{},{},{},{},{},{:.4},{:.4}",
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
                // At the range's first bound already: the threshold may lie below it.
                Some(t) if c.points.first().is_some_and(|p| &p.bound == t) => eprintln!(
                    "{}: every run succeeds at every bound of the range, from {t} on: the \
                     threshold is {t} or lower (lower --from to find it)",
                    c.property
                ),
                Some(t) => eprintln!("{}: every run succeeds from bound {t} on", c.property),
                // Not one run succeeding anywhere: the range is too low, or the property
                // fails for a reason its bounds do not move.
                None if c.points.iter().all(|p| p.successes == 0 && p.failures > 0) => {
                    eprintln!(
                        "{}: no run succeeds at any bound in the range: the threshold is above it (raise --to), or what fails does not depend on the bound (`hindsight trace MODEL --run K` shows a run)",
                        c.property
                    )
                }
                None => eprintln!(
                    "{}: no bound in the range makes every run succeed",
                    c.property
                ),
            }
        }
    }
    if let Some(path) = &args.svg {
        let plot_curves = plot::sweep_curves(values, &curves);
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
