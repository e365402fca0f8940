//! Stopping rules for statistical model checking: when a study has run enough, and what
//! it may claim (estimate, confidence interval, and for Wald's test an answer).
//!
//! Every property of a study owns one rule instance ([`StoppingRule`], usually built from
//! a [`RuleConfig`]). The runner feeds it the property's judged runs in run-index order:
//! `successes` out of `runs`. Rules:
//!
//! | rule | stops when | interval reported |
//! | --- | --- | --- |
//! | [`AdaptiveBound`] (default, SCAN's) | `runs >= okamoto(c,e) * (1 - 4(|p - 1/2| - 2e/3)^2)` | `p ± e'`, `e'` solved from the same bound |
//! | [`OkamotoBound`] | `runs >= ln(2/(1-c)) / (2e^2)` (fixed) | Hoeffding, `p ± sqrt(ln(2/(1-c)) / (2 runs))` |
//! | [`WilsonInterval`] | Wilson score half-width `<= e` | Wilson score interval |
//! | [`ClopperPearson`] | exact half-width `<= e` | Clopper-Pearson (exact binomial) interval |
//! | [`Sprt`] | Wald's likelihood ratio leaves `(B, A)` | Wilson score interval (information only) |
//!
//! `c` is the confidence, `e` the precision (half-width), `p = successes / runs`.
//!
//! The interval rules (Wilson, Clopper-Pearson) are fixed-sample intervals checked after
//! every run; stopping on the half-width only uses the number of runs and the estimate,
//! which is the usual practice, but the confidence is then nominal rather than
//! guaranteed. The Okamoto bound is a guarantee for any `p`; the adaptive bound is the
//! heuristic refinement SCAN uses (Budde, D'Argenio, Hartmanns, Sedwards, STTT 2020).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::math::{inv_reg_inc_beta, normal_quantile};

/// A closed interval `[lower, upper]` inside `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// Lower end, in `[0, 1]`.
    pub lower: f64,
    /// Upper end, in `[lower, 1]`.
    pub upper: f64,
}

impl Interval {
    /// The whole `[0, 1]`: nothing is known.
    pub(crate) const UNIT: Interval = Interval {
        lower: 0.0,
        upper: 1.0,
    };

    /// `[center - half, center + half]` clipped to `[0, 1]`.
    pub fn around(center: f64, half: f64) -> Interval {
        Interval::clipped(center - half, center + half)
    }

    /// `[lower, upper]` clipped to `[0, 1]`.
    pub fn clipped(lower: f64, upper: f64) -> Interval {
        let lower = lower.clamp(0.0, 1.0);
        Interval {
            lower,
            upper: upper.clamp(lower, 1.0),
        }
    }

    /// Half the width.
    pub fn half_width(&self) -> f64 {
        0.5 * (self.upper - self.lower)
    }

    /// Whether `p` lies in the interval (ends included).
    pub fn contains(&self, p: f64) -> bool {
        self.lower <= p && p <= self.upper
    }
}

impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{:.4}, {:.4}]", self.lower, self.upper)
    }
}

/// The answer of Wald's sequential test to "is `P >= theta`?".
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decision {
    /// `P >= theta` (the test accepted `P >= theta + e`).
    Accept,
    /// `P < theta` (the test accepted `P <= theta - e`).
    Reject,
}

/// What a rule reports for one property.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// Judged runs that satisfied the property.
    pub successes: u64,
    /// Judged runs.
    pub runs: u64,
    /// `successes / runs`; `None` before the first judged run.
    pub estimate: Option<f64>,
    /// The rule's confidence interval for the probability.
    pub interval: Interval,
    /// Whether the rule's stopping condition holds.
    pub done: bool,
    /// Wald's test answer, for [`Sprt`] once it has decided.
    pub decision: Option<Decision>,
}

/// A stopping rule for one property: fed the judged runs in run order.
///
/// Implementations are pure functions of `(successes, runs)`, so a study's outcome does
/// not depend on when or how often they are asked.
pub trait StoppingRule: fmt::Debug + Send + Sync {
    /// Short name, e.g. `"adaptive"`.
    fn name(&self) -> &'static str;

    /// Whether the study may stop for this property after `runs` judged runs.
    fn done(&self, successes: u64, runs: u64) -> bool;

    /// The confidence interval to report after `runs` judged runs
    /// (`Interval::UNIT` when `runs == 0`).
    fn interval(&self, successes: u64, runs: u64) -> Interval;

    /// The test's answer, for rules that answer a question ([`Sprt`]).
    fn decision(&self, _successes: u64, _runs: u64) -> Option<Decision> {
        None
    }

    /// Estimated total judged runs the rule will need if the estimate stays where it is
    /// (for a progress bar's time left); `None` when the rule cannot say.
    fn runs_needed(&self, _successes: u64, _runs: u64) -> Option<u64> {
        None
    }

    /// Runs of a fixed-size study that meet the requested precision whatever the
    /// probability (worst case); `None` for sequential-only rules.
    fn fixed_runs(&self) -> Option<u64>;

    /// Everything at once.
    fn estimate(&self, successes: u64, runs: u64) -> Estimate {
        Estimate {
            successes,
            runs,
            estimate: (runs > 0).then(|| successes as f64 / runs as f64),
            interval: self.interval(successes, runs),
            done: self.done(successes, runs),
            decision: self.decision(successes, runs),
        }
    }
}

/// A bad rule parameter.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum StatsError {
    /// Confidence outside `(0, 1)`.
    Confidence(f64),
    /// Precision outside `(0, 0.5]`.
    Precision(f64),
    /// Threshold outside `[0, 1]`.
    Threshold(f64),
}

impl fmt::Display for StatsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StatsError::Confidence(c) => write!(f, "confidence {c} is not in (0, 1)"),
            StatsError::Precision(e) => write!(f, "precision {e} is not in (0, 0.5]"),
            StatsError::Threshold(t) => write!(f, "threshold {t} is not in [0, 1]"),
        }
    }
}

impl std::error::Error for StatsError {}

/// Confidence `c` in `(0, 1)` and precision `e` (interval half-width) in `(0, 0.5]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    confidence: f64,
    precision: f64,
}

impl Accuracy {
    /// Checks both parameters.
    pub fn new(confidence: f64, precision: f64) -> Result<Accuracy, StatsError> {
        if !(confidence > 0.0 && confidence < 1.0) {
            return Err(StatsError::Confidence(confidence));
        }
        if !(precision > 0.0 && precision <= 0.5) {
            return Err(StatsError::Precision(precision));
        }
        Ok(Accuracy {
            confidence,
            precision,
        })
    }

    /// The confidence `c`.
    pub fn confidence(&self) -> f64 {
        self.confidence
    }

    /// The precision `e`.
    pub fn precision(&self) -> f64 {
        self.precision
    }

    /// `ln(2 / (1 - c))`, the Hoeffding constant.
    fn hoeffding_log(&self) -> f64 {
        (2.0 / (1.0 - self.confidence)).ln()
    }

    /// The two-sided normal quantile `z_{1 - (1-c)/2}`.
    fn z(&self) -> f64 {
        normal_quantile(1.0 - (1.0 - self.confidence) / 2.0)
    }
}

/// The Okamoto (Chernoff-Hoeffding) bound: `ln(2 / (1 - c)) / (2 e^2)` runs give an
/// estimate within `e` of the probability with confidence `c`, whatever the probability.
pub fn okamoto(confidence: f64, precision: f64) -> f64 {
    (2.0 / (1.0 - confidence)).ln() / (2.0 * precision * precision)
}

/// SCAN's adaptive bound: `okamoto(c, e) * (1 - 4(|p - 1/2| - 2e/3)^2)` runs, with `p` the
/// current estimate.
pub fn adaptive_bound(estimate: f64, confidence: f64, precision: f64) -> f64 {
    let d = (estimate - 0.5).abs() - 2.0 * precision / 3.0;
    okamoto(confidence, precision) * (1.0 - 4.0 * d * d)
}

/// Smallest `n >= from` with `ok(n)`, assuming `ok` is monotone from some point on;
/// `None` if none is found below 2^62.
fn first_n(from: u64, ok: impl Fn(u64) -> bool) -> Option<u64> {
    let mut lo = from.max(1);
    if ok(lo) {
        return Some(lo);
    }
    let mut hi = lo.saturating_mul(2);
    while !ok(hi) {
        if hi >= 1 << 62 {
            return None;
        }
        lo = hi;
        hi = hi.saturating_mul(2);
    }
    // ok(hi) and !ok(lo).
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The default rule: SCAN's adaptive bound (see [`adaptive_bound`]).
///
/// Stops after the first run where `runs >= adaptive_bound(p, c, e)`. The interval is
/// `p ± e'` where `e'` solves `runs = adaptive_bound(p, c, e')` for `e'` (a quadratic);
/// once the rule is done `e' <= e` up to rounding.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveBound {
    accuracy: Accuracy,
}

impl AdaptiveBound {
    /// A rule for this confidence and precision.
    pub fn new(accuracy: Accuracy) -> AdaptiveBound {
        AdaptiveBound { accuracy }
    }

    /// The precision `e'` that `runs` runs with estimate `p` achieve under the bound.
    pub fn achieved_precision(&self, successes: u64, runs: u64) -> f64 {
        if runs == 0 {
            return f64::INFINITY;
        }
        let n = runs as f64;
        let p = successes as f64 / n;
        let d = (p - 0.5).abs();
        let k = self.accuracy.hoeffding_log();
        // n = k/(2e^2) (1 - 4(d - 2e/3)^2)  <=>  A e^2 - B e - C = 0 with:
        let a = n + 8.0 * k / 9.0;
        let b = 8.0 * k * d / 3.0;
        let c = 0.5 * k * (1.0 - 4.0 * d * d);
        (b + (b * b + 4.0 * a * c).sqrt()) / (2.0 * a)
    }
}

impl StoppingRule for AdaptiveBound {
    fn name(&self) -> &'static str {
        "adaptive"
    }

    fn done(&self, successes: u64, runs: u64) -> bool {
        runs > 0
            && runs as f64
                >= adaptive_bound(
                    successes as f64 / runs as f64,
                    self.accuracy.confidence,
                    self.accuracy.precision,
                )
    }

    fn interval(&self, successes: u64, runs: u64) -> Interval {
        if runs == 0 {
            return Interval::UNIT;
        }
        Interval::around(
            successes as f64 / runs as f64,
            self.achieved_precision(successes, runs),
        )
    }

    fn runs_needed(&self, successes: u64, runs: u64) -> Option<u64> {
        let p = if runs == 0 {
            0.5
        } else {
            successes as f64 / runs as f64
        };
        Some(
            adaptive_bound(p, self.accuracy.confidence, self.accuracy.precision)
                .ceil()
                .max(1.0) as u64,
        )
    }

    fn fixed_runs(&self) -> Option<u64> {
        // The bound's factor is at most 1 (at |p - 1/2| = 2e/3).
        Some(okamoto(self.accuracy.confidence, self.accuracy.precision).ceil() as u64)
    }
}

/// The fixed Okamoto (Chernoff-Hoeffding) bound: stop after
/// `ceil(ln(2/(1-c)) / (2e^2))` runs; interval `p ± sqrt(ln(2/(1-c)) / (2 runs))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OkamotoBound {
    accuracy: Accuracy,
    runs: u64,
}

impl OkamotoBound {
    /// A rule for this confidence and precision.
    pub fn new(accuracy: Accuracy) -> OkamotoBound {
        OkamotoBound {
            accuracy,
            runs: okamoto(accuracy.confidence, accuracy.precision).ceil() as u64,
        }
    }
}

impl StoppingRule for OkamotoBound {
    fn name(&self) -> &'static str {
        "okamoto"
    }

    fn done(&self, _successes: u64, runs: u64) -> bool {
        runs >= self.runs
    }

    fn interval(&self, successes: u64, runs: u64) -> Interval {
        if runs == 0 {
            return Interval::UNIT;
        }
        let half = (self.accuracy.hoeffding_log() / (2.0 * runs as f64)).sqrt();
        Interval::around(successes as f64 / runs as f64, half)
    }

    fn runs_needed(&self, _successes: u64, _runs: u64) -> Option<u64> {
        Some(self.runs)
    }

    fn fixed_runs(&self) -> Option<u64> {
        Some(self.runs)
    }
}

/// The Wilson score interval at `successes / runs` with normal quantile `z`.
pub fn wilson_interval(successes: u64, runs: u64, z: f64) -> Interval {
    if runs == 0 {
        return Interval::UNIT;
    }
    let n = runs as f64;
    let p = successes as f64 / n;
    let z2 = z * z;
    let scale = 1.0 + z2 / n;
    let center = (p + z2 / (2.0 * n)) / scale;
    let half = z / scale * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    Interval::around(center, half)
}

/// Wilson score interval; stops when its half-width is at most the precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WilsonInterval {
    accuracy: Accuracy,
    z: f64,
}

impl WilsonInterval {
    /// A rule for this confidence and precision.
    pub fn new(accuracy: Accuracy) -> WilsonInterval {
        WilsonInterval {
            accuracy,
            z: accuracy.z(),
        }
    }
}

impl StoppingRule for WilsonInterval {
    fn name(&self) -> &'static str {
        "wilson"
    }

    fn done(&self, successes: u64, runs: u64) -> bool {
        runs > 0 && self.interval(successes, runs).half_width() <= self.accuracy.precision
    }

    fn interval(&self, successes: u64, runs: u64) -> Interval {
        wilson_interval(successes, runs, self.z)
    }

    fn runs_needed(&self, successes: u64, runs: u64) -> Option<u64> {
        let p = if runs == 0 {
            0.5
        } else {
            successes as f64 / runs as f64
        };
        first_n(runs, |n| {
            let s = (p * n as f64).round() as u64;
            self.done(s.min(n), n)
        })
    }

    fn fixed_runs(&self) -> Option<u64> {
        // The half-width is largest at p = 1/2: z / (2 sqrt(n + z^2)) <= e.
        let z2 = self.z * self.z;
        let e = self.accuracy.precision;
        Some((z2 / (4.0 * e * e) - z2).ceil().max(1.0) as u64)
    }
}

/// The exact Clopper-Pearson interval at confidence `c`: the `(1-c)/2` quantile of
/// `Beta(s, n - s + 1)` and the `1 - (1-c)/2` quantile of `Beta(s + 1, n - s)`.
pub fn clopper_pearson_interval(successes: u64, runs: u64, confidence: f64) -> Interval {
    if runs == 0 {
        return Interval::UNIT;
    }
    let successes = successes.min(runs);
    let tail = (1.0 - confidence) / 2.0;
    let (s, n) = (successes as f64, runs as f64);
    let lower = if successes == 0 {
        0.0
    } else {
        inv_reg_inc_beta(s, n - s + 1.0, tail)
    };
    let upper = if successes == runs {
        1.0
    } else {
        inv_reg_inc_beta(s + 1.0, n - s, 1.0 - tail)
    };
    Interval::clipped(lower, upper)
}

/// Exact Clopper-Pearson interval; stops when its half-width is at most the precision.
///
/// The most expensive rule to evaluate (two inverse incomplete beta functions per check,
/// a few microseconds); [`StoppingRule::runs_needed`] uses the Wilson interval's answer,
/// which is close.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClopperPearson {
    accuracy: Accuracy,
    wilson: WilsonInterval,
}

impl ClopperPearson {
    /// A rule for this confidence and precision.
    pub fn new(accuracy: Accuracy) -> ClopperPearson {
        ClopperPearson {
            accuracy,
            wilson: WilsonInterval::new(accuracy),
        }
    }
}

impl StoppingRule for ClopperPearson {
    fn name(&self) -> &'static str {
        "clopper-pearson"
    }

    fn done(&self, successes: u64, runs: u64) -> bool {
        runs > 0 && self.interval(successes, runs).half_width() <= self.accuracy.precision
    }

    fn interval(&self, successes: u64, runs: u64) -> Interval {
        clopper_pearson_interval(successes, runs, self.accuracy.confidence)
    }

    fn runs_needed(&self, successes: u64, runs: u64) -> Option<u64> {
        self.wilson.runs_needed(successes, runs)
    }

    fn fixed_runs(&self) -> Option<u64> {
        // Worst case near p = 1/2 (approximately: the interval is discrete).
        first_n(1, |n| self.done(n / 2, n))
    }
}

/// Wald's sequential probability ratio test for "is `P >= theta`?", with indifference
/// region `[theta - e, theta + e]` (`e` the precision) and error probabilities
/// `alpha = beta = 1 - c`.
///
/// Tests `H0: P >= p0 = theta + e` against `H1: P <= p1 = theta - e` (both clamped to
/// `[0, 1]`). After `s` successes in `n` runs the log-likelihood ratio is
/// `L = s ln(p1/p0) + (n - s) ln((1-p1)/(1-p0))`; it answers [`Decision::Reject`]
/// (`P < theta`) once `L >= ln((1-beta)/alpha)` and [`Decision::Accept`] once
/// `L <= ln(beta/(1-alpha))`. Inside the indifference region either answer may come.
/// The interval reported is the Wilson score interval at confidence `c`, for information.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sprt {
    accuracy: Accuracy,
    threshold: f64,
    z: f64,
}

impl Sprt {
    /// A test of `P >= threshold`.
    pub fn new(accuracy: Accuracy, threshold: f64) -> Result<Sprt, StatsError> {
        if !(0.0..=1.0).contains(&threshold) {
            return Err(StatsError::Threshold(threshold));
        }
        Ok(Sprt {
            accuracy,
            threshold,
            z: accuracy.z(),
        })
    }

    /// The threshold `theta`.
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// The log-likelihood ratio `ln(L(p1) / L(p0))`; `NaN` when the counts are
    /// impossible under both hypotheses.
    pub(crate) fn log_likelihood_ratio(&self, successes: u64, runs: u64) -> f64 {
        let e = self.accuracy.precision;
        let p0 = (self.threshold + e).min(1.0);
        let p1 = (self.threshold - e).max(0.0);
        let failures = runs.saturating_sub(successes);
        let mut ratio = 0.0;
        if successes > 0 {
            ratio += successes as f64 * (p1.ln() - p0.ln());
        }
        if failures > 0 {
            ratio += failures as f64 * ((-p1).ln_1p() - (-p0).ln_1p());
        }
        ratio
    }
}

impl StoppingRule for Sprt {
    fn name(&self) -> &'static str {
        "sprt"
    }

    fn done(&self, successes: u64, runs: u64) -> bool {
        self.decision(successes, runs).is_some()
    }

    fn interval(&self, successes: u64, runs: u64) -> Interval {
        wilson_interval(successes, runs, self.z)
    }

    fn decision(&self, successes: u64, runs: u64) -> Option<Decision> {
        let error = 1.0 - self.accuracy.confidence;
        let upper = ((1.0 - error) / error).ln();
        let lower = (error / (1.0 - error)).ln();
        let ratio = self.log_likelihood_ratio(successes, runs);
        if ratio >= upper {
            Some(Decision::Reject)
        } else if ratio <= lower {
            Some(Decision::Accept)
        } else {
            None
        }
    }

    fn fixed_runs(&self) -> Option<u64> {
        None
    }
}

/// Which rule a property uses.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RuleKind {
    /// [`AdaptiveBound`], SCAN's default.
    #[default]
    Adaptive,
    /// [`OkamotoBound`].
    Okamoto,
    /// [`WilsonInterval`].
    Wilson,
    /// [`ClopperPearson`].
    ClopperPearson,
    /// [`Sprt`] for `P >= threshold`.
    Sprt {
        /// The `theta` of `P >= theta`.
        threshold: f64,
    },
}

/// A rule and its parameters, as given on the command line and stored in result files.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RuleConfig {
    /// Which rule.
    pub kind: RuleKind,
    /// Confidence `c` in `(0, 1)`.
    pub confidence: f64,
    /// Precision `e` in `(0, 0.5]`.
    pub precision: f64,
}

impl Default for RuleConfig {
    /// The adaptive bound at confidence 0.95 and precision 0.01.
    fn default() -> RuleConfig {
        RuleConfig {
            kind: RuleKind::Adaptive,
            confidence: 0.95,
            precision: 0.01,
        }
    }
}

impl RuleConfig {
    /// Checks the parameters and builds the rule.
    pub fn build(&self) -> Result<Box<dyn StoppingRule>, StatsError> {
        let accuracy = Accuracy::new(self.confidence, self.precision)?;
        Ok(match self.kind {
            RuleKind::Adaptive => Box::new(AdaptiveBound::new(accuracy)),
            RuleKind::Okamoto => Box::new(OkamotoBound::new(accuracy)),
            RuleKind::Wilson => Box::new(WilsonInterval::new(accuracy)),
            RuleKind::ClopperPearson => Box::new(ClopperPearson::new(accuracy)),
            RuleKind::Sprt { threshold } => Box::new(Sprt::new(accuracy, threshold)?),
        })
    }
}
