//! Simulation throughput on the museum guide and UC3 (a measurement, not a timed assertion).
//!
//! Run with `cargo test --release -p hindsight --test sim_bench -- --ignored --nocapture`.

mod common;

use hindsight::verify::sim::{CompiledModel, EndReason, RunConfig, Simulator};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::PathBuf;
use std::time::Instant;

fn corpus() -> PathBuf {
    common::corpus_root()
}

/// Runs `runs` seeded runs; prints runs/s and steps/s; returns steps per second.
fn measure(name: &str, m: &CompiledModel, cfg: &RunConfig, runs: u64) -> f64 {
    let mut sim = Simulator::new(m);
    // Warm up buffers.
    sim.run(
        &mut Xoshiro256PlusPlus::seed_from_u64(u64::MAX),
        cfg,
        &mut (),
    );
    let t0 = Instant::now();
    let mut steps = 0;
    for seed in 0..runs {
        let out = sim.run(&mut Xoshiro256PlusPlus::seed_from_u64(seed), cfg, &mut ());
        assert!(
            matches!(out.end, EndReason::Quiescent | EndReason::MaxTime),
            "{out:?}"
        );
        steps += out.steps;
    }
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{name}: {runs} runs in {dt:.3} s = {:.1} runs/s, {:.2} M steps/s ({} steps/run)",
        runs as f64 / dt,
        steps as f64 / dt / 1e6,
        steps / runs
    );
    steps as f64 / dt
}

#[test]
#[ignore = "benchmark: run in release with --ignored --nocapture"]
fn throughput() {
    let t0 = Instant::now();
    let m = common::museum_fixed();
    println!("museum: compiled in {:.3} s", t0.elapsed().as_secs_f64());
    // 100 s of model time: the global timer's 1000 steps of 100 ms.
    measure("museum (100 s model time)", &m, &RunConfig::default(), 500);
    if common::corpus_or_skip().is_none() {
        return;
    }
    let t0 = Instant::now();
    let u = CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    println!("uc3: compiled in {:.3} s", t0.elapsed().as_secs_f64());
    let cfg = RunConfig {
        max_time: 1000,
        ..RunConfig::default()
    };
    measure("uc3 (100 s model time)", &u, &cfg, 20);
}
