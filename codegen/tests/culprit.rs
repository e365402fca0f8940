//! At a property's first false point, `monitor_core::analysis::culprit` names the
//! subformula that explains it and `print::node_formula` prints it: checked on formulas
//! whose failing part is known by construction.

use codegen::{compile_spec, print};
use monitor_core::{analysis, Monitor, Value};

/// Steps `trace` (one `(time, [a, b, c])` per point) through property 0 of `formula` and
/// returns, at its first false point, the culprit's text and value.
fn culprit_at_first_false(formula: &str, trace: &[(u64, [bool; 3])]) -> Option<(String, bool)> {
    let src = format!("event a;\nevent b;\nevent c;\nproperty p = {formula};\n");
    let c = compile_spec(&src, "t.hspec").unwrap_or_else(|d| panic!("{d}"));
    let m = Monitor::try_new(c.program()).unwrap();
    let mut state = vec![0u64; m.state_words()];
    let mut verdicts = [false];
    for (t, vals) in trace {
        let vars: Vec<Value> = vals.iter().map(|&v| Value::Bool(v)).collect();
        m.try_step(&mut state, *t, &vars, &mut verdicts).unwrap();
        if !verdicts[0] {
            let program = c.program();
            let value = |n| m.node_value(&state, n);
            let n = analysis::culprit(&program, program.props[0].root, value);
            return Some((print::node_formula(&c, n), value(n).unwrap()));
        }
    }
    None
}

#[test]
fn an_invariant_is_explained_by_the_part_that_broke() {
    // H(a -> b): at the point where a holds without b, the culprit is b, false.
    let got = culprit_at_first_false(
        "H({a} -> {b})",
        &[
            (0, [false, false, false]),
            (1, [true, true, false]),
            (2, [true, false, false]),
        ],
    );
    assert_eq!(got, Some(("{b}".to_string(), false)));
    // H(a && b): the first false conjunct.
    let got = culprit_at_first_false(
        "H({a} && {b})",
        &[(0, [true, true, false]), (1, [true, false, false])],
    );
    assert_eq!(got, Some(("{b}".to_string(), false)));
}

#[test]
fn a_response_window_is_explained_by_the_window_itself() {
    // H(!(!c S[2:] a)): c must answer a within 2 ticks; at t = 2 it has not. The bounded
    // Since is its own explanation (true: the window ran out).
    let got = culprit_at_first_false(
        "H(!(!{c} S[2:] {a}))",
        &[
            (0, [true, false, false]),
            (1, [false, false, false]),
            (2, [false, false, false]),
        ],
    );
    assert_eq!(got, Some(("(!{c} S[2:] {a})".to_string(), true)));
}

#[test]
fn a_property_that_never_fails_has_no_culprit() {
    assert_eq!(
        culprit_at_first_false(
            "H({a} || !{a})",
            &[(0, [true, false, false]), (1, [false; 3])]
        ),
        None
    );
}
