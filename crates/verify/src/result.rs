//! A study's result as one serialisable type: what `verify --json` and `merge --json`
//! print, what `hindsight report --study` reads back, and what the report page shows.
//!
//! Fields only the report fills (settings, formulas) are left out of the JSON when empty,
//! so the command-line output and the page read the same type.

use serde::{Deserialize, Serialize};

use crate::smc::runner::PropertyCounts;
use crate::smc::stats::{Estimate, Interval};

/// A study: settings, how its runs ended, one row per guarantee.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Study {
    /// The model path.
    pub model: String,
    /// The property file.
    pub properties_file: String,
    /// Study seed.
    pub seed: u64,
    /// Confidence of the intervals.
    pub confidence: f64,
    /// Target precision.
    pub precision: f64,
    /// Runs started and consumed.
    pub runs: u64,
    /// Runs discarded because an assumption was violated.
    pub discarded: u64,
    /// Runs that ended at the time horizon.
    pub time_horizon: u64,
    /// Runs that reached the step limit.
    pub step_limit: u64,
    /// Runs stopped early because every verdict was final.
    pub decided: u64,
    /// Runs that ended because nothing could move.
    pub quiescent: u64,
    /// Whether Ctrl-C / SIGTERM stopped the study before its rules were done: the
    /// numbers are those of the runs done (left out of the JSON when false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
    /// The scheduler every run was under, when `--scheduler` named one (left out of the
    /// JSON otherwise: the uniform scheduler).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scheduler: Option<String>,
    /// Wall-clock seconds (0 for a merged study).
    #[serde(default)]
    pub seconds: f64,
    /// Seconds of model time in one step, when the model has a time unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_seconds: Option<f64>,
    /// The run length in seconds of model time, when the model has a time unit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_time_seconds: Option<f64>,
    /// Further settings as name and value (rule, run length, threads), in order: filled
    /// for the report page only.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub settings: Vec<(String, String)>,
    /// One row per guarantee.
    pub properties: Vec<PropertyRow>,
}

/// One guarantee's result.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct PropertyRow {
    /// The guarantee's id.
    pub property: String,
    /// Estimated probability that a run satisfies it (`null` with no judged run).
    pub probability: Option<f64>,
    /// Lower end of the interval (widened over unknown runs).
    pub lower: f64,
    /// Upper end of the interval.
    pub upper: f64,
    /// Runs judged.
    pub runs: u64,
    /// Runs that satisfied it.
    pub successes: u64,
    /// Runs cut short before its verdict was final (not judged).
    pub cut_short: u64,
    /// With a threshold: `accept` (P >= theta) or `reject`.
    #[serde(default)]
    pub decision: Option<String>,
    /// The formula as written in the property file (report page only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub formula: Option<String>,
    /// The formula as compiled: checked, bounds in ticks, every operation parenthesised
    /// (report page only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compiled: Option<String>,
    /// With `verify --schedulers N`: the smallest and largest probability among the
    /// sampled schedulers, their witnesses, and whether the property is order-sensitive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub schedulers: Option<crate::schedulers::SchedulerBounds>,
}

impl PropertyRow {
    /// The row of guarantee `name` from its estimate, interval and counts.
    pub fn new(
        name: &str,
        estimate: &Estimate,
        interval: &Interval,
        counts: &PropertyCounts,
    ) -> Self {
        PropertyRow {
            property: name.to_string(),
            probability: estimate.estimate,
            lower: interval.lower,
            upper: interval.upper,
            runs: counts.judged(),
            successes: counts.successes,
            cut_short: counts.unknown,
            decision: estimate.decision.map(|d| format!("{d:?}").to_lowercase()),
            formula: None,
            compiled: None,
            schedulers: None,
        }
    }
}
