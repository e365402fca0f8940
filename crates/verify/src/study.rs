//! Running a study: simulated runs judged by the monitors, under a stopping rule.
//!
//! [`Runner`] runs one simulation with its [`Judge`] (the function every study
//! shares: `verify`, `sweep`, shards, the benches); [`study`] hands it to
//! [`crate::smc::run_study`] with one stopping rule per guarantee, `study_shard` to
//! [`crate::smc::shard::run_shard`] for one slice of a fixed-size study.

use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

use rand_xoshiro::Xoshiro256PlusPlus;

use super::observe::{Judge, PropertySet};
use crate::sim::{CompiledModel, EndReason, RunConfig, Scheduler, Simulator, SpinKind};
use crate::smc::shard::{run_shard, FixedStudy, PartialResult, Shard};
use crate::smc::stats::{RuleConfig, StatsError};
// A study's progress, as callers draw it.
pub use crate::smc::progress::{log_line, message, LOG_EVERY};
pub use crate::smc::Progress;
use crate::smc::{run_study_until, RunEnd, RunOutcome, StudyConfig, StudyResult, Verdict};

/// Runs a study of `set` on `model`: the function `verify` and `sweep` share. `progress`
/// is told of every run consumed (the binary draws a bar; the library prints nothing).
pub fn study(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> Result<StudyResult, StudyError> {
    study_until(
        model,
        set,
        run_cfg,
        study_cfg,
        rule,
        progress,
        &AtomicBool::new(false),
    )
}

/// [`study`] that stops early, with a partial result, once `stop` is set (see
/// [`run_study_until`]): `verify` sets it on Ctrl-C.
pub(crate) fn study_until(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    progress: &mut dyn FnMut(&Progress<'_>),
    stop: &AtomicBool,
) -> Result<StudyResult, StudyError> {
    let rules = set
        .guarantee_names()
        .iter()
        .map(|_| rule.build())
        .collect::<Result<Vec<_>, _>>()
        .map_err(StudyError::Rule)?;
    let runner = Runner::new(model, set, run_cfg);
    let result = run_study_until(
        study_cfg,
        &rules,
        |k, rng| runner.run(k, rng),
        progress,
        stop,
    );
    runner.finish().map_err(StudyError::Model)?;
    Ok(result)
}

/// Shard `shard` of the fixed-size study `fixed` (`verify --runs R [--shard I/N]`):
/// its runs judged by the same [`Runner`] as every study, counted by
/// [`crate::smc::shard::run_shard`] (no early stop; `fixed` gives the seed).
pub(crate) fn study_shard(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    fixed: &FixedStudy,
    shard: Shard,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> Result<PartialResult, ModelFailure> {
    let runner = Runner::new(model, set, run_cfg);
    let part = run_shard(
        study_cfg,
        fixed,
        shard,
        |k, rng| runner.run(k, rng),
        progress,
    );
    runner.finish()?;
    Ok(part)
}

/// Why a [`study`] gave no result.
#[derive(Clone, Debug, PartialEq)]
pub enum StudyError {
    /// The stopping rule is invalid.
    Rule(StatsError),
    /// The model failed during a run (bad input: the model's fault).
    Model(ModelFailure),
}

impl std::fmt::Display for StudyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StudyError::Rule(e) => write!(f, "statistics: {e}"),
            StudyError::Model(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for StudyError {}

/// The first model failure a [`Runner`]'s runs met (a spin, a run-time error, a value
/// the monitors cannot take): the run, its scheduler, and what went wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelFailure {
    /// The run's index.
    pub run: u64,
    /// The scheduler it ran under.
    pub scheduler: Scheduler,
    /// What went wrong, as the simulator or the judge says it.
    pub what: String,
}

impl std::fmt::Display for ModelFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the model failed during simulation: run {}", self.run)?;
        if self.scheduler != Scheduler::Uniform {
            // A failure names the scheduler when it is not the uniform one.
            write!(f, " (scheduler {})", self.scheduler)?;
        }
        write!(f, ": {}", self.what)
    }
}

impl std::error::Error for ModelFailure {}

/// Runs one simulation with its judge: the run function every study shares.
///
/// Simulators and judges are pooled and reused across runs (no allocation per step);
/// the first model failure (a spin, a run-time error) is kept and ends the study.
pub struct Runner<'m> {
    model: &'m CompiledModel,
    set: &'m PropertySet,
    run_cfg: &'m RunConfig,
    pool: Mutex<Vec<(Simulator<'m>, Judge<'m>)>>,
    failure: Mutex<Option<ModelFailure>>,
    /// What a run that blocks time under a sampled scheduler does (see [`Unfair`]).
    unfair: Unfair,
    /// Per sampled scheduler, its first unfair run (lowest index) and why.
    unfair_runs: Mutex<std::collections::BTreeMap<UnfairKey, (u64, String)>>,
}

/// A sampled scheduler as a map key (its name: id, memory and put-backs).
type UnfairKey = String;

/// What a run under a *sampled* scheduler that blocks time does: a run whose instant
/// reaches `max_steps_per_instant` steps (time never advances again: the scheduler keeps
/// choosing moves that keep the instant going, which the uniform scheduler does with
/// probability 0 when its own runs let time pass). See docs/SEMANTICS.md, "Fair
/// schedulers". Under the uniform scheduler it is a model failure, as always.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Unfair {
    /// A model failure, as under the uniform scheduler (the study stops).
    #[default]
    Fail,
    /// The run ends as failed without a failure message; `Runner::unfair_run` names
    /// it, so that the study leaves its scheduler out.
    LeaveOut,
    /// The run is kept: judged as it stands, as if the time horizon were the instant it
    /// blocked (`verify --keep-unfair`).
    Keep,
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
            unfair: Unfair::Fail,
            unfair_runs: Mutex::new(Default::default()),
        }
    }

    /// This runner with `unfair` for runs that block time under a sampled scheduler.
    pub(crate) fn with_unfair(mut self, unfair: Unfair) -> Self {
        self.unfair = unfair;
        self
    }

    /// The first run (lowest index) of `scheduler` that blocked time and was left out
    /// ([`Unfair::LeaveOut`]), and why.
    pub(crate) fn unfair_run(&self, scheduler: &Scheduler) -> Option<(u64, String)> {
        let runs = self.unfair_runs.lock().ok()?;
        runs.get(&scheduler.to_string()).cloned()
    }

    /// Run `k` with its stream.
    pub fn run(&self, k: u64, rng: &mut Xoshiro256PlusPlus) -> RunOutcome {
        self.run_under(k, rng, self.run_cfg.scheduler)
    }

    /// Run `k` with its stream under `scheduler` instead of the configuration's.
    pub(crate) fn run_under(
        &self,
        k: u64,
        rng: &mut Xoshiro256PlusPlus,
        scheduler: Scheduler,
    ) -> RunOutcome {
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
            let out = if scheduler == self.run_cfg.scheduler {
                sim.run(rng, self.run_cfg, &mut judge)
            } else {
                let cfg = RunConfig {
                    scheduler,
                    ..self.run_cfg.clone()
                };
                sim.run(rng, &cfg, &mut judge)
            };
            let failed = |what: String| ModelFailure {
                run: k,
                scheduler,
                what,
            };
            let end = match &out.end {
                e @ (EndReason::Quiescent
                | EndReason::MaxTime
                | EndReason::MaxSteps
                | EndReason::Stopped) => judged_end(e),
                EndReason::Spin(s)
                    if s.kind == SpinKind::NoTimeProgress
                        && scheduler != Scheduler::Uniform
                        && self.unfair != Unfair::Fail =>
                {
                    if self.unfair == Unfair::Keep {
                        Some(RunEnd::TimeHorizon)
                    } else {
                        if let Ok(mut runs) = self.unfair_runs.lock() {
                            let slot = runs
                                .entry(scheduler.to_string())
                                .or_insert((u64::MAX, String::new()));
                            // The lowest index: the run a study consuming in order meets
                            // first, whatever ran ahead on other threads.
                            if k < slot.0 {
                                *slot = (k, s.to_string());
                            }
                        }
                        None
                    }
                }
                EndReason::Spin(s) => {
                    record(&self.failure, failed(s.to_string()));
                    None
                }
                EndReason::Error(e) => {
                    record(&self.failure, failed(e.to_string()));
                    None
                }
            };
            if let Some(err) = &judge.error {
                record(&self.failure, failed(err.to_string()));
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
    pub fn finish(self) -> Result<(), ModelFailure> {
        match self.failure.into_inner().ok().flatten() {
            Some(failure) => Err(failure),
            None => Ok(()),
        }
    }
}

/// Keeps the first failure.
fn record(slot: &Mutex<Option<ModelFailure>>, failure: ModelFailure) {
    if let Ok(mut s) = slot.lock() {
        s.get_or_insert(failure);
    }
}

/// How a run that ended as `end` is judged: at the time horizon, quiescent, cut at the
/// step limit or decided. `None` for a spin or an error, which a study does not judge
/// as it stands (`Runner::run_under` decides what becomes of them).
pub(crate) fn judged_end(end: &EndReason) -> Option<RunEnd> {
    match end {
        EndReason::Quiescent => Some(RunEnd::Quiescent),
        EndReason::MaxTime => Some(RunEnd::TimeHorizon),
        EndReason::MaxSteps => Some(RunEnd::StepLimit),
        EndReason::Stopped => Some(RunEnd::Decided),
        EndReason::Spin(_) | EndReason::Error(_) => None,
    }
}
