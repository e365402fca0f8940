//! One `verify` from its settings to its result, in the order its parts run: the study
//! itself (sequential under the stopping rule, or a fixed number of runs, whole or one
//! shard, with or without sampled schedulers), the failing runs it kept, the bounds over
//! schedulers, and the witnesses' failing runs for the report page.
//!
//! The command line fills a [`Request`], calls [`verify`] (or [`verify_both`] for `--bt
//! both`) and prints what comes back; it orders nothing itself. Nothing here prints:
//! progress is an [`Event`] given to a callback, files written come back as their paths,
//! and what an interruption left out comes back as [`Verified::left_out`].
//!
//! A fixed-size study of the museum example, in a dozen lines:
//!
//! ```
//! use std::sync::atomic::AtomicBool;
//! use hindsight_verify::load::{load, LoadOptions};
//! use hindsight_verify::options::VerifyOptions;
//! use hindsight_verify::pipeline::{verify, Outcome, Request};
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/museum-scxml");
//! let loaded = load(&LoadOptions { model: dir.into(), ..LoadOptions::default() }).unwrap();
//! let opts = VerifyOptions { seed: 3, threads: 1, max_time: Some("300".into()), ..VerifyOptions::default() };
//! let request = Request { runs: Some(20), ..Request::new(&loaded, dir.as_ref(), &opts) };
//! let Outcome::Study(done) = verify(&request, &mut |_| {}, &AtomicBool::new(false)).unwrap() else {
//!     unreachable!("not a shard")
//! };
//! assert_eq!(done.study.runs, 20);
//! assert_eq!(done.study.properties.len(), loaded.set.guarantee_names().len());
//! ```

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use crate::fixed::fixed_study;
use crate::load::{Loaded, MaxTimeError};
use crate::observe::JudgeError;
use crate::options::VerifyOptions;
use crate::replay::{failing_runs, save, witness_runs, Failing, Replay, ReplayError};
use crate::result::{PropertyRow, Study};
use crate::sched_fixed::{run_all, run_stage, Choices, Plan, StageError};
use crate::schedulers::{bounds, BoundsError, Stage};
use crate::sim::RunConfig;
use crate::smc::shard::{merge, Shard, ShardError};
use crate::smc::{Progress, StudyConfig};
use crate::study::{study_shard, study_until, StudyError};

/// What one `verify` is asked, beyond its [`VerifyOptions`].
#[derive(Clone)]
pub struct Request<'a> {
    /// The model and properties, loaded.
    pub loaded: &'a Loaded,
    /// The model as the user named it (the result names it so).
    pub model: &'a Path,
    /// The study's settings.
    pub opts: &'a VerifyOptions,
    /// The behavior tree's semantics, named in the result's settings (`None`: AS2FM's,
    /// the default, not named).
    pub bt_label: Option<&'static str>,
    /// A fixed-size study of this many runs (`--runs`); `None`: sequential.
    pub runs: Option<u64>,
    /// Only this shard of the fixed-size study (`--shard`): the outcome is its part.
    pub shard: Option<Shard>,
    /// A fixed-size scheduler study's plan (`--plan`), to run its current stage.
    pub plan: Option<&'a Path>,
    /// Replay the failing runs the study kept, named under this folder
    /// (`--save-failing`, `--report`).
    pub failing_dir: Option<&'a Path>,
    /// Write those failing runs there (`--save-failing`).
    pub save_failing: bool,
    /// Also replay, per order-sensitive property, a failing run under its minimising
    /// witness and one under the uniform scheduler (`--report` with `--schedulers`).
    pub witnesses: bool,
}

impl<'a> Request<'a> {
    /// A sequential study of `loaded` with `opts`, nothing replayed.
    pub fn new(loaded: &'a Loaded, model: &'a Path, opts: &'a VerifyOptions) -> Self {
        Request {
            loaded,
            model,
            opts,
            bt_label: None,
            runs: None,
            shard: None,
            plan: None,
            failing_dir: None,
            save_failing: false,
            witnesses: false,
        }
    }
}

/// What a running `verify` reports, for a progress display.
pub enum Event<'a> {
    /// Runs of the study done so far.
    Runs(&'a Progress<'a>),
    /// A step of the bounds over schedulers (`--schedulers` of a sequential study).
    Bounds(Stage<'a>),
    /// A fixed-size scheduler study starts a stage: its number and how many run ranges.
    Stage {
        /// The stage.
        stage: u32,
        /// What it runs ([`Plan::stage_kind`]).
        kind: &'static str,
        /// Its run ranges.
        jobs: usize,
    },
}

/// What `verify` gives back.
#[derive(Debug)]
pub enum Outcome {
    /// The whole study.
    Study(Box<Verified>),
    /// One shard's part, as the JSON text `merge` reads (`--shard`).
    Part(String),
}

/// A whole study and what was replayed or written for it.
#[derive(Debug, Default)]
pub struct Verified {
    /// The result, as `verify --json` prints it.
    pub study: Study,
    /// The failing runs the study kept, replayed (with [`Request::failing_dir`]).
    pub failing: Vec<Failing>,
    /// The witnesses' failing runs (with [`Request::witnesses`]).
    pub witnesses: Vec<Failing>,
    /// The files written (with [`Request::save_failing`]).
    pub written: Vec<PathBuf>,
    /// What an interruption left out, one line each.
    pub left_out: Vec<&'static str>,
    /// Whether every run the study asked for was done (its failing runs, if asked, were
    /// replayed): false for a sequential study interrupted during its runs.
    pub runs_complete: bool,
}

impl Verified {
    /// The runs a report page shows: the kept failing runs, then the witnesses'.
    pub fn shown_runs(&self) -> Vec<Failing> {
        self.failing
            .iter()
            .chain(&self.witnesses)
            .cloned()
            .collect()
    }
}

/// Why a `verify` gave no result.
#[derive(Debug)]
pub enum VerifyError {
    /// The run length (`--max-time`) does not fit the model.
    MaxTime(MaxTimeError),
    /// The property file has no guarantee: nothing to estimate (bad input).
    NoGuarantee(PathBuf),
    /// The stopping rule, or the model during a run (bad input).
    Study(StudyError),
    /// The bounds over schedulers (bad input: their rule, or too few fair schedulers).
    Bounds(BoundsError),
    /// A stage of a fixed-size scheduler study, or its plan (bad input).
    Stage(StageError),
    /// Merging a fixed-size study's one part (bad input: `--runs`).
    Merge(ShardError),
    /// `--plan` cannot be read (bad input).
    Read(codegen::diag::Diagnostic),
    /// `--plan` is not a plan of this study (bad input).
    Plan(PathBuf, String),
    /// A kept run could not be replayed (not the input's fault).
    Replay(ReplayError),
    /// The failing runs could not be written (not the input's fault).
    Save(PathBuf, std::io::Error),
    /// A shard's part could not be written as JSON (not the input's fault).
    Json(String),
}

impl VerifyError {
    /// Whether the input is at fault (exit code 2) rather than the machine (1).
    pub fn is_input(&self) -> bool {
        !matches!(
            self,
            VerifyError::Replay(_) | VerifyError::Save(..) | VerifyError::Json(_)
        )
    }
}

impl std::fmt::Display for VerifyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VerifyError::MaxTime(e) => write!(f, "--max-time: {e}"),
            VerifyError::NoGuarantee(p) => write!(
                f,
                "{}: no guarantee to verify (a <property> under <guarantees>); \
                 assumptions alone estimate nothing",
                p.display()
            ),
            VerifyError::Study(e) => write!(f, "{e}"),
            VerifyError::Bounds(e @ BoundsError::Rule(_)) => write!(f, "--schedulers: {e}"),
            VerifyError::Bounds(e) => write!(f, "{e}"),
            VerifyError::Stage(e) => write!(f, "--schedulers: {e}"),
            VerifyError::Merge(e) => write!(f, "--runs: {e}"),
            VerifyError::Read(d) => write!(f, "{d}"),
            VerifyError::Plan(p, e) => write!(f, "{}: {e}", p.display()),
            VerifyError::Replay(e) => write!(f, "{e}"),
            VerifyError::Save(p, e) => write!(f, "{}: {e}", p.display()),
            VerifyError::Json(e) => write!(f, "json: {e}"),
        }
    }
}

impl std::error::Error for VerifyError {}

impl From<StudyError> for VerifyError {
    fn from(e: StudyError) -> Self {
        VerifyError::Study(e)
    }
}

impl From<BoundsError> for VerifyError {
    fn from(e: BoundsError) -> Self {
        VerifyError::Bounds(e)
    }
}

impl From<StageError> for VerifyError {
    fn from(e: StageError) -> Self {
        VerifyError::Stage(e)
    }
}

impl From<ReplayError> for VerifyError {
    fn from(e: ReplayError) -> Self {
        VerifyError::Replay(e)
    }
}

impl From<JudgeError> for VerifyError {
    fn from(e: JudgeError) -> Self {
        VerifyError::Replay(ReplayError::Judge(e))
    }
}

/// Runs what `request` asks, reporting progress to `event`; once `stop` is set, no run
/// starts (a sequential study returns what it has, marked interrupted).
pub fn verify(
    request: &Request<'_>,
    event: &mut dyn FnMut(Event<'_>),
    stop: &AtomicBool,
) -> Result<Outcome, VerifyError> {
    let (loaded, opts) = (request.loaded, request.opts);
    let run_cfg = opts.run_config(loaded).map_err(VerifyError::MaxTime)?;
    if loaded.set.guarantee_names().is_empty() {
        // A study would run and print an empty table (a fixed-size one with
        // "confidence 0", since no property carries the rule).
        return Err(VerifyError::NoGuarantee(loaded.props_path.clone()));
    }
    let study_cfg = opts.study_config();
    let Some(runs) = request.runs else {
        return sequential(request, &run_cfg, &study_cfg, event, stop)
            .map(|v| Outcome::Study(Box::new(v)));
    };
    let fixed = fixed_study(loaded, request.model, opts.seed, &run_cfg, &opts.rule, runs);
    let mut study = if let Some(sched) = &opts.schedulers {
        // A fixed-size scheduler study: one shard of one stage, or every stage here.
        let plan = match request.plan {
            Some(path) => {
                let text = codegen::diag::read_source(path).map_err(VerifyError::Read)?;
                let plan: Plan = serde_json::from_str(&text).map_err(|e| {
                    VerifyError::Plan(path.into(), format!("not a scheduler study's plan: {e}"))
                })?;
                plan.check(&fixed, sched)
                    .map_err(|e| VerifyError::Plan(path.into(), e.to_string()))?;
                plan
            }
            None => Plan::new(fixed, sched, Choices::of(&loaded.model, &run_cfg)),
        };
        if let Some(shard) = request.shard {
            let part = run_stage(
                &loaded.model,
                &loaded.set,
                &run_cfg,
                &study_cfg,
                &plan,
                shard,
            )?;
            let json =
                serde_json::to_string(&part).map_err(|e| VerifyError::Json(e.to_string()))?;
            return Ok(Outcome::Part(json));
        }
        let plan = run_all(
            &loaded.model,
            &loaded.set,
            &run_cfg,
            &study_cfg,
            plan,
            &mut |p: &Plan| {
                event(Event::Stage {
                    stage: p.stage,
                    kind: p.stage_kind(),
                    jobs: p.jobs.len(),
                })
            },
        )?;
        plan.study()?
    } else {
        // A fixed-size study: one shard of it, or all of it (shard 0/1) reported as
        // `merge` reports the shards of one, so both give the same numbers.
        let shard = request.shard.unwrap_or(Shard::WHOLE);
        let part = study_shard(
            &loaded.model,
            &loaded.set,
            &run_cfg,
            &study_cfg,
            &fixed,
            shard,
            &mut |p| event(Event::Runs(p)),
        )
        .map_err(|m| VerifyError::Study(StudyError::Model(m)))?;
        if request.shard.is_some() {
            return Ok(Outcome::Part(part.to_json()));
        }
        Study::merged(&merge(&[part], 0).map_err(VerifyError::Merge)?)
    };
    study.model = request.model.display().to_string();
    study.properties_file = loaded.props_path.display().to_string();
    // A fixed-size study keeps counts, not runs: nothing to replay.
    Ok(Outcome::Study(Box::new(Verified {
        study,
        runs_complete: true,
        ..Verified::default()
    })))
}

/// The sequential study: the runs, the failing ones replayed, the bounds, the witnesses.
fn sequential(
    request: &Request<'_>,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    event: &mut dyn FnMut(Event<'_>),
    stop: &AtomicBool,
) -> Result<Verified, VerifyError> {
    let (loaded, opts) = (request.loaded, request.opts);
    let (model, set) = (&loaded.model, &loaded.set);
    let result = study_until(
        model,
        set,
        run_cfg,
        study_cfg,
        &opts.rule,
        &mut |p| event(Event::Runs(p)),
        stop,
    )?;
    let mut done = Verified {
        runs_complete: !result.interrupted,
        ..Verified::default()
    };
    if let Some(dir) = request.failing_dir {
        if result.interrupted {
            done.left_out
                .push("--save-failing and --report are not written for a partial study");
        } else {
            done.failing = failing_runs(model, set, run_cfg, opts.seed, &result, dir)?;
            if request.save_failing {
                done.written =
                    save(dir, &done.failing).map_err(|e| VerifyError::Save(dir.into(), e))?;
            }
        }
    }
    let mut study = Study::of_result(
        request.model,
        &loaded.props_path,
        set,
        &opts.rule,
        opts.seed,
        opts.scheduler,
        &result,
    );
    if let (Some(sched), false) = (&opts.schedulers, result.interrupted) {
        let found = bounds(
            model,
            set,
            run_cfg,
            study_cfg,
            &opts.rule,
            sched,
            stop,
            &mut |s| event(Event::Bounds(s)),
        )?;
        match found {
            Some(found) => {
                for (row, b) in study.properties.iter_mut().zip(found) {
                    row.schedulers = Some(b);
                }
            }
            None => {
                done.left_out
                    .push("the bounds over schedulers are left out");
                study.interrupted = true;
            }
        }
    }
    if let Some(label) = request.bt_label {
        study.settings.push(("bt".into(), label.into()));
    }
    study.set_time_unit(loaded.unit_ns, run_cfg.max_time);
    study.replay = Some(Replay::of(loaded, request.model, run_cfg));
    if request.witnesses && !study.interrupted {
        done.witnesses = witness_runs(model, set, run_cfg, opts.seed, &study)?;
    }
    done.study = study;
    Ok(done)
}

/// `verify --bt both`: the same study under AS2FM's node models and under BehaviorTree.CPP
/// 4, and per property whether the two differ beyond the precision.
#[derive(Debug)]
pub struct Both {
    /// The study under each semantics, as asked (AS2FM's first), with its label.
    pub studies: Vec<(&'static str, Study)>,
    /// Per property, both probabilities.
    pub rows: Vec<Sensitivity>,
    /// What an interruption left out, one line each.
    pub left_out: Vec<&'static str>,
}

impl Both {
    /// Whether either study was interrupted.
    pub fn interrupted(&self) -> bool {
        self.studies.iter().any(|(_, s)| s.interrupted)
    }

    /// The runs of both studies.
    pub fn runs(&self) -> u64 {
        self.studies.iter().map(|(_, s)| s.runs).sum()
    }
}

/// One property under both semantics.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Sensitivity {
    /// The property.
    pub property: String,
    /// Its probability under AS2FM's node models.
    pub as2fm: Option<f64>,
    /// Its probability under BehaviorTree.CPP 4.
    pub btcpp: Option<f64>,
    /// BT.CPP's estimate minus AS2FM's.
    pub difference: Option<f64>,
    /// The two intervals are disjoint: the difference is beyond the precision.
    #[serde(rename = "semantics_sensitive")]
    pub sensitive: bool,
}

impl Sensitivity {
    /// `a` (AS2FM's row) against `b` (BT.CPP's).
    pub fn of(a: &PropertyRow, b: &PropertyRow) -> Self {
        let difference = a.probability.zip(b.probability).map(|(x, y)| y - x);
        let sensitive = difference.is_some() && (a.upper < b.lower || b.upper < a.lower);
        Sensitivity {
            property: a.property.clone(),
            as2fm: a.probability,
            btcpp: b.probability,
            difference,
            sensitive,
        }
    }
}

/// [`verify`]'s study of each of `loads` (the same model under AS2FM's semantics, then
/// BT.CPP's, each with its label) with the same settings and seed, and the comparison:
/// sequential, or of `runs` runs each (`--runs`). `started(label)` is called as each
/// begins. Once `stop` is set, the next sequential study starts no run (0 runs, no
/// estimate).
pub fn verify_both(
    loads: [(&'static str, &Loaded); 2],
    model: &Path,
    opts: &VerifyOptions,
    runs: Option<u64>,
    started: &mut dyn FnMut(&'static str),
    event: &mut dyn FnMut(Event<'_>),
    stop: &AtomicBool,
) -> Result<Both, VerifyError> {
    let (mut studies, mut left_out) = (Vec::new(), Vec::new());
    for (label, loaded) in loads {
        started(label);
        let request = Request {
            bt_label: Some(label),
            runs,
            ..Request::new(loaded, model, opts)
        };
        let done = match verify(&request, event, stop)? {
            Outcome::Study(done) => *done,
            // No shard was asked for.
            Outcome::Part(_) => return Err(VerifyError::Json("--bt both: a shard".into())),
        };
        left_out.extend(done.left_out);
        studies.push((label, done.study));
    }
    let rows = studies[0]
        .1
        .properties
        .iter()
        .zip(&studies[1].1.properties)
        .map(|(x, y)| Sensitivity::of(x, y))
        .collect();
    Ok(Both {
        studies,
        rows,
        left_out,
    })
}

/// What `merge` makes of the parts of one study.
#[derive(Debug)]
pub enum Merged {
    /// The whole study (a fixed-size study's shards, or a scheduler study's last stage),
    /// and each shard given more than once, identical, and counted once (with its files).
    Study(Box<Study>, Vec<(Shard, String)>),
    /// A scheduler study's stage that is not the last: the next stage's plan.
    Next(Box<Plan>),
}

/// Why the parts given to `merge` are not one study.
#[derive(Debug)]
pub enum MergeError {
    /// A plain shard's part among a scheduler study's stage parts.
    Mixed {
        /// The plain part.
        file: String,
        /// A stage part beside it.
        staged: String,
    },
    /// A part that does not parse.
    Part {
        /// Its file.
        file: String,
        /// What is wrong with it.
        error: String,
    },
    /// The stage parts do not make one stage of one study.
    Stage(StageError),
    /// The shards do not make one study (with the files of the shard at fault).
    Shard(ShardError, Option<String>),
    /// The last stage's bounds.
    Bounds(BoundsError),
}

impl std::fmt::Display for MergeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MergeError::Mixed { file, staged } => write!(
                f,
                "merge: {file}: not a part of a scheduler study's stage, while {staged} is: \
                 merge the parts of one study"
            ),
            MergeError::Part { file, error } => write!(f, "{file}: {error}"),
            MergeError::Stage(e) => write!(f, "merge: {e}"),
            MergeError::Shard(e, Some(files)) => write!(f, "merge: {e} ({files})"),
            MergeError::Shard(e, None) => write!(f, "merge: {e}"),
            MergeError::Bounds(e @ BoundsError::Rule(_)) => write!(f, "--schedulers: {e}"),
            MergeError::Bounds(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for MergeError {}

/// `merge`: the parts `verify --shard I/N --runs R` wrote (each its file's name and
/// text), checked to cover one study exactly once (a fixed-size study's shards, or the
/// shards of one stage of a scheduler study), then merged.
pub fn merge_parts(parts: &[(String, String)]) -> Result<Merged, MergeError> {
    use crate::sched_fixed::{merge_stage, StagePart, PART_FORMAT};
    use crate::smc::shard::{duplicates, PartialResult};
    // Each part's JSON, read once: its `format` says whether it is a stage's part.
    let json: Vec<Result<serde_json::Value, String>> = parts
        .iter()
        .map(|(_, t)| serde_json::from_str(t).map_err(|e: serde_json::Error| e.to_string()))
        .collect();
    let staged: Vec<bool> = json
        .iter()
        .map(|v| {
            v.as_ref()
                .is_ok_and(|v| v.get("format").and_then(|f| f.as_str()) == Some(PART_FORMAT))
        })
        .collect();
    if let Some(first) = staged.iter().position(|&s| s) {
        let mut stage_parts = Vec::new();
        for (((file, _), v), &is) in parts.iter().zip(json).zip(&staged) {
            let part_error = |error: String| MergeError::Part {
                file: file.clone(),
                error,
            };
            // A file that is not JSON at all (cut short, or another file) is said as such.
            let v = v.map_err(part_error)?;
            if !is {
                return Err(MergeError::Mixed {
                    file: file.clone(),
                    staged: parts[first].0.clone(),
                });
            }
            stage_parts.push(
                serde_json::from_value::<StagePart>(v).map_err(|e| part_error(e.to_string()))?,
            );
        }
        let plan = merge_stage(&stage_parts).map_err(MergeError::Stage)?;
        if !plan.done() {
            return Ok(Merged::Next(Box::new(plan)));
        }
        let study = plan.study().map_err(MergeError::Bounds)?;
        return Ok(Merged::Study(Box::new(study), Vec::new()));
    }
    let mut results = Vec::new();
    for (file, text) in parts {
        results.push(
            PartialResult::from_json(text).map_err(|e| MergeError::Part {
                file: file.clone(),
                error: e.to_string(),
            })?,
        );
    }
    // Name the files of a shard in every message about it.
    let files_of = |shard: Shard| -> String {
        let names: Vec<&str> = parts
            .iter()
            .zip(&results)
            .filter(|(_, p)| p.shard.index == shard.index)
            .map(|((f, _), _)| f.as_str())
            .collect();
        names.join(", ")
    };
    let m = merge(&results, 0).map_err(|e| {
        let shard = match &e {
            ShardError::Mismatch { shard, .. }
            | ShardError::Duplicate(shard)
            | ShardError::Range(shard)
            | ShardError::Counts { shard, .. } => Some(*shard),
            _ => None,
        };
        let files = shard.map(files_of);
        MergeError::Shard(e, files)
    })?;
    let twice = duplicates(&results)
        .into_iter()
        .map(|(shard, _)| (shard, files_of(shard)))
        .collect();
    Ok(Merged::Study(Box::new(Study::merged(&m)), twice))
}
