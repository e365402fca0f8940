//! Proves, with a counting allocator, that a run in steady state allocates nothing.
//!
//! The first runs grow the simulator's buffers (queues, message slots, arrays);
//! after that, whole runs - every step, every reset - must not allocate.

mod common;

use hindsight::verify::sim::{CompiledModel, EndReason, EventSemantics, RunConfig, Simulator};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};

#[global_allocator]
static GLOBAL: common::alloc::Counting = common::alloc::Counting;

fn corpus() -> PathBuf {
    common::corpus_root()
}

/// Warms up with `warm` runs, then checks that `runs` more runs allocate nothing.
fn assert_steady_state_allocation_free(m: &CompiledModel, cfg: &RunConfig, warm: u64, runs: u64) {
    let mut sim = Simulator::new(m);
    for seed in 0..warm {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        sim.run(&mut rng, cfg, &mut ());
    }
    let mut steps = 0;
    for seed in 0..runs {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let before = common::alloc::count();
        let out = sim.run(&mut rng, cfg, &mut ());
        let n = common::alloc::count() - before;
        assert!(
            !matches!(out.end, EndReason::Error(_) | EndReason::Spin(_)),
            "{out:?}"
        );
        assert_eq!(
            n, 0,
            "run {seed} allocated {n} times in {} steps",
            out.steps
        );
        steps += out.steps;
    }
    assert!(steps > 0);
}

#[test]
fn museum_runs_allocate_nothing() {
    let m = common::museum_fixed();
    assert_steady_state_allocation_free(&m, &RunConfig::default(), 3, 3);
}

#[test]
fn uc3_runs_with_array_messages_allocate_nothing() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let m = CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    let cfg = RunConfig {
        max_time: 300,
        ..RunConfig::default()
    };
    assert_steady_state_allocation_free(&m, &cfg, 3, 2);
}

/// Arrays grow and shrink inside their buffers; an array of arrays or structs that a run
/// empties and regrows (the `structs` model does that with `shape.corners`) reuses the
/// elements it set aside.
#[test]
fn array_models_allocate_nothing_once_warm() {
    for name in [
        "arrays",
        "structs",
        "targetexpr",
        "delay",
        "internal",
        "ping_pong",
    ] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/sim")
            .join(name);
        let m = CompiledModel::load(&dir).unwrap();
        assert_steady_state_allocation_free(&m, &RunConfig::default(), 3, 5);
    }
}

/// AS2FM's event semantics (global pending events, broadcast deliveries, receivers'
/// copies) on AS2FM's plain translations: a BT with a blackboard, action threads with
/// array messages, and the museum guide's 60 machines.
#[test]
fn as2fm_semantics_allocate_nothing_once_warm() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let cfg = RunConfig {
        events: EventSemantics::As2fm,
        ..RunConfig::default()
    };
    for case in [
        "grid_robot_blackboard_simple_main",
        "fibonacci_action_example_main",
        "uc3_museum_guide_main",
    ] {
        let m = CompiledModel::load(&corpus().join("as2fm/plain").join(case)).unwrap();
        assert_steady_state_allocation_free(&m, &cfg, 3, 3);
    }
}
