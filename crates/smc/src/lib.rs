//! Statistical model checking: stopping rules, the deterministic parallel runner, and
//! sharded studies.
//!
//! `hindsight-smc` knows nothing about models: a run is any function of its index and its
//! random stream that returns one [`Verdict`] per property. It depends on no other crate of
//! the project; `hindsight`'s `verify` supplies the simulator and the monitors as that
//! function.
//!
//! # Public API
//!
//! - [`run_study`] / [`run_study_until`]: a sequential study, stopped by one
//!   [`StoppingRule`] per property (built from a [`RuleConfig`]), returning a
//!   [`StudyResult`].
//! - [`run_shard`], [`merge`] and [`run_fixed_study`]: a fixed-size study of `N` runs,
//!   split into [`Shard`]s whose [`PartialResult`]s (JSON) merge into a [`MergedResult`].
//! - [`stream`]: the random stream of run `k`; [`progress`]: a progress report as text.
//!
//! ```
//! use hindsight_smc::{run_study, RuleConfig, RunEnd, RunOutcome, StudyConfig, Verdict};
//! use rand_core::Rng;
//!
//! // One property that holds in a run with probability 1/4.
//! let rules = vec![RuleConfig::default().build().unwrap()];
//! let config = StudyConfig { seed: 1, threads: 2, ..StudyConfig::default() };
//! let run = |_index: u64, rng: &mut rand_xoshiro::Xoshiro256PlusPlus| RunOutcome {
//!     verdicts: vec![if rng.next_u64() % 4 == 0 { Verdict::True } else { Verdict::False }],
//!     assumptions: Verdict::True,
//!     end: RunEnd::Quiescent,
//!     steps: 1,
//!     time: 0,
//! };
//! let result = run_study(&config, &rules, run, &mut |_| {});
//! let p = &result.properties[0];
//! assert!(p.stopped_at.is_some()); // the adaptive bound was reached
//! assert!(p.interval.lower <= 0.25 && 0.25 <= p.interval.upper);
//!
//! // Same seed, same numbers, whatever the thread count.
//! let one = StudyConfig { threads: 1, ..config };
//! assert_eq!(run_study(&one, &rules, run, &mut |_| {}).properties[0].counts, p.counts);
//! ```
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
//! 5. **Progress** ([`progress`]): a study hands its [`Progress`] reports to a callback;
//!    [`progress::log_line`] and [`progress::message`] spell one as text. The crate prints
//!    nothing (`hindsight` draws the bar).
//!
//! Discarded runs (assumptions violated) and runs cut short (step limit) are counted,
//! never silently judged: see [`runner`] for the policy.

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

mod jump;
pub mod math;
pub mod progress;
pub mod runner;
pub mod shard;
pub mod stats;

pub use runner::{
    run_range, run_study, run_study_until, stream, Progress, PropertyCounts, PropertyResult,
    RangeCounts, RunCounts, RunEnd, RunOutcome, StudyConfig, StudyResult, Verdict, MAX_THREADS,
    UNJUDGED_LIMIT,
};
pub use shard::{
    merge, run_fixed_study, run_shard, FixedStudy, MergedProperty, MergedResult, PartialProperty,
    PartialResult, PropertySpec, Shard, ShardError,
};
pub use stats::{
    AdaptiveBound, ClopperPearson, Decision, Estimate, Interval, OkamotoBound, RuleConfig,
    RuleKind, Sprt, StatsError, StoppingRule, WilsonInterval,
};
