//! The deterministic parallel runner: run `k` draws from stream `k` of xoshiro256++, and
//! the stopping rules consume results strictly in run-index order.
//!
//! # Streams
//!
//! The generator is seeded from the study seed ([`SeedableRng::seed_from_u64`]); stream
//! `k` is that generator after `k` calls of [`Xoshiro256PlusPlus::jump`] (`2^128` draws
//! apart, so streams never overlap). The runner keeps the next stream and jumps it once
//! per run handed out, never from zero; [`stream`] rebuilds one stream on its own (to
//! replay run `k` and write its trace).
//!
//! # Order and determinism
//!
//! Worker threads take run indices in increasing order and run them concurrently; the
//! calling thread puts finished runs in a reorder buffer and hands them to the stopping
//! rules strictly by index. The study stops after the first index at which every rule is
//! done, so the runs it uses, and every number it reports, are a function of the seed
//! alone: identical on 1 or N threads, and with no bias toward runs that finish quickly.
//! Runs started past the stopping index are thrown away unused. Workers never run more
//! than a bounded window ahead of the oldest unconsumed run, so memory stays bounded.
//!
//! # Policy for runs that are discarded or cut short
//!
//! - A run whose assumptions are violated ([`RunOutcome::assumptions`] is
//!   [`Verdict::False`]) is *discarded*: counted in [`RunCounts::discarded`] and seen by
//!   no property. Estimates are conditional on the assumptions.
//! - A run that reaches the model's time horizon ([`RunEnd::TimeHorizon`]) is complete:
//!   the horizon is part of the question (as in SCAN), and its verdicts count.
//! - A run stopped by the step limit ([`RunEnd::StepLimit`]) is *cut short* and counted as
//!   such ([`RunCounts::step_limit`]). Only verdicts that could no longer change (the run
//!   function reports them as [`Verdict::True`] / [`Verdict::False`]) count; a verdict
//!   that could still change must be reported as [`Verdict::Unknown`]. The same holds
//!   for assumptions: an unknown assumption makes every verdict of that run unknown.
//! - Unknown verdicts are never judged: they are counted per property
//!   ([`PropertyCounts::unknown`]), they do not enter the stopping rule, and the reported
//!   interval ([`PropertyResult::interval`]) is widened to cover every possible value of
//!   those runs: with `n` judged runs, `u` unknown ones and rule interval `[lo, hi]`, it
//!   is `[lo n / (n + u), (hi n + u) / (n + u)]`.
//!
//! # Per-property stopping
//!
//! Every property has its own rule. A property's counts are frozen at the run where its
//! rule becomes done (that run's index is [`PropertyResult::stopped_at`]); the study
//! goes on until every rule is done or [`StudyConfig::max_runs`] runs were consumed.
//!
//! A property none of whose runs can be judged (every one cut short before its verdict
//! was final, or discarded by the assumptions) would keep a study going forever: no run
//! brings its rule closer to done. So once [`UNJUDGED_LIMIT`] runs were consumed and no
//! property that is not done has a single judged run, the study stops there
//! ([`StudyResult::unjudged`]): those properties have no estimate, and the runs say why
//! (their counts of unknown and discarded runs). A property with some judged runs goes
//! on, however rare they are.
//!
//! # Interruption
//!
//! [`run_study_until`] also takes a stop flag (set by `verify`'s Ctrl-C handler). Once it
//! is set, no worker takes a new run index (one atomic load per run handed out, none per
//! step); the runs already started finish and are consumed in index order like any
//! others, so the partial study is the study of runs `0..n` for some `n`, and
//! [`StudyResult::interrupted`] says it stopped early. When the flag is never set, the
//! study is exactly [`run_study`]'s.

use std::collections::BTreeMap;
use std::ops::{ControlFlow, Range};
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Condvar, Mutex, PoisonError};
use std::thread;
use std::time::{Duration, Instant};

use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use super::stats::{Estimate, Interval, StoppingRule};

/// The verdict of one property (or of the assumptions) on one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The run satisfies the property.
    True,
    /// The run violates the property.
    False,
    /// The run was cut short before the verdict became final: not judged.
    Unknown,
}

impl From<bool> for Verdict {
    fn from(value: bool) -> Verdict {
        if value {
            Verdict::True
        } else {
            Verdict::False
        }
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunEnd {
    /// Nothing could move any more.
    Quiescent,
    /// Every verdict became final, so the run was stopped early.
    Decided,
    /// The model's time horizon (`--max-time`) was reached: a complete run.
    TimeHorizon,
    /// The step limit (`--max-steps`) was reached: the run was cut short.
    StepLimit,
    /// The model failed (a run-time error, a loop that lets no time pass, a message a
    /// property cannot read): its verdicts are unknown and the study stops at once, so
    /// that the failure is reported instead of being run around.
    Failed,
}

/// What one run reports to the runner.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOutcome {
    /// One verdict per property, in the order of the study's rules. Missing entries
    /// count as [`Verdict::Unknown`], extra ones are ignored.
    pub verdicts: Vec<Verdict>,
    /// Whether the assumptions held ([`Verdict::True`], also when there are none), were
    /// violated (the run is discarded), or could not be judged.
    pub assumptions: Verdict,
    /// Why the run ended.
    pub end: RunEnd,
    /// Simulation steps taken.
    pub steps: u64,
    /// Model time at the end of the run, in the model's time unit.
    pub time: u64,
}

/// The generator of stream `k` for a study seed: seeded from `seed`, then jumped `k`
/// times. Beyond a few thousand jumps it applies the jump's powers instead (`jump.rs`):
/// the same generator, at a cost that does not grow with `k`. The runner itself derives
/// the streams after the first one incrementally.
pub fn stream(seed: u64, k: u64) -> Xoshiro256PlusPlus {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    if k >= crate::jump::FEW_JUMPS {
        return crate::jump::jumped(&rng, k);
    }
    for _ in 0..k {
        rng.jump();
    }
    rng
}

/// Per-property counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PropertyCounts {
    /// Judged runs that satisfied the property.
    pub successes: u64,
    /// Judged runs that violated it.
    pub failures: u64,
    /// Runs whose verdict was unknown (cut short): not judged.
    pub unknown: u64,
}

impl PropertyCounts {
    /// Judged runs: `successes + failures`.
    pub fn judged(&self) -> u64 {
        self.successes + self.failures
    }

    /// Adds another set of counts.
    pub fn add(&mut self, other: &PropertyCounts) {
        self.successes += other.successes;
        self.failures += other.failures;
        self.unknown += other.unknown;
    }

    fn record(&mut self, verdict: Verdict) {
        match verdict {
            Verdict::True => self.successes += 1,
            Verdict::False => self.failures += 1,
            Verdict::Unknown => self.unknown += 1,
        }
    }
}

/// Counts over all runs consumed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunCounts {
    /// Runs consumed (in index order), discarded ones included.
    pub runs: u64,
    /// Runs discarded because an assumption was violated.
    pub discarded: u64,
    /// Runs that ended in quiescence.
    pub quiescent: u64,
    /// Runs stopped early because every verdict was final.
    pub decided: u64,
    /// Runs that reached the time horizon.
    pub time_horizon: u64,
    /// Runs cut short by the step limit.
    pub step_limit: u64,
    /// Runs in which the model failed (the study stops at the first).
    #[serde(default)]
    pub failed: u64,
    /// Simulation steps, summed over runs.
    pub steps: u64,
    /// Model time, summed over runs.
    pub model_time: u64,
}

impl RunCounts {
    /// Adds another set of counts.
    pub fn add(&mut self, other: &RunCounts) {
        self.runs += other.runs;
        self.discarded += other.discarded;
        self.quiescent += other.quiescent;
        self.decided += other.decided;
        self.time_horizon += other.time_horizon;
        self.step_limit += other.step_limit;
        self.failed += other.failed;
        self.steps += other.steps;
        self.model_time += other.model_time;
    }

    fn record(&mut self, outcome: &RunOutcome) {
        self.runs += 1;
        self.steps += outcome.steps;
        self.model_time += outcome.time;
        match outcome.end {
            RunEnd::Quiescent => self.quiescent += 1,
            RunEnd::Decided => self.decided += 1,
            RunEnd::TimeHorizon => self.time_horizon += 1,
            RunEnd::StepLimit => self.step_limit += 1,
            RunEnd::Failed => self.failed += 1,
        }
        if outcome.assumptions == Verdict::False {
            self.discarded += 1;
        }
    }
}

/// The per-property verdicts of one run after the assumption policy: `None` when the run
/// is discarded.
fn effective_verdict(outcome: &RunOutcome, property: usize) -> Option<Verdict> {
    match outcome.assumptions {
        Verdict::False => None,
        Verdict::Unknown => Some(Verdict::Unknown),
        Verdict::True => Some(
            outcome
                .verdicts
                .get(property)
                .copied()
                .unwrap_or(Verdict::Unknown),
        ),
    }
}

/// The interval of `rule` on the judged runs, widened to cover the unknown ones.
pub fn widened_interval(rule: &dyn StoppingRule, counts: &PropertyCounts) -> Interval {
    let judged = counts.judged();
    let interval = rule.interval(counts.successes, judged);
    if counts.unknown == 0 {
        return interval;
    }
    let n = judged as f64;
    let total = n + counts.unknown as f64;
    Interval::clipped(
        interval.lower * n / total,
        (interval.upper * n + counts.unknown as f64) / total,
    )
}

/// Settings of a sequential study.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyConfig {
    /// The study seed.
    pub seed: u64,
    /// Worker threads; `0` means [`thread::available_parallelism`].
    pub threads: usize,
    /// Stop after this many runs even if some rule is not done.
    pub max_runs: Option<u64>,
    /// Keep the indices of up to this many failing runs per property (to replay them).
    pub keep_failing: usize,
    /// Minimum time between two progress reports.
    pub progress_every: Duration,
}

impl Default for StudyConfig {
    fn default() -> StudyConfig {
        StudyConfig {
            seed: 0,
            threads: 0,
            max_runs: None,
            keep_failing: 0,
            progress_every: Duration::from_millis(100),
        }
    }
}

impl StudyConfig {
    /// The number of worker threads this configuration asks for.
    pub(crate) fn thread_count(&self) -> usize {
        if self.threads > 0 {
            self.threads.min(MAX_THREADS)
        } else {
            thread::available_parallelism().map_or(1, |n| n.get())
        }
    }
}

/// The result for one property.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PropertyResult {
    /// Counts, frozen when the rule became done.
    pub counts: PropertyCounts,
    /// The rule's report on the judged runs.
    pub estimate: Estimate,
    /// The interval to report: the rule's, widened over unknown runs (see the module doc).
    pub interval: Interval,
    /// Index of the run after which the rule was done; `None` if it never was.
    pub stopped_at: Option<u64>,
    /// Indices of the first failing runs (up to [`StudyConfig::keep_failing`]).
    pub failing_runs: Vec<u64>,
}

/// A progress report, given to the callback at most every
/// [`StudyConfig::progress_every`] and once at the end.
#[derive(Clone, Debug)]
pub struct Progress<'a> {
    /// Runs consumed so far.
    pub runs: u64,
    /// Time since the study started.
    pub elapsed: Duration,
    /// Estimated time left, when the rules can say.
    pub eta: Option<Duration>,
    /// Estimated total runs the study will consume, when the rules can say.
    pub expected_runs: Option<u64>,
    /// Current per-property results.
    pub properties: &'a [PropertyResult],
    /// Whether this is the last report.
    pub finished: bool,
}

/// The outcome of a sequential study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyResult {
    /// The study seed.
    pub seed: u64,
    /// One result per rule, in order.
    pub properties: Vec<PropertyResult>,
    /// Counts over every run consumed.
    pub runs: RunCounts,
    /// Whether the study stopped at [`StudyConfig::max_runs`] with some rule not done
    /// (or was interrupted with some rule not done).
    pub capped: bool,
    /// Whether the stop flag of [`run_study_until`] ended the study before every rule was
    /// done: the counts are those of the runs consumed, a partial study.
    #[serde(default)]
    pub interrupted: bool,
    /// Whether the study stopped after [`UNJUDGED_LIMIT`] runs because no property that
    /// was not done had a judged run (see the module doc).
    #[serde(default)]
    pub unjudged: bool,
    /// Wall-clock time (not deterministic, unlike everything else).
    pub elapsed: Duration,
}

/// The most worker threads a study starts: each is an OS thread, and the results do not
/// depend on the count, so [`StudyConfig::threads`] above it is taken as this.
pub const MAX_THREADS: usize = 1024;

/// Runs after which a sequential study stops when no property still going has a judged
/// run (every run cut short or discarded): the module doc, "Per-property stopping".
pub const UNJUDGED_LIMIT: u64 = 1000;

/// Where one property stands during a study.
struct Tracker {
    counts: PropertyCounts,
    stopped_at: Option<u64>,
    failing: Vec<u64>,
}

fn result_of(rule: &dyn StoppingRule, tracker: &Tracker) -> PropertyResult {
    PropertyResult {
        counts: tracker.counts,
        estimate: rule.estimate(tracker.counts.successes, tracker.counts.judged()),
        interval: widened_interval(rule, &tracker.counts),
        stopped_at: tracker.stopped_at,
        failing_runs: tracker.failing.clone(),
    }
}

/// Runs still to consume: the largest number of judged runs a rule still needs, scaled
/// by the share of runs that are judged for it. `None` when some rule cannot say.
fn remaining_runs(
    rules: &[Box<dyn StoppingRule>],
    trackers: &[Tracker],
    consumed: u64,
) -> Option<f64> {
    if consumed == 0 {
        return None;
    }
    let mut remaining_runs = 0.0f64;
    for (rule, tracker) in rules.iter().zip(trackers) {
        if tracker.stopped_at.is_some() {
            continue;
        }
        let judged = tracker.counts.judged();
        let needed = rule.runs_needed(tracker.counts.successes, judged)?;
        // Judged runs per consumed run (discards and unknowns do not count).
        let rate = judged.max(1) as f64 / consumed as f64;
        remaining_runs = remaining_runs.max(needed.saturating_sub(judged) as f64 / rate);
    }
    Some(remaining_runs)
}

/// How often (in consumed runs) the runner re-estimates the runs still needed, to keep
/// workers from starting runs far past the likely stopping point.
const HINT_EVERY: u64 = 8;

/// Runs a sequential study: run `k` gets stream `k`, results are consumed in index order
/// by one rule per property, and the study stops when every rule is done (or at
/// [`StudyConfig::max_runs`]). `rules.len()` is the number of properties.
///
/// `progress` is called on the calling thread. A panic in `run` is propagated.
pub fn run_study<F>(
    config: &StudyConfig,
    rules: &[Box<dyn StoppingRule>],
    run: F,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> StudyResult
where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
{
    run_study_until(config, rules, run, progress, &AtomicBool::new(false))
}

/// [`run_study`] that also stops when `stop` is set (see the module doc, Interruption):
/// no run is started after that, the runs in progress are finished and consumed in index
/// order, and the result has [`StudyResult::interrupted`] set if some rule was not done.
pub fn run_study_until<F>(
    config: &StudyConfig,
    rules: &[Box<dyn StoppingRule>],
    run: F,
    progress: &mut dyn FnMut(&Progress<'_>),
    stop: &AtomicBool,
) -> StudyResult
where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
{
    let start = Instant::now();
    let mut trackers: Vec<Tracker> = rules
        .iter()
        .map(|_| Tracker {
            counts: PropertyCounts::default(),
            stopped_at: None,
            failing: Vec::new(),
        })
        .collect();
    let mut runs = RunCounts::default();
    let mut last_report = start;
    let mut remaining_hint = u64::MAX;
    let mut unjudged = false;
    let all_done = |trackers: &[Tracker]| trackers.iter().all(|t| t.stopped_at.is_some());
    let end = config.max_runs;
    let mut report = |trackers: &[Tracker], consumed: u64, finished: bool| {
        let elapsed = start.elapsed();
        let properties: Vec<PropertyResult> = rules
            .iter()
            .zip(trackers)
            .map(|(rule, tracker)| result_of(rule.as_ref(), tracker))
            .collect();
        let remaining = if finished {
            Some(0.0)
        } else {
            remaining_runs(rules, trackers, consumed)
        };
        let eta = remaining.map(|remaining| {
            let per_run = elapsed.as_secs_f64() / consumed.max(1) as f64;
            Duration::from_secs_f64((remaining * per_run).min(1e9))
        });
        progress(&Progress {
            runs: consumed,
            elapsed,
            eta,
            expected_runs: remaining.map(|remaining| consumed + remaining.ceil() as u64),
            properties: &properties,
            finished,
        });
    };

    if !all_done(&trackers) && end != Some(0) {
        drive(
            config.seed,
            config.thread_count(),
            0,
            end,
            stop,
            &run,
            |index, outcome| {
                runs.record(&outcome);
                if outcome.end == RunEnd::Failed {
                    return ControlFlow::Break(());
                }
                for (i, (rule, tracker)) in rules.iter().zip(trackers.iter_mut()).enumerate() {
                    if tracker.stopped_at.is_some() {
                        continue;
                    }
                    let Some(verdict) = effective_verdict(&outcome, i) else {
                        continue;
                    };
                    tracker.counts.record(verdict);
                    if verdict == Verdict::False && tracker.failing.len() < config.keep_failing {
                        tracker.failing.push(index);
                    }
                    if verdict != Verdict::Unknown
                        && rule.done(tracker.counts.successes, tracker.counts.judged())
                    {
                        tracker.stopped_at = Some(index);
                    }
                }
                if all_done(&trackers) {
                    return ControlFlow::Break(());
                }
                if runs.runs >= UNJUDGED_LIMIT
                    && trackers
                        .iter()
                        .all(|t| t.stopped_at.is_some() || t.counts.judged() == 0)
                {
                    unjudged = true;
                    return ControlFlow::Break(());
                }
                let now = Instant::now();
                if now.duration_since(last_report) >= config.progress_every {
                    last_report = now;
                    report(&trackers, runs.runs, false);
                }
                remaining_hint = if runs.runs % HINT_EVERY == 0 {
                    remaining_runs(rules, &trackers, runs.runs)
                        .map_or(u64::MAX, |remaining| remaining.ceil() as u64)
                } else {
                    remaining_hint.saturating_sub(1)
                };
                ControlFlow::Continue(remaining_hint)
            },
        );
    }
    report(&trackers, runs.runs, true);
    let capped = !all_done(&trackers);
    // Stopped by the flag, not by the rules, the cap or a failed run.
    let interrupted = capped
        && stop.load(Ordering::Relaxed)
        && runs.failed == 0
        && end.is_none_or(|end| runs.runs < end);
    StudyResult {
        seed: config.seed,
        properties: rules
            .iter()
            .zip(&trackers)
            .map(|(rule, tracker)| result_of(rule.as_ref(), tracker))
            .collect(),
        runs,
        capped,
        interrupted,
        unjudged,
        elapsed: start.elapsed(),
    }
}

/// Counts of a fixed range of runs (a shard, or a whole fixed-size study).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RangeCounts {
    /// Per-property counts over the whole range.
    pub properties: Vec<PropertyCounts>,
    /// Indices of the first failing runs per property (up to `keep_failing`).
    pub failing_runs: Vec<Vec<u64>>,
    /// Counts over every run of the range.
    pub runs: RunCounts,
}

/// Runs every index of `range` exactly once (run `k` on stream `k` of `seed`) and counts
/// verdicts for `properties` properties, with the policy of the module doc. Progress
/// reports carry no per-property results (`properties` is empty) and an ETA from the
/// range's size.
pub fn run_range<F>(
    config: &StudyConfig,
    range: Range<u64>,
    properties: usize,
    run: F,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> RangeCounts
where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
{
    let start = Instant::now();
    let mut counts = RangeCounts {
        properties: vec![PropertyCounts::default(); properties],
        failing_runs: vec![Vec::new(); properties],
        runs: RunCounts::default(),
    };
    let total = range.end.saturating_sub(range.start);
    let mut last_report = start;
    let mut report = |done: u64, finished: bool| {
        let elapsed = start.elapsed();
        let eta = (done > 0).then(|| {
            let per_run = elapsed.as_secs_f64() / done as f64;
            Duration::from_secs_f64((per_run * (total - done) as f64).min(1e9))
        });
        progress(&Progress {
            runs: done,
            elapsed,
            eta,
            expected_runs: Some(total),
            properties: &[],
            finished,
        });
    };
    if total > 0 {
        drive(
            config.seed,
            config.thread_count(),
            range.start,
            Some(range.end),
            &AtomicBool::new(false),
            &run,
            |index, outcome| {
                counts.runs.record(&outcome);
                if outcome.end == RunEnd::Failed {
                    return ControlFlow::Break(());
                }
                for i in 0..properties {
                    let Some(verdict) = effective_verdict(&outcome, i) else {
                        continue;
                    };
                    counts.properties[i].record(verdict);
                    if verdict == Verdict::False
                        && counts.failing_runs[i].len() < config.keep_failing
                    {
                        counts.failing_runs[i].push(index);
                    }
                }
                let now = Instant::now();
                if now.duration_since(last_report) >= config.progress_every {
                    last_report = now;
                    report(counts.runs.runs, false);
                }
                ControlFlow::Continue(u64::MAX)
            },
        );
    }
    report(counts.runs.runs, true);
    counts
}

/// How far (in runs) workers may run ahead of the oldest unconsumed run, per thread.
const WINDOW_PER_THREAD: u64 = 64;

/// Shared between the consumer and the workers.
struct Dispenser {
    /// The next run index to hand out.
    next: u64,
    /// The generator of stream `next`.
    rng: Xoshiro256PlusPlus,
    /// Workers may not take an index at or past this (the reorder window).
    window_end: u64,
    /// Set when the consumer has stopped (or a run panicked).
    stop: bool,
}

/// What a worker sends back.
type Finished = (u64, thread::Result<RunOutcome>);

/// Runs indices `start, start + 1, ...` (up to `end`, exclusive, if given) on `threads`
/// threads and calls `consume` strictly in index order on the calling thread, until it
/// breaks or the range is exhausted. `consume` continues with its estimate of the runs
/// still needed (`u64::MAX` for "unknown"): workers start at most that many runs (plus
/// one per thread) past the last consumed one, so few runs are wasted at the end.
///
/// Once `stop` is set no new index is handed out; the runs already started finish and
/// are consumed in order (they form a contiguous range, so none is lost).
fn drive<F, C>(
    seed: u64,
    threads: usize,
    start: u64,
    end: Option<u64>,
    stop: &AtomicBool,
    run: &F,
    mut consume: C,
) where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
    C: FnMut(u64, RunOutcome) -> ControlFlow<(), u64>,
{
    let mut rng = stream(seed, start);
    let past_end = |index: u64| end.is_some_and(|end| index >= end);
    // One relaxed load per run handed out: the flag only has to be seen soon, not at once.
    let stopped = || stop.load(Ordering::Relaxed);
    if threads <= 1 {
        let mut index = start;
        while !past_end(index) && !stopped() {
            let mut own = rng.clone();
            rng.jump();
            let outcome = run(index, &mut own);
            if consume(index, outcome).is_break() {
                return;
            }
            index += 1;
        }
        return;
    }

    let window = WINDOW_PER_THREAD * threads as u64;
    let shared = Mutex::new(Dispenser {
        next: start,
        rng,
        window_end: start.saturating_add(window),
        stop: false,
    });
    let wake = Condvar::new();
    let (sender, receiver) = mpsc::channel::<Finished>();
    let mut panicked: Option<Box<dyn std::any::Any + Send>> = None;

    thread::scope(|scope| {
        for _ in 0..threads {
            let sender = sender.clone();
            let shared = &shared;
            let wake = &wake;
            scope.spawn(move || loop {
                let (index, mut own) = {
                    let mut guard = shared.lock().unwrap_or_else(PoisonError::into_inner);
                    loop {
                        if guard.stop || past_end(guard.next) || stopped() {
                            return;
                        }
                        if guard.next < guard.window_end {
                            break;
                        }
                        guard = wake.wait(guard).unwrap_or_else(PoisonError::into_inner);
                    }
                    let index = guard.next;
                    let own = guard.rng.clone();
                    guard.rng.jump();
                    guard.next += 1;
                    (index, own)
                };
                let outcome = panic::catch_unwind(AssertUnwindSafe(|| run(index, &mut own)));
                let failed = outcome.is_err();
                if sender.send((index, outcome)).is_err() || failed {
                    return;
                }
            });
        }
        drop(sender);

        let mut pending: BTreeMap<u64, RunOutcome> = BTreeMap::new();
        let mut expected = start;
        let mut ahead = window;
        'consume: for (index, outcome) in receiver.iter() {
            match outcome {
                Ok(outcome) => {
                    pending.insert(index, outcome);
                }
                Err(payload) => {
                    panicked = Some(payload);
                    break 'consume;
                }
            }
            while let Some(outcome) = pending.remove(&expected) {
                let flow = consume(expected, outcome);
                expected += 1;
                match flow {
                    ControlFlow::Break(()) => break 'consume,
                    ControlFlow::Continue(remaining) => {
                        ahead = remaining.saturating_add(threads as u64).min(window);
                    }
                }
                if past_end(expected) {
                    break 'consume;
                }
            }
            let mut guard = shared.lock().unwrap_or_else(PoisonError::into_inner);
            guard.window_end = expected.saturating_add(ahead);
            drop(guard);
            wake.notify_all();
        }
        shared.lock().unwrap_or_else(PoisonError::into_inner).stop = true;
        wake.notify_all();
        drop(receiver);
    });
    if let Some(payload) = panicked {
        panic::resume_unwind(payload);
    }
}
