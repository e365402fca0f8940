//! Unit tests of the whole front end: parsing, checking, sizing, compiling and running.

use monitor_core::{Monitor, Value};

use crate::compile_spec;

#[test]
fn end_to_end_absence() {
    let src = "event alarm;\nstate battery_level: int = 100;\nproperty absence = H({battery_level >= 30} -> H(!{alarm}));\n";
    let c = compile_spec(src, "t.hspec").unwrap_or_else(|d| panic!("{d}"));
    let m = Monitor::try_new(c.program()).unwrap();
    let mut st = vec![0u64; m.state_words()];
    m.reset(&mut st).unwrap();
    let mut v = [false];
    m.try_step(&mut st, 0, &[Value::Bool(false), Value::Int(100)], &mut v)
        .unwrap();
    assert!(v[0]);
    m.try_step(&mut st, 1, &[Value::Bool(true), Value::Int(100)], &mut v)
        .unwrap();
    assert!(!v[0]);
}

#[test]
fn step_errors_name_the_atom_and_the_variable() {
    let c = compile_spec(
        "unit 1s;\nstate p: bool = false;\nstate x: int = 0;\nproperty f = H({x + 1 > 0} || {p});\n",
        "d.hspec",
    )
    .expect("compiles");
    let m = Monitor::try_new(c.program()).expect("valid");
    let mut s = vec![0u64; m.state_words()];
    let e = m
        .try_step(
            &mut s,
            0,
            &[Value::Bool(false), Value::Int(i64::MAX)],
            &mut [false],
        )
        .expect_err("overflow");
    assert_eq!(
        c.describe(&e),
        "atom `{(x + 1) > 0}`: integer overflow or division by zero"
    );
    let e = m
        .try_step(
            &mut s,
            0,
            &[Value::Bool(false), Value::Bool(true)],
            &mut [false],
        )
        .expect_err("a boolean for x");
    assert_eq!(
        c.describe(&e),
        "variable `x`: a value that is not of its type `int`"
    );
    // Indices the spec does not have, and other errors, read as before.
    for e in [
        monitor_core::StepError::Arithmetic { atom: 9 },
        monitor_core::StepError::VarType { var: 9 },
        monitor_core::StepError::TimeOutOfRange,
    ] {
        assert_eq!(c.describe(&e), e.to_string());
    }
}
