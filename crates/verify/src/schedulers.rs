//! Bounds over schedulers (`verify --schedulers N`): the smallest and largest probability
//! of each property among N sampled deterministic schedulers, each with an interval that
//! stays valid although the scheduler was selected for being extreme.
//!
//! # Method
//!
//! Smart sampling (D'Argenio, Legay, Sedwards, Traonouez, "Smart sampling for lightweight
//! verification of Markov decision processes", STTT 17(4), 2015, Algorithm 1), with the
//! selection and the estimate kept apart:
//!
//! 1. **Schedulers.** Scheduler `i` of a study with seed `s` has the id
//!    `mix(mix(s, IDS), i)` ([`crate::sim::mix`]); its choices are those of
//!    [`crate::sim::Sampled`] (memoryless or history-dependent, `--scheduler-memory`).
//! 2. **Selection.** Every scheduler runs `R` runs (`--selection-runs`); then, for each
//!    property, the half of the survivors with the lowest estimate is kept as min
//!    candidates and the half with the highest as max candidates, and the survivors get
//!    more runs so that every round costs about the same (`N * R` runs), until
//!    `CANDIDATES` remain per property and side. Runs of the selection use the streams
//!    of a seed of their own (`mix(s, SELECT)`), the same run indices for every scheduler.
//! 3. **Estimate.** Each remaining candidate is estimated afresh, by the study's stopping
//!    rule on the streams of another seed (`mix(s, ESTIMATE)`), none of which the
//!    selection saw: a candidate is a fixed scheduler for these runs, so its interval is
//!    an ordinary one. Per property, the min (max) reported is the candidate of its min
//!    (max) side with the lowest (highest) fresh estimate.
//! 4. **Confidence.** Per property, `2 * CANDIDATES` intervals are computed, each at
//!    confidence `1 - (1 - c) / (2 * CANDIDATES)`: by Bonferroni's inequality they all
//!    hold together with probability at least `c`, so the two reported ones do, whichever
//!    was picked.
//!
//! 5. **Sources** (order-sensitive properties only). Each witness is estimated again,
//!    on the same streams as its fresh estimate, with one kind of choice put back to
//!    uniform at a time ([`crate::sim::PutBack`]): which machine moves, which pending
//!    event is delivered, which enabled transition fires. For a kind that moves the
//!    probability by more than twice the precision, each machine's (event's) position
//!    alone is put back too. The kinds and machines whose change moves the probability
//!    most are where the order comes from ([`Source`]). These intervals are each at the
//!    study's confidence on their own: they describe the witnesses, and no bound rests
//!    on them.
//!
//! The guarantee: with confidence `c`, the min interval holds the probability of the
//! property under the min witness scheduler, and the max interval that under the max
//! witness. Hence the true minimum over all schedulers is at most the min interval's upper
//! end, and the true maximum at least the max interval's lower end. Sampling finds
//! extremes only as well as N schedulers reach them: a smaller true minimum (larger
//! maximum) may exist that no sampled scheduler reaches.
//!
//! Results depend on the seed, N, R and the rule, never on the thread count (every batch
//! is a [`run_range`] or [`run_study_until`], which consume runs in index order).

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use super::observe::PropertySet;
use super::study::{Runner, Unfair};
use crate::sim::{
    mix, CompiledModel, EventId, EventSemantics, MachineId, Memory, PutBack, RunConfig, Sampled,
    Scheduler, TransitionChoice,
};
use crate::smc::stats::RuleConfig;
use crate::smc::{run_range, run_study_until, PropertyCounts, StudyConfig};

/// Candidates kept per property and side (min, max) for the fresh estimate.
pub(crate) const CANDIDATES: usize = 2;

/// Salts of the seeds derived from the study seed.
const IDS: u64 = 0x5c4e_d01e_0000_0001;
pub(crate) const SELECT: u64 = 0x5c4e_d01e_0000_0002;
pub(crate) const ESTIMATE: u64 = 0x5c4e_d01e_0000_0003;

/// What `--schedulers` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SchedulerOptions {
    /// Schedulers sampled (at least 1).
    pub count: u64,
    /// What their choices depend on.
    pub memory: Memory,
    /// Runs per scheduler in the first selection round (at least 1).
    pub selection_runs: u64,
    /// What a run that blocks time under a sampled scheduler does: leave the scheduler
    /// out (the default of `verify`), keep the run, or fail the study.
    pub unfair: Unfair,
}

/// Scheduler `i` of a study with `seed`.
pub fn sampled(seed: u64, i: u64, memory: Memory) -> Sampled {
    Sampled {
        id: mix(mix(seed, IDS), i),
        memory,
        uniform: PutBack::default(),
    }
}

/// One bound: the witness scheduler, its fresh estimate and interval.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bound {
    /// The estimate under the witness (`null` with no judged run).
    pub probability: Option<f64>,
    /// Its interval, `[lower, upper]`, at the study's confidence (see the module doc).
    pub interval: [f64; 2],
    /// The witness: what `--scheduler` replays.
    pub scheduler: String,
    /// Judged runs of the fresh estimate.
    pub runs: u64,
    /// Of which satisfied the property.
    pub successes: u64,
}

/// A property's bounds over the sampled schedulers (`"schedulers"` in `verify --json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SchedulerBounds {
    /// Schedulers sampled.
    pub sampled: u64,
    /// `memoryless` or `history`.
    pub memory: String,
    /// The smallest probability found.
    pub min: Bound,
    /// The largest probability found.
    pub max: Bound,
    /// `max - min` exceeds twice the precision: the probability depends on an order the
    /// model leaves open.
    pub order_sensitive: bool,
    /// Where the order comes from (order-sensitive properties only): each witness with
    /// one kind of choice, or one machine's or event's position, put back to uniform.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<Source>,
    /// Sampled schedulers left out as unfair (a run of theirs blocked time), the same
    /// for every property: the bounds are over the others.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub left_out: u64,
    /// The first of them (up to `LEFT_OUT_SHOWN`), in the order they were met.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub left_out_first: Vec<LeftOut>,
}

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// Left-out schedulers listed by name in the report.
pub(crate) const LEFT_OUT_SHOWN: usize = 5;

/// A sampled scheduler left out of the bounds as unfair.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LeftOut {
    /// The scheduler.
    pub scheduler: String,
    /// `selection` or `estimate`: where its unfair run was met.
    pub phase: String,
    /// The run (index in that phase's streams): `verify --scheduler ID` replays it.
    pub run: u64,
    /// Why: the machine and state that kept the instant going.
    pub reason: String,
}

/// An estimate of a source and its interval.
type Estimated = (Option<f64>, [f64; 2]);

/// One witness re-estimated with one kind of choice put back to uniform.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Source {
    /// `min` or `max`: whose witness.
    pub witness: String,
    /// The choice put back: `machine` (which machine moves), `delivery` (which pending
    /// event is delivered), `transition` (which enabled transition fires); with
    /// `machine` or `event` set, that one machine's (event's) position only.
    pub choice: String,
    /// The machine whose position is put back.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// The event whose position is put back.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub event: Option<String>,
    /// The estimate (`null` with no judged run).
    pub probability: Option<f64>,
    /// Its interval at the study's confidence (on its own).
    pub interval: [f64; 2],
    /// `probability` minus the witness's probability.
    pub shift: f64,
    /// What `--scheduler` replays.
    pub scheduler: String,
}

impl Source {
    /// Whether the change moved the witness's probability by more than `2 * precision`.
    pub fn matters(&self, precision: f64) -> bool {
        self.shift.abs() > 2.0 * precision
    }
}

/// One line saying where a property's order comes from, e.g. "depends on whether a or b
/// moves first", from its [`Source`]s (`None` when there are none).
pub fn explain(sources: &[Source], precision: f64) -> Option<String> {
    if sources.is_empty() {
        return None;
    }
    let biggest = |choice: &str, items: bool| -> Vec<&Source> {
        let mut v: Vec<&Source> = sources
            .iter()
            .filter(|s| {
                s.choice == choice
                    && (s.machine.is_some() || s.event.is_some()) == items
                    && s.matters(precision)
            })
            .collect();
        v.sort_by(|a, b| b.shift.abs().total_cmp(&a.shift.abs()));
        v
    };
    let mut kinds: Vec<&Source> = ["machine", "delivery", "transition"]
        .iter()
        .flat_map(|k| biggest(k, false))
        .collect();
    kinds.sort_by(|a, b| b.shift.abs().total_cmp(&a.shift.abs()));
    let Some(top) = kinds.first() else {
        return Some(
            "no one kind of choice moves it alone: the order comes from several kinds at once"
                .to_string(),
        );
    };
    let mut names: Vec<&str> = Vec::new();
    for s in biggest(&top.choice, true) {
        let n = s.machine.as_deref().or(s.event.as_deref()).unwrap_or("");
        if !names.contains(&n) {
            names.push(n);
        }
    }
    let (verb, kind) = match top.choice.as_str() {
        "machine" => ("moves", "which machine moves first"),
        "delivery" => ("is delivered", "which pending event is delivered first"),
        _ => ("fires", "which enabled transition fires"),
    };
    let mut line = match names.as_slice() {
        [] => format!("depends on {kind}"),
        [one] => format!("depends on when {one} {verb} ({kind})"),
        [a, b] => format!("depends on whether {a} or {b} {verb} first"),
        [a, b, rest @ ..] => format!(
            "depends on whether {a} or {b} {verb} first (also {})",
            rest.iter().take(3).copied().collect::<Vec<_>>().join(", ")
        ),
    };
    let others: Vec<&str> = kinds
        .iter()
        .skip(1)
        .map(|s| s.choice.as_str())
        .filter(|c| *c != top.choice)
        .collect();
    if let Some(o) = others.first() {
        line.push_str(&format!("; {o} order matters too"));
    }
    Some(line)
}

/// What happened, for progress lines.
pub enum Stage<'a> {
    /// A selection round starts: survivors and runs each will have.
    Round {
        /// Schedulers still in the running.
        alive: usize,
        /// Runs each will have after the round.
        runs: u64,
    },
    /// The sources of an order-sensitive property are estimated.
    Sources {
        /// The property.
        property: &'a str,
    },
    /// The fresh estimate of candidate `index` of `of` starts.
    Estimate {
        /// 1-based.
        index: usize,
        /// Candidates in all.
        of: usize,
        /// The scheduler.
        scheduler: &'a Scheduler,
    },
}

/// The selection of candidates by successive halving (step 2 of the module doc), as
/// state advanced one round at a time, so that a round's runs can be run in one process
/// ([`bounds`]) or as the shards of a stage ([`super::sched_fixed`]).
///
/// Rounds run only while some side holds more than `CANDIDATES` schedulers: the
/// counts of a round after which nothing is ranked would choose nothing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// Runs of one round in all, `N * R`.
    budget: u64,
    /// Runs each scheduler has after the first round, `R`.
    first: u64,
    /// Per scheduler, its counts per property so far.
    counts: Vec<Vec<PropertyCounts>>,
    /// Per scheduler, the selection runs it had so far (runs `0..done`).
    done: Vec<u64>,
    /// Per property, the min and max sides still in the running.
    pub sides: Vec<[Vec<usize>; 2]>,
    /// The schedulers on some side, in index order.
    pub alive: Vec<usize>,
    /// Runs each of them has after the current round.
    pub per: u64,
}

impl Selection {
    /// The selection of `n` schedulers over `props` properties, `selection_runs` runs
    /// each in the first round.
    pub fn new(n: usize, props: usize, selection_runs: u64) -> Selection {
        let all: Vec<usize> = (0..n).collect();
        let first = selection_runs.max(1);
        let budget = (n as u64).saturating_mul(first);
        Selection {
            budget,
            first,
            counts: vec![vec![PropertyCounts::default(); props]; n],
            done: vec![0; n],
            sides: vec![[all.clone(), all.clone()]; props],
            per: (budget / n.max(1) as u64).max(first),
            alive: all,
        }
    }

    /// Whether every side is down to `CANDIDATES` (no round left to run).
    pub fn finished(&self) -> bool {
        self.sides
            .iter()
            .flatten()
            .all(|side| side.len() <= CANDIDATES)
    }

    /// Leaves scheduler `i` out (unfair): off every side, no more runs.
    pub(crate) fn leave_out(&mut self, i: usize) {
        for side in self.sides.iter_mut().flatten() {
            side.retain(|&j| j != i);
        }
        self.alive.retain(|&j| j != i);
    }

    /// The runs of the current round: per scheduler that needs more, its selection run
    /// indices (streams of the selection seed).
    pub fn round(&self) -> Vec<(usize, std::ops::Range<u64>)> {
        self.alive
            .iter()
            .filter(|&&i| self.done[i] < self.per)
            .map(|&i| (i, self.done[i]..self.per))
            .collect()
    }

    /// Adds the counts of scheduler `i`'s runs of the current round.
    pub(crate) fn absorb(&mut self, i: usize, got: &[PropertyCounts]) {
        for (c, g) in self.counts[i].iter_mut().zip(got) {
            c.add(g);
        }
        self.done[i] = self.per;
    }

    /// Ends the round: per property, keeps the lower and the upper half of each side
    /// (at least [`CANDIDATES`]) by the counts so far, ties by index.
    pub(crate) fn halve(&mut self) {
        let counts = &self.counts;
        for (p, [low, high]) in self.sides.iter_mut().enumerate() {
            let rate = |i: &usize| {
                let c = &counts[*i][p];
                match c.judged() {
                    0 => None,
                    j => Some(c.successes as f64 / j as f64),
                }
            };
            // Unjudged schedulers go last on both sides; ties by index.
            low.sort_by(|a, b| {
                let (x, y) = (
                    rate(a).unwrap_or(f64::INFINITY),
                    rate(b).unwrap_or(f64::INFINITY),
                );
                x.total_cmp(&y).then(a.cmp(b))
            });
            high.sort_by(|a, b| {
                let (x, y) = (rate(a).unwrap_or(-1.0), rate(b).unwrap_or(-1.0));
                y.total_cmp(&x).then(a.cmp(b))
            });
            // Sides have one size unless schedulers were left out.
            low.truncate((low.len() / 2).max(CANDIDATES));
            high.truncate((high.len() / 2).max(CANDIDATES));
        }
        let mut next: Vec<usize> = self
            .sides
            .iter()
            .flat_map(|s| s.iter().flatten().copied())
            .collect();
        next.sort_unstable();
        next.dedup();
        self.alive = next;
        self.per = (self.budget / self.alive.len().max(1) as u64).max(self.first);
    }
}

/// Per property, the min and max witnesses among its sides' candidates: the candidate
/// with the lowest (highest) fresh estimate `value(i, p)`, ties by index, unjudged ones
/// last.
pub fn witnesses(
    sides: &[[Vec<usize>; 2]],
    value: impl Fn(usize, usize) -> Option<f64>,
) -> Vec<[usize; 2]> {
    sides
        .iter()
        .enumerate()
        .map(|(p, [low, high])| {
            let lo = *low
                .iter()
                .min_by(|a, b| {
                    let (x, y) = (
                        value(**a, p).unwrap_or(f64::INFINITY),
                        value(**b, p).unwrap_or(f64::INFINITY),
                    );
                    x.total_cmp(&y).then(a.cmp(b))
                })
                .expect("at least one candidate");
            let hi = *high
                .iter()
                .min_by(|a, b| {
                    let (x, y) = (value(**a, p).unwrap_or(-1.0), value(**b, p).unwrap_or(-1.0));
                    y.total_cmp(&x).then(a.cmp(b))
                })
                .expect("at least one candidate");
            [lo, hi]
        })
        .collect()
}

/// The intervals each property's confidence is split over: the most candidates on a
/// property's two sides (`2 K`; with schedulers left out a property's sides may hold
/// fewer, and the most keeps the split valid for each).
pub(crate) fn split_count(sides: &[[Vec<usize>; 2]]) -> usize {
    sides
        .iter()
        .map(|[low, high]| low.len() + high.len())
        .max()
        .unwrap_or(2)
        .max(1)
}

/// The confidence of each fresh estimate: `1 - (1 - c) / m` over `m` intervals
/// ([`split_count`]; Bonferroni's inequality).
pub(crate) fn split_rule(rule: &RuleConfig, m: usize) -> RuleConfig {
    RuleConfig {
        confidence: 1.0 - (1.0 - rule.confidence) / m.max(1) as f64,
        ..*rule
    }
}

/// Why [`bounds`] failed.
#[derive(Debug)]
pub enum BoundsError {
    /// The model failed during a run.
    Model(crate::study::ModelFailure),
    /// A run of this phase failed and left no message.
    Silent(&'static str),
    /// The stopping rule is invalid.
    Rule(crate::smc::stats::StatsError),
    /// A fixed-size study's plan asked for its report before its last stage (the stage).
    Unfinished(u32),
    /// Every candidate of some property's side was left out as unfair.
    AllUnfair {
        /// Schedulers left out.
        left_out: u64,
        /// Sampled.
        sampled: u64,
    },
}

impl std::fmt::Display for BoundsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoundsError::Model(m) => write!(f, "{m}"),
            BoundsError::Silent(what) => write!(f, "{what} failed without a message"),
            BoundsError::Rule(e) => write!(f, "statistics: {e}"),
            BoundsError::Unfinished(stage) => write!(
                f,
                "the scheduler study's plan is at stage {stage}, not finished: run its shards \
                 with --plan and merge them"
            ),
            BoundsError::AllUnfair { left_out, sampled } => write!(
                f,
                "{left_out} of {sampled} sampled schedulers were left out as unfair (a run \
                 blocked time), leaving no candidate on some side: sample more schedulers, \
                 or keep them with --keep-unfair"
            ),
        }
    }
}

impl std::error::Error for BoundsError {}

/// Bounds over `opts.count` sampled schedulers, one per guarantee of `set`, or `None` when
/// `stop` was set before the end. `study_cfg` gives the seed and threads (its `max_runs`
/// caps each fresh estimate), `rule` the stopping rule and the confidence split over the
/// candidates.
#[allow(clippy::too_many_arguments)]
pub fn bounds(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    study_cfg: &StudyConfig,
    rule: &RuleConfig,
    opts: &SchedulerOptions,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(Stage<'_>),
) -> Result<Option<Vec<SchedulerBounds>>, BoundsError> {
    let props = set.guarantee_names().len();
    let n = opts.count.max(1) as usize;
    let seed = study_cfg.seed;
    let scheds: Vec<Scheduler> = (0..n as u64)
        .map(|i| Scheduler::Sampled(sampled(seed, i, opts.memory)))
        .collect();
    let runner = Runner::new(model, set, run_cfg).with_unfair(opts.unfair);
    let mut quiet = |_: &crate::smc::Progress<'_>| {};
    let mut left_out: Vec<LeftOut> = Vec::new();
    let mut leave_out = |i: usize, phase: &str, (run, reason): (u64, String)| {
        left_out.push(LeftOut {
            scheduler: scheds[i].to_string(),
            phase: phase.to_string(),
            run,
            reason,
        });
    };

    // Selection: successive halving per property and side.
    let select_cfg = StudyConfig {
        seed: mix(seed, SELECT),
        keep_failing: 0,
        max_runs: None,
        ..study_cfg.clone()
    };
    let mut selection = Selection::new(n, props, opts.selection_runs);
    while !selection.finished() {
        progress(Stage::Round {
            alive: selection.alive.len(),
            runs: selection.per,
        });
        for (i, range) in selection.round() {
            if stop.load(Ordering::Relaxed) {
                return Ok(None);
            }
            let got = run_range(
                &select_cfg,
                range,
                props,
                |k, rng| runner.run_under(k, rng, scheds[i]),
                &mut quiet,
            );
            if got.runs.failed > 0 {
                if let Some(why) = runner.unfair_run(&scheds[i]) {
                    leave_out(i, "selection", why);
                    selection.leave_out(i);
                    continue;
                }
                runner.finish().map_err(BoundsError::Model)?;
                return Err(BoundsError::Silent("a selection run"));
            }
            selection.absorb(i, &got.properties);
        }
        selection.halve();
    }
    let (mut sides, alive) = (selection.sides, selection.alive);

    // Fresh estimates of the candidates, confidence split over each property's 2K.
    let split = split_rule(rule, split_count(&sides));
    let rules = (0..props)
        .map(|_| split.build())
        .collect::<Result<Vec<_>, _>>()
        .map_err(BoundsError::Rule)?;
    let estimate_cfg = StudyConfig {
        seed: mix(seed, ESTIMATE),
        keep_failing: 0,
        ..study_cfg.clone()
    };
    let mut fresh = vec![None; n];
    for (j, &i) in alive.iter().enumerate() {
        progress(Stage::Estimate {
            index: j + 1,
            of: alive.len(),
            scheduler: &scheds[i],
        });
        let r = run_study_until(
            &estimate_cfg,
            &rules,
            |k, rng| runner.run_under(k, rng, scheds[i]),
            &mut quiet,
            stop,
        );
        if r.runs.failed > 0 {
            if let Some(why) = runner.unfair_run(&scheds[i]) {
                leave_out(i, "estimate", why);
                for side in sides.iter_mut().flatten() {
                    side.retain(|&j| j != i);
                }
                continue;
            }
            runner.finish().map_err(BoundsError::Model)?;
            return Err(BoundsError::Silent("an estimate run"));
        }
        if r.interrupted {
            return Ok(None);
        }
        fresh[i] = Some(r.properties);
    }

    let bound = |i: usize, p: usize| -> Bound {
        let r = &fresh[i].as_ref().expect("every candidate was estimated")[p];
        Bound {
            probability: r.estimate.estimate,
            interval: [r.interval.lower, r.interval.upper],
            scheduler: scheds[i].to_string(),
            runs: r.counts.judged(),
            successes: r.counts.successes,
        }
    };
    if sides.iter().flatten().any(|side| side.is_empty()) {
        return Err(BoundsError::AllUnfair {
            left_out: left_out.len() as u64,
            sampled: n as u64,
        });
    }
    let value = |i: usize, p: usize| fresh[i].as_ref().and_then(|r| r[p].estimate.estimate);
    let witnesses = witnesses(&sides, value);
    let mut out = Vec::with_capacity(props);
    for (p, &[lo, hi]) in witnesses.iter().enumerate() {
        let (min, max) = (bound(lo, p), bound(hi, p));
        let order_sensitive = match (min.probability, max.probability) {
            (Some(a), Some(b)) => b - a > 2.0 * rule.precision,
            _ => false,
        };
        out.push(SchedulerBounds {
            sampled: n as u64,
            memory: opts.memory.label().to_string(),
            min,
            max,
            order_sensitive,
            sources: Vec::new(),
            left_out: left_out.len() as u64,
            left_out_first: left_out.iter().take(LEFT_OUT_SHOWN).cloned().collect(),
        });
    }

    // Sources: the witnesses again with one kind of choice put back to uniform, on the
    // streams of their fresh estimate. Every property's estimate comes from each study,
    // so a study serves every property whose witness it replays.
    let rules = (0..props)
        .map(|_| rule.build())
        .collect::<Result<Vec<_>, _>>()
        .map_err(BoundsError::Rule)?;
    let mut cache: std::collections::HashMap<Scheduler, Vec<crate::smc::PropertyResult>> =
        Default::default();
    let names = set.guarantee_names();
    for p in 0..props {
        if !out[p].order_sensitive {
            continue;
        }
        progress(Stage::Sources {
            property: &names[p],
        });
        let mut sources = Vec::new();
        for (side, &i) in ["min", "max"].iter().zip(&witnesses[p]) {
            let Scheduler::Sampled(w) = scheds[i] else {
                continue;
            };
            let base = fresh[i].as_ref().and_then(|r| r[p].estimate.estimate);
            // Err(true): a run of it blocked time (the source is left out); Err(false): the
            // model failed.
            let mut estimate = |uniform: PutBack| -> Result<Option<Estimated>, bool> {
                let sched = Scheduler::Sampled(Sampled { uniform, ..w });
                if let std::collections::hash_map::Entry::Vacant(slot) = cache.entry(sched) {
                    let r = run_study_until(
                        &estimate_cfg,
                        &rules,
                        |k, rng| runner.run_under(k, rng, sched),
                        &mut quiet,
                        stop,
                    );
                    if r.runs.failed > 0 {
                        return Err(runner.unfair_run(&sched).is_some());
                    }
                    if r.interrupted {
                        return Ok(None);
                    }
                    slot.insert(r.properties);
                }
                let r = &cache[&sched][p];
                Ok(Some((
                    r.estimate.estimate,
                    [r.interval.lower, r.interval.upper],
                )))
            };
            // Each choice put back to uniform, where the run's semantics makes it one.
            let none = PutBack::default();
            let kinds = [
                (
                    "machine",
                    true,
                    PutBack {
                        machines: true,
                        ..none
                    },
                ),
                (
                    "delivery",
                    run_cfg.events == EventSemantics::As2fm,
                    PutBack {
                        events: true,
                        ..none
                    },
                ),
                (
                    "transition",
                    run_cfg.transitions == TransitionChoice::Random,
                    PutBack {
                        transitions: true,
                        ..none
                    },
                ),
            ]
            .into_iter()
            .filter_map(|(choice, made, uniform)| made.then_some((choice, uniform)));
            for (choice, uniform) in kinds {
                let (probability, interval) = match estimate(uniform) {
                    Ok(Some(x)) => x,
                    Ok(None) => return Ok(None),
                    Err(true) => continue,
                    Err(false) => {
                        runner.finish().map_err(BoundsError::Model)?;
                        return Err(BoundsError::Silent("a run of the sources"));
                    }
                };
                let source = Source {
                    witness: side.to_string(),
                    choice: choice.to_string(),
                    machine: None,
                    event: None,
                    probability,
                    interval,
                    shift: probability.unwrap_or(0.0) - base.unwrap_or(0.0),
                    scheduler: Scheduler::Sampled(Sampled { uniform, ..w }).to_string(),
                };
                let deeper = source.matters(rule.precision);
                sources.push(source);
                if !deeper || choice == "transition" {
                    continue;
                }
                // One machine's (event's) position at a time.
                let items: Vec<(PutBack, Option<String>, Option<String>)> = if choice == "machine" {
                    (0..model.machine_count() as u32)
                        .map(|m| {
                            (
                                PutBack {
                                    machine: Some(m),
                                    ..PutBack::default()
                                },
                                Some(model.machine_name(MachineId(m)).to_string()),
                                None,
                            )
                        })
                        .collect()
                } else {
                    (0..model.event_count() as u32)
                        .filter(|&e| model.event_receivers(EventId(e)).next().is_some())
                        .map(|e| {
                            (
                                PutBack {
                                    event: Some(e),
                                    ..PutBack::default()
                                },
                                None,
                                Some(model.event_name(EventId(e)).to_string()),
                            )
                        })
                        .collect()
                };
                for (uniform, machine, event) in items {
                    let (probability, interval) = match estimate(uniform) {
                        Ok(Some(x)) => x,
                        Ok(None) => return Ok(None),
                        Err(true) => continue,
                        Err(false) => {
                            runner.finish().map_err(BoundsError::Model)?;
                            return Err(BoundsError::Silent("a run of the sources"));
                        }
                    };
                    sources.push(Source {
                        witness: side.to_string(),
                        choice: choice.to_string(),
                        machine,
                        event,
                        probability,
                        interval,
                        shift: probability.unwrap_or(0.0) - base.unwrap_or(0.0),
                        scheduler: Scheduler::Sampled(Sampled { uniform, ..w }).to_string(),
                    });
                }
            }
        }
        out[p].sources = sources;
    }
    runner.finish().map_err(BoundsError::Model)?;
    Ok(Some(out))
}
