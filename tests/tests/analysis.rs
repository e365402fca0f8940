//! `monitor_core::analysis` against the oracle: a final verdict never changes, a skipped repeat changes nothing.
//!
//! - Finality ([`analysis::settle`]): on every corpus case and on random formulas,
//!   the interpreter is stepped point by point and settled after each point. Once
//!   a property is declared final `v`, the interpreter's verdict is `v` and the
//!   oracle's verdict is `v` at that point and at every later point, both on the
//!   trace itself and on several random continuations of its prefix.
//! - Repeats ([`analysis::repeat_is_noop`]): for a random formula without `Y` /
//!   `Z`, the oracle gives the same verdicts on a trace with some points
//!   duplicated (the duplicate gets its original's verdict).

use hindsight_tests::gen::{self, FormulaConfig, Gen, TraceConfig};
use hindsight_tests::oracle::{self, Point, F};
use hindsight_tests::trace::{self, Case};
use hindsight_tests::{checked, engines};
use monitor_core::{analysis, Monitor, Value};

/// Steps `monitor` through `(times, vals)` and returns, per point, the verdict of
/// property 0 and its finality.
fn settled_run(
    monitor: &Monitor<'_>,
    times: &[u64],
    vals: &[Vec<Value>],
) -> Vec<(bool, Option<bool>)> {
    let program = monitor.program();
    let mut state = vec![0; monitor.state_words()];
    let mut out = vec![false; monitor.properties()];
    let mut finals = vec![None; program.nodes.len()];
    times
        .iter()
        .zip(vals)
        .map(|(&t, v)| {
            monitor.try_step(&mut state, t, v, &mut out).unwrap();
            let st = &state;
            analysis::settle(
                program,
                |n| monitor.node_value(st, n).unwrap_or(false),
                &mut finals,
            );
            (out[0], analysis::settled(program, &finals, 0))
        })
        .collect()
}

/// The first point declared final, if any, checked against `want` (the oracle):
/// from there on both the monitor and the oracle say the final value.
fn check_final(run: &[(bool, Option<bool>)], want: &[bool]) -> Result<Option<usize>, String> {
    let Some(k) = run.iter().position(|(_, f)| f.is_some()) else {
        return Ok(None);
    };
    let v = run[k].1.unwrap();
    for (j, ((got, fin), &w)) in run.iter().zip(want).enumerate().skip(k) {
        if *fin != Some(v) || *got != v || w != v {
            return Err(format!(
                "final {v} at point {k}, but at point {j}: monitor {got}, final {fin:?}, oracle {w}"
            ));
        }
    }
    Ok(Some(k))
}

#[test]
fn corpus_verdicts_declared_final_never_change() {
    let corpus = trace::load_corpus(&trace::corpus_dir()).unwrap_or_else(|e| panic!("{e}"));
    let (mut settled, mut failures) = (0, Vec::new());
    for (file, case) in &corpus {
        match corpus_case(case) {
            Ok(Some(_)) => settled += 1,
            Ok(None) => {}
            Err(e) => failures.push(format!("{file} `{}` {}: {e}", case.name, case.formula)),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The check was exercised: many cases settle before their last point.
    assert!(settled >= 20, "only {settled} cases settled");
}

fn corpus_case(case: &Case) -> Result<Option<usize>, String> {
    let decls = trace::parse_decls(&case.decls).map_err(|e| format!("decls {e}"))?;
    let points = trace::parse_trace(&case.trace, &decls).map_err(|e| format!("trace {e}"))?;
    let src = format!("{}\nproperty p = {};\n", case.decls, case.formula);
    let compiled = codegen::compile_spec(&src, &case.name).map_err(|d| d.to_string())?;
    let by_decl = trace::valuations(&decls, &points);
    let values = engines::values(&compiled, &decls, &by_decl)?;
    let order = engines::var_order(&compiled, &decls)?;
    let vals: Vec<Vec<_>> = by_decl
        .iter()
        .map(|p| order.iter().map(|&k| p[k].clone()).collect())
        .collect();
    let times: Vec<u64> = points.iter().map(|p| p.time).collect();
    let spec = compiled.checked();
    let (f, atoms) = checked::to_oracle(&spec.properties[0].formula);
    let opoints = checked::oracle_points(spec, &atoms, &times, &vals)
        .map_err(|(i, e)| format!("point {i}: {e}"))?;
    let want = oracle::eval(&f, &opoints);
    let monitor = Monitor::try_new(compiled.program()).map_err(|e| format!("{e:?}"))?;
    check_final(&settled_run(&monitor, &times, &values), &want)
}

fn inputs(trace: &[Point]) -> (Vec<u64>, Vec<Vec<Value>>) {
    let times = trace.iter().map(|p| p.time).collect();
    let vals = trace
        .iter()
        .map(|p| p.atoms.iter().map(|&b| Value::Bool(b)).collect())
        .collect();
    (times, vals)
}

fn random_trace(rng: &mut Gen, start: u64) -> Vec<Point> {
    let cfg = TraceConfig {
        len: gen::range(rng, 1, 40) as usize,
        atoms: gen::DIFF_ATOMS,
        p_true: [0.1, 0.5, 0.9][gen::range(rng, 0, 2) as usize],
        p_repeat: 0.3,
        max_gap: gen::range(rng, 1, 4),
        p_jump: 0.05,
        big_gap: 50,
        start,
    };
    gen::trace(rng, &cfg)
}

/// Formulas small enough to settle often: depth up to 4, small bounds mostly.
fn random_formula(rng: &mut Gen) -> F {
    let cfg = FormulaConfig {
        max_depth: 4,
        atoms: gen::DIFF_ATOMS,
        small: 4,
        large: 40,
        p_large: 0.1,
    };
    gen::formula(rng, &cfg)
}

fn compile(f: &F) -> codegen::Compiled {
    codegen::compile_spec(&gen::spec(f, gen::DIFF_ATOMS), "random.hspec")
        .unwrap_or_else(|d| panic!("{}: {d}", oracle::print(f)))
}

#[test]
fn random_verdicts_declared_final_never_change() {
    let mut rng = gen::rng(0x5e77_1e00);
    let (mut settled, mut continuations) = (0, 0);
    for _ in 0..1500 {
        let f = random_formula(&mut rng);
        let compiled = compile(&f);
        let monitor = Monitor::try_new(compiled.program()).unwrap();
        for _ in 0..8 {
            let start = gen::range(&mut rng, 0, 3);
            let trace = random_trace(&mut rng, start);
            let (times, vals) = inputs(&trace);
            let run = settled_run(&monitor, &times, &vals);
            let k = check_final(&run, &oracle::eval(&f, &trace))
                .unwrap_or_else(|e| panic!("{}: {e}\n{trace:?}", oracle::print(&f)));
            let Some(k) = k else { continue };
            settled += 1;
            // Other futures of the same prefix: the verdict stays final and the same.
            for _ in 0..4 {
                let mut other = trace[..=k].to_vec();
                let start = trace[k].time + gen::range(&mut rng, 0, 2);
                other.extend(random_trace(&mut rng, start));
                let (times, vals) = inputs(&other);
                let run = settled_run(&monitor, &times, &vals);
                let want = oracle::eval(&f, &other);
                match check_final(&run, &want) {
                    Ok(Some(j)) if j == k => continuations += 1,
                    r => panic!("{}: {r:?} on {other:?}", oracle::print(&f)),
                }
            }
        }
    }
    assert!(
        settled > 500 && continuations > 2000,
        "{settled} settled, {continuations} continuations"
    );
}

/// A few formulas whose finality is known by hand: unbounded once/historically
/// settle, bounded windows never do.
#[test]
fn settling_follows_the_rules() {
    let run = |formula: &str, points: &[(u64, bool)]| {
        let src = format!("state p: bool = false;\nproperty f = {formula};\n");
        let c = codegen::compile_spec(&src, "t.hspec").unwrap();
        let m = Monitor::try_new(c.program()).unwrap();
        let times: Vec<u64> = points.iter().map(|p| p.0).collect();
        let vals: Vec<_> = points.iter().map(|p| vec![Value::Bool(p.1)]).collect();
        settled_run(&m, &times, &vals)
    };
    let r = run("H(!{p})", &[(0, false), (1, true), (2, false)]);
    assert_eq!(
        r,
        vec![(true, None), (false, Some(false)), (false, Some(false))]
    );
    let r = run(
        "P[3:] {p}",
        &[(0, true), (1, false), (3, false), (9, false)],
    );
    assert_eq!(r[..2], [(false, None), (false, None)]);
    assert_eq!(r[2..], [(true, Some(true)), (true, Some(true))]);
    // H[0:5] P {p}: false at first, true later; never declared final.
    let pts: Vec<_> = (0..12).map(|t| (t, t >= 1)).collect();
    let r = run("H[0:5] P {p}", &pts);
    assert!(r.iter().all(|(_, f)| f.is_none()), "{r:?}");
    assert!(!r[0].0 && r[11].0);
    let r = run("P[0:2] {p}", &[(0, true), (1, false), (5, false)]);
    assert!(r.iter().all(|(_, f)| f.is_none()), "{r:?}");
    // `Y` of a final operand settles once the shifted value agrees.
    let r = run("Y false", &[(0, true), (1, true)]);
    assert_eq!(r, vec![(false, Some(false)), (false, Some(false))]);
}

fn has_yesterday(f: &F) -> bool {
    match f {
        F::Y(_) | F::Z(_) => true,
        F::True | F::False | F::Atom(_) => false,
        F::Not(a) | F::Once { f: a, .. } | F::Hist { f: a, .. } => has_yesterday(a),
        F::And(a, b) | F::Or(a, b) | F::Implies(a, b) | F::Iff(a, b) => {
            has_yesterday(a) || has_yesterday(b)
        }
        F::Since { l, r, .. } => has_yesterday(l) || has_yesterday(r),
    }
}

#[test]
fn a_repeated_point_changes_no_verdict_without_yesterday() {
    let mut rng = gen::rng(0x0e9e_a7ed);
    let (mut noop, mut checked_pairs) = (0, 0);
    for _ in 0..1500 {
        let f = random_formula(&mut rng);
        let compiled = compile(&f);
        let is_noop = analysis::repeat_is_noop(&compiled.program());
        // The analysis says exactly "no Y / Z in the formula".
        assert_eq!(is_noop, !has_yesterday(&f), "{}", oracle::print(&f));
        if !is_noop {
            continue;
        }
        noop += 1;
        for _ in 0..4 {
            let trace = random_trace(&mut rng, 0);
            let want = oracle::eval(&f, &trace);
            // Duplicate some points; every point keeps its verdict and the copy shares it.
            let mut doubled = Vec::new();
            let mut origin = Vec::new();
            for (i, p) in trace.iter().enumerate() {
                doubled.push(p.clone());
                origin.push(i);
                if gen::chance(&mut rng, 0.4) {
                    doubled.push(p.clone());
                    origin.push(i);
                }
            }
            let got = oracle::eval(&f, &doubled);
            for (j, &i) in origin.iter().enumerate() {
                assert_eq!(got[j], want[i], "{} at {j}", oracle::print(&f));
            }
            checked_pairs += 1;
        }
    }
    assert!(noop > 300 && checked_pairs > 1200, "{noop} {checked_pairs}");
}

/// Reads and horizon of a property, by hand.
#[test]
fn reads_and_horizon() {
    let src = "state a: bool = false;\nstate n: i64 = 0;\nstate b: bool = false;\n\
               property p = H[0:7] ({a} -> P[2:] {n > 3});\nproperty q = Y {b};\n";
    let c = codegen::compile_spec(src, "t.hspec").unwrap();
    let program = c.program();
    let reads = |p: usize| {
        let mut v = Vec::new();
        analysis::for_each_read(&program, &program.props[p], |x| v.push(x));
        v.sort_unstable();
        v.dedup();
        v
    };
    let index = |name: &str| program.vars.iter().position(|v| v.name == name).unwrap() as u16;
    let mut want_p = vec![index("a"), index("n")];
    want_p.sort_unstable();
    assert_eq!(reads(0), want_p);
    assert_eq!(reads(1), vec![index("b")]);
    assert_eq!(analysis::horizon(&program, &program.props[0]), 7);
    assert_eq!(analysis::horizon(&program, &program.props[1]), 0);
}
