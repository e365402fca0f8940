//! The conformance corpus through every form of a monitor: the three forms and the oracle agree with `expect`.
//!
//! Each case of `tests/conformance/*.toml` becomes a spec (its declarations
//! plus `property p = <formula>;`), compiled with `codegen::compile_spec`, and
//! its trace is judged by:
//! - the interpreter: `monitor_core::Monitor` on `Compiled::program()`;
//! - the table: `Compiled::to_table_bytes()` loaded with `Table::from_bytes`;
//! - the generated code: `build.rs` emitted one module per case with
//!   `codegen::emit_rust` (`OUT_DIR/corpus_generated.rs`, included here);
//! - the oracle: codegen's checked AST converted to an oracle formula, atoms
//!   evaluated by the tests' own tree-walking evaluator.
//!
//! Every verdict at every point must equal the hand-computed `expect`; a
//! failure names the file, the case, the engine, the point and the rationale.

use hindsight_tests::checked;
use hindsight_tests::engines::{self, Verdicts};
use hindsight_tests::oracle;
use hindsight_tests::trace::{self, Case, Val};

#[allow(dead_code, missing_docs)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/corpus_generated.rs"));
}

/// Everything one case needs, parsed and compiled, or why it could not be.
struct Prepared {
    times: Vec<u64>,
    values: Vec<Vec<monitor_core::Value>>,
    compiled: codegen::Compiled,
    /// The valuations in codegen's variable order, for the oracle's atom evaluator.
    vals: Vec<Vec<Val>>,
}

fn prepare(case: &Case) -> Result<Prepared, String> {
    let decls = trace::parse_decls(&case.decls).map_err(|e| format!("decls {e}"))?;
    let points = trace::parse_trace(&case.trace, &decls).map_err(|e| format!("trace {e}"))?;
    let src = format!("{}\nproperty p = {};\n", case.decls, case.formula);
    let compiled = codegen::compile_spec(&src, &case.name)
        .map_err(|d| format!("codegen rejected the spec:\n{d}"))?;
    let by_decl = trace::valuations(&decls, &points);
    let values = engines::values(&compiled, &decls, &by_decl)?;
    let order = engines::var_order(&compiled, &decls)?;
    let vals = by_decl
        .iter()
        .map(|p| order.iter().map(|&k| p[k].clone()).collect())
        .collect();
    Ok(Prepared {
        times: points.iter().map(|p| p.time).collect(),
        values,
        compiled,
        vals,
    })
}

/// The oracle's verdicts on the checked AST of property 0.
fn oracle_verdicts(p: &Prepared) -> Result<Vec<bool>, String> {
    let spec = p.compiled.checked();
    let (f, atoms) = checked::to_oracle(&spec.properties[0].formula);
    let points = checked::oracle_points(spec, &atoms, &p.times, &p.vals)
        .map_err(|(i, e)| format!("point {i}: {e}"))?;
    Ok(oracle::eval(&f, &points))
}

/// Checks one case; `Err` lists every engine that disagrees with `expect`.
fn check(file: &str, case: &Case, runner: &Result<generated::Runner, &str>) -> Result<(), String> {
    let head = format!("{file} `{}` ({})", case.name, case.rationale);
    let want = case
        .expected()
        .ok_or_else(|| format!("{head}: expect `{}` is not T/F", case.expect))?;
    let p = prepare(case).map_err(|e| format!("{head}: {e}"))?;
    let mut problems = Vec::new();
    let mut judge = |engine: &str, got: Result<Vec<Verdicts>, String>| match got {
        Err(e) => problems.push(format!("  {engine}: {e}")),
        Ok(got) => {
            if let Some((i, said)) = engines::first_difference(&got, 0, &want) {
                problems.push(format!(
                    "  {engine}: point {i} (`{}`) is {said}, expected {}; all points {} vs expect {}",
                    case.trace.get(i).map_or("-", String::as_str),
                    want.get(i).map_or("-".into(), |&b| engines::tf(&[b])),
                    engines::tf_results(&got, 0),
                    case.expect
                ));
            }
        }
    };
    let table = p.compiled.to_table_bytes();
    judge(
        "interpreter",
        engines::run_interpreter(p.compiled.program(), &p.times, &p.values)
            .map_err(|e| format!("{e:?}")),
    );
    judge(
        "table",
        engines::run_table(&table, &p.times, &p.values).map_err(|e| format!("{e:?}")),
    );
    judge(
        "generated",
        runner
            .map(|run| run(&p.times, &p.values))
            .map_err(str::to_string),
    );
    judge(
        "oracle",
        oracle_verdicts(&p).map(|v| v.into_iter().map(|b| Ok(vec![b])).collect()),
    );
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{head}:\n  formula {}\n{}",
            case.formula,
            problems.join("\n")
        ))
    }
}

#[test]
fn every_form_agrees_with_the_corpus() {
    let corpus = trace::load_corpus(&trace::corpus_dir()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        corpus.len(),
        generated::CORPUS.len(),
        "build.rs generated code for another corpus"
    );
    let mut failures = Vec::new();
    let mut points = 0;
    for ((file, case), (gen_file, gen_name, runner)) in corpus.iter().zip(generated::CORPUS) {
        assert_eq!((file.as_str(), case.name.as_str()), (*gen_file, *gen_name));
        points += case.trace.len();
        if let Err(e) = check(file, case, runner) {
            failures.push(e);
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases disagree:\n{}",
        failures.len(),
        corpus.len(),
        failures.join("\n")
    );
    assert!(
        corpus.len() >= 200 && points >= 800,
        "{} cases, {points} points",
        corpus.len()
    );
}

/// The checked-AST route reaches the oracle: a case with every kind of atom judged by hand here.
#[test]
fn the_oracle_route_evaluates_typed_atoms() {
    use monitor_core::Value::Str;
    let case = Case {
        name: "typed".into(),
        rationale: "ints, floats, strings and an event in one atom each".into(),
        decls: "event go; state n: i8 = -2; state x: float = 0.5; state m: string = \"a\";".into(),
        formula: "{go} || ({n * 2 < x} && {m == \"b\"})".into(),
        trace: vec![
            "0:".into(),
            "1: m=\"b\"".into(),
            "1: n=1".into(),
            "2: go".into(),
        ],
        expect: "FTFT".into(),
    };
    let p = prepare(&case).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        oracle_verdicts(&p).map(|v| engines::tf(&v)),
        Ok(case.expect.clone())
    );
    // Texts that are no constant get ids past the constants, equal texts equal ids.
    let unknown = Case {
        decls: "state m: string = \"zz\"; state k: string = \"zz\";".into(),
        formula: "{m == k}".into(),
        trace: vec![
            "0:".into(),
            "1: m=\"y\"".into(),
            "2: k=\"y\"".into(),
            "3: k=\"w\"".into(),
        ],
        expect: "TFTF".into(),
        ..case
    };
    let p = prepare(&unknown).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p.compiled.strings(), ["zz"]);
    assert_eq!(p.values[2], [Str(1), Str(1)]);
    assert_eq!(p.values[3], [Str(1), Str(2)]);
    let interpreter = engines::run_interpreter(p.compiled.program(), &p.times, &p.values);
    let table = engines::run_table(&p.compiled.to_table_bytes(), &p.times, &p.values);
    assert_eq!(
        interpreter.map(|r| engines::tf_results(&r, 0)),
        Ok(unknown.expect.clone())
    );
    assert_eq!(
        table.map(|r| engines::tf_results(&r, 0)),
        Ok(unknown.expect.clone())
    );
    assert_eq!(
        oracle_verdicts(&p).map(|v| engines::tf(&v)),
        Ok(unknown.expect)
    );
}
