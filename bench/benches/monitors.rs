//! `cargo bench -p hindsight-bench`: nanoseconds per point and state bytes of every
//! benchmarked formula, for the table interpreter and the generated code, as ratios
//! against a baseline loop measured in the same run.
//!
//! Options (after `--`): `--points N` (default 1000000), `--reps R` (default 7:
//! the median of R timed passes is reported; passes interleave the engines so that
//! machine noise spreads over all of them), `--csv PATH` (also write the trace as
//! CSV for `hindsight replay`).

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use hindsight_bench::{
    floor, generated_state_bytes, run_baseline, run_generated, Interpreted, Trace, FORMULAS, SEED,
};

struct Options {
    points: usize,
    reps: usize,
    csv: Option<String>,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        points: 1_000_000,
        reps: 7,
        csv: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--points" => {
                o.points = value("--points")?
                    .parse()
                    .map_err(|e| format!("--points: {e}"))?
            }
            "--reps" => {
                o.reps = value("--reps")?
                    .parse()
                    .map_err(|e| format!("--reps: {e}"))?
            }
            "--csv" => o.csv = Some(value("--csv")?),
            // `cargo bench` passes `--bench` to every harness-less bench.
            "--bench" => {}
            other => {
                return Err(format!(
                    "unknown argument `{other}` (expected --points N, --reps R, --csv PATH)"
                ))
            }
        }
    }
    if o.points == 0 || o.reps == 0 {
        return Err("--points and --reps must be positive".into());
    }
    Ok(o)
}

/// Times one pass of `$body` over `$n` points, with `$s` bound to a sink that
/// counts true verdicts: `Ok((ns per point, trues))`. A macro rather than a function
/// so that every engine's loop is instantiated with this concrete closure (a
/// `dyn FnMut` sink would add an indirect call per point to every figure).
macro_rules! timed {
    ($n:expr, |$s:ident| $body:expr) => {{
        let mut trues = 0u64;
        let mut $s = |v: bool| trues += v as u64;
        let start = Instant::now();
        let result: Result<(), String> = $body;
        let ns = start.elapsed().as_nanos() as f64 / $n as f64;
        result.map(|()| (ns, black_box(trues)))
    }};
}

fn median(xs: &mut [f64]) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

fn main() -> ExitCode {
    match bench() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hindsight-bench: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bench() -> Result<(), String> {
    let opts = options()?;
    let trace = Trace::generate(opts.points, SEED);
    let [np, nq, nr] = trace.counts();
    println!(
        "trace: {} points, seed {SEED:#x}, timestamps = index; p {np}, q {nq}, r {nr} true",
        trace.len()
    );
    if let Some(path) = &opts.csv {
        std::fs::write(path, trace.to_csv()).map_err(|e| format!("{path}: {e}"))?;
        println!("trace written to {path}");
    }

    let interp: Vec<Interpreted> = FORMULAS
        .iter()
        .map(|f| Interpreted::new(f).map_err(|d| format!("{f}: {d}")))
        .collect::<Result<_, _>>()?;

    // Untimed check first: all three runs give the same verdict at every point.
    let mut trues = Vec::with_capacity(FORMULAS.len());
    for (k, f) in FORMULAS.iter().enumerate() {
        let mut a = Vec::with_capacity(trace.len());
        let mut b = Vec::with_capacity(trace.len());
        let mut c = Vec::with_capacity(trace.len());
        interp[k]
            .run(&trace, &mut |v| a.push(v))
            .map_err(|e| format!("{f}: try_step: {e}"))?;
        interp[k]
            .run_atoms(&trace, &mut |v| b.push(v))
            .map_err(|e| format!("{f}: try_step_atoms: {e}"))?;
        run_generated(k, &trace, &mut |v| c.push(v)).map_err(|e| format!("{f}: generated: {e}"))?;
        if a.len() != trace.len() || b != a || c != a {
            let i = (0..trace.len()).find(|&i| b.get(i) != a.get(i) || c.get(i) != a.get(i));
            return Err(format!("{f}: the engines disagree at point {i:?}"));
        }
        if *f == floor::FORMULA {
            let mut d = Vec::with_capacity(trace.len());
            floor::run(&trace, &mut |v| d.push(v)).map_err(|e| format!("{f}: floor: {e}"))?;
            if d != a {
                return Err(format!("{f}: the contract floor disagrees with try_step"));
            }
        }
        trues.push(a.iter().filter(|v| **v).count() as u64);
    }
    println!(
        "check: try_step, try_step_atoms and generated code agree on every point of every formula"
    );

    // Timed passes, interleaved: the baseline, then each formula's three runs.
    let n = trace.len();
    let mut base = Vec::new();
    let mut floor_ns = Vec::new();
    let fk = FORMULAS.iter().position(|f| *f == floor::FORMULA);
    let mut times = vec![[Vec::new(), Vec::new(), Vec::new()]; FORMULAS.len()];
    for _ in 0..opts.reps {
        let (ns, _) = timed!(n, |s| {
            run_baseline(black_box(&trace), &mut s);
            Ok(())
        })?;
        base.push(ns);
        if let Some(fk) = fk {
            let (ns, c) = timed!(n, |s| floor::run(black_box(&trace), &mut s)
                .map_err(|e| e.to_string()))?;
            if c != trues[fk] {
                return Err(format!("{}: floor verdict count changed", floor::FORMULA));
            }
            floor_ns.push(ns);
        }
        for (k, t) in times.iter_mut().enumerate() {
            let tr = black_box(&trace);
            let e = |e: hindsight_bench::RunError| e.to_string();
            let runs = [
                timed!(n, |s| interp[k].run(tr, &mut s).map_err(e))?,
                timed!(n, |s| interp[k].run_atoms(tr, &mut s).map_err(e))?,
                timed!(n, |s| run_generated(k, tr, &mut s).map_err(e))?,
            ];
            for ((ns, c), t) in runs.into_iter().zip(t.iter_mut()) {
                if c != trues[k] {
                    return Err(format!(
                        "{}: verdict count changed between passes",
                        FORMULAS[k]
                    ));
                }
                t.push(ns);
            }
        }
    }
    let base = median(&mut base);
    let med: Vec<[f64; 3]> = times
        .iter_mut()
        .map(|[a, b, c]| [median(a), median(b), median(c)])
        .collect();

    println!(
        "\nns per point, median of {} passes; (x) = ratio to the baseline loop that only reads \
         the trace and computes the atoms: {base:.2} ns/point; step/gen = try_step / generated\n",
        opts.reps
    );
    println!(
        "| {:<41} | {:>15} | {:>15} | {:>15} | {:>8} | {:>8} | {:>8} | {:>6} |",
        "formula",
        "try_step",
        "try_step_atoms",
        "generated",
        "step/gen",
        "table B",
        "gen B",
        "true"
    );
    println!(
        "|{:-<43}|{:->17}|{:->17}|{:->17}|{:->10}|{:->10}|{:->10}|{:->8}|",
        "", "", "", "", "", "", "", ""
    );
    let cell = |ns: f64| format!("{ns:.2} ({:.1}x)", ns / base);
    for (k, f) in FORMULAS.iter().enumerate() {
        println!(
            "| {:<41} | {:>15} | {:>15} | {:>15} | {:>7.1}x | {:>8} | {:>8} | {:>5.1}% |",
            format!("`{f}`"),
            cell(med[k][0]),
            cell(med[k][1]),
            cell(med[k][2]),
            med[k][0] / med[k][2],
            interp[k].state_bytes(),
            generated_state_bytes(k),
            100.0 * trues[k] as f64 / n as f64
        );
    }
    // The runtime's goal (issue 15): try_step within 4x the generated code
    // and within 10x the baseline loop, on every formula.
    let within = |k: usize| (med[k][0] <= 4.0 * med[k][2], med[k][0] <= 10.0 * base);
    let count = |f: &dyn Fn(usize) -> bool| (0..FORMULAS.len()).filter(|&k| f(k)).count();
    println!(
        "\ngoal, try_step within 4x generated and within 10x baseline: {} of {} formulas \
         ({} within 4x generated, {} within 10x baseline)",
        count(&|k| within(k) == (true, true)),
        FORMULAS.len(),
        count(&|k| within(k).0),
        count(&|k| within(k).1),
    );
    for (k, f) in FORMULAS.iter().enumerate() {
        let (gen, baseline) = within(k);
        if !(gen && baseline) {
            let miss = match (gen, baseline) {
                (false, false) => "4x generated, 10x baseline",
                (false, true) => "4x generated",
                _ => "10x baseline",
            };
            println!("  misses {miss}: `{f}`");
        }
    }
    // What the goal leaves an interpreter: the contract floor (`floor.rs`).
    if let Some(fk) = fk {
        let fl = median(&mut floor_ns);
        println!(
            "\ncontract floor, `{}` by hand (try_step's arguments, checks and state, the \
             formula in the code, nothing interpreted): {fl:.2} ns = {:.1}x generated, \
             {:.1}x baseline; try_step = {:.1}x the floor",
            floor::FORMULA,
            fl / med[fk][2],
            fl / base,
            med[fk][0] / fl,
        );
    }
    // The point intervals: the spread of the cost over bounds 10 .. 100000.
    let sweep: Vec<usize> = (0..FORMULAS.len())
        .filter(|&k| FORMULAS[k].starts_with("P[") && point_interval(FORMULAS[k]))
        .collect();
    if let (Some(&lo), Some(&hi)) = (sweep.first(), sweep.last()) {
        println!(
            "\nbound independence, {} / {}: try_step {:.2}x, try_step_atoms {:.2}x, generated {:.2}x",
            FORMULAS[hi], FORMULAS[lo],
            med[hi][0] / med[lo][0],
            med[hi][1] / med[lo][1],
            med[hi][2] / med[lo][2],
        );
        for (e, name) in ["try_step", "try_step_atoms", "generated"]
            .iter()
            .enumerate()
        {
            let xs: Vec<f64> = sweep.iter().map(|&k| med[k][e]).collect();
            let min = xs.iter().copied().fold(f64::INFINITY, f64::min);
            let max = xs.iter().copied().fold(0.0, f64::max);
            println!(
                "  {name}: {min:.2} .. {max:.2} ns/point over the {} bounds",
                xs.len()
            );
        }
    }
    Ok(())
}

/// Whether `f` is `P[b:b] ...` (a point interval).
fn point_interval(f: &str) -> bool {
    f.strip_prefix("P[")
        .and_then(|r| r.split_once(']'))
        .and_then(|(i, _)| i.split_once(':'))
        .is_some_and(|(a, b)| a == b)
}
