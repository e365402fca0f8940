//! Tests of the deterministic parallel SMC runner with fake run functions whose
//! probabilities are known analytically.

use std::collections::HashMap;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Mutex;
use std::time::Duration;

use hindsight::verify::smc::{
    run_range, run_study, stream, Decision, Progress, RuleConfig, RuleKind, RunEnd, RunOutcome,
    StoppingRule, StudyConfig, StudyResult, Verdict, UNJUDGED_LIMIT,
};
use rand_core::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

/// A run where property `i` holds independently with probability `probabilities[i]`.
fn bernoulli(
    probabilities: &[f64],
) -> impl Fn(u64, &mut Xoshiro256PlusPlus) -> RunOutcome + Sync + '_ {
    move |_, rng| RunOutcome {
        verdicts: probabilities
            .iter()
            .map(|&p| Verdict::from(uniform(rng) < p))
            .collect(),
        assumptions: Verdict::True,
        end: RunEnd::Quiescent,
        steps: 1 + rng.next_u64() % 100,
        time: 10,
    }
}

fn rules(
    kind: RuleKind,
    confidence: f64,
    precision: f64,
    count: usize,
) -> Vec<Box<dyn StoppingRule>> {
    (0..count)
        .map(|_| {
            RuleConfig {
                kind,
                confidence,
                precision,
            }
            .build()
            .expect("valid rule")
        })
        .collect()
}

fn config(seed: u64, threads: usize) -> StudyConfig {
    StudyConfig {
        seed,
        threads,
        keep_failing: 5,
        ..StudyConfig::default()
    }
}

fn quiet(_: &Progress<'_>) {}

/// Everything but the wall-clock time.
fn deterministic_part(result: &StudyResult) -> impl PartialEq + std::fmt::Debug + '_ {
    (result.seed, &result.properties, result.runs, result.capped)
}

#[test]
fn true_probability_lies_in_the_reported_interval_across_seeds() {
    let probabilities = [0.05, 0.3, 0.5, 0.8, 1.0];
    let mut covered = 0;
    let mut total = 0;
    for seed in 0..12 {
        for kind in [
            RuleKind::Adaptive,
            RuleKind::Wilson,
            RuleKind::ClopperPearson,
        ] {
            let rules = rules(kind, 0.95, 0.03, probabilities.len());
            let result = run_study(
                &config(seed, 2),
                &rules,
                bernoulli(&probabilities),
                &mut quiet,
            );
            assert!(!result.capped);
            for (property, &p) in result.properties.iter().zip(&probabilities) {
                let estimate = property.estimate.estimate.expect("some runs");
                assert!(property.interval.contains(estimate));
                assert!(property.estimate.done);
                assert!(property.interval.half_width() <= 0.03 + 1e-9);
                total += 1;
                if property.interval.contains(p) {
                    covered += 1;
                }
            }
        }
    }
    // Nominal 95%: allow sampling noise over 180 intervals.
    assert!(
        covered as f64 >= 0.92 * total as f64,
        "{covered} of {total}"
    );
}

#[test]
fn same_seed_same_result_on_one_and_four_threads() {
    let probabilities = [0.2, 0.5, 0.97];
    for kind in [
        RuleKind::Adaptive,
        RuleKind::Okamoto,
        RuleKind::ClopperPearson,
        RuleKind::Sprt { threshold: 0.6 },
    ] {
        let rules = rules(kind, 0.9, 0.04, probabilities.len());
        let one = run_study(
            &config(42, 1),
            &rules,
            bernoulli(&probabilities),
            &mut quiet,
        );
        let four = run_study(
            &config(42, 4),
            &rules,
            bernoulli(&probabilities),
            &mut quiet,
        );
        assert_eq!(
            deterministic_part(&one),
            deterministic_part(&four),
            "{kind:?}"
        );
        let other_seed = run_study(
            &config(43, 4),
            &rules,
            bernoulli(&probabilities),
            &mut quiet,
        );
        assert_ne!(one.properties, other_seed.properties, "{kind:?}");
    }
}

#[test]
fn slow_failures_do_not_bias_a_parallel_study() {
    // Failing runs take much longer than passing ones: a runner that consumed results in
    // completion order would over-count successes on many threads.
    let p = 0.5;
    let run = |_: u64, rng: &mut Xoshiro256PlusPlus| {
        let ok = uniform(rng) < p;
        if !ok {
            std::thread::sleep(Duration::from_micros(300));
        }
        RunOutcome {
            verdicts: vec![Verdict::from(ok)],
            assumptions: Verdict::True,
            end: RunEnd::Quiescent,
            steps: 1,
            time: 0,
        }
    };
    let rules = rules(RuleKind::Wilson, 0.95, 0.05, 1);
    let one = run_study(&config(9, 1), &rules, run, &mut quiet);
    let four = run_study(&config(9, 4), &rules, run, &mut quiet);
    assert_eq!(deterministic_part(&one), deterministic_part(&four));
    assert!(four.properties[0].interval.contains(p));
}

#[test]
fn run_k_uses_stream_k() {
    let seen = Mutex::new(HashMap::new());
    let run = |k: u64, rng: &mut Xoshiro256PlusPlus| {
        seen.lock().expect("not poisoned").insert(k, rng.next_u64());
        RunOutcome {
            verdicts: vec![Verdict::True],
            assumptions: Verdict::True,
            end: RunEnd::Quiescent,
            steps: 1,
            time: 0,
        }
    };
    let study = StudyConfig {
        max_runs: Some(40),
        ..config(5, 3)
    };
    let rules = rules(RuleKind::Okamoto, 0.95, 0.01, 1);
    let result = run_study(&study, &rules, run, &mut quiet);
    assert!(result.capped);
    assert_eq!(result.runs.runs, 40);
    let seen = seen.into_inner().expect("not poisoned");
    for k in 0..40 {
        assert_eq!(seen.get(&k), Some(&stream(5, k).next_u64()), "run {k}");
    }
    // Streams differ from each other.
    assert_ne!(stream(5, 0).next_u64(), stream(5, 1).next_u64());
}

#[test]
fn failing_runs_are_the_first_ones_and_replay() {
    let probabilities = [0.7];
    let run = bernoulli(&probabilities);
    let rules = rules(RuleKind::Adaptive, 0.95, 0.05, 1);
    let result = run_study(&config(11, 4), &rules, &run, &mut quiet);
    let failing = &result.properties[0].failing_runs;
    assert_eq!(failing.len(), 5);
    let replayed: Vec<u64> = (0..)
        .filter(|&k| run(k, &mut stream(11, k)).verdicts[0] == Verdict::False)
        .take(5)
        .collect();
    assert_eq!(failing, &replayed);
}

#[test]
fn assumptions_filter_runs_and_are_counted() {
    // x uniform; assumption: x < 0.6; property: x < 0.3. P(property | assumption) = 1/2.
    let run = |_: u64, rng: &mut Xoshiro256PlusPlus| {
        let x = uniform(rng);
        RunOutcome {
            verdicts: vec![Verdict::from(x < 0.3)],
            assumptions: Verdict::from(x < 0.6),
            end: RunEnd::Quiescent,
            steps: 3,
            time: 1,
        }
    };
    let rules = rules(RuleKind::ClopperPearson, 0.95, 0.03, 1);
    let result = run_study(&config(3, 2), &rules, run, &mut quiet);
    let property = &result.properties[0];
    assert!(property.interval.contains(0.5), "{:?}", property.interval);
    assert_eq!(
        property.counts.judged() + result.runs.discarded,
        result.runs.runs
    );
    let discarded = result.runs.discarded as f64 / result.runs.runs as f64;
    assert!((discarded - 0.4).abs() < 0.05, "{discarded}");
    assert_eq!(result.runs.steps, 3 * result.runs.runs);
}

#[test]
fn runs_cut_short_are_counted_and_widen_the_interval() {
    // 20% of runs hit the step limit before the verdict is final.
    let run = |_: u64, rng: &mut Xoshiro256PlusPlus| {
        let cut = uniform(rng) < 0.2;
        let ok = uniform(rng) < 0.5;
        RunOutcome {
            verdicts: vec![if cut {
                Verdict::Unknown
            } else {
                Verdict::from(ok)
            }],
            assumptions: Verdict::True,
            end: if cut {
                RunEnd::StepLimit
            } else {
                RunEnd::Quiescent
            },
            steps: 10,
            time: 1,
        }
    };
    let rules = rules(RuleKind::Wilson, 0.95, 0.03, 1);
    let result = run_study(&config(8, 3), &rules, run, &mut quiet);
    let property = &result.properties[0];
    let counts = property.counts;
    assert_eq!(counts.judged() + counts.unknown, result.runs.runs);
    assert_eq!(result.runs.step_limit, counts.unknown);
    assert!(counts.unknown > 0);
    // The rule saw only judged runs; the reported interval covers any value of the rest.
    let n = counts.judged() as f64;
    let total = n + counts.unknown as f64;
    let rule = &property.estimate.interval;
    assert!((property.interval.lower - rule.lower * n / total).abs() < 1e-12);
    assert!(
        (property.interval.upper - (rule.upper * n + counts.unknown as f64) / total).abs() < 1e-12
    );
    // The share of satisfying runs among all (0.4) and among judged ones (0.5) both lie inside.
    assert!(property.interval.contains(0.4) && property.interval.contains(0.5));
}

#[test]
fn unknown_assumptions_make_every_verdict_unknown() {
    let run = |k: u64, _: &mut Xoshiro256PlusPlus| RunOutcome {
        verdicts: vec![Verdict::True, Verdict::False],
        assumptions: if k % 4 == 0 {
            Verdict::Unknown
        } else {
            Verdict::True
        },
        end: if k % 4 == 0 {
            RunEnd::StepLimit
        } else {
            RunEnd::TimeHorizon
        },
        steps: 1,
        time: 100,
    };
    let study = StudyConfig {
        max_runs: Some(100),
        ..config(1, 2)
    };
    let rules = rules(RuleKind::Okamoto, 0.95, 0.01, 2);
    let result = run_study(&study, &rules, run, &mut quiet);
    assert_eq!(result.properties[0].counts.unknown, 25);
    assert_eq!(result.properties[0].counts.successes, 75);
    assert_eq!(result.properties[1].counts.failures, 75);
    assert_eq!(result.runs.time_horizon, 75);
    assert_eq!(result.runs.step_limit, 25);
    assert_eq!(result.runs.model_time, 100 * 100);
}

#[test]
fn each_property_stops_on_its_own_and_the_study_when_all_are_done() {
    // Property 0 is always true (the adaptive bound stops early), property 1 is a coin.
    let probabilities = [1.0, 0.5];
    let rules = rules(RuleKind::Adaptive, 0.95, 0.02, 2);
    let result = run_study(&config(2, 2), &rules, bernoulli(&probabilities), &mut quiet);
    let first = &result.properties[0];
    let second = &result.properties[1];
    let stopped_first = first.stopped_at.expect("done");
    let stopped_second = second.stopped_at.expect("done");
    assert!(stopped_first < stopped_second);
    assert_eq!(first.counts.judged(), stopped_first + 1);
    assert_eq!(second.counts.judged(), stopped_second + 1);
    assert_eq!(result.runs.runs, stopped_second + 1);
    assert_eq!(first.estimate.estimate, Some(1.0));
}

#[test]
fn sprt_answers_far_from_the_threshold() {
    for seed in 0..10 {
        let probabilities = [0.9, 0.1, 0.75];
        let rules = rules(RuleKind::Sprt { threshold: 0.5 }, 0.99, 0.05, 3);
        let result = run_study(
            &config(seed, 2),
            &rules,
            bernoulli(&probabilities),
            &mut quiet,
        );
        assert_eq!(
            result.properties[0].estimate.decision,
            Some(Decision::Accept)
        );
        assert_eq!(
            result.properties[1].estimate.decision,
            Some(Decision::Reject)
        );
        assert_eq!(
            result.properties[2].estimate.decision,
            Some(Decision::Accept)
        );
    }
}

/// A study none of whose runs can be judged for a property still going stops after
/// `UNJUDGED_LIMIT` runs (it ran forever before: no run brought the rule closer to done),
/// whether the runs are cut short or discarded; a property with rare judged runs goes on.
#[test]
fn a_study_that_can_judge_no_run_stops() {
    // Property 0 is judged on every run (a coin); property 1 on none: cut short, or (with
    // the assumption false) every run discarded.
    for discard in [false, true] {
        let run = move |_: u64, rng: &mut Xoshiro256PlusPlus| RunOutcome {
            verdicts: vec![Verdict::from(uniform(rng) < 0.5), Verdict::Unknown],
            assumptions: if discard {
                Verdict::False
            } else {
                Verdict::True
            },
            end: RunEnd::StepLimit,
            steps: 1,
            time: 0,
        };
        for threads in [1, 3] {
            let rules = rules(RuleKind::Okamoto, 0.95, 0.1, 2);
            let result = run_study(&config(5, threads), &rules, run, &mut quiet);
            // Okamoto at 0.1 needs 185 judged runs: property 0 is done long before, and
            // the study stops at the limit, not at a cap (there is none) nor never.
            assert!(result.unjudged && result.capped, "discard {discard}");
            assert_eq!(result.runs.runs, UNJUDGED_LIMIT, "discard {discard}");
            assert_eq!(result.properties[1].counts.judged(), 0);
            assert_eq!(result.properties[1].stopped_at, None);
            if discard {
                assert_eq!(result.runs.discarded, UNJUDGED_LIMIT);
                assert_eq!(result.properties[0].counts.judged(), 0);
            } else {
                assert_eq!(result.properties[1].counts.unknown, UNJUDGED_LIMIT);
                assert!(result.properties[0].stopped_at.is_some());
            }
        }
    }
    // One judged run in 500 (the first at run 499) keeps the property going past the
    // limit until its rule is done.
    let rare = |k: u64, rng: &mut Xoshiro256PlusPlus| RunOutcome {
        verdicts: vec![if k % 500 == 499 {
            Verdict::from(uniform(rng) < 0.5)
        } else {
            Verdict::Unknown
        }],
        assumptions: Verdict::True,
        end: RunEnd::StepLimit,
        steps: 1,
        time: 0,
    };
    let study = StudyConfig {
        max_runs: Some(5 * UNJUDGED_LIMIT),
        ..config(5, 2)
    };
    let result = run_study(
        &study,
        &rules(RuleKind::Okamoto, 0.95, 0.1, 1),
        rare,
        &mut quiet,
    );
    assert!(!result.unjudged);
    assert_eq!(result.runs.runs, 5 * UNJUDGED_LIMIT);
    assert_eq!(result.properties[0].counts.judged(), 10);
}

/// A thread count past MAX_THREADS (a library caller's, the CLI refuses it) is taken as
/// MAX_THREADS: the study runs, with the numbers of one thread.
#[test]
fn a_huge_thread_count_is_capped() {
    let probabilities = [0.5];
    let rules = rules(RuleKind::Okamoto, 0.95, 0.1, 1);
    let huge = StudyConfig {
        max_runs: Some(50),
        ..config(3, usize::MAX)
    };
    let one = StudyConfig {
        max_runs: Some(50),
        ..config(3, 1)
    };
    let a = run_study(&huge, &rules, bernoulli(&probabilities), &mut quiet);
    let b = run_study(&one, &rules, bernoulli(&probabilities), &mut quiet);
    assert_eq!(a.runs.runs, 50);
    assert_eq!(deterministic_part(&a), deterministic_part(&b));
}

#[test]
fn a_rule_that_cannot_finish_is_capped() {
    let run = |_: u64, _: &mut Xoshiro256PlusPlus| RunOutcome {
        verdicts: vec![Verdict::Unknown],
        assumptions: Verdict::True,
        end: RunEnd::StepLimit,
        steps: 1,
        time: 0,
    };
    let study = StudyConfig {
        max_runs: Some(333),
        ..config(0, 4)
    };
    let result = run_study(
        &study,
        &rules(RuleKind::Adaptive, 0.95, 0.01, 1),
        run,
        &mut quiet,
    );
    assert!(result.capped);
    assert_eq!(result.runs.runs, 333);
    assert_eq!(result.properties[0].stopped_at, None);
    assert_eq!(result.properties[0].interval.lower, 0.0);
    assert_eq!(result.properties[0].interval.upper, 1.0);
}

#[test]
fn progress_reports_end_with_a_final_one() {
    let probabilities = [0.5];
    let study = StudyConfig {
        progress_every: Duration::ZERO,
        ..config(4, 2)
    };
    let mut reports = Vec::new();
    let mut expected = Vec::new();
    // Draws only if the test's standard error is a terminal.
    let mut bar = hindsight::cli::progress::TerminalProgress::stderr();
    let result = run_study(
        &study,
        &rules(RuleKind::Adaptive, 0.95, 0.05, 1),
        bernoulli(&probabilities),
        &mut |progress: &Progress<'_>| {
            reports.push((progress.runs, progress.finished, progress.eta.is_some()));
            expected.push(progress.expected_runs);
            bar.update(progress);
        },
    );
    let last = *reports.last().expect("a report");
    assert_eq!(last, (result.runs.runs, true, true));
    assert_eq!(expected.last(), Some(&Some(result.runs.runs)));
    // The adaptive bound's estimate of the total is never below the runs already done.
    assert!(reports
        .iter()
        .zip(&expected)
        .all(|(report, total)| total.is_none_or(|total| total >= report.0)));
    assert!(reports.windows(2).all(|w| w[0].0 <= w[1].0));
    assert_eq!(reports.iter().filter(|r| r.1).count(), 1);
    // With progress every run, ETAs are reported once runs exist.
    assert!(reports.iter().filter(|r| r.0 > 0).all(|r| r.2));
}

#[test]
fn a_panicking_run_is_propagated() {
    let run = |k: u64, _: &mut Xoshiro256PlusPlus| {
        assert!(k != 17, "run 17 fails");
        RunOutcome {
            verdicts: vec![Verdict::True],
            assumptions: Verdict::True,
            end: RunEnd::Quiescent,
            steps: 1,
            time: 0,
        }
    };
    for threads in [1, 3] {
        let rules = rules(RuleKind::Okamoto, 0.95, 0.01, 1);
        let outcome = panic::catch_unwind(AssertUnwindSafe(|| {
            run_study(&config(0, threads), &rules, run, &mut quiet)
        }));
        assert!(outcome.is_err(), "{threads} threads");
    }
}

#[test]
fn run_range_counts_every_run_once() {
    let probabilities = [0.25, 0.75];
    let counts = |threads| {
        run_range(
            &config(21, threads),
            100..1100,
            2,
            bernoulli(&probabilities),
            &mut quiet,
        )
    };
    let one = counts(1);
    assert_eq!(one, counts(4));
    assert_eq!(one.runs.runs, 1000);
    assert_eq!(one.properties[0].judged(), 1000);
    let share = one.properties[1].successes as f64 / 1000.0;
    assert!((share - 0.75).abs() < 0.05, "{share}");
}

#[test]
fn few_runs_are_wasted_past_the_stopping_point() {
    use std::sync::atomic::{AtomicU64, Ordering};
    for threads in [2, 4] {
        let started = AtomicU64::new(0);
        let run = |_: u64, _: &mut Xoshiro256PlusPlus| {
            started.fetch_add(1, Ordering::Relaxed);
            std::thread::sleep(Duration::from_micros(50));
            RunOutcome {
                verdicts: vec![Verdict::True],
                assumptions: Verdict::True,
                end: RunEnd::Quiescent,
                steps: 1,
                time: 0,
            }
        };
        let rules = rules(RuleKind::Adaptive, 0.95, 0.01, 1);
        let result = run_study(&config(0, threads), &rules, run, &mut quiet);
        let started = started.load(Ordering::Relaxed);
        assert!(
            started <= result.runs.runs + 2 * threads as u64,
            "{threads} threads: {started} started for {} used",
            result.runs.runs
        );
    }
}
