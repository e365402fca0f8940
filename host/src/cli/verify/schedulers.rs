//! `hindsight verify --schedulers N`: per property, the probability under the uniform
//! scheduler beside the smallest and largest found among N sampled deterministic
//! schedulers, and which properties are order-sensitive.

use super::{CliError, VerifyArgs};
use crate::verify::options::{Memory, Scheduler};
use crate::verify::result::Study;
use crate::verify::schedulers::{explain, Stage};

/// What a sampled scheduler's choices depend on, as named on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MemoryArg {
    /// The model's current state only (memoryless).
    #[default]
    Memoryless,
    /// The current state and every state and choice before it in the run.
    History,
}

impl From<MemoryArg> for Memory {
    fn from(m: MemoryArg) -> Self {
        match m {
            MemoryArg::Memoryless => Memory::Memoryless,
            MemoryArg::History => Memory::History,
        }
    }
}

/// A `--scheduler` value that names no scheduler: the text and what is wrong with it.
pub use crate::verify::options::BadScheduler;

/// Parses `--scheduler`: `uniform`, `memoryless:ID` or `history:ID` (with `+...`
/// put-backs, as `--json` names them).
pub fn parse_scheduler(text: &str) -> Result<Scheduler, BadScheduler> {
    text.parse()
}

/// Refuses combinations `--schedulers` does not support, with the reason.
pub(super) fn check(args: &VerifyArgs) -> Result<(), CliError> {
    let refuse = |what: &str, why: &str| {
        Err(CliError::Input(format!(
            "--schedulers: not with {what}: {why}"
        )))
    };
    if args.schedulers.is_none() {
        if args.plan.is_some() {
            return Err(CliError::Input(
                "--plan: the plan of a sharded scheduler study needs --schedulers N --runs R \
                 --shard I/K (the same as the plan's first stage)"
                    .into(),
            ));
        }
        return Ok(());
    }
    if args.threshold.is_some() {
        return refuse(
            "--threshold",
            "the threshold question over schedulers is already answered by the bounds \
             without a second test: with confidence c, if the min interval's upper end is \
             below THETA some scheduler (the min witness) has P < THETA, and if the max \
             interval's lower end is above THETA some scheduler has P > THETA; Wald's \
             sequential test (--threshold) would decide the same of one fixed scheduler \
             only, and of no scheduler outside the sample. Run --schedulers N and compare \
             THETA with the intervals, or ask it of one witness: --scheduler ID \
             --threshold THETA",
        );
    }
    if args.scheduler.is_some() {
        return refuse(
            "--scheduler",
            "the study's own estimate is the uniform scheduler's; --scheduler replays one \
             witness alone",
        );
    }
    Ok(())
}

/// A step of the bounds over schedulers, on standard error.
pub(super) fn say_stage(s: Stage<'_>) {
    match s {
        Stage::Round { alive, runs } => {
            eprintln!("schedulers: selecting among {alive}, {runs} runs each")
        }
        Stage::Estimate {
            index,
            of,
            scheduler,
        } => eprintln!("schedulers: fresh estimate {index}/{of} ({scheduler})"),
        Stage::Sources { property } => eprintln!(
            "schedulers: where the order of {property} comes from (choices put back to \
             uniform one kind at a time)"
        ),
    }
}

/// The table of bounds under the study's table (nothing without `--schedulers`).
pub(super) fn print_bounds(r: &Study) {
    let rows = r.scheduler_rows();
    let Some((_, first)) = rows.first() else {
        return;
    };
    let w = rows
        .iter()
        .map(|(p, _)| p.property.len())
        .max()
        .unwrap_or(8)
        .max(8);
    println!();
    println!(
        "bounds over {} sampled {} schedulers (each interval holds the witness's probability; \
         together at confidence {}):",
        first.sampled, first.memory, r.confidence
    );
    println!(
        "{:<w$}  {:>7}  {:>7}  {:>17}  {:>7}  {:>17}  order",
        "property", "uniform", "min", "interval", "max", "interval"
    );
    let num = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.4}"));
    for (p, b) in &rows {
        let iv = |i: [f64; 2]| format!("[{:.4}, {:.4}]", i[0], i[1]);
        println!(
            "{:<w$}  {:>7}  {:>7}  {:>17}  {:>7}  {:>17}  {}",
            p.property,
            num(p.probability),
            num(b.min.probability),
            iv(b.min.interval),
            num(b.max.probability),
            iv(b.max.interval),
            if b.order_sensitive {
                "order-sensitive"
            } else {
                "-"
            }
        );
    }
    println!("witnesses (replay with --scheduler ID on verify, trace or sweep):");
    for (p, b) in &rows {
        println!(
            "  {:<w$}  min {}  max {}",
            p.property, b.min.scheduler, b.max.scheduler
        );
    }
    let explained: Vec<_> = rows
        .iter()
        .filter_map(|(p, b)| explain(&b.sources, r.precision).map(|line| (p, b, line)))
        .collect();
    if !explained.is_empty() {
        println!(
            "where the order comes from (each witness with one kind of choice put back to \
             uniform; --json lists every estimate):"
        );
    }
    for (p, b, line) in explained {
        println!("  {:<w$}  {line}", p.property);
        let mut top: Vec<_> = b.sources.iter().collect();
        top.sort_by(|x, y| y.shift.abs().total_cmp(&x.shift.abs()));
        for s in top.iter().take(4).filter(|s| s.matters(r.precision)) {
            let what = match (&s.machine, &s.event) {
                (Some(m), _) => format!("machine {m}'s position"),
                (_, Some(e)) => format!("event {e}'s position"),
                _ => format!("{} order", s.choice),
            };
            let base = if s.witness == "min" {
                b.min.probability
            } else {
                b.max.probability
            };
            println!(
                "  {:<w$}    {} witness {} -> {} with {what} uniform",
                "",
                s.witness,
                num(base),
                num(s.probability)
            );
        }
    }
    if first.left_out > 0 {
        println!(
            "left out as unfair: {} of {} sampled schedulers (a run of theirs kept one instant \
             going without letting time advance; the bounds are over the others; \
             --keep-unfair keeps them):",
            first.left_out, first.sampled
        );
        for l in &first.left_out_first {
            println!(
                "  {} ({} run {}): {}",
                l.scheduler, l.phase, l.run, l.reason
            );
        }
        if first.left_out as usize > first.left_out_first.len() {
            println!(
                "  ... and {} more",
                first.left_out as usize - first.left_out_first.len()
            );
        }
    }
    let sensitive = rows.iter().filter(|(_, b)| b.order_sensitive).count();
    println!(
        "{sensitive} of {} properties order-sensitive (max - min > 2 x precision {})",
        rows.len(),
        r.precision
    );
}
