//! Sharded fixed-size studies: `--shard i/n` runs a deterministic slice of a study of
//! `N` runs and writes a [`PartialResult`]; [`merge`] checks that a set of partial
//! results is one study covered exactly once and reports every property.
//!
//! Shard `i` of `n` covers the contiguous block of run indices
//! `[floor(i N / n), floor((i + 1) N / n))` ([`Shard::range`]): contiguous blocks let a
//! shard derive its streams with one jump per run (a round-robin slice would need `n`),
//! and the blocks of `0/n .. (n-1)/n` tile `[0, N)` exactly. Run `k` uses stream `k`
//! whatever the shard, so merged counts equal those of the same study run on one
//! machine ([`run_fixed_study`]), for any thread count.
//!
//! A fixed-size study does not stop early: every property sees all `N` runs, and the
//! rule only provides the interval (and, for Wald's test, the answer on those counts).
//!
//! ```
//! use hindsight_smc::{
//!     merge, run_fixed_study, run_shard, FixedStudy, PartialResult, PropertySpec, RuleConfig,
//!     RunEnd, RunOutcome, Shard, StudyConfig, Verdict,
//! };
//! use rand_core::Rng;
//!
//! let study = FixedStudy {
//!     seed: 3,
//!     study_runs: 100,
//!     model: "model hash".into(),
//!     properties_fingerprint: "properties hash".into(),
//!     properties: vec![PropertySpec { id: "p".into(), rule: RuleConfig::default() }],
//!     paths: None,
//! };
//! let run = |_: u64, rng: &mut rand_xoshiro::Xoshiro256PlusPlus| RunOutcome {
//!     verdicts: vec![if rng.next_u64() % 2 == 0 { Verdict::True } else { Verdict::False }],
//!     assumptions: Verdict::True,
//!     end: RunEnd::Quiescent,
//!     steps: 1,
//!     time: 0,
//! };
//! let config = StudyConfig::default();
//! // Two machines each run one half and write JSON...
//! let parts: Vec<PartialResult> = ["0/2", "1/2"]
//!     .iter()
//!     .map(|s| run_shard(&config, &study, s.parse::<Shard>().unwrap(), run, &mut |_| {}))
//!     .map(|part| PartialResult::from_json(&part.to_json()).unwrap())
//!     .collect();
//! // ...and the merge counts exactly what one machine counts.
//! let merged = merge(&parts, 0).unwrap();
//! let whole = run_fixed_study(&config, &study, run, &mut |_| {}).unwrap();
//! assert_eq!(merged.properties[0].counts, whole.properties[0].counts);
//! assert_eq!(merged.properties[0].counts.judged(), 100);
//! // A shard missing is an error, not a smaller study.
//! assert!(merge(&parts[..1], 0).is_err());
//! ```

use std::collections::BTreeMap;
use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

use super::runner::{
    run_range, widened_interval, Progress, PropertyCounts, RunCounts, RunOutcome, StudyConfig,
};
use super::stats::{Estimate, Interval, RuleConfig, StatsError};

/// The `format` tag of partial result files.
pub(crate) const PARTIAL_FORMAT: &str = "hindsight-partial-1";

/// Slice `index` of `count` (`--shard index/count`, `index < count`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Shard {
    /// Which slice, from 0.
    pub index: u64,
    /// How many slices.
    pub count: u64,
}

impl Shard {
    /// The whole study as one shard (`0/1`).
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Checks `index < count`.
    pub fn new(index: u64, count: u64) -> Result<Shard, ShardError> {
        if count == 0 || index >= count {
            return Err(ShardError::Invalid(format!("{index}/{count}")));
        }
        Ok(Shard { index, count })
    }

    /// The run indices this shard covers in a study of `study_runs` runs.
    pub fn range(&self, study_runs: u64) -> Range<u64> {
        let at = |i: u64| ((i as u128 * study_runs as u128) / self.count as u128) as u64;
        at(self.index)..at(self.index + 1)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    /// Parses `i/n`.
    fn from_str(text: &str) -> Result<Shard, ShardError> {
        let invalid = || ShardError::Invalid(text.to_owned());
        let (index, count) = text.trim().split_once('/').ok_or_else(invalid)?;
        let index = index.trim().parse().map_err(|_| invalid())?;
        let count = count.trim().parse().map_err(|_| invalid())?;
        Shard::new(index, count).map_err(|_| invalid())
    }
}

/// Errors of sharding and merging.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ShardError {
    /// A shard that is not `i/n` with `i < n`.
    Invalid(String),
    /// A partial result file that does not parse.
    Json(String),
    /// A partial result of another format version.
    Format(String),
    /// No partial results to merge.
    Empty,
    /// Two partial results disagree on a field that identifies the study.
    Mismatch {
        /// Which field.
        field: &'static str,
        /// The shard whose value differs from the first one's.
        shard: Shard,
    },
    /// The same shard given twice with different contents (a shard re-run gives the same
    /// counts, so an identical copy is counted once instead).
    Duplicate(Shard),
    /// Shards of the study are missing (every one, in index order).
    Missing(Vec<Shard>),
    /// A partial result whose run range is not its shard's.
    Range(Shard),
    /// A partial result whose counts cannot come from its runs (more verdicts than
    /// runs, a failing run outside its range, ...): `what` says which count.
    Counts {
        /// The shard.
        shard: Shard,
        /// What is wrong, naming the count.
        what: String,
    },
    /// A property's rule is invalid.
    Rule(StatsError),
}

impl fmt::Display for ShardError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShardError::Invalid(text) => {
                write!(f, "invalid shard `{text}`: expected i/n with 0 <= i < n")
            }
            ShardError::Json(message) => write!(f, "invalid partial result: {message}"),
            ShardError::Format(format) => write!(
                f,
                "partial result format `{format}` is not `{PARTIAL_FORMAT}`"
            ),
            ShardError::Empty => write!(f, "no partial results to merge"),
            ShardError::Mismatch { field, shard } => write!(
                f,
                "shard {shard} belongs to another study: its `{field}` differs"
            ),
            ShardError::Duplicate(shard) => write!(
                f,
                "shard {shard} is given twice with different counts (a re-run of a shard \
                 gives the same counts: one of them is from another build or settings)"
            ),
            ShardError::Missing(shards) => {
                let list: Vec<String> = shards.iter().map(Shard::to_string).collect();
                let (noun, verb) = if shards.len() == 1 {
                    ("shard", "is")
                } else {
                    ("shards", "are")
                };
                write!(
                    f,
                    "{noun} {} {verb} missing: run each with the same `verify ... --runs R \
                     --shard I/N` and merge again with every part",
                    list.join(", ")
                )
            }
            ShardError::Range(shard) => {
                write!(f, "shard {shard} does not cover its own range of runs")
            }
            ShardError::Counts { shard, what } => {
                write!(f, "shard {shard} has counts its runs cannot give: {what}")
            }
            ShardError::Rule(error) => write!(f, "{error}"),
        }
    }
}

impl std::error::Error for ShardError {}

/// A property as the caller names it, with its rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PropertySpec {
    /// The property's id.
    pub id: String,
    /// Its stopping rule (only the interval matters in a fixed-size study).
    pub rule: RuleConfig,
}

/// What identifies a fixed-size study; the same for all its shards.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FixedStudy {
    /// The study seed.
    pub seed: u64,
    /// Total runs of the study, `N`.
    pub study_runs: u64,
    /// A fingerprint of the model, supplied by the caller (e.g. a content hash).
    pub model: String,
    /// A fingerprint of the properties and run settings, supplied by the caller.
    pub properties_fingerprint: String,
    /// The properties, in verdict order.
    pub properties: Vec<PropertySpec>,
    /// Where the model and its property file were read, as the shard's command line
    /// named them: what a merged report names. Not compared (machines mount files in
    /// different places; the fingerprints say whether they are the same).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paths: Option<StudyPaths>,
}

/// The model and property file of a study, as named on the command line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyPaths {
    /// The model's path.
    pub model: String,
    /// The property file's path.
    pub properties: String,
    /// The caller's record of how to replay a run of the study (opaque here: the
    /// options its model was loaded and run with), carried into the merged result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replay: Option<serde_json::Value>,
}

/// One property's counts in a partial result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialProperty {
    /// The property's id.
    pub id: String,
    /// Counts over the shard's runs.
    pub counts: PropertyCounts,
    /// Indices of the shard's first failing runs.
    pub failing_runs: Vec<u64>,
}

/// The result of one shard, as written to a JSON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialResult {
    /// Always `PARTIAL_FORMAT`.
    pub format: String,
    /// The study this shard belongs to.
    pub study: FixedStudy,
    /// Which shard.
    pub shard: Shard,
    /// The run indices covered, `shard.range(study.study_runs)`.
    pub first_run: u64,
    /// End of the run indices covered (exclusive).
    pub end_run: u64,
    /// Per-property counts, in the order of `study.properties`.
    pub properties: Vec<PartialProperty>,
    /// Counts over every run of the shard.
    pub runs: RunCounts,
}

impl PartialResult {
    /// The JSON text of this result.
    pub fn to_json(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Reads a partial result from JSON and checks its format tag.
    pub fn from_json(text: &str) -> Result<PartialResult, ShardError> {
        let result: PartialResult =
            serde_json::from_str(text).map_err(|error| ShardError::Json(error.to_string()))?;
        if result.format != PARTIAL_FORMAT {
            return Err(ShardError::Format(result.format));
        }
        Ok(result)
    }
}

/// Runs shard `shard` of the fixed-size study `study` (see the module doc).
pub fn run_shard<F>(
    config: &StudyConfig,
    study: &FixedStudy,
    shard: Shard,
    run: F,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> PartialResult
where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
{
    let range = shard.range(study.study_runs);
    let config = StudyConfig {
        seed: study.seed,
        max_runs: None,
        ..config.clone()
    };
    let counts = run_range(
        &config,
        range.clone(),
        study.properties.len(),
        run,
        progress,
    );
    PartialResult {
        format: PARTIAL_FORMAT.to_owned(),
        study: study.clone(),
        shard,
        first_run: range.start,
        end_run: range.end,
        properties: study
            .properties
            .iter()
            .zip(counts.properties.iter().zip(counts.failing_runs))
            .map(|(spec, (counts, failing_runs))| PartialProperty {
                id: spec.id.clone(),
                counts: *counts,
                failing_runs,
            })
            .collect(),
        runs: counts.runs,
    }
}

/// Runs a whole fixed-size study on this machine (shard `0/1`) and reports it.
pub fn run_fixed_study<F>(
    config: &StudyConfig,
    study: &FixedStudy,
    run: F,
    progress: &mut dyn FnMut(&Progress<'_>),
) -> Result<MergedResult, ShardError>
where
    F: Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync,
{
    merge(
        &[run_shard(config, study, Shard::WHOLE, run, progress)],
        config.keep_failing,
    )
}

/// One property of a merged study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MergedProperty {
    /// The property's id.
    pub id: String,
    /// Its rule.
    pub rule: RuleConfig,
    /// Counts over the whole study.
    pub counts: PropertyCounts,
    /// The rule's report on the judged runs.
    pub estimate: Estimate,
    /// The interval to report, widened over unknown runs.
    pub interval: Interval,
    /// Indices of the first failing runs of the study.
    pub failing_runs: Vec<u64>,
}

/// A whole fixed-size study, merged from its shards.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MergedResult {
    /// The study.
    pub study: FixedStudy,
    /// Shards merged.
    pub shards: u64,
    /// Per-property results.
    pub properties: Vec<MergedProperty>,
    /// Counts over every run.
    pub runs: RunCounts,
}

/// Checks that `part`'s counts can come from its runs: every run ends one way, no more
/// discarded runs than runs, each property's successes, failures and unknown verdicts
/// sum (without overflow) to the runs not discarded, and its failing runs are in the
/// shard's range, in order, no more of them than failures.
fn check_counts(part: &PartialResult) -> Result<(), ShardError> {
    let bad = |what: String| {
        Err(ShardError::Counts {
            shard: part.shard,
            what,
        })
    };
    let r = &part.runs;
    let ends = [
        r.quiescent,
        r.decided,
        r.time_horizon,
        r.step_limit,
        r.failed,
    ]
    .iter()
    .try_fold(0u64, |sum, &n| sum.checked_add(n));
    if ends != Some(r.runs) {
        return bad(format!(
            "its runs' ends (quiescent, decided, time horizon, step limit, failed) do not \
             sum to its {} runs",
            r.runs
        ));
    }
    if r.discarded > r.runs {
        return bad(format!("{} runs discarded of {} runs", r.discarded, r.runs));
    }
    let kept = r.runs - r.discarded;
    for p in &part.properties {
        let c = &p.counts;
        let sum = c
            .successes
            .checked_add(c.failures)
            .and_then(|s| s.checked_add(c.unknown));
        if sum != Some(kept) {
            return bad(format!(
                "`{}` has {} successes, {} failures and {} unknown verdicts, which do not \
                 sum to its {kept} runs not discarded",
                p.id, c.successes, c.failures, c.unknown
            ));
        }
        if p.failing_runs.len() as u64 > c.failures {
            return bad(format!(
                "`{}` lists {} failing runs but has {} failures",
                p.id,
                p.failing_runs.len(),
                c.failures
            ));
        }
        if let Some(k) = p
            .failing_runs
            .iter()
            .find(|&&k| k < part.first_run || k >= part.end_run)
        {
            return bad(format!(
                "`{}` names failing run {k}, outside the shard's runs {}..{}",
                p.id, part.first_run, part.end_run
            ));
        }
        if p.failing_runs.windows(2).any(|w| w[0] >= w[1]) {
            return bad(format!(
                "`{}` lists its failing runs out of order or twice",
                p.id
            ));
        }
    }
    Ok(())
}

/// `a + b`, `None` on overflow.
fn add_runs(a: &RunCounts, b: &RunCounts) -> Option<RunCounts> {
    Some(RunCounts {
        runs: a.runs.checked_add(b.runs)?,
        discarded: a.discarded.checked_add(b.discarded)?,
        quiescent: a.quiescent.checked_add(b.quiescent)?,
        decided: a.decided.checked_add(b.decided)?,
        time_horizon: a.time_horizon.checked_add(b.time_horizon)?,
        step_limit: a.step_limit.checked_add(b.step_limit)?,
        failed: a.failed.checked_add(b.failed)?,
        steps: a.steps.checked_add(b.steps)?,
        model_time: a.model_time.checked_add(b.model_time)?,
    })
}

/// `a + b`, `None` on overflow.
fn add_property(a: &PropertyCounts, b: &PropertyCounts) -> Option<PropertyCounts> {
    Some(PropertyCounts {
        successes: a.successes.checked_add(b.successes)?,
        failures: a.failures.checked_add(b.failures)?,
        unknown: a.unknown.checked_add(b.unknown)?,
    })
}

/// The shards given more than once among `parts`, each with the positions (in `parts`)
/// of its copies, in shard order.
pub fn duplicates(parts: &[PartialResult]) -> Vec<(Shard, Vec<usize>)> {
    let mut at: BTreeMap<u64, (Shard, Vec<usize>)> = BTreeMap::new();
    for (k, part) in parts.iter().enumerate() {
        at.entry(part.shard.index)
            .or_insert_with(|| (part.shard, Vec::new()))
            .1
            .push(k);
    }
    at.into_values().filter(|(_, ks)| ks.len() > 1).collect()
}

/// Merges the partial results of one study: they must share format, seed, study size,
/// fingerprints and properties, have the same shard count, and cover every shard, each on
/// its own range. A shard given twice counts once when both copies are identical (a
/// batch system that re-ran a finished shard); see [`duplicates`] to report them.
/// Failing-run lists are merged in index order and cut to `keep_failing` per property.
pub fn merge(parts: &[PartialResult], keep_failing: usize) -> Result<MergedResult, ShardError> {
    let first = parts.first().ok_or(ShardError::Empty)?;
    let count = first.shard.count;
    let mut by_index: BTreeMap<u64, &PartialResult> = BTreeMap::new();
    for part in parts {
        let shard = part.shard;
        if part.format != PARTIAL_FORMAT {
            return Err(ShardError::Format(part.format.clone()));
        }
        if shard.count == 0 || shard.index >= shard.count {
            return Err(ShardError::Invalid(shard.to_string()));
        }
        let mismatch = |field| Err(ShardError::Mismatch { field, shard });
        if shard.count != count {
            return mismatch("shard count");
        }
        if part.study.seed != first.study.seed {
            return mismatch("seed");
        }
        if part.study.study_runs != first.study.study_runs {
            return mismatch("study_runs");
        }
        if part.study.model != first.study.model {
            return mismatch("model");
        }
        if part.study.properties_fingerprint != first.study.properties_fingerprint {
            return mismatch("properties_fingerprint");
        }
        if part.study.properties != first.study.properties {
            return mismatch("properties");
        }
        let ids_match = part.properties.len() == part.study.properties.len()
            && part
                .properties
                .iter()
                .zip(&part.study.properties)
                .all(|(counts, spec)| counts.id == spec.id);
        if !ids_match {
            return mismatch("properties");
        }
        let range = shard.range(part.study.study_runs);
        let covered = part.runs.runs;
        if part.first_run != range.start
            || part.end_run != range.end
            || covered != range.end - range.start
        {
            return Err(ShardError::Range(shard));
        }
        // Two different copies of a shard are named as such first: that one of them
        // was altered is the more useful news.
        if let Some(before) = by_index.insert(shard.index, part) {
            if before.properties != part.properties || before.runs != part.runs {
                return Err(ShardError::Duplicate(shard));
            }
        }
        check_counts(part)?;
    }
    let missing: Vec<Shard> = (0..count)
        .filter(|i| !by_index.contains_key(i))
        .map(|index| Shard { index, count })
        .collect();
    if !missing.is_empty() {
        return Err(ShardError::Missing(missing));
    }

    let study = first.study.clone();
    let mut runs = RunCounts::default();
    let mut counts = vec![PropertyCounts::default(); study.properties.len()];
    let mut failing: Vec<Vec<u64>> = vec![Vec::new(); study.properties.len()];
    for part in by_index.values() {
        // Every count was checked against the shard's runs, and the ranges tile the
        // study, so only the sums of steps and model time can overflow; all sums are
        // checked so that no forged file wraps to a clean-looking total.
        let overflow = |what: &str| ShardError::Counts {
            shard: part.shard,
            what: format!("the study's total {what} does not fit in 64 bits"),
        };
        runs = add_runs(&runs, &part.runs).ok_or_else(|| overflow("of run counts"))?;
        for (i, property) in part.properties.iter().enumerate() {
            counts[i] = add_property(&counts[i], &property.counts)
                .ok_or_else(|| overflow(&format!("counts of `{}`", property.id)))?;
            failing[i].extend(&property.failing_runs);
        }
    }
    let mut properties = Vec::with_capacity(study.properties.len());
    for ((spec, counts), mut failing_runs) in study.properties.iter().zip(counts).zip(failing) {
        let rule = spec.rule.build().map_err(ShardError::Rule)?;
        failing_runs.sort_unstable();
        failing_runs.truncate(keep_failing);
        properties.push(MergedProperty {
            id: spec.id.clone(),
            rule: spec.rule,
            counts,
            estimate: rule.estimate(counts.successes, counts.judged()),
            interval: widened_interval(rule.as_ref(), &counts),
            failing_runs,
        });
    }
    Ok(MergedResult {
        study,
        shards: count,
        properties,
        runs,
    })
}
