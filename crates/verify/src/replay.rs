//! Runs of a study replayed one at a time, each as the CSV [`crate::record`] writes:
//! [`replay_csv`] for `trace` (run k of a seed is stream k, whatever ran before it), the
//! failing runs a study kept for `--save-failing` and `--report` ([`failing_runs`],
//! [`save`]) and, under `--schedulers`, a failing run under each order-sensitive
//! property's witness (`witness_runs`); [`Replay`] is what a study's JSON records of how
//! its model ran, from which [`scheduler_runs`] replays it under any scheduler (`report
//! --study FILE --scheduler ID`); [`play_run`] plays one run to an observer of
//! the caller's (`hindsight run` paces it in wall-clock time). Nothing here prints: the files written come
//! back as values.
//!
//! ```
//! use hindsight_verify::load::{load, LoadOptions};
//! use hindsight_verify::replay::{file_stem, replay_csv};
//! use hindsight_verify::sim::RunConfig;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/museum-scxml");
//! let loaded = load(&LoadOptions { model: dir.into(), ..LoadOptions::default() }).unwrap();
//! let run_cfg = RunConfig { max_time: 200, events: loaded.events, ..RunConfig::default() };
//! let (csv, _) = replay_csv(&loaded.model, &loaded.set, &run_cfg, 1, 3).unwrap();
//! // The same run twice is the same text; its header names time and step first.
//! assert_eq!(csv, replay_csv(&loaded.model, &loaded.set, &run_cfg, 1, 3).unwrap().0);
//! assert!(csv.starts_with("time,step,"));
//! // A property id as a file name never leaves the folder.
//! assert_eq!(file_stem("../etc/x"), "_._etc_x");
//! ```

use std::path::{Path, PathBuf};

use crate::observe::{Judge, JudgeError, PropertySet};
use crate::record::{Culprit, Recorder};
use crate::result::Study;
// What a played run reports to and how it ends, as callers name them.
use crate::sim::{
    BadScheduler, CompiledModel, EndReason, EventSemantics, Quiescence, RunConfig, Scheduler,
    Simulator,
};
pub use crate::sim::{Observer, RunOutcome};
use crate::smc::StudyResult;

/// One failing run replayed: its property, run index, file name and CSV.
#[derive(Clone, Debug)]
pub struct Failing {
    /// The property it was kept for.
    pub property: String,
    /// Its index in the study.
    pub run: u64,
    /// The file it is written to (`--save-failing`), or, for a run that is only shown,
    /// what names it on the page.
    pub file: String,
    /// The CSV text.
    pub csv: String,
    /// Per property that turned false: the subformula that explains it, and its value.
    pub culprits: Vec<Culprit>,
}

/// Why a run could not be replayed.
#[derive(Clone, Debug)]
pub enum ReplayError {
    /// The monitors refused the compiled program (a bug, not bad input).
    Judge(JudgeError),
    /// A witness in the study names no scheduler.
    Witness(BadScheduler),
}

impl std::fmt::Display for ReplayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReplayError::Judge(e) => write!(f, "{e}"),
            ReplayError::Witness(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ReplayError {}

impl From<JudgeError> for ReplayError {
    fn from(e: JudgeError) -> Self {
        ReplayError::Judge(e)
    }
}

/// Replays run `k` like [`replay_csv`] and returns its CSV with how the run ended
/// ([`how_it_ended`] words it): `trace`'s two outputs.
pub fn trace_run(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    k: u64,
) -> Result<(String, RunOutcome), JudgeError> {
    replayed(model, set, run_cfg, seed, k).map(|r| (r.csv, r.out))
}

/// How a run ended, in words, its time also in seconds when the model's step is known
/// (`unit_ns`). A robot model's run that went quiet before the horizon is a deadlock (its
/// global timer runs until `max_time`); a plain model's may have stopped its own timer.
pub fn how_it_ended(out: &RunOutcome, unit_ns: Option<u64>) -> String {
    let at = match unit_ns {
        Some(u) => format!(
            "time {} ({})",
            out.time,
            codegen::duration::seconds(out.time.saturating_mul(u))
        ),
        None => format!("time {}", out.time),
    };
    let steps = out.steps;
    match &out.end {
        EndReason::Quiescent => format!(
            "went quiet at {at} after {steps} steps, before the time horizon: nothing could \
             move and no timer was pending"
        ),
        EndReason::MaxTime => format!("reached the time horizon, {at}, after {steps} steps"),
        EndReason::MaxSteps => {
            format!("was cut at the step limit, {steps} steps, at {at} (raise --max-steps)")
        }
        EndReason::Stopped => format!("stopped at {at} after {steps} steps"),
        EndReason::Spin(s) => format!("stopped at {at} after {steps} steps: {s}"),
        EndReason::Error(e) => format!("failed at {at} after {steps} steps: {e}"),
    }
}

/// Replays run `k` of a study with `seed` and returns its CSV (see [`crate::record`])
/// and, per property that turned false, the subformula that explains it.
pub fn replay_csv(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    k: u64,
) -> Result<(String, Vec<Culprit>), JudgeError> {
    replayed(model, set, run_cfg, seed, k).map(|r| (r.csv, r.culprits))
}

/// Run `k` of `seed` replayed: its CSV and culprits, and the judge and outcome it ended
/// with (whether it fails a property: [`run_fails`]).
struct Replayed<'s> {
    csv: String,
    culprits: Vec<Culprit>,
    judge: Judge<'s>,
    out: RunOutcome,
}

/// The one replay of a run behind [`replay_csv`] and the failing-run searches.
fn replayed<'s>(
    model: &'s CompiledModel,
    set: &'s PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    k: u64,
) -> Result<Replayed<'s>, JudgeError> {
    let mut judge = Judge::new(set)?;
    let (csv, culprits, out) = {
        let mut rec = Recorder::new(&mut judge, model);
        rec.start();
        let mut rng = crate::smc::runner::stream(seed, k);
        let out = Simulator::new(model).run(&mut rng, run_cfg, &mut rec);
        (rec.csv, rec.culprits, out)
    };
    Ok(Replayed {
        csv,
        culprits,
        judge,
        out,
    })
}

/// Plays run `k` of a study with `seed` (the run `verify --seed` numbers `k`: the same
/// choices) once, up to model time `max_time` under `events`, reporting every point to
/// `observer`. Time advances when no machine can move (the run waits for its next timer,
/// or for what `observer` posts into it), as a system running in real time does.
pub fn play_run<O: Observer + ?Sized>(
    model: &CompiledModel,
    events: EventSemantics,
    max_time: u64,
    (seed, k): (u64, u64),
    observer: &mut O,
) -> RunOutcome {
    let cfg = RunConfig {
        max_time,
        events,
        quiescence: Quiescence::AdvanceTime,
        ..RunConfig::default()
    };
    let mut rng = crate::smc::runner::stream(seed, k);
    Simulator::new(model).run(&mut rng, &cfg, observer)
}

/// Why a played run ended, as `hindsight run` says it: `reached the duration` at its
/// `max_time`, else the simulator's reason.
pub fn end_text(end: &EndReason) -> String {
    match end {
        EndReason::MaxTime => "reached the duration".to_string(),
        EndReason::Quiescent => "went quiet: nothing could move and no timer was pending".into(),
        EndReason::MaxSteps => "was cut at the step limit".to_string(),
        EndReason::Stopped => "was stopped".to_string(),
        EndReason::Spin(s) => s.to_string(),
        EndReason::Error(e) => e.to_string(),
    }
}

/// `id` as a file name: ids are checked where declared (`props::is_valid_id`), so this
/// changes nothing for them; any other character (a name from elsewhere) becomes `_`,
/// and a leading `.` too, so no name is a path (`../x`, `/etc/x`) or a hidden file.
pub fn file_stem(id: &str) -> String {
    let stem: String = id
        .chars()
        .enumerate()
        .map(|(i, c)| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '_' | '-' => c,
            '.' if i > 0 => c,
            _ => '_',
        })
        .take(crate::props::MAX_ID_LEN)
        .collect();
    if stem.is_empty() {
        "property".to_owned()
    } else {
        stem
    }
}

/// Replays each failing run `result` kept (run k is stream k of `seed`), each named
/// `out/PROPERTY-runK.csv`; [`save`] writes them.
pub fn failing_runs(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    result: &StudyResult,
    out: &Path,
) -> Result<Vec<Failing>, JudgeError> {
    let mut kept = Vec::new();
    for (name, p) in set.guarantee_names().iter().zip(&result.properties) {
        for &k in &p.failing_runs {
            let (csv, culprits) = replay_csv(model, set, run_cfg, seed, k)?;
            let path = out.join(format!("{}-run{k}.csv", file_stem(name)));
            kept.push(Failing {
                property: name.clone(),
                run: k,
                file: path.display().to_string(),
                csv,
                culprits,
            });
        }
    }
    Ok(kept)
}

/// Writes each of `failing` (from [`failing_runs`]) to its file, creating `out` first;
/// returns the files written, in order.
pub fn save(out: &Path, failing: &[Failing]) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out)?;
    let mut written = Vec::new();
    for f in failing {
        let path = PathBuf::from(&f.file);
        std::fs::write(&path, &f.csv)?;
        written.push(path);
    }
    Ok(written)
}

/// Runs searched for a failing one under each scheduler (`witness_runs`).
pub(crate) const SEARCH: u64 = 500;

/// For `--report` with `--schedulers`: per order-sensitive property of `study`, the first
/// failing run of `seed` under its minimising witness and the first under the uniform
/// scheduler, one after the other, named by their scheduler, so that the page shows how
/// the witness's order fails the property beside how a uniformly random one does.
/// `verify --scheduler ID --save-failing 1` writes the same runs (run k is stream k of
/// the seed whatever the scheduler). A scheduler with no failing run among the first
/// [`SEARCH`] adds none.
pub(crate) fn witness_runs(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    study: &Study,
) -> Result<Vec<Failing>, ReplayError> {
    let mut out = Vec::new();
    for (row, b) in study.scheduler_rows() {
        if !b.order_sensitive {
            continue;
        }
        let min: Scheduler = b.min.scheduler.parse().map_err(ReplayError::Witness)?;
        for (label, scheduler) in [
            (format!("min witness {min}"), min),
            ("uniform scheduler".to_string(), Scheduler::Uniform),
        ] {
            let cfg = RunConfig {
                scheduler,
                ..run_cfg.clone()
            };
            out.extend(first_failing(
                model,
                set,
                &cfg,
                seed,
                &row.property,
                &label,
            )?);
        }
    }
    Ok(out)
}

/// The first failing run of `property` among the first [`SEARCH`] runs of `seed` under
/// `run_cfg`, named "PROPERTY under the LABEL, run K" (`None`: none fails). A run fails it
/// as the study judges runs ([`run_fails`]), not where its verdict was false at some point.
fn first_failing(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    property: &str,
    label: &str,
) -> Result<Option<Failing>, ReplayError> {
    let Some(p) = set.guarantee_names().iter().position(|n| n == property) else {
        return Ok(None);
    };
    for k in 0..SEARCH {
        let r = replayed(model, set, run_cfg, seed, k)?;
        if run_fails(&r.judge, &r.out, p) {
            return Ok(Some(Failing {
                property: property.to_string(),
                run: k,
                file: format!("{property} under the {label}, run {k}"),
                csv: r.csv,
                culprits: r.culprits,
            }));
        }
    }
    Ok(None)
}

/// Whether a run that ended as `out`, judged by `judge`, fails guarantee `p` as a study
/// counts it (`study.rs`, `Runner::run_under`): its verdict false at the last point (or
/// final before), its assumptions not false. A run that ended in an error, a spin or with
/// the judge failing is not judged, so it fails nothing (a sampled scheduler's run that
/// blocks time is left out, as a study leaves it out without `--keep-unfair`).
fn run_fails(judge: &Judge<'_>, out: &RunOutcome, p: usize) -> bool {
    use crate::smc::Verdict;
    let Some(end) = crate::study::judged_end(&out.end) else {
        return false;
    };
    if judge.error.is_some() {
        return false;
    }
    let judged = judge.outcome(end, out.steps, out.time);
    judged.verdicts.get(p) == Some(&Verdict::False) && judged.assumptions != Verdict::False
}

/// How a study's model was loaded and run, recorded in its JSON (`"replay"`) so that its
/// runs can be replayed from the file alone (`hindsight report --study FILE --scheduler
/// ID`): the model and property file as the study named them (relative to where it ran)
/// and every option that changes a run. A run replayed from it is the run the study made
/// (run k is stream k of the seed), the scheduler aside.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Replay {
    /// The model, as named.
    pub model: String,
    /// The property file read.
    pub properties: String,
    /// `--time-unit` in nanoseconds, when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_unit_ns: Option<u64>,
    /// How sends were delivered: `queues` or `as2fm`.
    pub events: String,
    /// The behavior tree's semantics (`--bt`): `as2fm`, `btcpp` or `btcpp-exactly-once`.
    pub bt: String,
    /// `--only`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub only: Vec<String>,
    /// `--skip`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skip: Vec<String>,
    /// `--interfaces`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub interfaces: Vec<String>,
    /// The run length in model steps.
    pub max_time: u64,
    /// The step limit of a run.
    pub max_steps: u64,
    /// The step limit of one instant.
    pub max_instant_steps: u64,
}

/// Why a study's runs cannot be replayed from its JSON.
#[derive(Debug)]
pub enum RerunError {
    /// The study records no `"replay"` (written by an older version).
    NotRecorded,
    /// The recorded settings name an option value this version does not know.
    Setting(String),
    /// The model the study names is not there (paths are relative to where it ran).
    Missing(String),
    /// The model or its properties no longer load.
    Load(crate::load::LoadError),
    /// A run could not be replayed.
    Replay(ReplayError),
}

impl std::fmt::Display for RerunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RerunError::NotRecorded => write!(
                f,
                "the study does not record how its model was run (it has no \"replay\": it \
                 was written by an older version); replay with `verify MODEL --scheduler ID \
                 --report FILE` instead"
            ),
            RerunError::Setting(m) => write!(f, "the study's \"replay\": {m}"),
            RerunError::Missing(m) => write!(
                f,
                "the study's model `{m}` is not found from here: the study names it as \
                 `verify` was given it, so run `report` in the folder `verify` ran in"
            ),
            RerunError::Load(e) => write!(f, "{e}"),
            RerunError::Replay(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RerunError {}

impl Replay {
    /// The settings of a study of `loaded` run with `run_cfg`, its model named `model`.
    pub fn of(loaded: &crate::load::Loaded, model: &Path, run_cfg: &RunConfig) -> Replay {
        let o = &loaded.options;
        let names = |v: &[PathBuf]| v.iter().map(|p| p.display().to_string()).collect();
        Replay {
            model: model.display().to_string(),
            properties: loaded.props_path.display().to_string(),
            time_unit_ns: o.time_unit_ns,
            events: loaded.events.label().to_string(),
            bt: o.bt.label().to_string(),
            only: o.only.clone(),
            skip: o.skip.clone(),
            interfaces: names(&o.interfaces),
            max_time: run_cfg.max_time,
            max_steps: run_cfg.max_steps,
            max_instant_steps: run_cfg.max_steps_per_instant,
        }
    }

    /// The load options these settings name.
    pub fn load_options(&self) -> Result<crate::load::LoadOptions, RerunError> {
        let events = EventSemantics::from_label(&self.events)
            .ok_or_else(|| RerunError::Setting(format!("unknown events `{}`", self.events)))?;
        let bt = crate::robot::bt::BtSemantics::from_label(&self.bt)
            .ok_or_else(|| RerunError::Setting(format!("unknown bt `{}`", self.bt)))?;
        Ok(crate::load::LoadOptions {
            model: PathBuf::from(&self.model),
            props: Some(PathBuf::from(&self.properties)),
            time_unit_ns: self.time_unit_ns,
            events: Some(events),
            only: self.only.clone(),
            skip: self.skip.clone(),
            interfaces: self.interfaces.iter().map(PathBuf::from).collect(),
            bt,
            props_optional: false,
        })
    }

    /// The run configuration these settings name, under `scheduler`.
    pub fn run_config(&self, events: EventSemantics, scheduler: Scheduler) -> RunConfig {
        RunConfig {
            max_time: self.max_time,
            max_steps: self.max_steps,
            max_steps_per_instant: self.max_instant_steps,
            events,
            scheduler,
            ..RunConfig::default()
        }
    }
}

/// Whether the study saw `row`'s property fail: in a judged run, or under the witness of
/// its smallest probability over schedulers. [`scheduler_runs`] searches only those: a
/// search that finds nothing replays 500 runs per scheduler.
fn seen_failing(row: &crate::result::PropertyRow) -> bool {
    let min_fails = row
        .schedulers
        .as_ref()
        .is_some_and(|b| b.min.successes < b.min.runs);
    row.successes < row.runs || min_fails
}

/// What `hindsight report --study FILE --scheduler ID` shows: the study's model loaded
/// again from its recorded settings, and per guarantee the study saw fail (in a judged run
/// or under its minimising witness) the first failing run (among the first 500 of its
/// seed) under `scheduler` and, when that is not the uniform scheduler, the first under
/// the uniform one beside it. A property that no run fails under either adds nothing.
/// Returns the model as loaded (its warnings are the caller's to print) and the runs;
/// `searching` is told each property and scheduler label before its search starts (a
/// search replays up to 500 runs: a progress line for the caller).
pub fn scheduler_runs(
    study: &Study,
    scheduler: Scheduler,
    searching: &mut dyn FnMut(&str, &str),
) -> Result<(crate::load::Loaded, Vec<Failing>), RerunError> {
    let settings = study.replay.as_ref().ok_or(RerunError::NotRecorded)?;
    if !Path::new(&settings.model).exists() {
        return Err(RerunError::Missing(settings.model.clone()));
    }
    let loaded = crate::load::load(&settings.load_options()?).map_err(RerunError::Load)?;
    let mut runs = Vec::new();
    let mut schedulers = vec![(format!("scheduler {scheduler}"), scheduler)];
    if scheduler != Scheduler::Uniform {
        schedulers.push(("uniform scheduler".to_string(), Scheduler::Uniform));
    }
    for row in study.properties.iter().filter(|r| seen_failing(r)) {
        for (label, s) in &schedulers {
            searching(&row.property, label);
            let cfg = settings.run_config(loaded.events, *s);
            let found = first_failing(
                &loaded.model,
                &loaded.set,
                &cfg,
                study.seed,
                &row.property,
                label,
            )
            .map_err(RerunError::Replay)?;
            runs.extend(found);
        }
    }
    Ok((loaded, runs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{load, LoadOptions};

    fn museum() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/museum-scxml")
    }

    #[test]
    fn recorded_settings_load_the_same_model_and_run_the_same_runs() {
        let opts = LoadOptions {
            model: museum(),
            time_unit_ns: Some(100_000_000),
            events: Some(EventSemantics::As2fm),
            skip: vec!["absence".into()],
            ..LoadOptions::default()
        };
        let loaded = load(&opts).unwrap();
        let run_cfg = RunConfig {
            max_time: 300,
            max_steps: 50_000,
            max_steps_per_instant: 4_000,
            events: loaded.events,
            ..RunConfig::default()
        };
        let recorded = Replay::of(&loaded, &opts.model, &run_cfg);
        let text = serde_json::to_string(&recorded).unwrap();
        let back: Replay = serde_json::from_str(&text).unwrap();
        assert_eq!(back, recorded);
        let again = load(&back.load_options().unwrap()).unwrap();
        assert_eq!(again.events, EventSemantics::As2fm);
        assert_eq!(again.unit_ns, Some(100_000_000));
        assert_eq!(again.set.guarantee_names(), loaded.set.guarantee_names());
        let cfg = back.run_config(again.events, Scheduler::Uniform);
        assert_eq!(
            (cfg.max_time, cfg.max_steps, cfg.max_steps_per_instant),
            (300, 50_000, 4_000)
        );
        // The same run, to the byte.
        let before = replay_csv(&loaded.model, &loaded.set, &run_cfg, 7, 2).unwrap();
        let after = replay_csv(&again.model, &again.set, &cfg, 7, 2).unwrap();
        assert_eq!(before.0, after.0);
    }

    #[test]
    fn every_semantics_reads_back_from_its_label() {
        use crate::robot::bt::{BtSemantics, BtTick};
        for e in [EventSemantics::Queues, EventSemantics::As2fm] {
            assert_eq!(EventSemantics::from_label(e.label()), Some(e));
        }
        for tick in [BtTick::Once, BtTick::ExactlyOnce] {
            let b = BtSemantics::Btcpp { tick };
            assert_eq!(BtSemantics::from_label(b.label()), Some(b));
        }
        assert_eq!(BtSemantics::from_label("as2fm"), Some(BtSemantics::As2fm));
        assert_eq!(BtSemantics::from_label("btcpp4"), None);
    }

    #[test]
    fn unknown_recorded_values_are_refused_by_name() {
        let base = Replay {
            model: museum().display().to_string(),
            properties: "p.xml".into(),
            events: "queues".into(),
            bt: "as2fm".into(),
            ..Replay::default()
        };
        for (events, bt, says) in [
            ("fifo", "as2fm", "events `fifo`"),
            ("queues", "bt4", "bt `bt4`"),
        ] {
            let r = Replay {
                events: events.into(),
                bt: bt.into(),
                ..base.clone()
            };
            let e = r.load_options().unwrap_err().to_string();
            assert!(e.contains(says), "{e}");
        }
        assert!(base.load_options().is_ok());
    }
}
