//! Each firmware image runs under QEMU, exits 0, and logs the verdicts the host interpreter computes, point for point.
//!
//! Needs the release images of `firmware-examples` (scripts/firmware builds
//! them) and `qemu-system-arm` on the PATH.

use std::time::Duration;

use host_check::log::{decode, Log};
use host_check::verdicts::{compare, static_expected, table_expected, Expected};
use host_check::{qemu, read_image, table_inputs};

const TIMEOUT: Duration = Duration::from_secs(30);

/// Boots `name`, requires exit status 0, and returns its decoded log.
fn run(name: &str) -> Log {
    let (path, elf) = read_image(name).unwrap();
    let run = qemu::run(&path, TIMEOUT).unwrap();
    let messages = decode(&elf, &run.stdout).unwrap();
    assert!(
        run.status.success(),
        "{name} exited with {:?}; log: {messages:#?}; stderr: {}",
        run.status,
        run.stderr
    );
    Log::parse(messages).unwrap()
}

fn check(name: &str, expected: &Expected) {
    let log = run(name);
    if let Err(e) = compare(expected, &log) {
        panic!("{name}: {e}\nlog: {:#?}", log.messages);
    }
    assert_eq!(log.start.as_ref().map(|s| s.name.as_str()), Some(name));
    let done = log.done.unwrap();
    assert!(done.replay_stack > 0, "{name}: no stack use measured");
    assert_eq!(done.stack, done.setup_stack.max(done.replay_stack));
}

#[test]
fn monitor_static_verdicts_equal_the_host_interpreter() {
    check("monitor-static", &static_expected().unwrap());
}

#[test]
fn monitor_table_verdicts_equal_the_host_interpreter() {
    let (table, trace) = table_inputs().unwrap();
    check("monitor-table", &table_expected(&table, &trace).unwrap());
}

#[test]
fn monitor_table_steps_the_whole_museum_run() {
    // No museum verdict is final before the end: the table image replays every point.
    let (table, trace) = table_inputs().unwrap();
    let expected = table_expected(&table, &trace).unwrap();
    if table == museum_spec::TABLE {
        assert_eq!(expected.final_point, None);
    }
}

#[test]
fn monitor_final_stops_where_every_verdict_becomes_final() {
    let expected = table_expected(museum_spec::FINAL_TABLE, &museum_spec::trace_bytes()).unwrap();
    // final.hspec's verdicts are all final at the run's first alarm, well before its end.
    let alarm = museum_spec::VAR_NAMES
        .iter()
        .position(|n| *n == "alarm")
        .unwrap();
    let first_alarm = museum_spec::TRACE
        .iter()
        .position(|p| p.values[alarm] == monitor_core::Value::Bool(true))
        .unwrap();
    assert_eq!(expected.final_point, Some(first_alarm));
    assert!(first_alarm + 1 < museum_spec::TRACE_LEN);
    check("monitor-final", &expected);
}

#[test]
fn baselines_replay_the_whole_trace() {
    for name in ["baseline", "baseline-bytes"] {
        let log = run(name);
        assert!(log.errors.is_empty(), "{name}: {:?}", log.errors);
        assert!(log.changes.is_empty());
        let done = log.done.expect("no `done` line");
        assert_eq!(done.points as usize, museum_spec::TRACE_LEN, "{name}");
        // Both read every value of the trace: count its events.
        let events = museum_spec::TRACE
            .iter()
            .flat_map(|p| p.values)
            .filter(|v| *v == monitor_core::Value::Bool(true))
            .count();
        let line = format!("replayed events={events} ");
        assert!(
            log.messages.iter().any(|m| m.starts_with(&line)),
            "{name}: {:?}",
            log.messages
        );
    }
}

#[test]
fn a_panic_fails_the_run() {
    let (path, elf) = read_image("panic-check").unwrap();
    let run = qemu::run(&path, TIMEOUT).unwrap();
    assert_eq!(run.status.code(), Some(1), "stderr: {}", run.stderr);
    let log = Log::parse(decode(&elf, &run.stdout).unwrap()).unwrap();
    assert!(log.done.is_none());
    assert!(
        log.errors
            .iter()
            .any(|e| e.starts_with("error panic at ") && e.contains("panic-check.rs")),
        "{:?}",
        log.messages
    );
}
