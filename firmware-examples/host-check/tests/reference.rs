//! The monitors compiled from `museum.hspec` mean what the spec says: the requirements agree with the verdicts `hindsight trace` recorded for the run, and a naive evaluator of each observer's definition agrees at every point.

use host_check::verdicts::{static_expected, REQUIREMENTS};
use monitor_core::Value;
use museum_spec::{museum, Point, TRACE, VAR_NAMES};

const CSV: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../museum-spec/museum-run0.csv"
));

/// The data rows of the committed run, split into cells, and its header.
fn csv() -> (Vec<&'static str>, Vec<Vec<&'static str>>) {
    let mut lines = CSV.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap().split(',').collect();
    (header, lines.map(|l| l.split(',').collect()).collect())
}

#[test]
fn requirements_equal_the_verdicts_hindsight_recorded() {
    let (header, rows) = csv();
    let monitor = static_expected().unwrap();
    assert_eq!(rows.len(), monitor.verdicts.len());
    let mut checked = 0;
    for (p, name) in museum::PROPERTY_NAMES.iter().enumerate() {
        let Some(col) = header.iter().position(|h| *h == format!("verdict_{name}")) else {
            continue;
        };
        assert!(p < REQUIREMENTS, "observer {name} has a recorded verdict");
        for (i, row) in rows.iter().enumerate() {
            let recorded: bool = row[col].parse().unwrap();
            assert_eq!(
                monitor.verdicts[i][p], recorded,
                "{name} at row {i} (time {})",
                row[0]
            );
        }
        checked += 1;
    }
    assert_eq!(checked, REQUIREMENTS);
}

fn var(name: &str) -> usize {
    VAR_NAMES.iter().position(|v| *v == name).unwrap()
}

fn flag(p: &Point, name: &str) -> bool {
    p.values[var(name)] == Value::Bool(true)
}

fn int(p: &Point, name: &str) -> i64 {
    match p.values[var(name)] {
        Value::Int(l) => l,
        other => panic!("{name} is {other:?}"),
    }
}

/// Whether some point j <= k with `lo <= tau_k - tau_j <= hi` satisfies `f`.
fn once(k: usize, lo: u64, hi: u64, f: impl Fn(&Point) -> bool) -> bool {
    let now = TRACE[k].time;
    TRACE[..=k]
        .iter()
        .any(|p| (lo..=hi).contains(&(now - p.time)) && f(p))
}

/// `lhs S[0:hi] rhs` at point `k`, from the definition.
fn since(k: usize, hi: u64, lhs: impl Fn(&Point) -> bool, rhs: impl Fn(&Point) -> bool) -> bool {
    let now = TRACE[k].time;
    (0..=k)
        .any(|j| now - TRACE[j].time <= hi && rhs(&TRACE[j]) && TRACE[j + 1..=k].iter().all(&lhs))
}

/// An observer's verdict at point `i`, from its definition.
type Reference = fn(usize) -> bool;

#[test]
fn observers_match_their_definitions_at_every_point() {
    let monitor = static_expected().unwrap();
    let observers: [(&str, Reference); 4] = [
        ("battery_fresh", |i| {
            once(i, 0, 5, |p| flag(p, "battery_published"))
        }),
        ("alarm_echo", |i| once(i, 3, 8, |p| flag(p, "alarm"))),
        ("low_since_alarm", |i| {
            since(
                i,
                20,
                |p| int(p, "battery_level") <= 30,
                |p| flag(p, "alarm"),
            )
        }),
        ("poi1_pending", |i| {
            let p = &TRACE[i];
            int(p, "current_poi") == 1
                && !(int(p, "poi_done_name") == 1 && int(p, "poi_done_value") == 1)
        }),
    ];
    assert_eq!(REQUIREMENTS + observers.len(), museum::PROPERTIES);
    for (k, (name, reference)) in observers.iter().enumerate() {
        let p = REQUIREMENTS + k;
        assert_eq!(museum::PROPERTY_NAMES[p], *name);
        for (i, got) in monitor.verdicts.iter().enumerate() {
            assert_eq!(
                got[p],
                reference(i),
                "{name} at point {i} (time {})",
                TRACE[i].time
            );
        }
    }
}
