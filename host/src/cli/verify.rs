//! `hindsight verify`: estimate each guarantee's probability on a plain SCXML model.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;

use super::CliError;
use crate::props;
use crate::robot::load::ExternalComponent;
use crate::sim::{CompiledModel, EndReason, EventSemantics, RunConfig, Simulator};
use crate::smc::progress::TerminalProgress;
use crate::smc::stats::{RuleConfig, RuleKind};
use crate::smc::{run_study, RunEnd, RunOutcome, StudyConfig, StudyResult, Verdict};
use crate::verify::observe::{Judge, PropertySet};

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

/// The event semantics for a property file when none is asked for: AS2FM's for a JANI
/// property file (the model is then AS2FM's plain SCXML), SCAN's queues otherwise.
pub fn default_events(props_path: &Path) -> EventSemantics {
    if is_jani(props_path) {
        EventSemantics::As2fm
    } else {
        EventSemantics::Queues
    }
}

fn is_jani(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("jani"))
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
    /// Worker threads (0: all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// A run ends when model time reaches this: model steps, or a duration (`100s`) when
    /// the model has a time unit [default: 10000 steps].
    #[arg(long, value_name = "T")]
    pub max_time: Option<String>,
    /// A run reaching this many steps is cut short: its open verdicts are unknown.
    #[arg(long, default_value_t = 100_000_000)]
    pub max_steps: u64,
    /// Stop the study after this many runs even if the rule wants more.
    #[arg(long)]
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
    pub shard: Option<crate::smc::shard::Shard>,
    /// Size of the fixed study that --shard slices.
    #[arg(long, value_name = "N")]
    pub runs: Option<u64>,
    /// File for the partial result of --shard.
    #[arg(long, value_name = "FILE")]
    pub partial: Option<PathBuf>,
}

/// One property's line of the report.
#[derive(Debug, Serialize)]
pub struct PropertyReport {
    /// The guarantee's id.
    pub property: String,
    /// Estimated probability that a run satisfies it (`null` with no judged run).
    pub probability: Option<f64>,
    /// Lower end of the interval (widened over unknown runs).
    pub lower: f64,
    /// Upper end of the interval.
    pub upper: f64,
    /// Runs judged.
    pub runs: u64,
    /// Runs that satisfied it.
    pub successes: u64,
    /// Runs cut short before its verdict was final (not judged).
    pub cut_short: u64,
    /// With --threshold: `accept` (P >= theta) or `reject`.
    pub decision: Option<String>,
}

impl PropertyReport {
    fn new(
        name: &str,
        estimate: &crate::smc::stats::Estimate,
        interval: &crate::smc::stats::Interval,
        counts: &crate::smc::runner::PropertyCounts,
    ) -> Self {
        PropertyReport {
            property: name.to_string(),
            probability: estimate.estimate,
            lower: interval.lower,
            upper: interval.upper,
            runs: counts.judged(),
            successes: counts.successes,
            cut_short: counts.unknown,
            decision: estimate.decision.map(|d| format!("{d:?}").to_lowercase()),
        }
    }
}

/// The whole report.
#[derive(Debug, Serialize)]
pub struct Report {
    /// The model path.
    pub model: String,
    /// The property file.
    pub properties_file: String,
    /// Study seed.
    pub seed: u64,
    /// Confidence of the intervals.
    pub confidence: f64,
    /// Target precision.
    pub precision: f64,
    /// Runs started and consumed.
    pub runs: u64,
    /// Runs discarded because an assumption was violated.
    pub discarded: u64,
    /// Runs that ended at the time horizon.
    pub time_horizon: u64,
    /// Runs that reached the step limit.
    pub step_limit: u64,
    /// Runs stopped early because every verdict was final.
    pub decided: u64,
    /// Runs that ended because nothing could move.
    pub quiescent: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Seconds of model time in one step, when the model has a time unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_seconds: Option<f64>,
    /// The run length in seconds of model time, when the model has a time unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_time_seconds: Option<f64>,
    /// Per guarantee.
    pub properties: Vec<PropertyReport>,
}

/// Finds the property file for a model when none is given.
fn default_props(model: &Path, compiled: &CompiledModel) -> Result<PathBuf, CliError> {
    if let Some(p) = compiled.properties_path() {
        return Ok(p.to_path_buf());
    }
    let dir = if model.is_dir() {
        model.to_path_buf()
    } else {
        model.parent().map(Path::to_path_buf).unwrap_or_default()
    };
    let p = dir.join("properties.xml");
    if p.is_file() {
        return Ok(p);
    }
    // A folder with exactly one JANI file (AS2FM's models keep their properties there).
    let mut jani: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_jani(p))
                .collect()
        })
        .unwrap_or_default();
    if jani.len() == 1 {
        return Ok(jani.remove(0));
    }
    Err(CliError::Input(format!(
        "{}: no property file given and none found (looked for {} and a single .jani file)",
        model.display(),
        p.display()
    )))
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
    /// A folder of ROS interface packages (DIR/<pkg>/msg/*.msg, or a package itself) for a
    /// robot model; repeat for more. Searched first, before the folders beside and above
    /// the model, the sourced ROS workspace (AMENT_PREFIX_PATH) and the built-ins.
    #[arg(long = "interfaces", value_name = "DIR")]
    pub interfaces: Vec<PathBuf>,
}

/// A model with its properties, compiled: everything `validate` checks.
pub struct Loaded {
    /// The simulator's model.
    pub model: CompiledModel,
    /// The property file as read.
    pub file: props::PropertyFile,
    /// Its guarantees and assumptions, compiled and resolved against the model.
    pub set: PropertySet,
    /// Where the properties came from.
    pub props_path: PathBuf,
    /// The length of one model time step in nanoseconds, when known.
    pub unit_ns: Option<u64>,
    /// The run length the model asks for (a robot main file's `max_time`), in steps.
    pub default_max_time: Option<u64>,
    /// How sends are delivered.
    pub events: EventSemantics,
}

impl Loaded {
    /// `--max-time`: model steps, or a duration when the model has a time unit; by
    /// default the main file's `max_time`, else 10,000 steps.
    pub fn max_time(&self, arg: Option<&str>) -> Result<u64, CliError> {
        let Some(text) = arg else {
            return Ok(self.default_max_time.unwrap_or(10_000));
        };
        match super::sweep::BoundValue::parse(text).map_err(CliError::Input)? {
            super::sweep::BoundValue::Units(v) => Ok(v),
            super::sweep::BoundValue::Nanos(ns) => match self.unit_ns {
                Some(unit) if ns % unit == 0 => Ok(ns / unit),
                Some(unit) => Err(CliError::Input(format!(
                    "--max-time {text} is not a whole number of model steps of {unit} ns"
                ))),
                None => Err(CliError::Input(format!(
                    "--max-time {text}: the model has no time unit (give --time-unit, or \
                     --max-time in steps)"
                ))),
            },
        }
    }
}

/// Parses `--time-unit`: a positive duration with a unit (`100ms`, `1s`).
fn parse_time_unit(text: &str) -> Result<u64, CliError> {
    match super::sweep::BoundValue::parse(text) {
        Ok(super::sweep::BoundValue::Nanos(ns)) if ns > 0 => Ok(ns),
        _ => Err(CliError::Input(format!(
            "--time-unit {text}: expected a positive duration with a unit (100ms, 1s, 50us)"
        ))),
    }
}

/// Loads the model and its properties: a robot model (a main file, or a folder holding
/// `main.xml`) through the robot pipeline, anything else as plain SCXML.
pub fn load(args: &ModelArgs) -> Result<Loaded, CliError> {
    load_without(args, &[]).map(|(l, _)| l)
}

/// [`load`] without the robot model's node models named in `external`, which processes
/// play instead (`hindsight run --external`); what each declared comes back with it.
pub fn load_without(
    args: &ModelArgs,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), CliError> {
    if let Some(main) = crate::robot::load::main_file_of(&args.model) {
        return load_robot(args, &main, external);
    }
    if let Some(dir) = args.interfaces.first() {
        return Err(CliError::Input(format!(
            "--interfaces {}: {} is not a robot model (a main file, or a folder with \
             main.xml); only a robot model reads ROS interfaces",
            dir.display(),
            args.model.display()
        )));
    }
    if let Some(name) = external.first() {
        return Err(CliError::Input(format!(
            "--external {name}: {} is not a robot model (a main file, or a folder with \
             main.xml); only a robot model's node models can be replaced by processes",
            args.model.display()
        )));
    }
    let model = &args.model;
    let unit_ns = args.time_unit.as_deref().map(parse_time_unit).transpose()?;
    let compiled = CompiledModel::load(model).map_err(|d| CliError::Input(d.to_string()))?;
    for w in compiled.warnings() {
        eprintln!("warning: {w}");
    }
    let props_path = match &args.props {
        Some(p) => p.to_path_buf(),
        None => default_props(model, &compiled)?,
    };
    let file = read_properties(&props_path, &compiled, args)?;
    let set = compile_properties(&file, &compiled, unit_ns)?;
    let events = args
        .events
        .map_or_else(|| default_events(&props_path), Into::into);
    Ok((
        Loaded {
            model: compiled,
            file,
            set,
            props_path,
            unit_ns,
            default_max_time: None,
            events,
        },
        Vec::new(),
    ))
}

/// Reads a property file: JANI (`.jani`) or SCAN XML (with ROS ports and patterns).
/// Reads the property file, keeping the guarantees `--only` / `--skip` select.
fn read_properties(
    path: &Path,
    model: &CompiledModel,
    args: &ModelArgs,
) -> Result<props::PropertyFile, CliError> {
    let wanted = |name: &str| {
        (args.only.is_empty() || args.only.iter().any(|o| o == name))
            && !args.skip.iter().any(|s| s == name)
    };
    let unknown_name = |names: &[String]| {
        for (option, given) in [("--only", &args.only), ("--skip", &args.skip)] {
            if let Some(missing) = given.iter().find(|n| !names.contains(n)) {
                return Err(CliError::Input(format!(
                    "{option} {missing}: {} has no property `{missing}` (properties: {})",
                    path.display(),
                    names.join(", ")
                )));
            }
        }
        Ok(())
    };
    let file = if is_jani(path) {
        // The reader sees every property's name, skipped or not.
        let mut names = Vec::new();
        let read = props::jani::parse_file_selected(path, model, &mut |name| {
            names.push(name.to_string());
            wanted(name)
        });
        // A misspelt name comes before what the properties it kept say (a file that is
        // not JSON at all names nothing: its own error comes first then).
        if read.is_ok() || !names.is_empty() {
            unknown_name(&names)?;
        }
        read.map_err(|d| {
            let text = d.to_string();
            // A property using what is not supported need not stop the others.
            let hint = if text.contains("not supported") {
                "\nhint: --skip NAME leaves a property out, --only NAME checks just that one"
            } else {
                ""
            };
            CliError::Input(format!("{text}{hint}"))
        })?
    } else {
        let mut file = props::parse_file(path).map_err(|d| CliError::Input(d.to_string()))?;
        let names: Vec<String> = file.guarantees.iter().map(|g| g.id.clone()).collect();
        unknown_name(&names)?;
        file.guarantees.retain(|g| wanted(&g.id));
        file
    };
    if file.guarantees.is_empty() && !(args.only.is_empty() && args.skip.is_empty()) {
        return Err(CliError::Input(format!(
            "--only/--skip leave no property of {} to check",
            path.display()
        )));
    }
    Ok(file)
}

/// Compiles a property file against a model; a bound with a unit on a model without one
/// gets a hint.
fn compile_properties(
    file: &props::PropertyFile,
    model: &CompiledModel,
    unit_ns: Option<u64>,
) -> Result<PropertySet, CliError> {
    PropertySet::with_unit(file, model, unit_ns).map_err(|e| {
        if unit_ns.is_none() && e.contains("no known duration") {
            CliError::Input(format!(
                "{e}\nhint: give the length of one model step with --time-unit (for example \
                 --time-unit 100ms)"
            ))
        } else {
            CliError::Input(e)
        }
    })
}

/// Loads a robot model: the main file and everything it names, lowered and compiled; the
/// properties are the file given, else the first one the main file names.
fn load_robot(
    args: &ModelArgs,
    main: &Path,
    external: &[String],
) -> Result<(Loaded, Vec<ExternalComponent>), CliError> {
    use crate::robot::main_file::InputKind;
    let search = crate::robot::interfaces::Search::from_env(args.interfaces.clone());
    let (robot, external) = crate::robot::load::load_searching(main, external, &search)
        .map_err(|d| CliError::Input(d.to_string()))?;
    for w in &robot.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(text) = &args.time_unit {
        let given = parse_time_unit(text)?;
        if given != robot.time_unit_ns {
            return Err(CliError::Input(format!(
                "--time-unit {text}: {} steps by {}, from its timers and max_time",
                main.display(),
                super::sweep::BoundValue::Nanos(robot.time_unit_ns).display()
            )));
        }
    }
    let props_path = match (&args.props, robot.main.properties.first()) {
        (Some(p), _) => p.clone(),
        (None, Some(input)) => {
            if input.kind == InputKind::Hspec {
                return Err(CliError::Input(format!(
                    "{}: an .hspec file names no messages of the model; write the \
                     properties over ROS names (XML) or give them on the command line",
                    input.path.display()
                )));
            }
            input.path.clone()
        }
        (None, None) => {
            return Err(CliError::Input(format!(
                "{}: the main file names no property file; give one after the model",
                main.display()
            )))
        }
    };
    let file = read_properties(&props_path, &robot.model, args)?;
    let set = compile_properties(&file, &robot.model, Some(robot.time_unit_ns))?;
    Ok((
        Loaded {
            model: robot.model,
            file,
            set,
            props_path,
            unit_ns: Some(robot.time_unit_ns),
            default_max_time: Some(robot.max_time_steps),
            // The lowering is AS2FM's translation; its sends mean what AS2FM's JANI means.
            events: args.events.map_or(EventSemantics::As2fm, Into::into),
        },
        external,
    ))
}

/// Runs a study of `set` on `model`: the function `verify` and `sweep` share.
pub fn study(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    show_progress: bool,
) -> Result<StudyResult, CliError> {
    let rules = set
        .guarantee_names()
        .iter()
        .map(|_| rule.build())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::Input(format!("statistics: {e}")))?;
    let runner = Runner::new(model, set, run_cfg);
    let mut bar = if show_progress {
        TerminalProgress::stderr()
    } else {
        TerminalProgress::hidden()
    };
    let result = run_study(study_cfg, &rules, |k, rng| runner.run(k, rng), &mut |p| {
        bar.update(p)
    });
    runner.finish()?;
    Ok(result)
}

/// Runs one simulation with its judge: the run function every study shares.
///
/// Simulators and judges are pooled and reused across runs (no allocation per step);
/// the first model failure (a spin, a run-time error) is kept and ends the study.
pub struct Runner<'m> {
    model: &'m CompiledModel,
    set: &'m PropertySet,
    run_cfg: &'m RunConfig,
    pool: Mutex<Vec<(Simulator<'m>, Judge<'m>)>>,
    failure: Mutex<Option<String>>,
}

impl<'m> Runner<'m> {
    /// A runner for `model` judged by `set`.
    pub fn new(model: &'m CompiledModel, set: &'m PropertySet, run_cfg: &'m RunConfig) -> Self {
        Runner {
            model,
            set,
            run_cfg,
            pool: Mutex::new(Vec::new()),
            failure: Mutex::new(None),
        }
    }

    /// Run `k` with its stream.
    pub fn run(&self, k: u64, rng: &mut Xoshiro256PlusPlus) -> RunOutcome {
        let popped = self.pool.lock().ok().and_then(|mut p| p.pop());
        let (mut sim, mut judge) = match popped {
            Some(pair) => pair,
            None => (
                Simulator::new(self.model),
                Judge::new(self.set).expect("validated program"),
            ),
        };
        let unknown = |end| RunOutcome {
            verdicts: Vec::new(),
            assumptions: Verdict::Unknown,
            end,
            steps: 0,
            time: 0,
        };
        let outcome = if judge.start() == crate::sim::Flow::Stop && judge.error.is_some() {
            unknown(RunEnd::Failed)
        } else {
            let out = sim.run(rng, self.run_cfg, &mut judge);
            let end = match &out.end {
                EndReason::Quiescent => Some(RunEnd::Quiescent),
                EndReason::MaxTime => Some(RunEnd::TimeHorizon),
                EndReason::MaxSteps => Some(RunEnd::StepLimit),
                EndReason::Stopped => Some(RunEnd::Decided),
                EndReason::Spin(s) => {
                    record(&self.failure, format!("run {k}: {s}"));
                    None
                }
                EndReason::Error(e) => {
                    record(&self.failure, format!("run {k}: {e}"));
                    None
                }
            };
            if let Some(err) = &judge.error {
                record(&self.failure, format!("run {k}: {err}"));
            }
            match end {
                Some(end) if judge.error.is_none() => judge.outcome(end, out.steps, out.time),
                _ => unknown(RunEnd::Failed),
            }
        };
        if let Ok(mut p) = self.pool.lock() {
            p.push((sim, judge));
        }
        outcome
    }

    /// The first model failure any run met, as a bad-input error.
    pub fn finish(self) -> Result<(), CliError> {
        match self.failure.into_inner().ok().flatten() {
            Some(msg) => Err(CliError::Input(format!(
                "the model failed during simulation: {msg}"
            ))),
            None => Ok(()),
        }
    }
}

/// FNV-1a over bytes: a stable fingerprint so `merge` can refuse mixed studies.
fn fingerprint(parts: &[&[u8]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in parts {
        for b in p.iter().chain(&[0xff]) {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

#[allow(clippy::too_many_arguments)]
fn run_shard_cli(
    args: &VerifyArgs,
    model: &CompiledModel,
    set: &PropertySet,
    props_path: &Path,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    shard: crate::smc::shard::Shard,
    runs: u64,
) -> Result<(), CliError> {
    use crate::smc::shard::{run_shard, FixedStudy, PropertySpec};
    let props_text = std::fs::read(props_path).unwrap_or_default();
    let model_desc = format!(
        "{} machines, {} events, max_time {}, max_steps {}",
        model.machine_count(),
        model.event_count(),
        run_cfg.max_time,
        run_cfg.max_steps
    );
    let fixed = FixedStudy {
        seed: args.seed,
        study_runs: runs,
        model: format!("{} ({model_desc})", fingerprint(&[model_desc.as_bytes()])),
        properties_fingerprint: fingerprint(&[&props_text]),
        properties: set
            .guarantee_names()
            .iter()
            .map(|id| PropertySpec {
                id: id.clone(),
                rule: *rule,
            })
            .collect(),
    };
    let runner = Runner::new(model, set, run_cfg);
    let mut bar = TerminalProgress::stderr();
    let part = run_shard(
        study_cfg,
        &fixed,
        shard,
        |k, rng| runner.run(k, rng),
        &mut |p| bar.update(p),
    );
    runner.finish()?;
    let json = part.to_json();
    match &args.partial {
        Some(p) => std::fs::write(p, json)
            .map_err(|e| CliError::Failed(format!("{}: {e}", p.display())))?,
        None => println!("{json}"),
    }
    Ok(())
}

/// Arguments of `hindsight merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Partial results written by `verify --shard I/N --runs R`, one per shard.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `hindsight merge`: checks the parts cover one study exactly once, then reports it.
pub fn merge(args: &MergeArgs) -> Result<(), CliError> {
    use crate::smc::shard::{merge, PartialResult};
    let mut parts = Vec::new();
    for p in &args.parts {
        let text = super::read_file(p)?;
        parts.push(
            PartialResult::from_json(&text)
                .map_err(|e| CliError::Input(format!("{}: {e}", p.display())))?,
        );
    }
    let m = merge(&parts, 0).map_err(|e| CliError::Input(format!("merge: {e}")))?;
    let report = Report {
        model: m.study.model.clone(),
        properties_file: m.study.properties_fingerprint.clone(),
        seed: m.study.seed,
        confidence: m.properties.first().map_or(0.0, |p| p.rule.confidence),
        precision: m.properties.first().map_or(0.0, |p| p.rule.precision),
        runs: m.runs.runs,
        discarded: m.runs.discarded,
        time_horizon: m.runs.time_horizon,
        step_limit: m.runs.step_limit,
        decided: m.runs.decided,
        quiescent: m.runs.quiescent,
        seconds: 0.0,
        step_seconds: None,
        max_time_seconds: None,
        properties: m
            .properties
            .iter()
            .map(|p| PropertyReport::new(&p.id, &p.estimate, &p.interval, &p.counts))
            .collect(),
    };
    print_report(&report, args.json)
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
    #[arg(long, default_value_t = 100_000_000)]
    pub max_steps: u64,
    /// Output CSV file; standard output when absent.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Runs `hindsight trace`: one run of the study, every point as CSV.
pub fn trace(args: &TraceArgs) -> Result<(), CliError> {
    let loaded = load(&args.input)?;
    let (model, set) = (&loaded.model, &loaded.set);
    let run_cfg = RunConfig {
        max_time: loaded.max_time(args.max_time.as_deref())?,
        max_steps: args.max_steps,
        events: loaded.events,
        ..RunConfig::default()
    };
    let csv = replay_csv(model, set, &run_cfg, args.seed, args.run)?;
    match &args.output {
        Some(p) => {
            std::fs::write(p, csv).map_err(|e| CliError::Failed(format!("{}: {e}", p.display())))?
        }
        None => print!("{csv}"),
    }
    Ok(())
}

/// Replays run `k` of a study with `seed` and returns its CSV (see `verify::record`).
fn replay_csv(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    k: u64,
) -> Result<String, CliError> {
    let mut judge = Judge::new(set).map_err(CliError::Failed)?;
    let mut rec = crate::verify::record::Recorder::new(&mut judge, model);
    rec.start();
    let mut rng = crate::smc::runner::stream(seed, k);
    Simulator::new(model).run(&mut rng, run_cfg, &mut rec);
    Ok(rec.csv)
}

/// Replays each kept failing run (run k is stream k of the seed) and writes its CSV.
fn save_failing(
    args: &VerifyArgs,
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    result: &StudyResult,
) -> Result<(), CliError> {
    let io = |e: std::io::Error| CliError::Failed(format!("{}: {e}", args.out.display()));
    std::fs::create_dir_all(&args.out).map_err(io)?;
    for (name, p) in set.guarantee_names().iter().zip(&result.properties) {
        for &k in &p.failing_runs {
            let csv = replay_csv(model, set, run_cfg, args.seed, k)?;
            let path = args.out.join(format!("{name}-run{k}.csv"));
            std::fs::write(&path, csv).map_err(io)?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn record(slot: &Mutex<Option<String>>, msg: String) {
    if let Ok(mut s) = slot.lock() {
        s.get_or_insert(msg);
    }
}

/// Runs `hindsight verify`.
pub fn run(args: &VerifyArgs) -> Result<(), CliError> {
    let loaded = load(&args.input)?;
    let (model, set, props_path) = (&loaded.model, &loaded.set, &loaded.props_path);
    let rule = RuleConfig {
        kind: match (args.threshold, args.rule) {
            (Some(threshold), _) => RuleKind::Sprt { threshold },
            (None, Rule::Adaptive) => RuleKind::Adaptive,
            (None, Rule::Okamoto) => RuleKind::Okamoto,
            (None, Rule::Wilson) => RuleKind::Wilson,
            (None, Rule::ClopperPearson) => RuleKind::ClopperPearson,
        },
        confidence: args.confidence,
        precision: args.precision,
    };
    let run_cfg = RunConfig {
        max_time: loaded.max_time(args.max_time.as_deref())?,
        max_steps: args.max_steps,
        events: loaded.events,
        ..RunConfig::default()
    };
    let study_cfg = StudyConfig {
        seed: args.seed,
        threads: args.threads,
        max_runs: args.max_runs,
        keep_failing: args.save_failing,
        progress_every: Duration::from_millis(200),
    };
    if let (Some(shard), Some(runs)) = (args.shard, args.runs) {
        return run_shard_cli(
            args, model, set, props_path, &run_cfg, &study_cfg, &rule, shard, runs,
        );
    }
    let result = study(model, set, &run_cfg, &study_cfg, &rule, !args.json)?;
    if args.save_failing > 0 {
        save_failing(args, model, set, &run_cfg, &result)?;
    }
    let mut report = report(args, props_path, set, &result);
    if let Some(unit) = loaded.unit_ns {
        report.step_seconds = Some(unit as f64 / 1e9);
        report.max_time_seconds = Some(run_cfg.max_time as f64 * unit as f64 / 1e9);
    }
    print_report(&report, args.json)
}

fn report(args: &VerifyArgs, props: &Path, set: &PropertySet, r: &StudyResult) -> Report {
    Report {
        step_seconds: None,
        max_time_seconds: None,
        model: args.input.model.display().to_string(),
        properties_file: props.display().to_string(),
        seed: args.seed,
        confidence: args.confidence,
        precision: args.precision,
        runs: r.runs.runs,
        discarded: r.runs.discarded,
        time_horizon: r.runs.time_horizon,
        step_limit: r.runs.step_limit,
        decided: r.runs.decided,
        quiescent: r.runs.quiescent,
        seconds: r.elapsed.as_secs_f64(),
        properties: set
            .guarantee_names()
            .iter()
            .zip(&r.properties)
            .map(|(name, p)| PropertyReport::new(name, &p.estimate, &p.interval, &p.counts))
            .collect(),
    }
}

/// Prints a report as JSON or as the table.
fn print_report(report: &Report, json: bool) -> Result<(), CliError> {
    if json {
        let text = serde_json::to_string_pretty(report)
            .map_err(|e| CliError::Failed(format!("json: {e}")))?;
        println!("{text}");
    } else {
        print_table(report);
    }
    Ok(())
}

fn print_table(r: &Report) {
    let w = r
        .properties
        .iter()
        .map(|p| p.property.len())
        .max()
        .unwrap_or(8)
        .max(8);
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

/// Runs `hindsight validate`: loads and compiles, prints a one-line summary.
pub fn validate(args: &ValidateArgs) -> Result<(), CliError> {
    let loaded = load(&args.input)?;
    let (model, set, props_path) = (&loaded.model, &loaded.set, &loaded.props_path);
    println!(
        "{}: {} machines, {} events; {}: {} guarantees, monitor state {} bytes: ok",
        args.input.model.display(),
        model.machine_count(),
        model.event_count(),
        props_path.display(),
        set.guarantee_names().len(),
        set.compiled().state_bytes()
    );
    Ok(())
}
