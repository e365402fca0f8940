//! A study's result as one serialisable type: what `verify --json` and `merge --json`
//! print, what `hindsight report --study` reads back, and what the report page shows.
//!
//! Fields only the report fills (settings, formulas) are left out of the JSON when empty,
//! so the command-line output and the page read the same type.
//!
//! A [`Study`] is assembled here from what ran: `Study::of_result` from a sequential
//! study, [`Study::merged`] from the shards of a fixed-size one; [`Study::add_formulas`]
//! and [`Study::read_formulas`] add each formula for the page, and
//! [`Study::scheduler_rows`] is the one list of bounds over schedulers that the table and
//! the page show.
//!
//! ```
//! use hindsight_verify::result::{PropertyRow, Study};
//! use hindsight_verify::schedulers::{Bound, SchedulerBounds};
//!
//! let mut study = Study::default();
//! study.properties.push(PropertyRow { property: "a".into(), ..PropertyRow::default() });
//! study.properties.push(PropertyRow { property: "b".into(), ..PropertyRow::default() });
//! assert!(study.scheduler_rows().is_empty());
//! let witness = |p: f64, id: &str| Bound {
//!     probability: Some(p),
//!     interval: [p - 0.01, p + 0.01],
//!     scheduler: id.into(),
//!     runs: 100,
//!     successes: (p * 100.0) as u64,
//! };
//! study.properties[1].schedulers = Some(SchedulerBounds {
//!     sampled: 8,
//!     memory: "memoryless".into(),
//!     min: witness(0.5, "memoryless:1"),
//!     max: witness(0.9, "memoryless:2"),
//!     order_sensitive: true,
//!     sources: Vec::new(),
//!     left_out: 0,
//!     left_out_first: Vec::new(),
//! });
//! let rows = study.scheduler_rows();
//! assert_eq!(rows.len(), 1);
//! assert_eq!(rows[0].0.property, "b");
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::load::Loaded;
use crate::observe::PropertySet;
use crate::schedulers::SchedulerBounds;
use crate::sim::Scheduler;
use crate::smc::runner::PropertyCounts;
use crate::smc::shard::MergedResult;
use crate::smc::stats::{Estimate, Interval, RuleConfig};
use crate::smc::StudyResult;

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
    /// Whether the study stopped because no run could be judged for the properties it
    /// still needed runs for (all cut short or discarded; see [`Study::unjudged_line`]);
    /// left out of the JSON when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unjudged: bool,
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
    /// How the model was loaded and run, so that its runs can be replayed from this file
    /// (`report --study FILE --scheduler ID`); a merged study has its shards' (they
    /// carry it in their paths).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub replay: Option<crate::replay::Replay>,
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
    pub schedulers: Option<SchedulerBounds>,
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

impl Study {
    /// The result of a sequential study of `set` (`result`), run with `rule`, `seed` and
    /// `scheduler` (named in the result when given) on the model at `model` with the
    /// property file `props`.
    pub(crate) fn of_result(
        model: &Path,
        props: &Path,
        set: &PropertySet,
        rule: &RuleConfig,
        seed: u64,
        scheduler: Option<Scheduler>,
        r: &StudyResult,
    ) -> Study {
        Study {
            step_seconds: None,
            max_time_seconds: None,
            model: model.display().to_string(),
            properties_file: props.display().to_string(),
            seed,
            confidence: rule.confidence,
            precision: rule.precision,
            runs: r.runs.runs,
            discarded: r.runs.discarded,
            time_horizon: r.runs.time_horizon,
            step_limit: r.runs.step_limit,
            decided: r.runs.decided,
            quiescent: r.runs.quiescent,
            interrupted: r.interrupted,
            unjudged: r.unjudged,
            scheduler: scheduler.map(|s| s.to_string()),
            seconds: r.elapsed.as_secs_f64(),
            settings: Vec::new(),
            replay: None,
            properties: set
                .guarantee_names()
                .iter()
                .zip(&r.properties)
                .map(|(name, p)| PropertyRow::new(name, &p.estimate, &p.interval, &p.counts))
                .collect(),
        }
    }

    /// Why a study that stopped with [`Study::unjudged`] has no estimate for some
    /// properties: which ones, and what became of their runs. `None` for any other study.
    pub fn unjudged_line(&self) -> Option<String> {
        if !self.unjudged {
            return None;
        }
        let names: Vec<&str> = self
            .properties
            .iter()
            .filter(|p| p.runs == 0)
            .map(|p| p.property.as_str())
            .collect();
        let mut why = Vec::new();
        if self
            .properties
            .iter()
            .any(|p| p.runs == 0 && p.cut_short > 0)
        {
            let limit = match &self.replay {
                Some(r) => format!(" (--max-steps {})", r.max_steps),
                None => String::new(),
            };
            why.push(format!(
                "cut at the step limit{limit} before the verdict was final: raise --max-steps"
            ));
        }
        if self.discarded > 0 {
            why.push("discarded because an assumption was violated: check the assumptions".into());
        }
        Some(format!(
            "stopped after {} runs: not one could be judged for {} (each was {})",
            self.runs,
            names.join(", "),
            why.join("; or ")
        ))
    }

    /// The report of a merged fixed-size study (`merge`, and `verify --runs R` alone):
    /// named by the paths the shards recorded, else by their fingerprints.
    pub fn merged(m: &MergedResult) -> Study {
        let (model, properties_file) = match &m.study.paths {
            Some(p) => (p.model.clone(), p.properties.clone()),
            None => (
                m.study.model.clone(),
                m.study.properties_fingerprint.clone(),
            ),
        };
        Study {
            model,
            properties_file,
            seed: m.study.seed,
            confidence: m.properties.first().map_or(0.0, |p| p.rule.confidence),
            precision: m.properties.first().map_or(0.0, |p| p.rule.precision),
            runs: m.runs.runs,
            discarded: m.runs.discarded,
            time_horizon: m.runs.time_horizon,
            step_limit: m.runs.step_limit,
            decided: m.runs.decided,
            quiescent: m.runs.quiescent,
            interrupted: false,
            unjudged: false,
            scheduler: None,
            seconds: 0.0,
            step_seconds: None,
            max_time_seconds: None,
            settings: Vec::new(),
            replay: m
                .study
                .paths
                .as_ref()
                .and_then(|p| p.replay.clone())
                .and_then(|v| serde_json::from_value(v).ok()),
            properties: m
                .properties
                .iter()
                .map(|p| PropertyRow::new(&p.id, &p.estimate, &p.interval, &p.counts))
                .collect(),
        }
    }

    /// Model time in seconds, for a model whose step is `unit_ns` nanoseconds and whose
    /// runs last `max_time` steps (nothing without a unit).
    pub fn set_time_unit(&mut self, unit_ns: Option<u64>, max_time: u64) {
        if let Some(unit) = unit_ns {
            self.step_seconds = Some(unit as f64 / 1e9);
            self.max_time_seconds = Some(max_time as f64 * unit as f64 / 1e9);
        }
    }

    /// The rows that have bounds over schedulers (`verify --schedulers N`), each with its
    /// bounds: what the table under the study and the report page's section show.
    pub fn scheduler_rows(&self) -> Vec<(&PropertyRow, &SchedulerBounds)> {
        self.properties
            .iter()
            .filter_map(|p| p.schedulers.as_ref().map(|b| (p, b)))
            .collect()
    }

    /// Each formula as written in `loaded`'s property file and as compiled (for the
    /// report page of `verify --report`).
    pub fn add_formulas(&mut self, loaded: &Loaded) {
        let checked = loaded.set.compiled().checked();
        for p in &mut self.properties {
            if let Some(g) = loaded.file.guarantees.iter().find(|g| g.id == p.property) {
                p.formula = Some(g.formula.as_str().to_string());
            }
            if let Some(def) = checked.properties.iter().find(|d| d.name == p.property) {
                p.compiled = Some(codegen::print::formula(&def.formula, checked));
            }
        }
    }

    /// Fills the formulas missing from a study read back from JSON from its property
    /// file, when that is a SCAN XML file found here (`hindsight report --study`). A file
    /// that does not read is an error the caller may show as a warning; the study is
    /// left as it was.
    pub fn read_formulas(
        &mut self,
    ) -> Result<(), codegen::diag::Diagnostics<crate::props::PropsErrorKind>> {
        let path = Path::new(&self.properties_file);
        if self.properties.iter().all(|p| p.formula.is_some())
            || path.extension().is_none_or(|e| e != "xml")
            || !path.is_file()
        {
            return Ok(());
        }
        let file = crate::props::parse_file(path)?;
        for p in &mut self.properties {
            if let Some(g) = file.guarantees.iter().find(|g| g.id == p.property) {
                p.formula
                    .get_or_insert_with(|| g.formula.as_str().to_string());
            }
        }
        Ok(())
    }
}
