//! `hindsight verify`: estimate each guarantee's probability on a plain SCXML model.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;

mod both;
mod schedulers;
mod shard;

pub use schedulers::{parse_scheduler, BadScheduler, MemoryArg};
pub use shard::{merge, MergeArgs};

use super::CliError;
use crate::codegen;
use crate::verify::load::ExternalComponent;
use crate::verify::load::{LoadOptions, Loaded, MaxTimeError};
use crate::verify::options::VerifyOptions;
use crate::verify::options::{BtSemantics, BtTick};
use crate::verify::options::{EventSemantics, Scheduler};
use crate::verify::options::{RuleConfig, RuleKind};
use crate::verify::pipeline::{verify, Event, Outcome, Request, VerifyError};
use crate::verify::replay::{how_it_ended, trace_run};
use crate::verify::result::Study;
use crate::verify::schedulers::SchedulerOptions;
use crate::verify::study::Unfair;

/// The stopping rule, as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Rule {
    /// SCAN's adaptive bound: Okamoto's count scaled by how far the estimate is from 1/2.
    Adaptive,
    /// The fixed Okamoto (Chernoff-Hoeffding) bound: ln(2/(1-c)) / (2 e^2) runs.
    Okamoto,
    /// Stop when the Wilson score interval is narrower than ±precision.
    Wilson,
    /// Stop when the exact Clopper-Pearson interval is narrower than ±precision.
    ClopperPearson,
}

/// How sends are delivered, as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Events {
    /// SCAN's channel system: per-machine FIFO queues, a send goes to its target.
    Queues,
    /// AS2FM's JANI semantics: one pending message per event, broadcast to every
    /// machine with a transition on it, senders blocking while it is pending.
    As2fm,
}

impl From<Events> for EventSemantics {
    fn from(e: Events) -> Self {
        match e {
            Events::Queues => EventSemantics::Queues,
            Events::As2fm => EventSemantics::As2fm,
        }
    }
}

/// Whose rules a robot model's behavior tree follows, as named on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum BtArg {
    /// AS2FM's SCXML models of the nodes (the reference probabilities come from them).
    #[default]
    As2fm,
    /// BehaviorTree.CPP 4 as it runs a tree loaded from XML.
    Btcpp,
    /// Both: `verify` runs the study under each and compares; `validate` checks both.
    Both,
}

/// How BehaviorTree.CPP's executor ticks the root, as named on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum BtTickArg {
    /// `Tree::tickOnce()`: ticked again at once while a wake-up is pending.
    #[default]
    Once,
    /// `Tree::tickExactlyOnce()`: one tick per timer event.
    ExactlyOnce,
}

/// The semantics `--bt` and `--bt-tick` name: one, or AS2FM's and BT.CPP's for `both`.
/// `--bt-tick` is refused without BT.CPP's semantics.
pub fn bt_semantics(bt: BtArg, tick: Option<BtTickArg>) -> Result<Vec<BtSemantics>, CliError> {
    if tick.is_some() && bt == BtArg::As2fm {
        return Err(CliError::Input(
            "--bt-tick: only BehaviorTree.CPP's executor has tick modes; give --bt btcpp or \
             --bt both"
                .into(),
        ));
    }
    let btcpp = BtSemantics::Btcpp {
        tick: match tick.unwrap_or_default() {
            BtTickArg::Once => BtTick::Once,
            BtTickArg::ExactlyOnce => BtTick::ExactlyOnce,
        },
    };
    Ok(match bt {
        BtArg::As2fm => vec![BtSemantics::As2fm],
        BtArg::Btcpp => vec![btcpp],
        BtArg::Both => vec![BtSemantics::As2fm, btcpp],
    })
}

/// Arguments of `hindsight verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// The model and its properties.
    #[command(flatten)]
    pub input: ModelArgs,
    /// Confidence of the reported intervals.
    #[arg(long, default_value_t = 0.95)]
    pub confidence: f64,
    /// Half-width of the intervals the study aims for.
    #[arg(long, default_value_t = 0.01)]
    pub precision: f64,
    /// Stopping rule (ignored with --threshold, which runs Wald's sequential test).
    #[arg(long, value_enum, default_value_t = Rule::Adaptive)]
    pub rule: Rule,
    /// Ask "is P >= THETA?" with Wald's SPRT (indifference region ±precision).
    #[arg(long, value_name = "THETA")]
    pub threshold: Option<f64>,
    /// Study seed: run k uses stream k of xoshiro256++, so results do not depend on --threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (0: all cores; at most 1024). The numbers do not depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::cli::thread_count)]
    pub threads: usize,
    /// A run ends when model time reaches this: model steps, or a duration (`100s`) when
    /// the model has a time unit [default: 10000 steps].
    #[arg(long, value_name = "T")]
    pub max_time: Option<String>,
    /// A run reaching this many steps is cut short: its open verdicts are unknown (not
    /// judged). A study that judges no run in its first 1000 stops and says why.
    #[arg(long, default_value_t = 100_000_000, value_parser = crate::cli::step_limit)]
    pub max_steps: u64,
    /// Stop the study after this many runs even if the rule wants more (at least 1).
    #[arg(long, value_parser = super::run_count)]
    pub max_runs: Option<u64>,
    /// Print JSON (one object) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Replay up to N failing runs per property and write each as CSV (time, step, event,
    /// origin, target, parameters, every property variable and verdict) into --out.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub save_failing: usize,
    /// Folder for --save-failing files (created if missing).
    #[arg(long, default_value = "failing-runs")]
    pub out: PathBuf,
    /// Run only slice I of N of a fixed-size study (needs --runs) and write a partial
    /// result as JSON (to --partial or standard output); combine them with `hindsight merge`.
    /// Slices are contiguous run ranges, so any batch scheduler (Slurm arrays,
    /// Kubernetes indexed jobs) can run them anywhere.
    #[arg(long, value_name = "I/N", requires = "runs")]
    pub shard: Option<crate::verify::options::Shard>,
    /// Run a fixed-size study of N runs: no early stop, the rule only gives the interval
    /// (the same numbers as its shards merged). With --shard, the size of the study it slices.
    #[arg(
        long,
        value_name = "N",
        conflicts_with_all = ["save_failing", "max_runs"],
        value_parser = super::run_count
    )]
    pub runs: Option<u64>,
    /// File for the partial result of --shard (which it needs).
    #[arg(long, value_name = "FILE", requires = "shard")]
    pub partial: Option<PathBuf>,
    /// Also write one self-contained HTML page (see `hindsight report --help`): settings,
    /// formulas, probabilities and the failing runs as timelines (those of --save-failing,
    /// else one per property).
    #[arg(long, value_name = "FILE", conflicts_with = "shard")]
    pub report: Option<PathBuf>,
    /// Also bound each probability over N sampled deterministic schedulers (lightweight
    /// scheduler sampling): the smallest and largest probability found, each with an
    /// interval valid although it was selected, the witness schedulers, and which
    /// properties are order-sensitive (max - min > 2 x precision).
    #[arg(long, value_name = "N", value_parser = super::run_count)]
    pub schedulers: Option<u64>,
    /// What a sampled scheduler's choices depend on: `memoryless` (the model's current
    /// state) or `history` (every state and choice so far in the run).
    #[arg(long, value_enum, default_value_t = MemoryArg::Memoryless)]
    pub scheduler_memory: MemoryArg,
    /// Runs per sampled scheduler in the first selection round of --schedulers (later
    /// rounds give the survivors more).
    #[arg(long, value_name = "R", default_value_t = 16, value_parser = super::run_count)]
    pub selection_runs: u64,
    /// With --schedulers: keep a sampled scheduler whose run blocks time (an instant of
    /// --max-instant-steps steps) and judge that run as it stands, instead of leaving the
    /// scheduler out as unfair (see docs/SEMANTICS.md, "Fair schedulers").
    #[arg(long, requires = "schedulers")]
    pub keep_unfair: bool,
    /// Steps one instant may take before the run is a loop that never lets time advance:
    /// a model failure under the uniform scheduler, an unfair run under a sampled one.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1_000_000,
        value_parser = clap::value_parser!(u64).range(1..)
    )]
    pub max_instant_steps: u64,
    /// The plan of a sharded scheduler study's next stage, as `hindsight merge --next`
    /// wrote it (with --schedulers N --runs R --shard I/K; without it, stage 0).
    #[arg(long, value_name = "FILE", requires = "shard")]
    pub plan: Option<PathBuf>,
    /// Run every run under this scheduler: `uniform` (the default) or a witness that
    /// --schedulers printed (`memoryless:ID`, `history:ID`).
    #[arg(long, value_name = "ID", value_parser = parse_scheduler)]
    pub scheduler: Option<Scheduler>,
}

impl VerifyArgs {
    /// The study's settings, read from the arguments once: every step of `verify` takes
    /// them from here.
    pub fn options(&self) -> VerifyOptions {
        VerifyOptions {
            rule: RuleConfig {
                kind: match (self.threshold, self.rule) {
                    (Some(threshold), _) => RuleKind::Sprt { threshold },
                    (None, Rule::Adaptive) => RuleKind::Adaptive,
                    (None, Rule::Okamoto) => RuleKind::Okamoto,
                    (None, Rule::Wilson) => RuleKind::Wilson,
                    (None, Rule::ClopperPearson) => RuleKind::ClopperPearson,
                },
                confidence: self.confidence,
                precision: self.precision,
            },
            seed: self.seed,
            threads: self.threads,
            max_runs: self.max_runs,
            max_time: self.max_time.clone(),
            max_steps: self.max_steps,
            max_instant_steps: self.max_instant_steps,
            scheduler: self.scheduler,
            keep_failing: match self.report {
                Some(_) => self.save_failing.max(1),
                None => self.save_failing,
            },
            schedulers: self.schedulers.map(|count| SchedulerOptions {
                count,
                memory: self.scheduler_memory.into(),
                selection_runs: self.selection_runs,
                unfair: if self.keep_unfair {
                    Unfair::Keep
                } else {
                    Unfair::LeaveOut
                },
            }),
        }
    }
}

/// The model and property arguments every command that loads a model takes.
#[derive(Debug, Default, clap::Args)]
pub struct ModelArgs {
    /// The model: a robot main file (`<roaml>` or `<convince_mc_tc>`) or a folder holding
    /// `main.xml`; a folder of plain .scxml machines, a SCAN model.xml, or one .scxml file.
    pub model: PathBuf,
    /// The property file; default: the one the main file or model.xml names, else
    /// MODEL/properties.xml.
    pub props: Option<PathBuf>,
    /// The length of one model time step (`100ms`), so that bounds with a unit (`6.2s`)
    /// and durations given to --max-time mean wall-clock time on a plain SCXML model.
    #[arg(long, value_name = "DURATION")]
    pub time_unit: Option<String>,
    /// How sends are delivered: `queues` (SCAN: per-machine FIFO queues) or `as2fm`
    /// (AS2FM's JANI semantics: one pending message per event, broadcast); default:
    /// `as2fm` for robot models and `.jani` property files, `queues` otherwise.
    #[arg(long, value_enum)]
    pub events: Option<Events>,
    /// Check only this property (by name; repeat for more). The others are not read
    /// beyond their names, so one that uses something not supported can be left out.
    #[arg(long = "only", value_name = "NAME")]
    pub only: Vec<String>,
    /// Leave this property out (by name; repeat for more), for example a JANI property
    /// with a step bound.
    #[arg(long = "skip", value_name = "NAME")]
    pub skip: Vec<String>,
    /// A folder of ROS interface packages (DIR/PKG/msg/*.msg, or a package itself) for a
    /// robot model; repeat for more. Searched first, before the folders beside and above
    /// the model, the sourced ROS workspace (AMENT_PREFIX_PATH) and the built-ins.
    #[arg(long = "interfaces", value_name = "DIR")]
    pub interfaces: Vec<PathBuf>,
    /// Whose rules the behavior tree's built-in nodes follow (robot models): `as2fm`,
    /// AS2FM's SCXML models of the nodes (the default); `btcpp`, BehaviorTree.CPP 4 as it
    /// runs a tree loaded from XML (only RUNNING children halted, Parallel counting across
    /// ticks, SequenceWithMemory keeping its place, wake-up yields); `both`: `verify`
    /// runs the study under each and says which properties are semantics-sensitive,
    /// `validate` checks both. On the command line only: AS2FM's main file has no
    /// parameter for it.
    #[arg(long = "bt", value_enum, default_value_t = BtArg::As2fm)]
    pub bt: BtArg,
    /// How BehaviorTree.CPP's executor ticks the root under --bt btcpp or both: `once`
    /// (`tickOnce`, what `tickWhileRunning` and ROS 2 executors call: the root is ticked
    /// again at once while a wake-up is pending; the default) or `exactly-once`
    /// (`tickExactlyOnce`).
    #[arg(long = "bt-tick", value_enum, value_name = "MODE")]
    pub bt_tick: Option<BtTickArg>,
}

impl ModelArgs {
    /// The semantics `--bt` / `--bt-tick` name (two for `--bt both`).
    pub fn semantics(&self) -> Result<Vec<BtSemantics>, CliError> {
        bt_semantics(self.bt, self.bt_tick)
    }

    /// The library's load options for these arguments (`--time-unit` parsed); `--bt
    /// both` is refused (only `verify` and `validate` take it).
    pub fn options(&self) -> Result<LoadOptions, CliError> {
        match self.semantics()?.as_slice() {
            [one] => self.options_with(*one),
            _ => Err(CliError::Input(
                "--bt both: only `verify` and `validate` compare the two semantics; give \
                 --bt as2fm or --bt btcpp"
                    .into(),
            )),
        }
    }

    /// [`ModelArgs::options`] with the behavior tree's semantics given.
    pub fn options_with(&self, bt: BtSemantics) -> Result<LoadOptions, CliError> {
        Ok(LoadOptions {
            bt,
            model: self.model.clone(),
            props: self.props.clone(),
            time_unit_ns: self.time_unit.as_deref().map(parse_time_unit).transpose()?,
            events: self.events.map(Into::into),
            only: self.only.clone(),
            skip: self.skip.clone(),
            interfaces: self.interfaces.clone(),
            props_optional: false,
        })
    }
}

/// Parses `--time-unit`: a positive duration with a unit (`100ms`, `1s`).
fn parse_time_unit(text: &str) -> Result<u64, CliError> {
    match codegen::duration::parse(text) {
        Ok(ns) if ns > 0 => Ok(ns),
        Ok(_) => Err(CliError::Input(format!(
            "--time-unit {text}: expected a positive duration (100ms, 1s, 50us)"
        ))),
        Err(m) => Err(CliError::Input(format!("--time-unit {text}: {m}"))),
    }
}

/// [`crate::verify::load::load`] with the command line's arguments.
pub fn load(args: &ModelArgs) -> Result<Loaded, CliError> {
    super::load_model(&args.options()?)
}

/// [`crate::verify::load::load_without`] with the command line's arguments.
pub fn load_without(
    args: &ModelArgs,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), CliError> {
    super::load_model_without(&args.options()?, external)
}

/// The progress bar of a study on standard error, or none (`--json`): the library reports
/// progress to a callback and prints nothing.
pub(super) fn progress_bar(show: bool) -> super::progress::TerminalProgress {
    if show {
        super::progress::TerminalProgress::stderr()
    } else {
        super::progress::TerminalProgress::hidden()
    }
}

/// Set by the first Ctrl-C (SIGINT) or SIGTERM once [`interrupt_flag`] installed the
/// handler; the sequential study checks it once per run it starts.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Installs (once) the handler that makes Ctrl-C / SIGTERM stop a sequential study
/// cleanly, and returns its flag. The first signal sets the flag: no run is started after
/// it, the runs in progress finish and the partial study is printed (exit code 130). A
/// second one ends the process at once, with the same code. If the handler cannot be
/// installed, the signals keep their default action (the process ends at once).
fn interrupt_flag() -> &'static AtomicBool {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        // ctrlc calls this on its own thread, not in the signal handler: printing and
        // exiting are safe here.
        let _ = ctrlc::set_handler(|| {
            if INTERRUPTED.swap(true, Ordering::Relaxed) {
                std::process::exit(130);
            }
            eprintln!(
                "\ninterrupted: finishing the runs in progress, then printing the partial \
                 study (interrupt again to quit at once)"
            );
        });
    });
    &INTERRUPTED
}

/// The line that heads a partial study's table.
fn interrupted_line(runs: u64) -> String {
    format!(
        "interrupted after {runs} runs: the numbers below are a partial study, their \
         intervals are those of the runs done"
    )
}

/// The error that ends an interrupted `verify` (exit code 130), after its partial study
/// was printed.
fn interrupted_error(runs: u64) -> CliError {
    CliError::Interrupted(format!(
        "interrupted after {runs} runs: the study printed is partial"
    ))
}

/// Arguments of `hindsight trace`.
#[derive(Debug, clap::Args)]
pub struct TraceArgs {
    /// The model and its properties, as for `verify`.
    #[command(flatten)]
    pub input: ModelArgs,
    /// The run to replay (its index in the study: run k uses stream k of the seed).
    #[arg(long, default_value_t = 0)]
    pub run: u64,
    /// The study seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A run ends when model time reaches this, as for `verify`.
    #[arg(long, value_name = "T")]
    pub max_time: Option<String>,
    /// A run is cut at this many steps.
    #[arg(long, default_value_t = 100_000_000, value_parser = crate::cli::step_limit)]
    pub max_steps: u64,
    /// Replay the run under this scheduler (a witness `verify --schedulers` printed).
    #[arg(long, value_name = "ID", value_parser = parse_scheduler)]
    pub scheduler: Option<Scheduler>,
    /// Output CSV file; standard output when absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs `hindsight trace`: one run of the study, every point as CSV.
pub fn trace(args: &TraceArgs) -> Result<(), CliError> {
    // A model alone has a trace too: its messages, without property columns.
    let loaded = super::load_model(&LoadOptions {
        props_optional: true,
        ..args.input.options()?
    })?;
    if let Some(why) = &loaded.no_props {
        eprintln!("note: {why}; the trace has no property columns");
    }
    let opts = VerifyOptions {
        seed: args.seed,
        max_time: args.max_time.clone(),
        max_steps: args.max_steps,
        scheduler: args.scheduler,
        ..VerifyOptions::default()
    };
    let run_cfg = opts.run_config(&loaded).map_err(max_time_error)?;
    let (csv, out) = trace_run(&loaded.model, &loaded.set, &run_cfg, opts.seed, args.run)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    match &args.output {
        Some(p) => {
            std::fs::write(p, csv).map_err(|e| CliError::Failed(format!("{}: {e}", p.display())))?
        }
        None => print!("{csv}"),
    }
    eprintln!(
        "run {} of seed {}: {}",
        args.run,
        opts.seed,
        how_it_ended(&out, loaded.unit_ns)
    );
    Ok(())
}

/// A run length (`--max-time`) that is not a number of model steps: bad input.
pub fn max_time_error(e: MaxTimeError) -> CliError {
    CliError::Input(format!("--max-time: {e}"))
}

/// Runs `hindsight verify`: the arguments as a [`Request`], the library's [`verify`],
/// then the table (or JSON), the files written and the report page.
pub fn run(args: &VerifyArgs) -> Result<(), CliError> {
    schedulers::check(args)?;
    let opts = args.options();
    if args.input.bt == BtArg::Both {
        return both::run_both(args, &opts);
    }
    let loaded = load(&args.input)?;
    let bt_label = match args.input.semantics()?.as_slice() {
        [bt] if *bt != BtSemantics::As2fm => Some(bt.label()),
        _ => None,
    };
    let keep = args.save_failing > 0 || args.report.is_some();
    let request = Request {
        bt_label,
        runs: args.runs,
        shard: args.shard,
        plan: args.plan.as_deref(),
        failing_dir: keep.then_some(args.out.as_path()),
        save_failing: args.save_failing > 0,
        witnesses: args.report.is_some(),
        ..Request::new(&loaded, &args.input.model, &opts)
    };
    // A fixed-size study draws its bar even with --json (on standard error); a sequential
    // one does not.
    let mut bar = progress_bar(args.runs.is_some() || !args.json);
    let show = !args.json;
    let started = std::time::Instant::now();
    let outcome = verify(
        &request,
        &mut |e| match e {
            Event::Runs(p) => bar.update(p),
            Event::Bounds(s) if show => schedulers::say_stage(s),
            Event::Stage { stage, kind, jobs } if show => {
                eprintln!("schedulers: stage {stage}, {kind} ({jobs} run ranges)")
            }
            _ => {}
        },
        interrupt_flag(),
    )
    .map_err(verify_error)?;
    let done = match outcome {
        Outcome::Part(json) => {
            return match &args.partial {
                Some(p) => std::fs::write(p, json)
                    .map_err(|e| CliError::Failed(format!("{}: {e}", p.display()))),
                None => {
                    println!("{json}");
                    Ok(())
                }
            }
        }
        Outcome::Study(done) => done,
    };
    for line in &done.left_out {
        eprintln!("interrupted: {line}");
    }
    for path in &done.written {
        eprintln!("wrote {}", path.display());
    }
    let run_cfg = opts.run_config(&loaded).map_err(max_time_error)?;
    if let Some(path) = args.report.as_ref().filter(|_| done.runs_complete) {
        // With --schedulers: a failing run under each order-sensitive property's min
        // witness beside one under the uniform scheduler. A fixed-size study keeps
        // counts, not runs: its page has no timelines.
        super::report::from_verify(
            path,
            &done.study,
            &loaded,
            opts.settings(&run_cfg),
            &done.shown_runs(),
        )?;
    }
    if args.runs.is_some() && !args.json {
        // A fixed-size study's result is the document `merge` makes of its shards, which
        // knows neither the time it took nor the model's time unit: the table of one made
        // here says both, as a sequential study's does.
        let mut shown = done.study.clone();
        shown.seconds = started.elapsed().as_secs_f64();
        shown.set_time_unit(loaded.unit_ns, run_cfg.max_time);
        print_report(&shown, false)?;
    } else {
        print_report(&done.study, args.json)?;
    }
    if let Some(line) = done.study.unjudged_line() {
        eprintln!("{line}");
    }
    if let Some(note) = loaded.deadlock_note(
        run_cfg.max_time,
        done.study.quiescent,
        done.study.runs,
        opts.seed,
    ) {
        eprintln!("{note}");
    }
    if done.study.interrupted {
        return Err(interrupted_error(done.study.runs));
    }
    Ok(())
}

/// A library error as the command line's: bad input (exit code 2) or a failure (1).
fn verify_error(e: VerifyError) -> CliError {
    if e.is_input() {
        CliError::Input(e.to_string())
    } else {
        CliError::Failed(e.to_string())
    }
}

/// Prints a report as JSON or as the table.
fn print_report(report: &Study, json: bool) -> Result<(), CliError> {
    if json {
        let text = serde_json::to_string_pretty(report)
            .map_err(|e| CliError::Failed(format!("json: {e}")))?;
        println!("{text}");
    } else {
        print_table(report);
        schedulers::print_bounds(report);
    }
    Ok(())
}

fn print_table(r: &Study) {
    let w = r
        .properties
        .iter()
        .map(|p| p.property.len())
        .max()
        .unwrap_or(8)
        .max(8);
    if r.interrupted {
        println!("{}", interrupted_line(r.runs));
    }
    println!(
        "{:<w$}  {:>11}  {:>17}  {:>7}  {:>9}  decision",
        "property", "probability", "interval", "runs", "cut short"
    );
    for p in &r.properties {
        let prob = p.probability.map_or("-".to_string(), |x| format!("{x:.4}"));
        let interval = format!("[{:.4}, {:.4}]", p.lower, p.upper);
        println!(
            "{:<w$}  {prob:>11}  {interval:>17}  {:>7}  {:>9}  {}",
            p.property,
            p.runs,
            p.cut_short,
            p.decision.as_deref().unwrap_or("")
        );
    }
    let speed = if r.seconds > 0.0 {
        format!(
            " in {:.2} s ({:.0} runs/s)",
            r.seconds,
            r.runs as f64 / r.seconds
        )
    } else {
        String::new()
    };
    println!(
        "{} runs{speed}; seed {}, confidence {}, precision {}: {} discarded by assumptions, {} stopped early (verdicts final), {} at the time horizon, {} quiescent, {} cut at the step limit",
        r.runs,
        r.seed,
        r.confidence,
        r.precision,
        r.discarded,
        r.decided,
        r.time_horizon,
        r.quiescent,
        r.step_limit
    );
    if let (Some(step), Some(max)) = (r.step_seconds, r.max_time_seconds) {
        println!("model time: steps of {step} s, runs of at most {max} s");
    }
}

/// Arguments of `hindsight validate`.
#[derive(Debug, clap::Args)]
pub struct ValidateArgs {
    /// The model and its properties, as for `verify`.
    #[command(flatten)]
    pub input: ModelArgs,
}

/// Runs `hindsight validate`: loads and compiles (under each semantics `--bt` names),
/// prints a one-line summary each, and warns where the behavior tree runs differently
/// under AS2FM's node models and BehaviorTree.CPP 4.
pub fn validate(args: &ValidateArgs) -> Result<(), CliError> {
    let semantics = args.input.semantics()?;
    for (k, &bt) in semantics.iter().enumerate() {
        // A model alone can be checked too: it loads, compiles and has no properties.
        let loaded = super::load_model(&LoadOptions {
            props_optional: true,
            ..args.input.options_with(bt)?
        })?;
        let (model, set, props_path) = (&loaded.model, &loaded.set, &loaded.props_path);
        let under = if bt == BtSemantics::As2fm && semantics.len() == 1 {
            String::new()
        } else {
            format!(" (--bt {})", bt.label())
        };
        let props = match &loaded.no_props {
            Some(why) => format!("{why}: the model alone is ok"),
            None => format!(
                "{}: {} guarantees, monitor state {} bytes: ok",
                props_path.display(),
                set.guarantee_names().len(),
                set.compiled().state_bytes()
            ),
        };
        println!(
            "{}{under}: {} machines, {} events; {props}",
            args.input.model.display(),
            model.machine_count(),
            model.event_count(),
        );
        if k == 0 {
            for n in &loaded.bt_notes {
                eprintln!("warning: {n}");
            }
            if !loaded.bt_notes.is_empty() {
                eprintln!(
                    "note: the tree's runs differ between AS2FM's node models (--bt as2fm, \
                     the default) and BehaviorTree.CPP 4 (--bt btcpp) where warned above; \
                     `hindsight verify --bt both` says which properties that changes"
                );
            }
        }
    }
    Ok(())
}
