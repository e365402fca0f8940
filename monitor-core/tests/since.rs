//! `S` with every bound shape against a brute-force reading of the definition, on random traces.

mod common;

use common::{program, since_nodes, Rng};
use monitor_core::{Monitor, StepError, Value};

/// Brute force: exists j <= i with lo <= t_i - t_j <= hi, q at j, p at every k in (j, i].
fn brute(trace: &[(u64, bool, bool)], i: usize, lo: u64, hi: Option<u64>) -> bool {
    (0..=i).rev().any(|j| {
        let d = trace[i].0 - trace[j].0;
        trace[j].2 && d >= lo && hi.is_none_or(|h| d <= h) && trace[j + 1..=i].iter().all(|pt| pt.1)
    })
}

fn check(lo: u64, hi: Option<u64>, seed: u64) {
    let nodes = since_nodes(lo, hi);
    let m = Monitor::try_new(program(&nodes)).expect("valid program");
    let mut state = vec![0u64; m.state_words()];
    m.reset(&mut state).unwrap();
    let mut rng = Rng(seed);
    let mut trace = Vec::new();
    let mut t = 0u64;
    for i in 0..400 {
        // Mostly small steps, some repeats (super-dense), some jumps.
        t += match rng.next() % 10 {
            0..=2 => 0,
            3..=7 => 1,
            8 => 3,
            _ => rng.next() % 20,
        };
        let (p, q) = (rng.chance(85), rng.chance(25));
        trace.push((t, p, q));
        let mut out = [false];
        m.try_step(&mut state, t, &[Value::Bool(p), Value::Bool(q)], &mut out)
            .unwrap();
        assert_eq!(
            out[0],
            brute(&trace, i, lo, hi),
            "S[{lo}:{hi:?}] seed {seed} point {i} trace {:?}",
            &trace[..=i]
        );
    }
}

#[test]
fn every_bound_shape_agrees_with_the_definition() {
    let shapes: &[(u64, Option<u64>)] = &[
        (0, None),
        (0, Some(0)),
        (0, Some(5)),
        (3, None),
        (1, Some(1)),
        (2, Some(4)),
        (4, Some(4)),
        (1, Some(9)),
        (5, Some(30)),
    ];
    for &(lo, hi) in shapes {
        for seed in 1..=20 {
            check(lo, hi, seed * 7919);
        }
    }
}

#[test]
fn time_going_backwards_is_an_error_and_changes_nothing() {
    let nodes = since_nodes(2, Some(4));
    let m = Monitor::try_new(program(&nodes)).unwrap();
    let mut state = vec![0u64; m.state_words()];
    let mut out = [false];
    let q = [Value::Bool(false), Value::Bool(true)];
    m.try_step(&mut state, 10, &q, &mut out).unwrap();
    let before = state.clone();
    assert_eq!(
        m.try_step(&mut state, 9, &q, &mut out),
        Err(StepError::TimeWentBackwards { last: 10, now: 9 })
    );
    assert_eq!(state, before);
    assert_eq!(
        m.try_step(&mut state, u64::MAX, &q, &mut out),
        Err(StepError::TimeOutOfRange)
    );
    // Equal timestamps are fine (super-dense time).
    m.try_step(&mut state, 10, &q, &mut out).unwrap();
}

#[test]
fn wrong_inputs_are_errors() {
    let nodes = since_nodes(0, None);
    let m = Monitor::try_new(program(&nodes)).unwrap();
    let mut state = vec![0u64; m.state_words()];
    let mut out = [false];
    assert_eq!(
        m.try_step(&mut state, 0, &[Value::Bool(true), Value::Int(1)], &mut out),
        Err(StepError::VarType { var: 1 })
    );
    assert!(matches!(
        m.try_step(&mut state, 0, &[Value::Bool(true)], &mut out),
        Err(StepError::InputSize { .. })
    ));
    let mut short = vec![0u64; m.state_words() - 1];
    assert!(matches!(
        m.try_step(
            &mut short,
            0,
            &[Value::Bool(true), Value::Bool(true)],
            &mut out
        ),
        Err(StepError::StateSize { .. })
    ));
}

#[test]
fn window_state_is_sized_by_the_bounds_alone() {
    // floor(b / (b - a + 1)) + 1 runs of two words, plus a header word.
    for (lo, hi, cap) in [
        (2u64, 4u64, 2u64),
        (4, 4, 5),
        (1, 9, 2),
        (10, 10, 11),
        (50, 100, 2),
    ] {
        let nodes = since_nodes(lo, Some(hi));
        let m = Monitor::try_new(program(&nodes)).unwrap();
        let base = monitor_core::layout::first_node_word(2, 3);
        assert_eq!(m.state_words(), base + 1 + 2 * cap as usize, "[{lo}:{hi}]");
    }
}

#[test]
fn capacities_that_do_not_fit_are_rejected_not_wrapped() {
    assert_eq!(
        monitor_core::layout::window_capacity(u64::MAX, u64::MAX),
        None
    );
    assert_eq!(monitor_core::layout::window_capacity(1, u64::MAX), Some(2));
    let nodes = [
        monitor_core::Node {
            op: monitor_core::Op::Atom(0),
            slot: 0,
        },
        monitor_core::Node {
            op: monitor_core::Op::Atom(1),
            slot: 0,
        },
        monitor_core::Node {
            op: monitor_core::Op::Since {
                lhs: 0,
                rhs: 1,
                lo: u64::MAX,
                hi: Some(u64::MAX),
            },
            slot: monitor_core::layout::first_node_word(2, 3) as u32,
        },
    ];
    assert!(Monitor::try_new(program(&nodes)).is_err());
}
