//! One engine over one benchmark formula, for instruction counting under load.
//!
//! `cargo build --profile bench -p hindsight-bench --example count`, then
//! `valgrind --tool=callgrind --toggle-collect='hindsight_bench::*run*' target/release/examples/count K ENGINE N`
//! counts only the measured loop (see `scripts/count-instructions`): formula `FORMULAS[K]`,
//! engine `step` (try_step, planned), `step0` (try_step, unplanned), `atoms` (try_step_atoms), `gen` (generated code) or `base`
//! (the baseline loop) or `floor` (the hand-written contract floor, formula 4 only), over the first N points of the bench trace.

use std::process::ExitCode;

use hindsight_bench::{run_baseline, run_generated, Interpreted, Trace, FORMULAS, SEED};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: count K step|step0|atoms|gen|base|floor N";
    let (Some(k), Some(engine), Some(n)) = (
        args.first().and_then(|a| a.parse::<usize>().ok()),
        args.get(1),
        args.get(2).and_then(|a| a.parse::<usize>().ok()),
    ) else {
        eprintln!("{usage}");
        return ExitCode::FAILURE;
    };
    let Some(formula) = FORMULAS.get(k) else {
        eprintln!("no formula {k} (0..{})", FORMULAS.len());
        return ExitCode::FAILURE;
    };
    let trace = Trace::generate(n, SEED);
    let interp = match Interpreted::new(formula) {
        Ok(i) => i,
        Err(d) => {
            eprintln!("{formula}: {d}");
            return ExitCode::FAILURE;
        }
    };
    let mut trues = 0u64;
    let mut sink = |v: bool| trues += v as u64;
    let result = match engine.as_str() {
        "step" => interp.run(&trace, &mut sink),
        "step0" => interp.run_unplanned(&trace, &mut sink),
        "atoms" => interp.run_atoms(&trace, &mut sink),
        "gen" => run_generated(k, &trace, &mut sink),
        "floor" if *formula == hindsight_bench::floor::FORMULA => {
            hindsight_bench::floor::run(&trace, &mut sink)
        }
        "base" => {
            run_baseline(&trace, &mut sink);
            Ok(())
        }
        _ => {
            eprintln!("{usage}");
            return ExitCode::FAILURE;
        }
    };
    match result {
        Ok(()) => {
            println!("{formula} {engine} {n} points: {trues} true");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{formula} {engine}: {e}");
            ExitCode::FAILURE
        }
    }
}
