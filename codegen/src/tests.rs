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
