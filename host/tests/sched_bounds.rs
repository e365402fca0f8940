//! Bounds over schedulers against known answers: small models whose smallest and largest
//! probability over schedulers an exhaustive explorer in this file computes, and the
//! sampled bounds of `verify::schedulers` must lie inside and reach.
//!
//! The explorer shares no code with the simulator: each model's choices are written here
//! as a small decision tree (the choices that change the outcome, the model state the
//! scheduler sees at each, the model's own random draws), and every scheduler of the tree
//! is enumerated: every map from seen states to options (memoryless), and backward
//! induction over the tree (history-dependent, which is optimal over all schedulers).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use hindsight::verify::load::{load, LoadOptions, Loaded};
use hindsight::verify::schedulers::{bounds, SchedulerBounds, SchedulerOptions};
use hindsight::verify::sim::{Memory, RunConfig, Scheduler};
use hindsight::verify::smc::stats::{RuleConfig, RuleKind};
use hindsight::verify::smc::StudyConfig;
use hindsight::verify::study::{study, Runner, Unfair};

/// A model's choices as a tree: the explorer's input.
enum Tree {
    /// The run is over: does the property hold?
    Leaf(bool),
    /// The scheduler picks one option; `state` names the model state it sees there.
    Choice(&'static str, Vec<Tree>),
    /// The model draws: option with its probability.
    Chance(Vec<(f64, Tree)>),
}

/// Probability of the property under the memoryless scheduler `policy` (state -> option);
/// states the policy does not name take option 0, recorded in `seen`.
fn value_under(t: &Tree, policy: &BTreeMap<&'static str, usize>) -> f64 {
    match t {
        Tree::Leaf(b) => *b as u8 as f64,
        Tree::Choice(s, opts) => value_under(&opts[policy.get(s).copied().unwrap_or(0)], policy),
        Tree::Chance(opts) => opts.iter().map(|(p, t)| p * value_under(t, policy)).sum(),
    }
}

fn states(t: &Tree, out: &mut BTreeMap<&'static str, usize>) {
    match t {
        Tree::Leaf(_) => {}
        Tree::Choice(s, opts) => {
            out.insert(s, opts.len());
            opts.iter().for_each(|t| states(t, out));
        }
        Tree::Chance(opts) => opts.iter().for_each(|(_, t)| states(t, out)),
    }
}

/// (min, max) over every memoryless deterministic scheduler: all maps state -> option.
fn memoryless_bounds(t: &Tree) -> (f64, f64) {
    let mut sizes = BTreeMap::new();
    states(t, &mut sizes);
    let names: Vec<_> = sizes.keys().copied().collect();
    let mut choice = vec![0usize; names.len()];
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    loop {
        let policy: BTreeMap<_, _> = names.iter().copied().zip(choice.iter().copied()).collect();
        let v = value_under(t, &policy);
        lo = lo.min(v);
        hi = hi.max(v);
        // Next policy, as an odometer.
        let mut i = 0;
        loop {
            if i == names.len() {
                return (lo, hi);
            }
            choice[i] += 1;
            if choice[i] < sizes[names[i]] {
                break;
            }
            choice[i] = 0;
            i += 1;
        }
    }
}

/// (min, max) over all schedulers, history-dependent ones included (backward induction).
fn history_bounds(t: &Tree) -> (f64, f64) {
    match t {
        Tree::Leaf(b) => (*b as u8 as f64, *b as u8 as f64),
        Tree::Choice(_, opts) => opts
            .iter()
            .map(history_bounds)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            }),
        Tree::Chance(opts) => opts.iter().fold((0.0, 0.0), |(lo, hi), (p, t)| {
            let (a, b) = history_bounds(t);
            (lo + p * a, hi + p * b)
        }),
    }
}

/// The probability under the uniform scheduler.
fn uniform(t: &Tree) -> f64 {
    match t {
        Tree::Leaf(b) => *b as u8 as f64,
        Tree::Choice(_, opts) => opts.iter().map(uniform).sum::<f64>() / opts.len() as f64,
        Tree::Chance(opts) => opts.iter().map(|(p, t)| p * uniform(t)).sum(),
    }
}

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn loaded(dir: &str) -> Loaded {
    load(&LoadOptions {
        model: data(dir),
        ..LoadOptions::default()
    })
    .unwrap_or_else(|e| panic!("{dir}: {e}"))
}

const PRECISION: f64 = 0.02;

fn rule() -> RuleConfig {
    RuleConfig {
        kind: RuleKind::Adaptive,
        confidence: 0.95,
        precision: PRECISION,
    }
}

fn run_cfg(max_time: u64) -> RunConfig {
    RunConfig {
        max_time,
        ..RunConfig::default()
    }
}

/// The bounds of `count` sampled schedulers, per guarantee, and the uniform estimates.
fn sampled(
    l: &Loaded,
    max_time: u64,
    count: u64,
    memory: Memory,
    seed: u64,
    threads: usize,
) -> (Vec<SchedulerBounds>, Vec<f64>) {
    let study_cfg = StudyConfig {
        seed,
        threads,
        ..StudyConfig::default()
    };
    let opts = SchedulerOptions {
        count,
        memory,
        selection_runs: 8,
        unfair: Unfair::LeaveOut,
    };
    let b = bounds(
        &l.model,
        &l.set,
        &run_cfg(max_time),
        &study_cfg,
        &rule(),
        &opts,
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .expect("bounds")
    .expect("not interrupted");
    let u = study(
        &l.model,
        &l.set,
        &run_cfg(max_time),
        &study_cfg,
        &rule(),
        &mut |_| {},
    )
    .expect("uniform study");
    let u = u
        .properties
        .iter()
        .map(|p| p.estimate.estimate.expect("judged"))
        .collect();
    (b, u)
}

/// The sampled bounds lie inside the true ones (up to their intervals) and reach them.
fn check(name: &str, b: &SchedulerBounds, u: f64, (lo, hi): (f64, f64), uni: f64) {
    let (min, max) = (b.min.probability.unwrap(), b.max.probability.unwrap());
    // Inside: no witness is below the true minimum or above the true maximum, beyond its
    // interval.
    assert!(
        b.min.interval[1] >= lo,
        "{name}: min {:?} below {lo}",
        b.min
    );
    assert!(
        b.max.interval[0] <= hi,
        "{name}: max {:?} above {hi}",
        b.max
    );
    // Reached: each interval holds the true bound.
    assert!(
        b.min.interval[0] <= lo && lo <= b.min.interval[1],
        "{name}: min {min} {:?} misses {lo}",
        b.min.interval
    );
    assert!(
        b.max.interval[0] <= hi && hi <= b.max.interval[1],
        "{name}: max {max} {:?} misses {hi}",
        b.max.interval
    );
    assert!(
        (u - uni).abs() <= 2.0 * PRECISION,
        "{name}: uniform {u} far from {uni}"
    );
    assert_eq!(
        b.order_sensitive,
        max - min > 2.0 * PRECISION,
        "{name}: flag against numbers"
    );
}

#[test]
fn two_machines_racing_for_a_variable_give_half_zero_and_one() {
    // a's and b's writes reach the cell in the order they are sent: who sends first is
    // the only choice that matters (the cell's own start and the loser's write do not).
    let tree = Tree::Choice("both ready", vec![Tree::Leaf(true), Tree::Leaf(false)]);
    let (lo, hi) = memoryless_bounds(&tree);
    assert_eq!((lo, hi), (0.0, 1.0));
    assert_eq!(history_bounds(&tree), (0.0, 1.0));
    assert_eq!(uniform(&tree), 0.5);
    let l = loaded("schedulers/race");
    for memory in [Memory::Memoryless, Memory::History] {
        let (b, u) = sampled(&l, 10, 32, memory, 1, 2);
        check("a_wins", &b[0], u[0], (lo, hi), 0.5);
        assert!(b[0].order_sensitive);
        // Someone always wins, whatever the order: never flagged.
        check("someone_wins", &b[1], u[1], (1.0, 1.0), 1.0);
        assert!(!b[1].order_sensitive);
        // The witnesses replay: a run under the min witness never has a win.
        let w: Scheduler = b[0].min.scheduler.parse().unwrap();
        let cfg = RunConfig {
            scheduler: w,
            ..run_cfg(10)
        };
        let runner = Runner::new(&l.model, &l.set, &cfg);
        for k in 0..20 {
            let mut rng = hindsight::verify::smc::stream(7, k);
            let out = runner.run(k, &mut rng);
            assert_eq!(
                out.verdicts[0],
                hindsight::verify::smc::Verdict::False,
                "run {k}"
            );
        }
    }
}

/// The alternate model's tree: a first (A) or b first (B) at instant 1, then at instant
/// 2, in the same model state `every instant`; `holds(first, second)`.
fn alternate(holds: fn(char, char) -> bool) -> Tree {
    let instant = |first: char| {
        Tree::Choice(
            "every instant",
            vec![Tree::Leaf(holds(first, 'A')), Tree::Leaf(holds(first, 'B'))],
        )
    };
    Tree::Choice("every instant", vec![instant('A'), instant('B')])
}

#[test]
fn a_history_dependent_scheduler_reaches_a_bound_no_memoryless_one_reaches() {
    let ab = alternate(|x, y| x == 'A' && y == 'B');
    // Only memory can put a first, then b first, in the same state: max 0 without it.
    assert_eq!(memoryless_bounds(&ab), (0.0, 0.0));
    assert_eq!(history_bounds(&ab), (0.0, 1.0));
    assert_eq!(uniform(&ab), 0.25);
    let aa = alternate(|x, y| x == 'A' && y == 'A');
    assert_eq!(memoryless_bounds(&aa), (0.0, 1.0));
    assert_eq!(history_bounds(&aa), (0.0, 1.0));

    let l = loaded("schedulers/alternate");
    let (b, u) = sampled(&l, 2, 64, Memory::Memoryless, 3, 2);
    check("a_then_b_first", &b[0], u[0], memoryless_bounds(&ab), 0.25);
    assert!(!b[0].order_sensitive, "memoryless: never");
    check("a_first_twice", &b[1], u[1], memoryless_bounds(&aa), 0.25);

    let (b, u) = sampled(&l, 2, 64, Memory::History, 3, 2);
    check("a_then_b_first", &b[0], u[0], history_bounds(&ab), 0.25);
    assert!(b[0].order_sensitive);
    assert_eq!(b[0].max.probability, Some(1.0));
    assert!(b[0].max.scheduler.starts_with("history:"));
    check("a_first_twice", &b[1], u[1], history_bounds(&aa), 0.25);
}

#[test]
fn a_model_without_nondeterminism_has_min_equal_max_and_is_never_flagged() {
    // The coin is thrown once (Math.random() < 0.3): a draw of the model, no choice.
    let tree = Tree::Chance(vec![(0.3, Tree::Leaf(true)), (0.7, Tree::Leaf(false))]);
    let (lo, hi) = history_bounds(&tree);
    assert!((lo - 0.3).abs() < 1e-12 && (hi - 0.3).abs() < 1e-12);
    assert_eq!(memoryless_bounds(&tree), (lo, hi));
    let l = loaded("verify/coin");
    for memory in [Memory::Memoryless, Memory::History] {
        let (b, u) = sampled(&l, 10, 16, memory, 5, 2);
        for (i, (name, p)) in [("heads", 0.3), ("tails", 0.7)].into_iter().enumerate() {
            // Every scheduler sees the same draws: the same runs, the same estimate.
            assert_eq!(b[i].min.probability, b[i].max.probability, "{name}");
            assert_eq!(b[i].min.interval, b[i].max.interval, "{name}");
            assert!(!b[i].order_sensitive, "{name}");
            check(name, &b[i], u[i], (p, p), p);
        }
    }
}

#[test]
fn bounds_do_not_depend_on_the_thread_count() {
    let l = loaded("schedulers/alternate");
    let one = sampled(&l, 2, 16, Memory::History, 11, 1).0;
    let two = sampled(&l, 2, 16, Memory::History, 11, 2).0;
    assert_eq!(one, two);
    let other_seed = sampled(&l, 2, 16, Memory::History, 12, 2).0;
    assert_ne!(one[0].min.scheduler, other_seed[0].min.scheduler);
}
