//! What a study is asked, set once: the stopping rule, the seed, the run bounds, the
//! scheduler. `hindsight verify` fills one [`VerifyOptions`] from its arguments; every
//! configuration the simulator and the runner take is derived from it here.
//!
//! ```
//! use hindsight_verify::load::{load, LoadOptions};
//! use hindsight_verify::options::VerifyOptions;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/museum-scxml");
//! let loaded = load(&LoadOptions { model: dir.into(), ..LoadOptions::default() }).unwrap();
//! let opts = VerifyOptions { seed: 7, max_time: Some("500".into()), ..VerifyOptions::default() };
//! let run_cfg = opts.run_config(&loaded).unwrap();
//! assert_eq!((run_cfg.max_time, opts.study_config().seed), (500, 7));
//! // A duration needs a model with a time unit: the error says so.
//! let bad = VerifyOptions { max_time: Some("2s".into()), ..VerifyOptions::default() };
//! assert!(bad.run_config(&loaded).is_err());
//! ```

use std::time::Duration;

// The types these settings are made of, from the crates below, named here so that a
// caller (the command line) sets a study with this crate's API alone.
pub use crate::robot::bt::{BtSemantics, BtTick};
pub use crate::sim::{BadScheduler, EventSemantics, Memory, Scheduler};
pub use crate::smc::shard::Shard;
pub use crate::smc::stats::{RuleConfig, RuleKind};

use crate::load::{Loaded, MaxTimeError};
use crate::schedulers::SchedulerOptions;
use crate::sim::RunConfig;
use crate::smc::StudyConfig;

/// Every setting of one `verify` study.
#[derive(Clone, Debug, PartialEq)]
pub struct VerifyOptions {
    /// The stopping rule, its confidence and precision.
    pub rule: RuleConfig,
    /// Study seed: run k uses stream k.
    pub seed: u64,
    /// Worker threads (0: all cores).
    pub threads: usize,
    /// Stop after this many runs even if the rule wants more.
    pub max_runs: Option<u64>,
    /// The run length as written: model steps, or a duration when the model has a time
    /// unit ([`Loaded::max_time`]); `None`: the model's own, else 10,000 steps.
    pub max_time: Option<String>,
    /// A run reaching this many steps is cut short.
    pub max_steps: u64,
    /// Steps one instant may take before the run is a loop that never lets time advance.
    pub max_instant_steps: u64,
    /// Every run under this scheduler (`None`: uniform, and not named in the result).
    pub scheduler: Option<Scheduler>,
    /// Failing runs kept per property (for `--save-failing` and the report page).
    pub keep_failing: usize,
    /// The bounds over sampled schedulers (`--schedulers N`), if asked.
    pub schedulers: Option<SchedulerOptions>,
}

impl Default for VerifyOptions {
    /// `hindsight verify`'s defaults.
    fn default() -> Self {
        let run = RunConfig::default();
        VerifyOptions {
            rule: RuleConfig::default(),
            seed: 0,
            threads: 0,
            max_runs: None,
            max_time: None,
            max_steps: run.max_steps,
            max_instant_steps: run.max_steps_per_instant,
            scheduler: None,
            keep_failing: 0,
            schedulers: None,
        }
    }
}

impl VerifyOptions {
    /// How each run of `loaded` is bounded, which event semantics and which scheduler it
    /// follows. The error is the run length's; the caller names its flag.
    pub fn run_config(&self, loaded: &Loaded) -> Result<RunConfig, MaxTimeError> {
        Ok(RunConfig {
            max_time: loaded.max_time(self.max_time.as_deref())?,
            max_steps: self.max_steps,
            max_steps_per_instant: self.max_instant_steps,
            events: loaded.events,
            scheduler: self.scheduler.unwrap_or_default(),
            ..RunConfig::default()
        })
    }

    /// The runner's configuration: seed, threads, run cap, failing runs kept; progress
    /// every 200 ms.
    pub fn study_config(&self) -> StudyConfig {
        StudyConfig {
            seed: self.seed,
            threads: self.threads,
            max_runs: self.max_runs,
            keep_failing: self.keep_failing,
            progress_every: Duration::from_millis(200),
        }
    }

    /// The settings lines a report page shows for a study run with `run_cfg`.
    pub fn settings(&self, run_cfg: &RunConfig) -> Vec<(String, String)> {
        [
            ("rule", format!("{:?}", self.rule.kind).to_lowercase()),
            ("run length in steps", run_cfg.max_time.to_string()),
            ("step limit", self.max_steps.to_string()),
            ("events", run_cfg.events.label().to_string()),
        ]
        .map(|(k, v)| (k.to_string(), v))
        .into_iter()
        .chain(
            self.scheduler
                .map(|s| ("scheduler".to_string(), s.to_string())),
        )
        .collect()
    }
}
