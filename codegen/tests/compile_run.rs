//! Compiling and running: layout validity, table round trips, sharing, state sizes, limits, and verdicts against a naive evaluator.

use codegen::ast::{BinaryOp, CheckedSpec, Expr, ExprKind, Formula, FormulaKind, UnaryOp};
use codegen::{compile_spec, Compiled, Limits, Spec};
use monitor_core::table::Table;
use monitor_core::{CmpOp, Monitor, Op, Value};
use proptest::prelude::*;

fn compile(src: &str) -> Compiled {
    compile_spec(src, "t.hspec").unwrap_or_else(|d| panic!("{d}"))
}

// ------------------------------------------------------------------ a naive oracle over the checked AST

fn eval_expr(e: &Expr, vals: &[Value]) -> Value {
    match &e.kind {
        ExprKind::Const(v) => *v,
        ExprKind::Var(i) => vals[*i as usize],
        ExprKind::ToFloat(a) => match eval_expr(a, vals) {
            Value::Int(i) => Value::Float(i as f64),
            v => panic!("ToFloat of {v:?}"),
        },
        ExprKind::Unary(op, a) => match (op, eval_expr(a, vals)) {
            (UnaryOp::Not, Value::Bool(b)) => Value::Bool(!b),
            (UnaryOp::Neg, Value::Int(i)) => Value::Int(-i),
            (UnaryOp::Neg, Value::Float(x)) => Value::Float(-x),
            (o, v) => panic!("{o:?} {v:?}"),
        },
        ExprKind::Binary(op, a, b) => {
            let (a, b) = (eval_expr(a, vals), eval_expr(b, vals));
            match (op, a, b) {
                (BinaryOp::And, Value::Bool(a), Value::Bool(b)) => Value::Bool(a && b),
                (BinaryOp::Or, Value::Bool(a), Value::Bool(b)) => Value::Bool(a || b),
                (BinaryOp::Add, Value::Int(a), Value::Int(b)) => Value::Int(a + b),
                (BinaryOp::Sub, Value::Int(a), Value::Int(b)) => Value::Int(a - b),
                (BinaryOp::Mul, Value::Int(a), Value::Int(b)) => Value::Int(a * b),
                (BinaryOp::Rem, Value::Int(a), Value::Int(b)) => Value::Int(a % b),
                (BinaryOp::Add, Value::Float(a), Value::Float(b)) => Value::Float(a + b),
                (BinaryOp::Mul, Value::Float(a), Value::Float(b)) => Value::Float(a * b),
                (BinaryOp::Cmp(c), a, b) => {
                    let ord = match (a, b) {
                        (Value::Int(a), Value::Int(b)) => a.partial_cmp(&b),
                        (Value::Float(a), Value::Float(b)) => a.partial_cmp(&b),
                        (Value::Bool(a), Value::Bool(b)) => a.partial_cmp(&b),
                        (Value::Str(a), Value::Str(b)) => a.partial_cmp(&b),
                        _ => panic!("cmp {a:?} {b:?}"),
                    };
                    let ord = ord.expect("no NaN in these tests");
                    Value::Bool(match c {
                        CmpOp::Eq => ord.is_eq(),
                        CmpOp::Ne => ord.is_ne(),
                        CmpOp::Lt => ord.is_lt(),
                        CmpOp::Le => ord.is_le(),
                        CmpOp::Gt => ord.is_gt(),
                        CmpOp::Ge => ord.is_ge(),
                    })
                }
                (o, a, b) => panic!("{o:?} {a:?} {b:?}"),
            }
        }
    }
}

/// Direct transcription of `docs/SEMANTICS.md` section 4, quadratic and obviously right.
fn holds(f: &Formula, trace: &[(u64, Vec<Value>)], i: usize) -> bool {
    let t = |k: usize| trace[k].0;
    match &f.kind {
        FormulaKind::Const(b) => *b,
        FormulaKind::Atom(e) => eval_expr(e, &trace[i].1) == Value::Bool(true),
        FormulaKind::Not(a) => !holds(a, trace, i),
        FormulaKind::And(a, b) => holds(a, trace, i) && holds(b, trace, i),
        FormulaKind::Or(a, b) => holds(a, trace, i) || holds(b, trace, i),
        FormulaKind::Implies(a, b) => !holds(a, trace, i) || holds(b, trace, i),
        FormulaKind::Iff(a, b) => holds(a, trace, i) == holds(b, trace, i),
        FormulaKind::Yesterday(a) => i > 0 && holds(a, trace, i - 1),
        FormulaKind::WeakYesterday(a) => i == 0 || holds(a, trace, i - 1),
        FormulaKind::Once(iv, a) => (0..=i).any(|j| iv.contains(t(i) - t(j)) && holds(a, trace, j)),
        FormulaKind::Historically(iv, a) => {
            (0..=i).all(|j| !iv.contains(t(i) - t(j)) || holds(a, trace, j))
        }
        FormulaKind::Since(iv, a, b) => (0..=i).any(|j| {
            iv.contains(t(i) - t(j))
                && holds(b, trace, j)
                && (j + 1..=i).all(|k| holds(a, trace, k))
        }),
    }
}

fn oracle(spec: &CheckedSpec, trace: &[(u64, Vec<Value>)]) -> Vec<Vec<bool>> {
    (0..trace.len())
        .map(|i| {
            spec.properties
                .iter()
                .map(|p| holds(&p.formula, trace, i))
                .collect()
        })
        .collect()
}

fn run(m: &Monitor<'_>, trace: &[(u64, Vec<Value>)]) -> Vec<Vec<bool>> {
    let mut st = vec![0u64; m.state_words()];
    m.reset(&mut st).unwrap();
    let mut out = Vec::new();
    for (t, vals) in trace {
        let mut v = vec![false; m.properties()];
        m.try_step(&mut st, *t, vals, &mut v).unwrap();
        out.push(v);
    }
    out
}

// ------------------------------------------------------------------ fixed cases

#[test]
fn every_compiled_program_passes_monitor_validation_and_round_trips() {
    let specs = [
        "event a; property p = {a};",
        "event alarm;\nstate battery_level: int = 100;\nproperty absence = H({battery_level >= 30} -> H(!{alarm}));",
        "unit 100ms; event a; event b; state x: float = 1.5; state m: string = \"idle\";\n\
         property w = {a} S[2:5] {b};\nproperty u = P[0:3s] {m == \"run\"} && H[1s:] {x * 2 < 10};\n\
         property y = Y {a} <-> Z !{b};\nproperty k = true -> false;",
        "event a; property one = P[3:3] {a}; property two = {a} S[0:] {a}; property three = H[1:] {a};",
    ];
    for src in specs {
        let c = compile(src);
        let m = Monitor::try_new(c.program()).unwrap();
        assert_eq!(m.state_bytes(), c.state_bytes(), "{src}");
        let bytes = c.to_table_bytes();
        let table = Table::<64>::from_bytes(&bytes).unwrap_or_else(|e| panic!("{src}: {e}"));
        assert_eq!(table.program(), c.program(), "{src}");
        let per_prop: usize = c.properties().iter().map(|p| p.state_bytes).sum();
        assert!(per_prop <= c.state_bytes());
        assert_eq!(
            c.property_names().collect::<Vec<_>>(),
            c.program().props.iter().map(|p| p.name).collect::<Vec<_>>()
        );
    }
}

#[test]
fn identical_subformulas_share_nodes_and_atoms() {
    let c = compile("event a; state x: int;\nproperty p = P {a} && P {a} || {x > 1} && Y {x > 1};\nproperty q = {x > 1};");
    let p = c.program();
    // p: true, atom a, since, and(since, since), atom x>1, yesterday, and, or.
    assert_eq!(p.props[0].root - p.props[0].first + 1, 8, "{}", c.ir());
    // Atoms are shared across properties too.
    assert_eq!(p.atoms.len(), 2, "{}", c.ir());
    assert_eq!(p.props[1].root, p.props[1].first);
}

#[test]
fn lowering_of_once_and_historically() {
    let c = compile("event a; property p = H[2:4] {a};");
    let ops: Vec<Op> = c.program().nodes.iter().map(|n| n.op).collect();
    assert_eq!(
        ops,
        vec![
            Op::Const(true),
            Op::Atom(0),
            Op::Not(1),
            Op::Since {
                lhs: 0,
                rhs: 2,
                lo: 2,
                hi: Some(4)
            },
            Op::Not(3),
        ]
    );
    let c = compile("event a; property p = once {a};");
    let ops: Vec<Op> = c.program().nodes.iter().map(|n| n.op).collect();
    assert_eq!(
        ops,
        vec![
            Op::Const(true),
            Op::Atom(0),
            Op::Since {
                lhs: 0,
                rhs: 1,
                lo: 0,
                hi: None
            }
        ]
    );
}

#[test]
fn state_sizes_follow_the_bounds() {
    let bytes = |f: &str| {
        compile(&format!("event a; event b; property p = {f};")).properties()[0].state_bytes
    };
    assert_eq!(bytes("{a} S {b}"), 0);
    assert_eq!(bytes("Y {a}"), 8);
    assert_eq!(bytes("{a} S[0:5] {b}"), 8);
    assert_eq!(bytes("{a} S[3:] {b}"), 8);
    // floor(5 / (5 - 2 + 1)) + 1 = 2 runs of two words, plus a header word.
    assert_eq!(bytes("{a} S[2:5] {b}"), 40);
    // floor(5 / 1) + 1 = 6 runs.
    assert_eq!(bytes("P[5:5] {a}"), 8 * 13);
    let c = compile("event a; property p = Y {a}; property q = P[0:1] {a};");
    // header + one word of atom bits + one word of value bits + two node words.
    assert_eq!(c.state_bytes(), 8 * 5);
    assert!(c.ir().contains("slot 3, 1 word"), "{}", c.ir());
}

#[test]
fn state_limit_is_enforced_and_configurable() {
    // 10^7 + 1 runs of 16 bytes: about 160 MB, over the 64 MiB default.
    let big = "unit 1ns; event a; property p = P[10ms:10ms] {a};";
    let d = compile_spec(big, "big.hspec").expect_err("too large");
    let e = d.errors().next().unwrap();
    assert_eq!((e.line, e.col), (1, 33), "{d}");
    assert!(e.message.contains("limit"), "{d}");
    // 10^6 + 1 runs fit the default ...
    let ok = "unit 1ns; event a; property p = P[1ms:1ms] {a};";
    assert!(compile_spec(ok, "ok.hspec").is_ok());
    // ... but not a 1 MiB limit.
    let small = Limits {
        max_state_bytes: 1 << 20,
    };
    let r = Spec::parse(ok, "ok.hspec")
        .unwrap()
        .check()
        .unwrap()
        .size(&small);
    assert!(r.is_err());
    // Capacities beyond u32 are reported, not wrapped.
    let huge = "unit 1ns; event a; property p = P[1min:1min] {a};";
    assert!(compile_spec(huge, "huge.hspec").is_err());
}

#[test]
fn deep_atoms_hit_the_stack_limit() {
    let deep = |n: usize| {
        format!(
            "state x: int; property p = {{{}x{} > 0}};",
            "x + (".repeat(n),
            ")".repeat(n)
        )
    };
    assert!(compile_spec(&deep(20), "d.hspec").is_ok());
    let d = compile_spec(&deep(40), "d.hspec").expect_err("too deep");
    assert!(d.to_string().contains("stack"), "{d}");
}

#[test]
fn variables_and_strings_for_hosts_and_emitters() {
    let c = compile("unit 10ms; event go; state level: u8 = 7; state mode: string = \"idle\";\nproperty p = {mode == \"run\" && level > 3} S {go};");
    assert_eq!(c.tick_ns(), 10_000_000);
    let names: Vec<_> = c
        .vars()
        .iter()
        .map(|v| (v.name.as_str(), v.type_name.as_str()))
        .collect();
    assert_eq!(
        names,
        vec![("go", "bool"), ("level", "u8"), ("mode", "string")]
    );
    assert_eq!(c.var_index("mode"), Some(2));
    assert_eq!(c.strings(), &["idle".to_string(), "run".to_string()]);
    assert_eq!(c.string_id("run"), Some(1));
    assert_eq!(c.program().vars[2].init, Value::Str(0));
    let m = Monitor::try_new(c.program()).unwrap();
    let run_id = Value::Str(c.string_id("run").unwrap());
    let trace = vec![
        (0, vec![Value::Bool(true), Value::Int(7), Value::Str(0)]),
        (1, vec![Value::Bool(false), Value::Int(7), run_id]),
        (2, vec![Value::Bool(false), Value::Int(2), run_id]),
        // Strings no constant mentions get an id past the table.
        (3, vec![Value::Bool(true), Value::Int(9), Value::Str(99)]),
    ];
    assert_eq!(run(&m, &trace), oracle(c.checked(), &trace));
    assert_eq!(
        run(&m, &trace)
            .into_iter()
            .map(|v| v[0])
            .collect::<Vec<_>>(),
        vec![true, true, false, true]
    );
}

#[test]
fn warnings_survive_to_the_compiled_spec() {
    let c = compile("event a; event b; event c; property p = {a} || {b} && {c};");
    assert_eq!(c.warnings().len(), 1);
    assert!(!c.warnings().has_errors());
}

#[test]
fn ir_lists_every_node() {
    let c = compile("event a; event b; property p = {a} S[1:3] {b}; property q = Y {a};");
    let ir = c.ir();
    let node_lines = ir.lines().filter(|l| l.starts_with("  n")).count();
    assert_eq!(node_lines, c.program().nodes.len(), "{ir}");
    assert!(ir.contains("since[1:3] n0 n1 (window of 2 runs)"), "{ir}");
    assert!(ir.contains("a1 {b}: load b"), "{ir}");
}

// ------------------------------------------------------------------ random formulas against the oracle

fn formula_strategy() -> impl Strategy<Value = String> {
    let atom = prop_oneof![
        Just("{a}".to_string()),
        Just("{b}".to_string()),
        Just("{x > 2}".to_string()),
        Just("{x % 2 == 0 || b}".to_string()),
        Just("{f * 2 >= x + 1}".to_string()),
        Just("true".to_string()),
        Just("false".to_string()),
    ];
    let bound = prop_oneof![
        Just(String::new()),
        (0u64..4, 0u64..4).prop_map(|(lo, w)| format!("[{lo}:{}]", lo + w)),
        (0u64..4).prop_map(|lo| format!("[{lo}:]")),
        (0u64..5).prop_map(|hi| format!("[:{hi}]")),
    ];
    atom.prop_recursive(4, 24, 2, move |inner| {
        prop_oneof![
            inner.clone().prop_map(|f| format!("!{f}")),
            inner.clone().prop_map(|f| format!("Y {f}")),
            inner.clone().prop_map(|f| format!("Z {f}")),
            (bound.clone(), inner.clone()).prop_map(|(b, f)| format!("P{b} {f}")),
            (bound.clone(), inner.clone()).prop_map(|(b, f)| format!("H{b} {f}")),
            (inner.clone(), bound.clone(), inner.clone())
                .prop_map(|(f, b, g)| format!("({f} S{b} {g})")),
            (
                inner.clone(),
                prop::sample::select(vec!["&&", "||", "->", "<->"]),
                inner.clone()
            )
                .prop_map(|(f, o, g)| format!("({f} {o} {g})")),
        ]
    })
}

fn trace_strategy() -> impl Strategy<Value = Vec<(u64, Vec<Value>)>> {
    prop::collection::vec(
        (0u64..3, any::<bool>(), any::<bool>(), 0i64..5, 0i64..4),
        1..25,
    )
    .prop_map(|points| {
        let mut t = 0;
        points
            .into_iter()
            .map(|(dt, a, b, x, f)| {
                t += dt;
                (
                    t,
                    vec![
                        Value::Bool(a),
                        Value::Bool(b),
                        Value::Int(x),
                        Value::Float(f as f64 / 2.0),
                    ],
                )
            })
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn monitor_agrees_with_the_naive_semantics(
        f in formula_strategy(),
        g in formula_strategy(),
        trace in trace_strategy(),
    ) {
        let src = format!("event a; event b; state x: int; state f: float;\nproperty p = {f};\nproperty q = {g};\nproperty r = {f} && {g};");
        let c = compile(&src);
        let expect = oracle(c.checked(), &trace);
        let m = Monitor::try_new(c.program()).unwrap();
        prop_assert_eq!(&run(&m, &trace), &expect, "{}", c.ir());
        let bytes = c.to_table_bytes();
        let table = Table::<256>::from_bytes(&bytes).unwrap();
        prop_assert_eq!(&run(&table.monitor().unwrap(), &trace), &expect);
    }
}
