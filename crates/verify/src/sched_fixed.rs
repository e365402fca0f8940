//! Fixed-size scheduler studies (`verify --schedulers N --runs R`, alone or as shards with
//! `--shard I/K`): the study of [`super::schedulers`] as a sequence of *stages*, each a
//! fixed list of run ranges, so that any number of machines can share a stage and the
//! merge of its shards is exactly the stage run on one machine.
//!
//! # Stages
//!
//! A [`Plan`] is the study's state between stages: its identity (seed, `R`, model and
//! property fingerprints, rules), the counts so far and the current stage's [`Job`]s, each
//! the runs `start..end` of one scheduler on the streams of one seed:
//!
//! 1. stage 0: the uniform study (runs `0..R` of the study seed, as `verify --runs R`)
//!    and the first selection round (runs `0..S` of each scheduler on the selection seed);
//! 2. one stage per further selection round ([`Selection`]: successive halving, the same
//!    rounds as the sequential study ranks by);
//! 3. the confirmation: runs `0..R` of each candidate on the estimate seed, a fixed-size
//!    study per candidate, its interval that of the rule at the split confidence
//!    (`schedulers::split_rule`), as in the sequential study but with `R` runs
//!    instead of the rule's stopping point (a stopping point is a sequential decision that
//!    one shard cannot take alone).
//!
//! 4. where the order comes from, for the order-sensitive properties only: runs `0..R` of
//!    each witness on the estimate seed with one kind of choice put back to uniform
//!    (which machine moves; which pending event is delivered, under AS2FM's semantics;
//!    which enabled transition fires, with random transitions), as the sequential study's
//!    `sources` but with `R` runs each;
//! 5. for a kind that moved a witness's probability by more than twice the precision,
//!    each machine's (event's) position alone put back, `R` runs each.
//!
//! After the last stage the plan holds everything the report needs.
//!
//! # Shards
//!
//! The jobs of a stage, laid end to end, are `T` runs; shard `I` of `K` runs the runs
//! `[floor(I T / K), floor((I + 1) T / K))` of that line (`run_stage`), each on its job's
//! stream (run `k` of a job is stream `k` of the job's seed whatever the shard), and writes
//! a [`StagePart`] holding the plan it ran. `merge_stage` checks the parts are shards of
//! one plan covering it exactly once, sums each job's counts and advances the plan
//! ([`Plan::advance`]): counts are sums, so the merged plan is the plan of the stage run
//! on one machine, for any `K` and any thread count. `verify --schedulers N --runs R`
//! without `--shard` runs every stage as the single shard `0/1` through the same two
//! functions.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::observe::PropertySet;
use super::schedulers::{
    sampled, split_count, split_rule, witnesses, Bound, BoundsError, LeftOut, SchedulerBounds,
    SchedulerOptions, Selection, Source, ESTIMATE, LEFT_OUT_SHOWN, SELECT,
};
use super::study::{Runner, Unfair};
use crate::sim::{
    mix, CompiledModel, EventId, EventSemantics, MachineId, Memory, PutBack, RunConfig, Scheduler,
    TransitionChoice,
};

/// An estimate and its interval.
type Estimated = (Option<f64>, [f64; 2]);
use crate::smc::runner::widened_interval;
use crate::smc::shard::{FixedStudy, MergedProperty, MergedResult, Shard};
use crate::smc::{run_range, PropertyCounts, RangeCounts, StudyConfig};

/// The `format` tag of a plan file.
pub(crate) const PLAN_FORMAT: &str = "hindsight-scheduler-plan-2";
/// The `format` tag of a stage's partial result.
pub(crate) const PART_FORMAT: &str = "hindsight-scheduler-partial-2";

/// Whose streams a job's runs use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Streams {
    /// The study seed: the uniform study.
    Study,
    /// The selection seed.
    Selection,
    /// The estimate seed: the confirmation.
    Estimate,
}

/// Runs `start..end` of one scheduler on one seed's streams.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Job {
    /// The sampled scheduler's index in the study (`None`: the uniform scheduler).
    pub scheduler: Option<usize>,
    /// Whose streams.
    pub streams: Streams,
    /// First run index.
    pub start: u64,
    /// End of the run indices (exclusive).
    pub end: u64,
    /// The choices put back to uniform in the scheduler (the sources' stages).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub put_back: Option<Uniform>,
}

/// [`PutBack`] as a plan file holds it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Uniform {
    /// Which runnable machine moves.
    #[serde(default)]
    pub machines: bool,
    /// Which deliverable event is delivered.
    #[serde(default)]
    pub events: bool,
    /// Which enabled transition fires.
    #[serde(default)]
    pub transitions: bool,
    /// This machine's position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<u32>,
    /// This event's position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub event: Option<u32>,
}

impl From<Uniform> for PutBack {
    fn from(u: Uniform) -> PutBack {
        PutBack {
            machines: u.machines,
            events: u.events,
            transitions: u.transitions,
            machine: u.machine,
            event: u.event,
        }
    }
}

/// What the sources of an order-sensitive property may put back, read from the model
/// and the run's semantics when the study starts (a plan is merged without the model).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Choices {
    /// Every machine's name, by id.
    pub machines: Vec<String>,
    /// The events some machine receives: id and name.
    pub events: Vec<(u32, String)>,
    /// Which pending event is delivered is a choice (AS2FM's semantics).
    pub deliveries: bool,
    /// Which enabled transition fires is a choice (random transitions).
    pub transitions: bool,
}

impl Choices {
    /// The choices of `model` run with `run_cfg`.
    pub fn of(model: &CompiledModel, run_cfg: &RunConfig) -> Choices {
        Choices {
            machines: (0..model.machine_count() as u32)
                .map(|m| model.machine_name(MachineId(m)).to_string())
                .collect(),
            events: (0..model.event_count() as u32)
                .filter(|&e| model.event_receivers(EventId(e)).next().is_some())
                .map(|e| (e, model.event_name(EventId(e)).to_string()))
                .collect(),
            deliveries: run_cfg.events == EventSemantics::As2fm,
            transitions: run_cfg.transitions == TransitionChoice::Random,
        }
    }

    /// The kinds of choice put back one at a time, with their names in a [`Source`].
    fn kinds(&self) -> Vec<(&'static str, Uniform)> {
        let none = Uniform::default();
        [
            (
                "machine",
                true,
                Uniform {
                    machines: true,
                    ..none
                },
            ),
            (
                "delivery",
                self.deliveries,
                Uniform {
                    events: true,
                    ..none
                },
            ),
            (
                "transition",
                self.transitions,
                Uniform {
                    transitions: true,
                    ..none
                },
            ),
        ]
        .into_iter()
        .filter_map(|(choice, made, u)| made.then_some((choice, u)))
        .collect()
    }

    /// Each machine's (`machine`) or event's (`delivery`) position alone, with its name.
    fn items(&self, choice: &str) -> Vec<(Uniform, Option<String>, Option<String>)> {
        match choice {
            "machine" => (0..self.machines.len() as u32)
                .map(|m| {
                    let u = Uniform {
                        machine: Some(m),
                        ..Uniform::default()
                    };
                    (u, Some(self.machines[m as usize].clone()), None)
                })
                .collect(),
            "delivery" => self
                .events
                .iter()
                .map(|(e, name)| {
                    let u = Uniform {
                        event: Some(*e),
                        ..Uniform::default()
                    };
                    (u, None, Some(name.clone()))
                })
                .collect(),
            _ => Vec::new(),
        }
    }
}

/// The counts of one witness with choices put back (`None`: a run blocked time, so the
/// source is left out, as the sequential study leaves it out).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SourceCounts {
    /// The witness's index in the study.
    pub scheduler: usize,
    /// What was put back.
    pub put_back: Uniform,
    /// Per property, its counts.
    pub counts: Option<Vec<PropertyCounts>>,
}

impl Job {
    fn len(&self) -> u64 {
        self.end - self.start
    }
}

/// The study's state between stages (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Always `PLAN_FORMAT`.
    pub format: String,
    /// The fixed-size study's identity (seed, `R`, fingerprints, properties and rules).
    pub study: FixedStudy,
    /// Schedulers sampled, `N`.
    pub schedulers: u64,
    /// `memoryless` or `history`.
    pub memory: String,
    /// Selection runs per scheduler in the first round, `S`.
    pub selection_runs: u64,
    /// Runs that block time under a sampled scheduler are kept (`--keep-unfair`), not
    /// left out with their scheduler.
    pub keep_unfair: bool,
    /// The current stage, from 0.
    pub stage: u32,
    /// Its jobs (none once the study is done).
    pub jobs: Vec<Job>,
    /// Whether the current stage is a selection round.
    pub selecting: bool,
    /// The uniform study's counts (after stage 0).
    pub uniform: Option<RangeCounts>,
    /// The selection so far.
    pub selection: Selection,
    /// Per candidate (scheduler index), its confirmation counts per property.
    pub fresh: Vec<(usize, Vec<PropertyCounts>)>,
    /// Schedulers left out as unfair so far, in the order met.
    pub left_out: Vec<LeftOut>,
    /// The intervals each property's confidence is split over, fixed when the
    /// confirmation starts (`split_count`).
    pub split_over: usize,
    /// What the sources may put back.
    pub choices: Choices,
    /// The sources' stages run so far: 0, 1 (the kinds) or 2 (the positions).
    pub sources_level: u8,
    /// The sources' counts, in job order.
    pub sources: Vec<SourceCounts>,
}

/// A job's first run (lowest index) that blocked time, and why.
pub type UnfairRun = Option<(u64, String)>;

/// Why a stage cannot be run or merged.
#[derive(Debug, PartialEq)]
pub enum StageError {
    /// A file that is not a plan or stage part of this format.
    Format(String),
    /// The plan belongs to another study than the command line's: which field differs.
    Mismatch(&'static str),
    /// No parts.
    Empty,
    /// A part of another stage or plan, or another shard count.
    Foreign(Shard),
    /// A shard given twice with different counts.
    Duplicate(Shard),
    /// Shards missing.
    Missing(Vec<Shard>),
    /// A part whose counts its runs cannot give (what is wrong).
    Counts(Shard, String),
    /// The model failed during a run.
    Model(crate::study::ModelFailure),
    /// A run failed and left no message.
    Silent,
    /// The study is done: there is no stage left to run.
    Done,
}

impl std::fmt::Display for StageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StageError::Format(m) => write!(f, "not a scheduler study's plan or part: {m}"),
            StageError::Mismatch(field) => write!(
                f,
                "the plan is another study's: its `{field}` differs from this command line's"
            ),
            StageError::Empty => write!(f, "no parts to merge"),
            StageError::Foreign(s) => write!(
                f,
                "shard {s} ran another stage or plan, or another shard count, than the first \
                 part: merge the parts of one stage, each run with the same --plan"
            ),
            StageError::Duplicate(s) => {
                write!(f, "shard {s} is given twice with different counts")
            }
            StageError::Missing(v) => {
                let list: Vec<String> = v.iter().map(Shard::to_string).collect();
                write!(
                    f,
                    "shard(s) {} of this stage missing: run each with the same --plan and \
                     merge again with every part",
                    list.join(", ")
                )
            }
            StageError::Counts(s, m) => write!(f, "shard {s} has counts its runs cannot give: {m}"),
            StageError::Model(m) => write!(f, "{m}"),
            StageError::Silent => write!(f, "a run failed without a message"),
            StageError::Done => write!(f, "the plan's study is done: no stage is left to run"),
        }
    }
}

impl std::error::Error for StageError {}

/// One shard of one stage, as written to a JSON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StagePart {
    /// Always `PART_FORMAT`.
    pub format: String,
    /// The plan the shard ran.
    pub plan: Plan,
    /// Which shard.
    pub shard: Shard,
    /// Per job it touched (index in `plan.jobs`): the runs it covered, their counts (up
    /// to the first unfair run) and its first unfair run.
    pub results: Vec<(usize, Range<u64>, RangeCounts, UnfairRun)>,
}

impl Plan {
    /// Stage 0 of the study `study` with the options of `--schedulers`, on a model whose
    /// choices are `choices`.
    pub fn new(study: FixedStudy, opts: &SchedulerOptions, choices: Choices) -> Plan {
        let props = study.properties.len();
        let n = opts.count.max(1) as usize;
        let mut plan = Plan {
            format: PLAN_FORMAT.to_string(),
            schedulers: n as u64,
            memory: opts.memory.label().to_string(),
            selection_runs: opts.selection_runs,
            keep_unfair: opts.unfair == Unfair::Keep,
            stage: 0,
            jobs: vec![Job {
                scheduler: None,
                streams: Streams::Study,
                start: 0,
                end: study.study_runs,
                put_back: None,
            }],
            selecting: false,
            uniform: None,
            selection: Selection::new(n, props, opts.selection_runs),
            fresh: Vec::new(),
            left_out: Vec::new(),
            split_over: 2,
            choices,
            sources_level: 0,
            sources: Vec::new(),
            study,
        };
        plan.next_jobs();
        plan
    }

    /// What the current stage runs: `selection`, `confirmation` or `sources` (where the
    /// order comes from); `done` after the last.
    pub fn stage_kind(&self) -> &'static str {
        if self.done() {
            "done"
        } else if self.jobs.iter().any(|j| j.streams == Streams::Study) {
            "uniform study and selection"
        } else if self.selecting {
            "selection"
        } else if self.jobs.iter().any(|j| j.put_back.is_some()) {
            "sources"
        } else {
            "confirmation"
        }
    }

    /// Whether every stage was run.
    pub fn done(&self) -> bool {
        self.jobs.is_empty()
    }

    fn memory(&self) -> Memory {
        if self.memory == "history" {
            Memory::History
        } else {
            Memory::Memoryless
        }
    }

    /// The scheduler a job runs under.
    fn scheduler(&self, job: &Job) -> Scheduler {
        match job.scheduler {
            None => Scheduler::Uniform,
            Some(i) => self.witness(i, job.put_back.unwrap_or_default()),
        }
    }

    /// Sampled scheduler `i` with `put_back` put back to uniform.
    fn witness(&self, i: usize, put_back: Uniform) -> Scheduler {
        let mut w = sampled(self.study.seed, i as u64, self.memory());
        w.uniform = put_back.into();
        Scheduler::Sampled(w)
    }

    /// The seed of a job's streams.
    fn seed(&self, job: &Job) -> u64 {
        match job.streams {
            Streams::Study => self.study.seed,
            Streams::Selection => mix(self.study.seed, SELECT),
            Streams::Estimate => mix(self.study.seed, ESTIMATE),
        }
    }

    /// Appends the jobs of the next stage: a selection round, else the confirmation of the
    /// candidates; skips rounds with no runs (every survivor already has its runs).
    fn next_jobs(&mut self) {
        let r = self.study.study_runs;
        while !self.selection.finished() {
            let round = self.selection.round();
            if round.is_empty() {
                self.selection.halve();
                continue;
            }
            self.selecting = true;
            self.jobs.extend(round.into_iter().map(|(i, range)| Job {
                scheduler: Some(i),
                streams: Streams::Selection,
                start: range.start,
                end: range.end,
                put_back: None,
            }));
            return;
        }
        self.selecting = false;
        self.split_over = split_count(&self.selection.sides);
        if self.fresh.is_empty() {
            self.jobs.extend(self.selection.alive.iter().map(|&i| Job {
                scheduler: Some(i),
                streams: Streams::Estimate,
                start: 0,
                end: r,
                put_back: None,
            }));
        }
    }

    /// Takes the counts of every job of the current stage (in job order), with each job's
    /// first unfair run, and moves to the next stage.
    pub fn advance(&mut self, results: Vec<(RangeCounts, UnfairRun)>) {
        let jobs = std::mem::take(&mut self.jobs);
        let selecting = self.selecting;
        let sourcing = jobs.iter().any(|j| j.put_back.is_some());
        let mut confirmed = false;
        for (job, (got, unfair)) in jobs.iter().zip(results) {
            if let (Some(put_back), Some(i)) = (job.put_back, job.scheduler) {
                self.sources.push(SourceCounts {
                    scheduler: i,
                    put_back,
                    counts: unfair.is_none().then_some(got.properties),
                });
                continue;
            }
            if let (Some(i), Some((run, reason))) = (job.scheduler, unfair) {
                self.left_out.push(LeftOut {
                    scheduler: self.scheduler(job).to_string(),
                    phase: match job.streams {
                        Streams::Estimate => "estimate",
                        _ => "selection",
                    }
                    .to_string(),
                    run,
                    reason,
                });
                self.selection.leave_out(i);
                confirmed |= job.streams == Streams::Estimate;
                continue;
            }
            match (job.streams, job.scheduler) {
                (Streams::Study, _) => self.uniform = Some(got),
                (Streams::Selection, Some(i)) => self.selection.absorb(i, &got.properties),
                (Streams::Estimate, Some(i)) => {
                    confirmed = true;
                    self.fresh.push((i, got.properties))
                }
                _ => {}
            }
        }
        if selecting {
            self.selection.halve();
        }
        self.stage += 1;
        if sourcing {
            if self.sources_level == 1 {
                self.sources_level = 2;
                self.position_jobs();
            }
        } else if confirmed {
            self.sources_level = 1;
            self.kind_jobs();
        } else {
            self.next_jobs();
        }
    }

    /// The jobs of the sources' first stage: each order-sensitive property's witnesses
    /// with each kind of choice put back (none when no property is order-sensitive).
    fn kind_jobs(&mut self) {
        let Ok(bounds) = self.bounds() else {
            return;
        };
        let kinds = self.choices.kinds();
        let mut jobs: Vec<Job> = Vec::new();
        for (b, witnesses) in &bounds {
            if !b.order_sensitive {
                continue;
            }
            for &i in witnesses {
                for (_, u) in &kinds {
                    self.push_source_job(&mut jobs, i, *u);
                }
            }
        }
        self.jobs = jobs;
    }

    /// The jobs of the sources' second stage: for each kind that moved a witness's
    /// probability by more than twice the precision, each machine's (event's) position.
    fn position_jobs(&mut self) {
        let Ok(bounds) = self.bounds() else {
            return;
        };
        let mut jobs: Vec<Job> = Vec::new();
        for (p, (b, witnesses)) in bounds.iter().enumerate() {
            if !b.order_sensitive {
                continue;
            }
            for (&i, base) in witnesses.iter().zip([&b.min, &b.max]) {
                for (choice, u) in self.choices.kinds() {
                    if self.source_matters(p, i, u, base.probability) {
                        for (item, _, _) in self.choices.items(choice) {
                            self.push_source_job(&mut jobs, i, item);
                        }
                    }
                }
            }
        }
        self.jobs = jobs;
    }

    /// Adds the job of witness `i` with `put_back` (runs `0..R` on the estimate seed)
    /// unless another property asked for it already.
    fn push_source_job(&self, jobs: &mut Vec<Job>, i: usize, put_back: Uniform) {
        let job = Job {
            scheduler: Some(i),
            streams: Streams::Estimate,
            start: 0,
            end: self.study.study_runs,
            put_back: Some(put_back),
        };
        if !jobs.contains(&job) {
            jobs.push(job);
        }
    }

    /// Property `p`'s estimate and interval (at the study's confidence, on its own) under
    /// witness `i` with `put_back`: `None` when not run or left out (a run blocked time).
    fn source_estimate(&self, p: usize, i: usize, put_back: Uniform) -> Option<Estimated> {
        let found = self
            .sources
            .iter()
            .find(|s| s.scheduler == i && s.put_back == put_back)?;
        let c = found.counts.as_ref()?.get(p)?;
        let rule = self.study.properties.get(p)?.rule.build().ok()?;
        let iv = widened_interval(rule.as_ref(), c);
        Some((
            rule.estimate(c.successes, c.judged()).estimate,
            [iv.lower, iv.upper],
        ))
    }

    /// Whether putting `put_back` back moved property `p`'s probability under witness `i`
    /// (`base`) by more than twice the precision (a kind whose positions are run next).
    fn source_matters(&self, p: usize, i: usize, put_back: Uniform, base: Option<f64>) -> bool {
        let precision = self.study.properties[p].rule.precision;
        self.source_estimate(p, i, put_back)
            .is_some_and(|(probability, _)| {
                (probability.unwrap_or(0.0) - base.unwrap_or(0.0)).abs() > 2.0 * precision
            })
    }

    /// Property `p`'s sources, as the sequential study lists them: per witness (min, then
    /// max), each kind, then, for a kind that matters, each position, in id order.
    fn sources_of(&self, p: usize, b: &SchedulerBounds, witnesses: [usize; 2]) -> Vec<Source> {
        let mut out = Vec::new();
        for ((side, &i), base) in ["min", "max"].iter().zip(&witnesses).zip([&b.min, &b.max]) {
            let source = |u: Uniform, machine, event, (probability, interval): Estimated| Source {
                witness: side.to_string(),
                choice: String::new(),
                machine,
                event,
                probability,
                interval,
                shift: probability.unwrap_or(0.0) - base.probability.unwrap_or(0.0),
                scheduler: self.witness(i, u).to_string(),
            };
            for (choice, u) in self.choices.kinds() {
                let Some(est) = self.source_estimate(p, i, u) else {
                    continue;
                };
                out.push(Source {
                    choice: choice.to_string(),
                    ..source(u, None, None, est)
                });
                if choice == "transition" || !self.source_matters(p, i, u, base.probability) {
                    continue;
                }
                for (item, machine, event) in self.choices.items(choice) {
                    if let Some(est) = self.source_estimate(p, i, item) {
                        out.push(Source {
                            choice: choice.to_string(),
                            ..source(item, machine, event, est)
                        });
                    }
                }
            }
        }
        out
    }

    /// The result of a finished study: the uniform study as `merge` reports a
    /// fixed-size one ([`crate::result::Study::merged`]), each property with its bounds.
    pub fn study(&self) -> Result<crate::result::Study, BoundsError> {
        let (merged, bounds) = self.report()?;
        let mut study = crate::result::Study::merged(&merged);
        for (row, b) in study.properties.iter_mut().zip(bounds) {
            row.schedulers = Some(b);
        }
        Ok(study)
    }

    /// The uniform study as `merge` reports a fixed-size study, and each property's
    /// bounds (an error before the last stage, or with a side emptied by unfair ones).
    pub fn report(&self) -> Result<(MergedResult, Vec<SchedulerBounds>), BoundsError> {
        let unfinished = BoundsError::Unfinished(self.stage);
        if !self.done() {
            return Err(unfinished);
        }
        let uniform = self.uniform.as_ref().ok_or(BoundsError::Unfinished(0))?;
        let mut properties = Vec::new();
        for (spec, counts) in self.study.properties.iter().zip(&uniform.properties) {
            let rule = spec.rule.build().map_err(BoundsError::Rule)?;
            properties.push(MergedProperty {
                id: spec.id.clone(),
                rule: spec.rule,
                counts: *counts,
                estimate: rule.estimate(counts.successes, counts.judged()),
                interval: widened_interval(rule.as_ref(), counts),
                failing_runs: Vec::new(),
            });
        }
        let merged = MergedResult {
            study: self.study.clone(),
            shards: 1,
            properties,
            runs: uniform.runs,
        };
        let bounds = self
            .bounds()?
            .into_iter()
            .enumerate()
            .map(|(p, (mut b, witnesses))| {
                if b.order_sensitive {
                    b.sources = self.sources_of(p, &b, witnesses);
                }
                b
            })
            .collect();
        Ok((merged, bounds))
    }

    /// Each property's bounds after the confirmation (no sources yet) and its witnesses
    /// (scheduler indices, min then max): an error with a side emptied by unfair ones.
    fn bounds(&self) -> Result<Vec<(SchedulerBounds, [usize; 2])>, BoundsError> {
        if self
            .selection
            .sides
            .iter()
            .flatten()
            .any(|side| side.is_empty())
        {
            return Err(BoundsError::AllUnfair {
                left_out: self.left_out.len() as u64,
                sampled: self.schedulers,
            });
        }
        let sides = &self.selection.sides;
        let fresh = |i: usize| self.fresh.iter().find(|(j, _)| *j == i).map(|(_, c)| c);
        let mut bounds = Vec::new();
        for (p, spec) in self.study.properties.iter().enumerate() {
            let split = split_rule(&spec.rule, self.split_over)
                .build()
                .map_err(BoundsError::Rule)?;
            let estimate = |i: usize| {
                let c = fresh(i)?.get(p)?;
                split.estimate(c.successes, c.judged()).estimate
            };
            let [lo, hi] = witnesses(&sides[p..=p], |i, _| estimate(i))[0];
            let bound = |i: usize| -> Option<Bound> {
                let c = *fresh(i)?.get(p)?;
                let iv = widened_interval(split.as_ref(), &c);
                Some(Bound {
                    probability: estimate(i),
                    interval: [iv.lower, iv.upper],
                    scheduler: self.witness(i, Uniform::default()).to_string(),
                    runs: c.judged(),
                    successes: c.successes,
                })
            };
            let (Some(min), Some(max)) = (bound(lo), bound(hi)) else {
                return Err(BoundsError::Unfinished(self.stage));
            };
            let order_sensitive = match (min.probability, max.probability) {
                (Some(a), Some(b)) => b - a > 2.0 * spec.rule.precision,
                _ => false,
            };
            bounds.push((
                SchedulerBounds {
                    sampled: self.schedulers,
                    memory: self.memory.clone(),
                    min,
                    max,
                    order_sensitive,
                    sources: Vec::new(),
                    left_out: self.left_out.len() as u64,
                    left_out_first: self.left_out.iter().take(LEFT_OUT_SHOWN).cloned().collect(),
                },
                [lo, hi],
            ));
        }
        Ok(bounds)
    }

    /// Checks that this plan is the study `study` with options `opts` (the paths may
    /// differ: machines mount files in different places).
    pub fn check(&self, study: &FixedStudy, opts: &SchedulerOptions) -> Result<(), StageError> {
        let s = &self.study;
        let fields: [(&'static str, bool); 9] = [
            ("format", self.format == PLAN_FORMAT),
            ("seed", s.seed == study.seed),
            ("study_runs", s.study_runs == study.study_runs),
            ("model", s.model == study.model),
            (
                "properties_fingerprint",
                s.properties_fingerprint == study.properties_fingerprint,
            ),
            ("properties", s.properties == study.properties),
            ("schedulers", self.schedulers == opts.count.max(1)),
            (
                "scheduler_memory / selection_runs",
                self.memory == opts.memory.label() && self.selection_runs == opts.selection_runs,
            ),
            (
                "keep_unfair",
                self.keep_unfair == (opts.unfair == Unfair::Keep),
            ),
        ];
        match fields.iter().find(|(_, ok)| !ok) {
            Some((field, _)) => Err(StageError::Mismatch(field)),
            None => Ok(()),
        }
    }
}

/// Runs shard `shard` of the plan's current stage (see the module doc).
pub(crate) fn run_stage(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    plan: &Plan,
    shard: Shard,
) -> Result<StagePart, StageError> {
    if plan.done() {
        return Err(StageError::Done);
    }
    let props = plan.study.properties.len();
    let total: u64 = plan.jobs.iter().map(Job::len).sum();
    let mine = shard.range(total);
    let unfair = if plan.keep_unfair {
        Unfair::Keep
    } else {
        Unfair::LeaveOut
    };
    let runner = Runner::new(model, set, run_cfg).with_unfair(unfair);
    let mut quiet = |_: &crate::smc::Progress<'_>| {};
    let mut results = Vec::new();
    let mut offset = 0;
    for (j, job) in plan.jobs.iter().enumerate() {
        let line = offset..offset + job.len();
        offset = line.end;
        let (lo, hi) = (mine.start.max(line.start), mine.end.min(line.end));
        if lo >= hi {
            continue;
        }
        let range = job.start + (lo - line.start)..job.start + (hi - line.start);
        let cfg = StudyConfig {
            seed: plan.seed(job),
            keep_failing: 0,
            max_runs: None,
            ..study_cfg.clone()
        };
        let sched = plan.scheduler(job);
        let got = run_range(
            &cfg,
            range.clone(),
            props,
            |k, rng| runner.run_under(k, rng, sched),
            &mut quiet,
        );
        let mut why = None;
        if got.runs.failed > 0 {
            why = runner.unfair_run(&sched);
            if why.is_none() {
                runner.finish().map_err(StageError::Model)?;
                return Err(StageError::Silent);
            }
        }
        results.push((j, range, got, why));
    }
    runner.finish().map_err(StageError::Model)?;
    Ok(StagePart {
        format: PART_FORMAT.to_string(),
        plan: plan.clone(),
        shard,
        results,
    })
}

/// Merges the shards of one stage and returns the plan of the next (see the module doc).
pub(crate) fn merge_stage(parts: &[StagePart]) -> Result<Plan, StageError> {
    let first = parts.first().ok_or(StageError::Empty)?;
    let count = first.shard.count;
    let mut by_index = std::collections::BTreeMap::new();
    for part in parts {
        if part.format != PART_FORMAT || part.plan.format != PLAN_FORMAT {
            return Err(StageError::Format(part.format.clone()));
        }
        if part.shard.count != count || part.plan != first.plan {
            return Err(StageError::Foreign(part.shard));
        }
        if let Some(before) = by_index.insert(part.shard.index, part) {
            if before.results != part.results {
                return Err(StageError::Duplicate(part.shard));
            }
        }
    }
    let missing: Vec<Shard> = (0..count)
        .filter(|i| !by_index.contains_key(i))
        .map(|index| Shard { index, count })
        .collect();
    if !missing.is_empty() {
        return Err(StageError::Missing(missing));
    }
    let plan = &first.plan;
    let props = plan.study.properties.len();
    let total: u64 = plan.jobs.iter().map(Job::len).sum();
    let mut sums = vec![
        RangeCounts {
            properties: vec![PropertyCounts::default(); props],
            failing_runs: vec![Vec::new(); props],
            ..RangeCounts::default()
        };
        plan.jobs.len()
    ];
    let mut unfair: Vec<UnfairRun> = vec![None; plan.jobs.len()];
    for part in by_index.values() {
        let bad = |m: String| StageError::Counts(part.shard, m);
        // The runs this shard had to cover, job by job.
        let mine = part.shard.range(total);
        let mut want = Vec::new();
        let mut offset = 0;
        for (j, job) in plan.jobs.iter().enumerate() {
            let (lo, hi) = (mine.start.max(offset), mine.end.min(offset + job.len()));
            if lo < hi {
                want.push((j, job.start + (lo - offset)..job.start + (hi - offset)));
            }
            offset += job.len();
        }
        let got: Vec<(usize, Range<u64>)> = part
            .results
            .iter()
            .map(|(j, r, _, _)| (*j, r.clone()))
            .collect();
        if got != want {
            return Err(bad("it does not cover its own runs of the stage".into()));
        }
        for (j, range, counts, why) in &part.results {
            if let Some((run, reason)) = why {
                if plan.jobs[*j].scheduler.is_none() || !range.contains(run) {
                    return Err(bad(format!(
                        "job {j}: its unfair run is not one of its runs"
                    )));
                }
                // The lowest index over the shards: what one machine meets first.
                let slot = &mut unfair[*j];
                if slot.as_ref().is_none_or(|(k, _)| run < k) {
                    *slot = Some((*run, reason.clone()));
                }
                continue;
            }
            let r = &counts.runs;
            if r.runs != range.end - range.start || r.failed > 0 || r.discarded > r.runs {
                return Err(bad(format!("job {j}: its run counts are not its runs'")));
            }
            if counts.properties.len() != props
                || counts.properties.iter().any(|c| {
                    c.successes
                        .checked_add(c.failures)
                        .and_then(|s| s.checked_add(c.unknown))
                        != Some(r.runs - r.discarded)
                })
            {
                return Err(bad(format!(
                    "job {j}: its verdicts do not sum to its runs not discarded"
                )));
            }
            let sum = &mut sums[*j];
            sum.runs.add(r);
            for (c, g) in sum.properties.iter_mut().zip(&counts.properties) {
                c.add(g);
            }
        }
    }
    let mut next = plan.clone();
    next.advance(sums.into_iter().zip(unfair).collect());
    Ok(next)
}

/// Runs every stage of `plan` in this process (shard `0/1` each): what a sharded study
/// merges to.
pub(crate) fn run_all(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    mut plan: Plan,
    progress: &mut dyn FnMut(&Plan),
) -> Result<Plan, StageError> {
    while !plan.done() {
        progress(&plan);
        let part = run_stage(model, set, run_cfg, study_cfg, &plan, Shard::WHOLE)?;
        plan = merge_stage(&[part])?;
    }
    Ok(plan)
}
