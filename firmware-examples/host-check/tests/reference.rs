//! The hand-lowered museum program means what its formulas say: a naive evaluator over the whole trace agrees with the monitor at every point.

use host_check::verdicts::static_expected;
use monitor_core::Value;
use museum_spec::{Point, FORMULAS, TRACE};

fn flag(p: &Point, var: usize) -> bool {
    p.values[var] == Value::Bool(true)
}

fn level(p: &Point) -> i64 {
    match p.values[1] {
        Value::Int(l) => l,
        other => panic!("battery_level is {other:?}"),
    }
}

/// Whether some point j <= k with `lo <= tau_k - tau_j <= hi` satisfies `f`.
fn once(k: usize, lo: u64, hi: u64, f: impl Fn(&Point) -> bool) -> bool {
    let now = TRACE[k].time;
    TRACE[..=k]
        .iter()
        .any(|p| (lo..=hi).contains(&(now - p.time)) && f(p))
}

/// Each formula of `FORMULAS`, evaluated from its definition at point `i`.
fn reference(i: usize) -> [bool; 3] {
    let published = |p: &Point| flag(p, 0);
    let every_10 = (0..=i).all(|k| !once(k, 10, u64::MAX, |_| true) || once(k, 0, 10, published));
    let dock_after_low = (0..=i).all(|k| !flag(&TRACE[k], 2) || once(k, 1, 20, |p| level(p) <= 30));
    let fresh = once(i, 0, 10, published);
    [every_10, dock_after_low, fresh]
}

#[test]
fn monitor_matches_the_formulas_at_every_point() {
    let monitor = static_expected().unwrap();
    for (i, got) in monitor.verdicts.iter().enumerate() {
        let want = reference(i);
        for p in 0..3 {
            assert_eq!(
                got[p], want[p],
                "{} at point {i} (time {})",
                FORMULAS[p], TRACE[i].time
            );
        }
    }
}

#[test]
fn the_trace_tells_the_intended_story() {
    let false_at = |p: usize| -> Vec<u64> {
        (0..TRACE.len())
            .filter(|&i| !reference(i)[p])
            .map(|i| TRACE[i].time)
            .collect()
    };
    // The publisher is silent after time 40: 11 units later nothing was
    // published within 10, and the invariant stays broken.
    assert_eq!(false_at(0).first(), Some(&51));
    assert_eq!(false_at(0).last(), Some(&120));
    // Freshness fails at the very first point (the message comes one micro-step
    // later) and from 51 until the publisher's return at 56.
    let fresh = false_at(2);
    assert_eq!(fresh[0], 0);
    assert_eq!(fresh[1..].first(), Some(&51));
    assert_eq!(fresh.last(), Some(&56));
    // The second dock request (time 118) comes 39 units after the last low reading.
    assert_eq!(false_at(1).first(), Some(&118));
}
