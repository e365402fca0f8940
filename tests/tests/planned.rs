//! Planned monitors (`Monitor<'_, N>`) step exactly like unplanned ones: same verdicts, errors and state at every point.
//!
//! Random specs of 1 to 12 random Past-MTL properties (every operator and
//! interval shape) whose atoms are the shapes the plan reads directly (a
//! boolean variable, its negation, an integer variable compared with a
//! constant on either side) and ones it hands to the atom machine (arithmetic
//! that can overflow, an event), or no atom at all. Each runs on random traces (repeated
//! timestamps, jumps, a timestamp that goes back, a value of the wrong type,
//! `i64` extremes) through `Monitor<'_>`, a `Monitor<'_, 16>` (planned only for
//! the smallest specs) and a `Monitor<'_, 256>` (planned, one value word or
//! several): after every point the result and the whole state buffer must be
//! the same. Specs over boolean variables alone take the plan's other paths
//! (atoms as bits of the variables, a transition table for networks of truth
//! tables, with timed steps before it, a table of the literal nodes' bits),
//! checked the same way.

use hindsight_tests::gen::{self, FormulaConfig, Gen};
use hindsight_tests::oracle;
use monitor_core::{Monitor, StepError, Value};

/// Atoms that replace `{a2}` of a random formula, one per spec.
const INT_ATOMS: &[&str] = &[
    "{i < 3}",
    "{2 >= i}",
    "{i == -1}",
    "{0 != i}",
    "{i > 1}",
    "{i <= 0}",
    "{i + 1 > 2}",
    "{e}",
    "{!a1 && i >= 2}",
];

fn spec(rng: &mut Gen) -> String {
    let mut text = String::from(
        "state a0: bool = false;\nstate a1: bool = true;\nstate i: int = 0;\nevent e;\n",
    );
    let props = gen::range(rng, 1, 12);
    // Some specs have no atom at all (no scratch word in the state).
    let constant = gen::chance(rng, 0.05);
    for k in 0..props {
        let cfg = FormulaConfig {
            atoms: 3,
            small: gen::range(rng, 2, 8),
            p_large: [0.0, 0.3][gen::range(rng, 0, 1) as usize],
            ..FormulaConfig::default()
        };
        let f = oracle::print(&gen::formula(rng, &cfg));
        let a2 = INT_ATOMS[gen::range(rng, 0, INT_ATOMS.len() as u64 - 1) as usize];
        let a0 = if gen::chance(rng, 0.3) {
            "{!a0}"
        } else {
            "{a0}"
        };
        let f = if constant {
            f.replace("{a0}", "true")
                .replace("{a1}", "false")
                .replace("{a2}", "true")
        } else {
            f.replace("{a2}", a2).replace("{a0}", a0)
        };
        text.push_str(&format!("property p{k} = {f};\n"));
    }
    text
}

/// One random point: its time (from `last`) and the values of `a0 a1 i e`.
fn point(rng: &mut Gen, last: u64) -> (u64, Vec<Value>) {
    let time = match gen::range(rng, 0, 19) {
        0 => last.saturating_sub(1),
        1 => last + gen::range(rng, 50, 400),
        2..=8 => last,
        _ => last + gen::range(rng, 1, 4),
    };
    let int = match gen::range(rng, 0, 9) {
        0 => i64::MAX,
        1 => i64::MIN,
        n => n as i64 - 5,
    };
    let mut vals = vec![
        Value::Bool(gen::chance(rng, 0.5)),
        Value::Bool(gen::chance(rng, 0.5)),
        Value::Int(int),
        Value::Bool(gen::chance(rng, 0.2)),
    ];
    if gen::chance(rng, 0.01) {
        vals[gen::range(rng, 0, 3) as usize] = Value::Float(0.5);
    }
    (time, vals)
}

type Step = Result<Vec<bool>, StepError>;

fn step<const N: usize>(m: &Monitor<'_, N>, state: &mut [u64], time: u64, vals: &[Value]) -> Step {
    let mut out = vec![false; m.properties()];
    m.try_step(state, time, vals, &mut out).map(|()| out)
}

/// Steps the unplanned monitor and both planned ones at one point and asserts that the
/// planned ones give its result and the same state; returns its result.
fn step_three(
    (plain, narrow, wide): (&Monitor<'_>, &Monitor<'_, 16>, &Monitor<'_, 256>),
    states: &mut [Vec<u64>; 3],
    (time, vals): (u64, &[Value]),
    at: &str,
    text: &str,
) -> Step {
    let [s0, s1, s2] = states;
    let want = step(plain, s0, time, vals);
    let got = [step(narrow, s1, time, vals), step(wide, s2, time, vals)];
    for (name, (got, state)) in ["N = 16", "N = 256"]
        .iter()
        .zip(got.iter().zip([&*s1, &*s2]))
    {
        assert_eq!(got, &want, "{at} ({name}):\n{text}");
        assert_eq!(state, &*s0, "{at} ({name}): state\n{text}");
    }
    want
}

#[test]
fn planned_monitors_step_like_unplanned_ones() {
    let mut rng = gen::rng(0x706c_616e);
    let (mut planned_small, mut planned_multiword, mut fallback, mut errors) = (0, 0, 0, 0);
    let mut atomless = 0;
    for case in 0..1500 {
        let text = spec(&mut rng);
        let compiled = codegen::compile_spec(&text, "planned.hspec")
            .unwrap_or_else(|d| panic!("case {case}: codegen rejected\n{text}\n{d}"));
        let program = compiled.program();
        let plain = Monitor::try_new(program).expect("codegen output validates");
        let narrow: Monitor<'_, 16> = Monitor::try_new_planned(program).expect("validates");
        let wide: Monitor<'_, 256> = Monitor::try_new_planned(program).expect("validates");
        let (nodes, atoms) = (program.nodes.len(), program.atoms.len());
        atomless += (atoms == 0) as usize;
        assert!(!plain.is_planned());
        assert_eq!(
            narrow.is_planned(),
            nodes <= 16 && atoms <= 16,
            "case {case}"
        );
        assert_eq!(
            wide.is_planned(),
            nodes <= 256 && atoms <= 256,
            "case {case}"
        );
        match (narrow.is_planned(), wide.is_planned(), nodes > 64) {
            (true, _, _) => planned_small += 1,
            (false, true, true) => planned_multiword += 1,
            _ => {}
        }
        if !narrow.is_planned() {
            fallback += 1;
        }
        let words = plain.state_words();
        assert_eq!((narrow.state_words(), wide.state_words()), (words, words));
        let mut states = [vec![0u64; words], vec![0u64; words], vec![0u64; words]];
        let mut last = 0;
        for k in 0..gen::range(&mut rng, 1, 80) {
            let (time, vals) = point(&mut rng, last);
            let want = step_three(
                (&plain, &narrow, &wide),
                &mut states,
                (time, &vals),
                &format!("case {case}, point {k}"),
                &text,
            );
            match want {
                Ok(_) => last = time,
                Err(_) => errors += 1,
            }
        }
    }
    // Every path was taken: planned in one word, planned over several, unplanned; and errors.
    assert!(
        planned_small > 20,
        "{planned_small} specs planned with N = 16"
    );
    assert!(
        planned_multiword > 20,
        "{planned_multiword} specs over 64 nodes planned"
    );
    assert!(fallback > 20, "{fallback} specs too large for N = 16");
    assert!(errors > 50, "{errors} points rejected");
    assert!(atomless > 20, "{atomless} specs without atoms");
}

/// Boolean-only networks: fixed ones (every node a truth table, so that the
/// transition table is used; with windows; with an event) and random ones.
const BOOL_FORMULAS: &[&str] = &[
    "H({a0} -> H(!{a1}))",
    "{a0} S {a1}",
    "{a1} S {a0}",
    "!{a2} || ({a0} S ({a1} && !{a0}))",
    "H({a0} -> P {a1}) && !(({a2} || {a1}) S !{a0})",
    "{a0} S[1:3] {a1}",
    "P[0:2] {a2}",
    "{a0} && {a1} && {a2} && {e}",
    "({e} -> Y {a0}) && H(!{a2})",
    // Timed steps over literals, then truth tables: a table after timed steps.
    "H(({a1} -> P {a0}) && !(!{a1} S[2:] {a0}))",
    "H(P[2:] true -> P[:3] {a2})",
    // A timed step over another's value, and over its negation.
    "P[0:3] (P[1:2] {a0}) -> {a1}",
    "P[0:2] !(P[1:] {a1}) && H {a0}",
    "({a0} S[0:2] !P[2:4] {a2}) || ({a1} S {a0})",
    // Windows, constants and negated atoms as the timed steps' children.
    "(true S[1:3] !{a0}) <-> ({a1} S[2:] true)",
    "!(!{a2} S[0:1] {a1}) -> Y {a0}",
];

#[test]
fn boolean_monitors_step_like_unplanned_ones() {
    let mut rng = gen::rng(0x626f_6f6c);
    let (mut errors, mut timed_tables) = (0, 0);
    for case in 0..600 {
        let mut text = String::from(
            "state a0: bool = false;\nstate a1: bool = true;\nstate a2: bool = false;\nevent e;\n",
        );
        for k in 0..gen::range(&mut rng, 1, 3) {
            let f = if gen::chance(&mut rng, 0.4) {
                BOOL_FORMULAS[gen::range(&mut rng, 0, BOOL_FORMULAS.len() as u64 - 1) as usize]
                    .to_string()
            } else {
                let cfg = FormulaConfig {
                    max_depth: gen::range(&mut rng, 2, 6) as usize,
                    atoms: 3,
                    small: 4,
                    p_large: 0.0,
                    ..FormulaConfig::default()
                };
                oracle::print(&gen::formula(&mut rng, &cfg))
            };
            text.push_str(&format!("property p{k} = {f};\n"));
        }
        let compiled = codegen::compile_spec(&text, "planned.hspec")
            .unwrap_or_else(|d| panic!("case {case}: codegen rejected\n{text}\n{d}"));
        let program = compiled.program();
        let plain = Monitor::try_new(program).expect("codegen output validates");
        let narrow: Monitor<'_, 16> = Monitor::try_new_planned(program).expect("validates");
        let wide: Monitor<'_, 256> = Monitor::try_new_planned(program).expect("validates");
        if wide.table_after_timed_steps().is_some_and(|k| k > 0) {
            timed_tables += 1;
        }
        let words = plain.state_words();
        let mut states = [vec![0u64; words], vec![0u64; words], vec![0u64; words]];
        let mut last = 0;
        for k in 0..gen::range(&mut rng, 1, 60) {
            let (time, mut vals) = point(&mut rng, last);
            // a0 a1 a2 e, all booleans; now and then a value of another type.
            vals[2] = Value::Bool(gen::chance(&mut rng, 0.5));
            if gen::chance(&mut rng, 0.02) {
                vals[gen::range(&mut rng, 0, 3) as usize] = Value::Int(1);
            }
            let want = step_three(
                (&plain, &narrow, &wide),
                &mut states,
                (time, &vals),
                &format!("case {case}, point {k}"),
                &text,
            );
            match want {
                Ok(_) => last = time,
                Err(_) => errors += 1,
            }
        }
    }
    assert!(errors > 20, "{errors} points rejected");
    // `compact` (the firmware's interpreter) folds nothing, so it builds no table.
    if !cfg!(feature = "compact") {
        assert!(
            timed_tables > 60,
            "{timed_tables} specs stepped by a table after timed steps"
        );
    }
}

/// `try_step_atoms` reads atom `k` from bit `k % 64` of word `k / 64` and
/// nothing else: bits past the last atom change no verdict of a planned
/// monitor (its tables are indexed by the atoms), as they change none of an
/// unplanned one.
#[test]
fn bits_past_the_atoms_are_ignored() {
    for f in BOOL_FORMULAS {
        let text = format!(
            "state a0: bool = false;\nstate a1: bool = true;\nstate a2: bool = false;\nevent e;\nproperty p = {f};\n"
        );
        let compiled = codegen::compile_spec(&text, "planned.hspec").expect("compiles");
        let program = compiled.program();
        let plain = Monitor::try_new(program).expect("validates");
        let planned: Monitor<'_, 64> = Monitor::try_new_planned(program).expect("validates");
        let n = program.atoms.len();
        let words = plain.state_words();
        let (mut s0, mut s1) = (vec![0u64; words], vec![0u64; words]);
        let mut rng = gen::rng(0x6174_6f6d);
        for time in 0..200u64 {
            let bits = gen::range(&mut rng, 0, u64::MAX - 1);
            let exact = bits & (u64::MAX >> (64 - n));
            let (mut want, mut got) = ([false], [false]);
            plain
                .try_step_atoms(&mut s0, time, &[exact], &mut want)
                .expect("steps");
            planned
                .try_step_atoms(&mut s1, time, &[bits], &mut got)
                .expect("steps");
            assert_eq!(got, want, "{f}, time {time}, atoms {bits:#x}");
        }
    }
}
