//! Tests of the SMC special functions and stopping rules against known values,
//! independent computations (binomial sums) and simulated coverage.

// Reference values are quoted with all the digits arbitrary-precision arithmetic gave.
#![allow(clippy::excessive_precision)]

use hindsight::verify::smc::math::{
    erfc, inv_reg_inc_beta, ln_gamma, normal_cdf, normal_quantile, reg_inc_beta,
};
use hindsight::verify::smc::stats::{
    adaptive_bound, clopper_pearson_interval, okamoto, wilson_interval, Accuracy, AdaptiveBound,
    ClopperPearson, Decision, OkamotoBound, RuleConfig, RuleKind, Sprt, StatsError, StoppingRule,
    WilsonInterval,
};
use rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn close(actual: f64, expected: f64, relative: f64) -> bool {
    (actual - expected).abs() <= relative * expected.abs().max(1e-300)
}

#[track_caller]
fn assert_close(actual: f64, expected: f64, relative: f64) {
    assert!(
        close(actual, expected, relative),
        "{actual} is not within {relative} (relative) of {expected}"
    );
}

fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// `P[Bin(n, p) >= k]` by direct summation.
fn binomial_upper_tail(n: u64, k: u64, p: f64) -> f64 {
    let mut total = 0.0;
    for j in k..=n {
        let mut choose = 1.0;
        for i in 0..j {
            choose *= (n - i) as f64 / (i + 1) as f64;
        }
        total += choose * p.powi(j as i32) * (1.0 - p).powi((n - j) as i32);
    }
    total
}

#[test]
fn ln_gamma_matches_known_values() {
    // Values from arbitrary-precision arithmetic.
    assert_close(ln_gamma(0.5), 0.572_364_942_924_700_1, 1e-14);
    assert_close(ln_gamma(3.7), 1.428_072_326_665_388_1, 1e-14);
    assert_close(ln_gamma(1e6), 12_815_504.569_147_612, 1e-15);
    assert_close(ln_gamma(1e-3), 6.907_178_885_383_853_7, 1e-14);
    // Integers: ln((n-1)!).
    let mut factorial = 1.0f64;
    for n in 1..30u32 {
        assert_close(ln_gamma(f64::from(n)).exp(), factorial, 1e-12);
        factorial *= f64::from(n);
    }
    assert!(ln_gamma(0.0).is_nan());
    assert!(ln_gamma(-1.5).is_nan());
}

#[test]
fn incomplete_beta_matches_known_values() {
    assert_close(reg_inc_beta(2.0, 3.0, 0.5), 0.6875, 1e-14);
    assert_close(reg_inc_beta(0.5, 0.5, 0.3), 0.369_010_119_565_545_4, 1e-13);
    assert_close(
        reg_inc_beta(50.0, 70.0, 0.4),
        0.359_134_608_834_494_7,
        1e-12,
    );
    assert_close(
        reg_inc_beta(2000.0, 3000.0, 0.41),
        0.925_262_126_208_304_2,
        1e-10,
    );
    assert_eq!(reg_inc_beta(2.0, 3.0, 0.0), 0.0);
    assert_eq!(reg_inc_beta(2.0, 3.0, 1.0), 1.0);
    assert_eq!(reg_inc_beta(2.0, 3.0, -4.0), 0.0);
    assert!(reg_inc_beta(0.0, 3.0, 0.5).is_nan());
    assert!(reg_inc_beta(2.0, f64::NAN, 0.5).is_nan());
}

#[test]
fn incomplete_beta_is_a_binomial_tail_for_integer_shapes() {
    for n in [1u64, 2, 7, 20, 45] {
        for k in 1..=n {
            for p in [0.001, 0.05, 0.3, 0.5, 0.77, 0.999] {
                let tail = binomial_upper_tail(n, k, p);
                let beta = reg_inc_beta(k as f64, (n - k + 1) as f64, p);
                assert!(
                    (beta - tail).abs() <= 1e-12,
                    "n={n} k={k} p={p}: {beta} vs {tail}"
                );
            }
        }
    }
}

#[test]
fn inverse_incomplete_beta_inverts() {
    let shapes = [
        (0.5, 0.5),
        (1.0, 1.0),
        (1.0, 1e6),
        (3.0, 1e6),
        (2.0, 5.0),
        (40.0, 3.0),
        (5000.0, 5001.0),
        (1e6, 2.0),
    ];
    for (a, b) in shapes {
        for y in [
            1e-12,
            1e-6,
            0.005,
            0.025,
            0.3,
            0.5,
            0.9,
            0.975,
            0.995,
            1.0 - 1e-9,
        ] {
            let x = inv_reg_inc_beta(a, b, y);
            assert!((0.0..=1.0).contains(&x), "a={a} b={b} y={y}: x={x}");
            let back = reg_inc_beta(a, b, x);
            // Either the value matches, or no double near x does better (the function
            // is too steep there for f64).
            let step = 8.0 * f64::EPSILON * x.max(f64::MIN_POSITIVE);
            let below = reg_inc_beta(a, b, x - step);
            let above = reg_inc_beta(a, b, x + step);
            assert!(
                (back - y).abs() <= 1e-9 * y.max(1e-3) || (below <= y && y <= above),
                "a={a} b={b} y={y}: x={x} gives {back}"
            );
        }
    }
    assert_eq!(inv_reg_inc_beta(2.0, 3.0, 0.0), 0.0);
    assert_eq!(inv_reg_inc_beta(2.0, 3.0, 1.0), 1.0);
    assert!(inv_reg_inc_beta(-2.0, 3.0, 0.4).is_nan());
}

#[test]
fn normal_distribution_matches_known_values() {
    assert_close(normal_quantile(0.975), 1.959_963_984_540_054, 1e-13);
    assert_close(normal_quantile(0.99), 2.326_347_874_040_841, 1e-13);
    assert_close(normal_quantile(0.995), 2.575_829_303_548_900_8, 1e-13);
    assert_close(normal_quantile(1e-10), -6.361_340_902_404_056, 1e-12);
    assert_close(normal_quantile(0.5).abs() + 1.0, 1.0, 1e-14);
    assert_close(normal_cdf(1.96), 0.975_002_104_851_779_6, 1e-13);
    assert_close(normal_cdf(-5.0), 2.866_515_718_791_939e-7, 1e-11);
    assert_close(erfc(10.0), 2.088_487_583_762_544_8e-45, 1e-11);
    assert_close(erfc(-0.3), 1.328_626_759_459_127_4, 1e-14);
    assert_close(erfc(0.7), 0.322_198_806_162_581_56, 1e-13);
    assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
    assert_eq!(normal_quantile(1.0), f64::INFINITY);
}

#[test]
fn clopper_pearson_matches_known_intervals() {
    // (successes, runs, confidence, lower, upper), from arbitrary-precision arithmetic.
    let cases = [
        (
            5,
            10,
            0.95,
            0.187_086_028_447_398_6,
            0.812_913_971_552_601_4,
        ),
        (0, 10, 0.95, 0.0, 0.308_497_107_818_760_76),
        (
            1,
            100,
            0.95,
            0.000_253_146_032_977_420_86,
            0.054_459_385_392_080_647,
        ),
        (
            99,
            100,
            0.95,
            0.945_540_614_607_919_35,
            0.999_746_853_967_022_58,
        ),
        (7, 40, 0.99, 0.053_670_516_935_561_4, 0.376_323_056_590_395),
        (
            3,
            1_000_000,
            0.95,
            6.186_725_501_906_4e-7,
            8.767_247_788_145_22e-6,
        ),
        (
            4950,
            10_000,
            0.95,
            0.485_153_327_187_275,
            0.504_849_586_246_614,
        ),
    ];
    for (successes, runs, confidence, lower, upper) in cases {
        let interval = clopper_pearson_interval(successes, runs, confidence);
        assert_close(interval.lower, lower, 1e-9);
        assert_close(interval.upper, upper, 1e-9);
    }
    assert_eq!(clopper_pearson_interval(10, 10, 0.95).upper, 1.0);
}

#[test]
fn wilson_matches_its_closed_form() {
    let z = normal_quantile(0.975);
    let interval = wilson_interval(5, 10, z);
    // Centre 1/2 by symmetry; half-width z/(1+z^2/n) sqrt(p(1-p)/n + z^2/(4n^2)).
    let half = z / (1.0 + z * z / 10.0) * (0.025 + z * z / 400.0f64).sqrt();
    assert_close(interval.lower, 0.5 - half, 1e-14);
    assert_close(interval.upper, 0.5 + half, 1e-14);
    assert!((interval.lower - 0.2366).abs() < 1e-4);
    let zero = wilson_interval(0, 20, z);
    assert_eq!(zero.lower, 0.0);
    assert!(zero.upper > 0.0 && zero.upper < 0.2);
}

#[test]
fn okamoto_rule_stops_at_the_chernoff_bound() {
    let accuracy = Accuracy::new(0.95, 0.01).expect("valid accuracy");
    let rule = OkamotoBound::new(accuracy);
    let needed = ((2.0f64 / 0.05).ln() / (2.0 * 0.01 * 0.01)).ceil() as u64;
    assert_eq!(rule.fixed_runs(), Some(needed));
    assert!(!rule.done(needed / 2, needed - 1));
    assert!(rule.done(needed / 2, needed));
    assert!(rule.interval(needed / 2, needed).half_width() <= 0.01);
    assert_close(okamoto(0.95, 0.01), (40.0f64).ln() / 0.0002, 1e-15);
}

#[test]
fn adaptive_rule_follows_scans_bound() {
    let (c, e) = (0.95, 0.01);
    let rule = AdaptiveBound::new(Accuracy::new(c, e).expect("valid accuracy"));
    // All runs succeed: the bound at p = 1 is ln(2/(1-c))/(2e^2) (1 - 4(1/2 - 2e/3)^2).
    let at_one =
        (2.0f64 / (1.0 - c)).ln() / (2.0 * e * e) * (1.0 - 4.0 * (0.5 - 2.0 * e / 3.0).powi(2));
    let first = at_one.ceil() as u64;
    assert!(!rule.done(first - 1, first - 1));
    assert!(rule.done(first, first));
    assert_close(adaptive_bound(1.0, c, e), at_one, 1e-12);
    // At p = 1/2 it needs almost the Okamoto bound.
    assert!(adaptive_bound(0.5, c, e) > 0.99 * okamoto(c, e));
    assert_eq!(rule.fixed_runs(), Some(okamoto(c, e).ceil() as u64));
    // Where the rule stops, the precision it reports is the requested one.
    for p in [0.0, 0.02, 0.1, 0.3, 0.5, 0.64, 0.97] {
        let mut n = 1;
        while !rule.done((p * n as f64).round() as u64, n) {
            n += 1;
        }
        let s = (p * n as f64).round() as u64;
        let achieved = rule.achieved_precision(s, n);
        assert!(achieved <= e * 1.0001, "p={p} n={n}: {achieved}");
        let before = rule.achieved_precision((p * (n - 1) as f64).round() as u64, n - 1);
        assert!(
            before > e * 0.98,
            "p={p}: precision {before} already reached before"
        );
    }
}

#[test]
fn interval_rules_stop_at_the_requested_half_width() {
    let accuracy = Accuracy::new(0.95, 0.02).expect("valid accuracy");
    let rules: [Box<dyn StoppingRule>; 2] = [
        Box::new(WilsonInterval::new(accuracy)),
        Box::new(ClopperPearson::new(accuracy)),
    ];
    for rule in &rules {
        for p in [0.0, 0.25, 0.5, 0.9] {
            let mut n = 1;
            while !rule.done((p * n as f64).round() as u64, n) {
                n += 1;
            }
            let s = (p * n as f64).round() as u64;
            assert!(rule.interval(s, n).half_width() <= 0.02);
            let needed = rule
                .runs_needed(s, n)
                .expect("interval rules estimate runs") as f64;
            // Exact for Wilson; Clopper-Pearson estimates with Wilson's answer.
            let slack = if rule.name() == "wilson" { 0.0 } else { 0.1 };
            assert!(
                (needed - n as f64).abs() <= slack * n as f64,
                "{} at p={p}: {needed} vs {n}",
                rule.name()
            );
        }
        let fixed = rule.fixed_runs().expect("interval rules have a fixed size");
        assert!(rule.done(fixed / 2, fixed), "{}", rule.name());
    }
}

/// Fraction of `trials` fixed-size samples of `runs` Bernoulli(p) draws whose interval
/// contains `p`.
fn coverage(rule: &dyn StoppingRule, p: f64, runs: u64, trials: u64, seed: u64) -> f64 {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut covered = 0;
    for _ in 0..trials {
        let successes = (0..runs).filter(|_| uniform(&mut rng) < p).count() as u64;
        if rule.interval(successes, runs).contains(p) {
            covered += 1;
        }
    }
    covered as f64 / trials as f64
}

#[test]
fn intervals_cover_the_true_probability() {
    let accuracy = Accuracy::new(0.95, 0.05).expect("valid accuracy");
    let exact = ClopperPearson::new(accuracy);
    let wilson = WilsonInterval::new(accuracy);
    let adaptive = AdaptiveBound::new(accuracy);
    for (i, p) in [0.03, 0.2, 0.5, 0.88].into_iter().enumerate() {
        let seed = 100 + i as u64;
        // Clopper-Pearson is exact (conservative): coverage >= 95% up to sampling noise.
        assert!(coverage(&exact, p, 150, 400, seed) >= 0.93, "exact, p={p}");
        assert!(
            coverage(&wilson, p, 150, 400, seed) >= 0.90,
            "wilson, p={p}"
        );
        assert!(
            coverage(&adaptive, p, 150, 400, seed) >= 0.93,
            "adaptive, p={p}"
        );
    }
}

#[test]
fn sprt_decides_far_from_the_threshold_and_keeps_its_error_rate() {
    let accuracy = Accuracy::new(0.95, 0.05).expect("valid accuracy");
    let test = Sprt::new(accuracy, 0.5).expect("valid threshold");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut run_test = |p: f64| {
        let (mut s, mut n) = (0, 0);
        loop {
            if let Some(decision) = test.decision(s, n) {
                return (decision, n);
            }
            n += 1;
            if uniform(&mut rng) < p {
                s += 1;
            }
        }
    };
    for _ in 0..50 {
        assert_eq!(run_test(0.9).0, Decision::Accept);
        assert_eq!(run_test(0.1).0, Decision::Reject);
    }
    // At the edges of the indifference region the error is about alpha = beta = 0.05.
    let trials = 2000;
    let wrong_high = (0..trials)
        .filter(|_| run_test(0.55).0 == Decision::Reject)
        .count();
    let wrong_low = (0..trials)
        .filter(|_| run_test(0.45).0 == Decision::Accept)
        .count();
    assert!((wrong_high as f64) < 0.075 * trials as f64, "{wrong_high}");
    assert!((wrong_low as f64) < 0.075 * trials as f64, "{wrong_low}");
    assert_eq!(test.fixed_runs(), None);
    assert!(test.done(40, 40));
}

#[test]
fn sprt_handles_thresholds_at_the_ends() {
    let accuracy = Accuracy::new(0.99, 0.01).expect("valid accuracy");
    let always = Sprt::new(accuracy, 1.0).expect("valid threshold");
    // P >= 1 is refuted by a single failure.
    assert_eq!(always.decision(10, 11), Some(Decision::Reject));
    let never = Sprt::new(accuracy, 0.0).expect("valid threshold");
    assert_eq!(never.decision(1, 1), Some(Decision::Accept));
    assert_eq!(never.decision(0, 0), None);
}

#[test]
fn rule_configs_are_checked() {
    let build = |kind, confidence, precision| {
        RuleConfig {
            kind,
            confidence,
            precision,
        }
        .build()
        .map(|rule| rule.name())
    };
    assert_eq!(build(RuleKind::Adaptive, 0.95, 0.01), Ok("adaptive"));
    assert_eq!(
        build(RuleKind::ClopperPearson, 0.9, 0.1),
        Ok("clopper-pearson")
    );
    assert_eq!(
        build(RuleKind::Sprt { threshold: 0.3 }, 0.9, 0.1),
        Ok("sprt")
    );
    assert_eq!(
        build(RuleKind::Wilson, 1.0, 0.01),
        Err(StatsError::Confidence(1.0))
    );
    assert_eq!(
        build(RuleKind::Okamoto, 0.95, 0.0),
        Err(StatsError::Precision(0.0))
    );
    assert_eq!(
        build(RuleKind::Sprt { threshold: 1.5 }, 0.95, 0.01),
        Err(StatsError::Threshold(1.5))
    );
    assert!(Accuracy::new(f64::NAN, 0.1).is_err());
    assert_eq!(
        RuleConfig::default().build().map(|r| r.name()),
        Ok("adaptive")
    );
}
