//! The sidecar's judging core without iceoryx2: the five verdicts, the loss rule, the filter, replay errors.

use hindsight::live::engine::Engine;
use hindsight::live::record::{apply, replay, verdict_line, Input};
use serde_json::json;

const SPEC: &str = "unit 1ms;
event b;
event c;
event req;
state x: int = 0;
property rec = H(P[3:] true -> P[:3] {b});
property never_neg = H({x >= 0});
property no_c = H(!{c});
property seen_b = P {b};
property req_ok = H({req} -> {x < 10});
";

fn sample(time: u64, sets: serde_json::Value) -> Input {
    let sets = sets.as_object().unwrap().clone().into_iter().collect();
    Input::Sample {
        time,
        source: "s".into(),
        sets,
    }
}

fn loss(time: u64, vars: &[&str]) -> Input {
    Input::Loss {
        time,
        source: "s".into(),
        vars: vars.iter().map(|v| v.to_string()).collect(),
        count: 1,
        reason: "test".into(),
    }
}

/// Runs `inputs`; returns `(property, time, verdict)` per reported change.
fn run(inputs: &[Input]) -> Vec<(String, u64, String)> {
    let spec = codegen::compile_spec(SPEC, "t.hspec").unwrap();
    let mut e = Engine::new(&spec, false).unwrap();
    let mut out = Vec::new();
    for i in inputs {
        apply(&spec, &mut e, i, &mut out).unwrap();
    }
    out.iter()
        .map(|c| {
            let v: serde_json::Value = serde_json::from_str(&verdict_line(&spec, c)).unwrap();
            (
                v["property"].as_str().unwrap().to_string(),
                v["time"].as_u64().unwrap(),
                v["verdict"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

fn of(r: &[(String, u64, String)], prop: &str) -> Vec<(u64, String)> {
    r.iter()
        .filter(|(p, _, _)| p == prop)
        .map(|(_, t, v)| (*t, v.clone()))
        .collect()
}

fn v(t: u64, s: &str) -> (u64, String) {
    (t, s.to_string())
}

#[test]
fn a_loss_makes_readers_unknown_for_their_largest_bound_then_they_judge_again() {
    let mut inputs: Vec<Input> = (0..5).map(|t| sample(t, json!({"b": true}))).collect();
    inputs.push(loss(5, &["b"]));
    inputs.extend((6..10).map(|t| sample(t, json!({"b": true}))));
    let r = run(&inputs);
    // rec's largest bound is 3: unknown at 5, 6 and 7; judging again from 8.
    assert_eq!(
        of(&r, "rec"),
        [
            v(0, "currently_true"),
            v(5, "unknown"),
            v(8, "currently_true")
        ]
    );
    // seen_b reads b too; its bound is 1 tick (no time bound).
    assert_eq!(
        of(&r, "seen_b"),
        [v(0, "true"), v(5, "unknown"), v(6, "true")]
    );
    // Properties that do not read b are not disturbed.
    assert_eq!(of(&r, "no_c"), [v(0, "currently_true")]);
    assert_eq!(of(&r, "never_neg"), [v(0, "currently_true")]);
}

#[test]
fn a_seen_violation_survives_a_loss() {
    let r = run(&[
        sample(0, json!({"x": 1})),
        sample(1, json!({"x": -1})),
        loss(2, &["x"]),
        sample(3, json!({"x": 1})),
    ]);
    assert_eq!(of(&r, "never_neg"), [v(0, "currently_true"), v(1, "false")]);
    // req_ok reads x as well and was not false: it goes unknown.
    assert_eq!(
        of(&r, "req_ok"),
        [
            v(0, "currently_true"),
            v(2, "unknown"),
            v(3, "currently_true")
        ]
    );
}

#[test]
fn a_late_event_turns_a_recurrence_false_for_good() {
    let r = run(&[
        sample(0, json!({"b": true})),
        Input::Tick { time: 2 },
        Input::Tick { time: 4 },
        sample(5, json!({"b": true})),
    ]);
    assert_eq!(of(&r, "rec"), [v(0, "currently_true"), v(4, "false")]);
    assert_eq!(of(&r, "seen_b"), [v(0, "true")]);
    let r = run(&[Input::Tick { time: 0 }]);
    assert_eq!(of(&r, "seen_b"), [v(0, "currently_false")]);
}

fn request(time: u64, sets: serde_json::Value, filter: bool) -> Input {
    Input::Request {
        time,
        source: "r".into(),
        sets: sets.as_object().unwrap().clone().into_iter().collect(),
        filter: filter.then(|| vec!["req_ok".to_string()]),
    }
}

#[test]
fn filter_refuses_a_falsifying_request_and_leaves_no_trace() {
    let spec = codegen::compile_spec(SPEC, "t.hspec").unwrap();
    let mut e = Engine::new(&spec, false).unwrap();
    let mut out = Vec::new();
    let mut decide = |i: &Input| apply(&spec, &mut e, i, &mut out).unwrap();
    assert_eq!(
        decide(&request(0, json!({"req": true, "x": 3}), true)),
        Some(true)
    );
    assert_eq!(
        decide(&request(1, json!({"req": true, "x": 12}), true)),
        Some(false)
    );
    // The refused request did not set x: this one is judged with x = 3.
    assert_eq!(decide(&request(2, json!({"req": true}), true)), Some(true));
    // `log` never refuses: the same request is judged and falsifies.
    assert_eq!(
        decide(&request(3, json!({"req": true, "x": 12}), false)),
        Some(true)
    );
    let lines: Vec<String> = out.iter().map(|c| verdict_line(&spec, c)).collect();
    let req_ok: Vec<&String> = lines.iter().filter(|l| l.contains("req_ok")).collect();
    assert_eq!(req_ok.len(), 2, "{lines:?}");
    assert!(req_ok[1].contains("\"time\":3") && req_ok[1].contains("\"verdict\":\"false\""));
}

#[test]
fn replay_errors_name_the_line() {
    let spec = codegen::compile_spec(SPEC, "t.hspec").unwrap();
    let log = "{\"kind\":\"tick\",\"time\":0}\n{\"kind\":\"sample\",\"time\":1,\"source\":\"s\",\"sets\":{\"nope\":true}}\n";
    let err = replay(&spec, log, "in.jsonl", false).unwrap_err();
    assert!(
        matches!(
            &err,
            hindsight::live::record::LogError::Record {
                line: 2,
                error: hindsight::live::record::RecordError::UnknownVariable(v),
                ..
            } if v == "nope"
        ),
        "{err:?}"
    );
    let e = err.to_string();
    assert!(
        e.starts_with("in.jsonl:2:1: `nope` is not a variable"),
        "{e}"
    );
    let e = replay(&spec, "{\"kind\":\"tick\"}\n", "in.jsonl", false)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("in.jsonl:1:"), "{e}");
    let e = replay(
        &spec,
        "{\"kind\":\"tick\",\"time\":5}\n{\"kind\":\"tick\",\"time\":4}\n",
        "in.jsonl",
        false,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("in.jsonl:2:1:"), "{e}");
}
