//! Simulation throughput on the museum guide and UC3 (a measurement, not a timed assertion).
//!
//! Run with `cargo test --release -p hindsight --test sim_bench -- --ignored --nocapture`.

use hindsight::model::ModelSource;
use hindsight::sim::{CompiledModel, EndReason, RunConfig, Simulator};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("shared/corpus"))
        .find(|dir| dir.is_dir())
        .expect("shared/corpus next to the repository")
}

fn museum() -> CompiledModel {
    let dir = corpus().join("museum-simpar2025/model_scxml");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "scxml"))
        .collect();
    paths.sort();
    let files: Vec<(String, String)> = paths
        .iter()
        .map(|p| {
            let t = std::fs::read_to_string(p).unwrap();
            (
                p.display().to_string(),
                t.replace("_event.thread_id", "_event.data.thread_id"),
            )
        })
        .collect();
    let src = ModelSource::from_texts(files.iter().map(|(a, b)| (a.as_str(), b.as_str()))).unwrap();
    CompiledModel::compile(src).unwrap()
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
    let m = museum();
    println!("museum: compiled in {:.3} s", t0.elapsed().as_secs_f64());
    // 100 s of model time: the global timer's 1000 steps of 100 ms.
    measure("museum (100 s model time)", &m, &RunConfig::default(), 500);
    let t0 = Instant::now();
    let u = CompiledModel::load(&corpus().join("uc3-plain/model.xml")).unwrap();
    println!("uc3: compiled in {:.3} s", t0.elapsed().as_secs_f64());
    let cfg = RunConfig {
        max_time: 1000,
        ..RunConfig::default()
    };
    measure("uc3 (100 s model time)", &u, &cfg, 20);
}
