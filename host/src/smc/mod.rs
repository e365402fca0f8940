//! Statistical model checking: stopping rules, the deterministic parallel runner, and
//! sharded studies.
//!
//! # Pipeline
//!
//! 1. **Rules** ([`stats`]): one [`StoppingRule`] per property, usually built from a
//!    [`RuleConfig`] (adaptive bound by default; Okamoto, Wilson, Clopper-Pearson, Wald's
//!    SPRT). Special functions live in [`math`].
//! 2. **Runs**: the caller supplies `Fn(run_index, &mut Xoshiro256PlusPlus) -> RunOutcome`
//!    (the simulator plus monitors); the runner knows nothing about models.
//! 3. **Sequential study** ([`run_study`]): run `k` on stream `k`, results consumed in run
//!    order on any number of threads, stop when every rule is done. Same seed, same
//!    numbers, whatever the thread count.
//! 4. **Fixed-size study, sharded** ([`shard`]): [`run_shard`] runs slice `i/n` and
//!    returns a [`PartialResult`] (JSON); [`merge`] checks and combines them.
//!
//! 5. **Progress** ([`progress`]): [`progress::TerminalProgress`] draws the reports as a
//!    bar on a terminal and stays silent otherwise.
//!
//! Discarded runs (assumptions violated) and runs cut short (step limit) are counted,
//! never silently judged: see [`runner`] for the policy.

pub mod math;
pub mod progress;
pub mod runner;
pub mod shard;
pub mod stats;

pub use runner::{
    run_range, run_study, run_study_until, stream, Progress, PropertyCounts, PropertyResult,
    RangeCounts, RunCounts, RunEnd, RunOutcome, StudyConfig, StudyResult, Verdict,
};
pub use shard::{
    merge, run_fixed_study, run_shard, FixedStudy, MergedProperty, MergedResult, PartialProperty,
    PartialResult, PropertySpec, Shard, ShardError,
};
pub use stats::{
    AdaptiveBound, ClopperPearson, Decision, Estimate, Interval, OkamotoBound, RuleConfig,
    RuleKind, Sprt, StatsError, StoppingRule, WilsonInterval,
};
