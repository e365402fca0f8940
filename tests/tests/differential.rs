//! Randomised differential test: interpreter, postcard table and generated code agree with the oracle.
//!
//! Formulas are random Past-MTL trees (depth up to 6, every operator, every
//! interval shape with small and large bounds) over boolean states `a0 a1 a2`,
//! printed with `oracle::print` and compiled by `codegen` from that text. Traces
//! are random and super-dense (repeated timestamps, long jumps, some starting
//! near the top of the `u64` range).
//!
//! - `fixed_formulas_agree_in_all_three_forms`: `build.rs` emitted Rust code for
//!   `gen::diff_formula(k)`, `k < HINDSIGHT_DIFF_FORMULAS` (default 400, read at
//!   build time); each runs on `HINDSIGHT_DIFF_TRACES` traces (default 100), so
//!   40,000 formula/trace pairs by default.
//! - `fresh_formulas_agree_at_run_time`: `HINDSIGHT_DIFF_FRESH` (default 4000)
//!   further formulas, drawn at run time from a seed (`HINDSIGHT_DIFF_SEED`,
//!   default fixed) and judged by the interpreter and the table only.
//!
//! A longer run is one command away:
//!
//! ```text
//! HINDSIGHT_DIFF_FORMULAS=5000 HINDSIGHT_DIFF_TRACES=200 cargo test -p hindsight-tests --release --test differential
//! ```
//!
//! On a disagreement the test prints the formula, the trace in the corpus
//! point syntax and the first differing point, as a `[[case]]` ready to paste
//! into `tests/conformance/` (fill in the rationale, check the verdicts by hand).

use codegen::ast::ExprKind;
use hindsight_tests::checked;
use hindsight_tests::engines::{self, Verdicts};
use hindsight_tests::gen::{self, FormulaConfig, Gen, TraceConfig};
use hindsight_tests::oracle::{self, Point, F};
use monitor_core::{Monitor, Value};

#[allow(dead_code, missing_docs)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/diff_generated.rs"));
}

/// Traces per fixed formula unless `HINDSIGHT_DIFF_TRACES` says otherwise.
const DEFAULT_TRACES: usize = 100;
/// Fresh formulas of the run-time loop unless `HINDSIGHT_DIFF_FRESH` says otherwise.
const DEFAULT_FRESH: usize = 4000;
/// Traces per fresh formula.
const FRESH_TRACES: usize = 10;
/// Disagreements printed in full before the test gives up listing them.
const MAX_REPORTS: usize = 5;

fn env_count(name: &str, default: usize) -> usize {
    match std::env::var(name) {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={v:?} is not a number")),
        Err(_) => default,
    }
}

/// A random trace shape, then a trace: mostly 1..=60 points, sometimes up to
/// 300 with unit gaps (which fill windows to their capacity), sparse to dense
/// atoms, few to many repeated timestamps, gaps past the largest bound, and
/// now and then a start near the top of the timestamp range.
fn random_trace(rng: &mut Gen) -> Vec<Point> {
    let long = gen::range(rng, 0, 9) == 0;
    let start = match gen::range(rng, 0, 9) {
        // Far enough below u64::MAX (reserved) for 300 points of the largest gap.
        0 => u64::MAX - 1_000_000 + gen::range(rng, 0, 1000),
        1 => gen::range(rng, 1, 1 << 40),
        _ => gen::range(rng, 0, 3),
    };
    let cfg = TraceConfig {
        len: if long {
            gen::range(rng, 100, 300)
        } else {
            gen::range(rng, 1, 60)
        } as usize,
        atoms: gen::DIFF_ATOMS,
        p_true: [0.15, 0.5, 0.85][gen::range(rng, 0, 2) as usize],
        p_repeat: [0.1, 0.35, 0.7][gen::range(rng, 0, 2) as usize],
        max_gap: if long { 1 } else { gen::range(rng, 1, 4) },
        p_jump: 0.05,
        big_gap: 1500,
        start,
    };
    gen::trace(rng, &cfg)
}

/// The engines' inputs for a trace over `a0 .. a(n-1)`: timestamps and values.
fn inputs(trace: &[Point]) -> (Vec<u64>, Vec<Vec<Value>>) {
    let times = trace.iter().map(|p| p.time).collect();
    let vals = trace
        .iter()
        .map(|p| p.atoms.iter().map(|&b| Value::Bool(b)).collect())
        .collect();
    (times, vals)
}

/// `f` with atom `k` renamed to `rename(k)`.
fn map_atoms(f: &F, rename: &dyn Fn(usize) -> Option<usize>) -> Option<F> {
    let m = |g: &F| map_atoms(g, rename).map(Box::new);
    Some(match f {
        F::True => F::True,
        F::False => F::False,
        F::Atom(k) => F::Atom(rename(*k)?),
        F::Not(a) => F::Not(m(a)?),
        F::And(a, b) => F::And(m(a)?, m(b)?),
        F::Or(a, b) => F::Or(m(a)?, m(b)?),
        F::Implies(a, b) => F::Implies(m(a)?, m(b)?),
        F::Iff(a, b) => F::Iff(m(a)?, m(b)?),
        F::Y(a) => F::Y(m(a)?),
        F::Z(a) => F::Z(m(a)?),
        F::Once { lo, hi, f } => F::Once {
            lo: *lo,
            hi: *hi,
            f: m(f)?,
        },
        F::Hist { lo, hi, f } => F::Hist {
            lo: *lo,
            hi: *hi,
            f: m(f)?,
        },
        F::Since { lo, hi, l, r } => F::Since {
            lo: *lo,
            hi: *hi,
            l: m(l)?,
            r: m(r)?,
        },
    })
}

/// One formula compiled, with its monitors built once for all its traces.
struct Subject {
    text: String,
    compiled: codegen::Compiled,
    table: Vec<u8>,
}

impl Subject {
    /// Compiles `f` from its printed text and checks that codegen read back the same tree.
    fn new(f: &F) -> Result<Subject, String> {
        let text = oracle::print(f);
        let compiled = codegen::compile_spec(&gen::spec(f, gen::DIFF_ATOMS), "random.hspec")
            .map_err(|d| format!("codegen rejected `{text}`:\n{d}"))?;
        let (tree, atoms) = checked::to_oracle(&compiled.checked().properties[0].formula);
        let var = |k: usize| match atoms.get(k).map(|e| &e.kind) {
            Some(ExprKind::Var(i)) => Some(*i as usize),
            _ => None,
        };
        let read = map_atoms(&tree, &var);
        if read.as_ref() != Some(f) {
            return Err(format!(
                "codegen read `{text}` as `{}`",
                oracle::print(&tree)
            ));
        }
        let table = compiled.to_table_bytes();
        Ok(Subject {
            text,
            compiled,
            table,
        })
    }
}

/// Every engine's results on one trace, compared with the oracle: the number
/// of true verdicts, or a printable report.
fn judge(
    subject: &Subject,
    f: &F,
    interpreter: &Monitor<'_>,
    table: &Monitor<'_>,
    generated: Option<generated::Runner>,
    trace: &[Point],
) -> Result<usize, String> {
    let want = oracle::eval(f, trace);
    let (times, vals) = inputs(trace);
    let mut runs: Vec<(&str, Vec<Verdicts>)> = vec![
        (
            "interpreter",
            engines::run_monitor(interpreter, &times, &vals),
        ),
        ("table", engines::run_monitor(table, &times, &vals)),
    ];
    if let Some(run) = generated {
        runs.push(("generated", run(&times, &vals)));
    }
    let mut diffs = Vec::new();
    for (engine, got) in &runs {
        if let Some((i, said)) = engines::first_difference(got, 0, &want) {
            diffs.push(format!(
                "  {engine}: point {i} is {said}, the oracle says {}; all points {} vs oracle {}",
                engines::tf(&want[i..=i]),
                engines::tf_results(got, 0),
                engines::tf(&want)
            ));
        }
    }
    if diffs.is_empty() {
        return Ok(want.iter().filter(|&&b| b).count());
    }
    let lines = gen::trace_lines(trace);
    let decls = gen::decls(gen::DIFF_ATOMS).replace('\n', " ");
    Err(format!(
        "formula {}\n{}\n[[case]]\nname = \"differential-...\"\nrationale = \"...\"\n\
         decls = {:?}\nformula = {:?}\ntrace = {:?}\nexpect = {:?}  # the oracle's verdicts\n",
        subject.text,
        diffs.join("\n"),
        decls.trim(),
        subject.text,
        lines,
        engines::tf(&want)
    ))
}

/// Collects reports and counts; panics at the end if anything disagreed.
#[derive(Default)]
struct Tally {
    pairs: usize,
    points: usize,
    true_verdicts: usize,
    failures: usize,
    reports: Vec<String>,
}

impl Tally {
    fn fail(&mut self, report: String) {
        self.failures += 1;
        if self.reports.len() < MAX_REPORTS {
            self.reports.push(report);
        }
    }

    fn finish(&self, what: &str) {
        assert!(
            self.failures == 0,
            "{what}: {} disagreements (first {} shown):\n\n{}",
            self.failures,
            self.reports.len(),
            self.reports.join("\n\n")
        );
    }
}

/// Runs `f` on `traces` random traces drawn from `rng` in every engine given.
fn run_formula(
    f: &F,
    generated: Option<(&str, Result<generated::Runner, &str>)>,
    traces: usize,
    rng: &mut Gen,
    tally: &mut Tally,
) {
    let subject = match Subject::new(f) {
        Ok(s) => s,
        Err(e) => return tally.fail(e),
    };
    let runner = match generated {
        None => None,
        Some((text, _)) if text != subject.text => {
            return tally.fail(format!(
                "build.rs generated `{text}` where the test draws `{}`",
                subject.text
            ))
        }
        Some((_, Err(e))) => return tally.fail(format!("formula {}: {e}", subject.text)),
        Some((_, Ok(run))) => Some(run),
    };
    let interpreter = match Monitor::try_new(subject.compiled.program()) {
        Ok(m) => m,
        Err(e) => return tally.fail(format!("formula {}: {e:?}", subject.text)),
    };
    let loaded = match engines::load_table(&subject.table) {
        Ok(t) => t,
        Err(e) => return tally.fail(format!("formula {}: table {e:?}", subject.text)),
    };
    let table = match loaded.monitor() {
        Ok(m) => m,
        Err(e) => return tally.fail(format!("formula {}: table {e:?}", subject.text)),
    };
    for _ in 0..traces {
        let trace = random_trace(rng);
        tally.pairs += 1;
        tally.points += trace.len();
        match judge(&subject, f, &interpreter, &table, runner, &trace) {
            Ok(trues) => tally.true_verdicts += trues,
            Err(report) => return tally.fail(report),
        }
    }
}

#[test]
fn fixed_formulas_agree_in_all_three_forms() {
    let traces = env_count("HINDSIGHT_DIFF_TRACES", DEFAULT_TRACES);
    let mut tally = Tally::default();
    for (k, &(text, runner)) in generated::DIFF.iter().enumerate() {
        let f = gen::diff_formula(k);
        let mut rng = gen::rng(0x7472_6163_6573 ^ (k as u64) << 20);
        run_formula(&f, Some((text, runner)), traces, &mut rng, &mut tally);
    }
    tally.finish("generated formulas");
    eprintln!(
        "differential: {} formulas x {traces} traces = {} pairs, {} points, {} true verdicts",
        generated::DIFF.len(),
        tally.pairs,
        tally.points,
        tally.true_verdicts
    );
    assert_eq!(tally.pairs, generated::DIFF.len() * traces);
    // Both verdicts occur often: the comparison is not between constant answers.
    assert!(tally.true_verdicts * 10 > tally.points && tally.true_verdicts * 10 < tally.points * 9);
}

#[test]
fn fresh_formulas_agree_at_run_time() {
    let count = env_count("HINDSIGHT_DIFF_FRESH", DEFAULT_FRESH);
    let seed = env_count("HINDSIGHT_DIFF_SEED", 2024) as u64;
    let mut tally = Tally::default();
    let mut rng = gen::rng(seed);
    for _ in 0..count {
        // Vary the bounds too: sometimes only small ones, sometimes mostly large ones.
        let cfg = FormulaConfig {
            atoms: gen::DIFF_ATOMS,
            small: gen::range(&mut rng, 2, 8),
            p_large: [0.0, 0.2, 0.6][gen::range(&mut rng, 0, 2) as usize],
            ..FormulaConfig::default()
        };
        let f = gen::formula(&mut rng, &cfg);
        run_formula(&f, None, FRESH_TRACES, &mut rng, &mut tally);
    }
    tally.finish(&format!("fresh formulas (HINDSIGHT_DIFF_SEED={seed})"));
    assert_eq!(tally.pairs, count * FRESH_TRACES);
}

/// The shapes the fixed set covers: every operator and interval shape occurs.
#[test]
fn the_fixed_set_covers_every_operator_and_shape() {
    fn walk(f: &F, seen: &mut std::collections::BTreeSet<String>) {
        let shape = |lo: u64, hi: Option<u64>| match (lo, hi) {
            (0, None) => "",
            (0, Some(_)) => "[0:b]",
            (_, None) => "[a:]",
            (a, Some(b)) if a == b => "[a:a]",
            _ => "[a:b]",
        };
        let name = match f {
            F::True | F::False | F::Atom(_) => return,
            F::Not(_) => "!".to_string(),
            F::And(..) => "&&".into(),
            F::Or(..) => "||".into(),
            F::Implies(..) => "->".into(),
            F::Iff(..) => "<->".into(),
            F::Y(_) => "Y".into(),
            F::Z(_) => "Z".into(),
            F::Once { lo, hi, .. } => format!("P{}", shape(*lo, *hi)),
            F::Hist { lo, hi, .. } => format!("H{}", shape(*lo, *hi)),
            F::Since { lo, hi, .. } => format!("S{}", shape(*lo, *hi)),
        };
        seen.insert(name);
        match f {
            F::Not(a) | F::Y(a) | F::Z(a) | F::Once { f: a, .. } | F::Hist { f: a, .. } => {
                walk(a, seen)
            }
            F::And(a, b) | F::Or(a, b) | F::Implies(a, b) | F::Iff(a, b) => {
                walk(a, seen);
                walk(b, seen);
            }
            F::Since { l, r, .. } => {
                walk(l, seen);
                walk(r, seen);
            }
            _ => {}
        }
    }
    let mut seen = std::collections::BTreeSet::new();
    let mut deepest = 0;
    for k in 0..generated::DIFF.len() {
        let f = gen::diff_formula(k);
        deepest = deepest.max(f.depth());
        walk(&f, &mut seen);
    }
    if generated::DIFF.len() >= 100 {
        let mut missing = Vec::new();
        for op in ["!", "&&", "||", "->", "<->", "Y", "Z"] {
            if !seen.contains(op) {
                missing.push(op.to_string());
            }
        }
        for op in ["P", "H", "S"] {
            for sh in ["", "[0:b]", "[a:]", "[a:a]", "[a:b]"] {
                if !seen.contains(&format!("{op}{sh}")) {
                    missing.push(format!("{op}{sh}"));
                }
            }
        }
        assert!(missing.is_empty(), "not covered: {missing:?}");
        assert_eq!(deepest, 6);
    }
}
