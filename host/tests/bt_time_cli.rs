//! BT.CPP 4's timed nodes on the command line: `verify --bt btcpp` on small robot models
//! whose verdicts depend on a Delay's or a Timeout's duration (the timers fire in model
//! time, kept by the root machine: `crates/robot/src/bt/btcpp4_time.rs`), and their
//! refusals under the default semantics and for durations the clock cannot time.

use std::path::{Path, PathBuf};
use std::process::Command;

fn hindsight(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run hindsight");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Answers RUNNING to every tick.
const RUN: &str = r#"<ascxml name="Run" initial="s">
  <state id="s">
    <bt_tick target="s"><bt_return_status status="RUNNING"/></bt_tick>
    <bt_halt target="s"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

const PROPS: &str = r#"{"properties": [
  {"name": "tree_success", "expression": {"op": "filter", "fun": "values",
    "values": {"op": "Pmin", "exp": {"op": "F", "exp": {"op": "=",
      "left": "bt_1000_response__status", "right": 1}}}, "states": {"op": "initial"}}},
  {"name": "tree_failure", "expression": {"op": "filter", "fun": "values",
    "values": {"op": "Pmin", "exp": {"op": "F", "exp": {"op": "=",
      "left": "bt_1000_response__status", "right": 2}}}, "states": {"op": "initial"}}}
]}"#;

/// A scratch model: `body` as the tree, the Run plugin, ticked at 1 Hz (first tick at
/// 1 s) for 5 s.
fn scratch(name: &str, body: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-bt-time-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let tree = format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n</root>\n"
    );
    std::fs::write(dir.join("tree.xml"), tree).unwrap();
    std::fs::write(dir.join("run.ascxml"), RUN).unwrap();
    std::fs::write(dir.join("properties.jani"), PROPS).unwrap();
    std::fs::write(
        dir.join("main.xml"),
        r#"<roaml>
  <parameters>
    <max_time value="5" unit="s"/>
    <bt_tick_rate value="1.0"/>
    <bt_tick_if_not_running value="false"/>
  </parameters>
  <behavior_tree>
    <input type="bt.cpp-xml" src="./tree.xml"/>
    <input type="bt-plugin-ascxml" src="./run.ascxml"/>
  </behavior_tree>
  <properties><input type="jani" src="./properties.jani"/></properties>
</roaml>"#,
    )
    .unwrap();
    dir
}

/// `(P(tree_success), P(tree_failure))` under `--bt btcpp` (`bt_tick` the tick mode).
fn verify(dir: &Path, tick: &str) -> (f64, f64) {
    let (code, out, err) = hindsight(
        dir,
        &[
            "verify",
            "main.xml",
            "--bt",
            "btcpp",
            "--bt-tick",
            tick,
            "--max-runs",
            "20",
            "--json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let p = |i: usize| {
        doc["properties"][i]["probability"]
            .as_f64()
            .unwrap_or_else(|| panic!("no probability {i} in {out}"))
    };
    (p(0), p(1))
}

#[test]
fn a_delay_succeeds_within_the_run_only_if_it_is_short_enough() {
    // Started by the tick at 1 s: 3.5 s fires at 4.5 s and the tick at 5 s (the run's
    // last instant) ticks AlwaysSuccess; 4.5 s would fire at 5.5 s, after the run.
    for tick in ["once", "exactly-once"] {
        let dir = scratch(
            "delay_short",
            "<Delay delay_msec=\"3500\">\n<AlwaysSuccess/>\n</Delay>",
        );
        assert_eq!(verify(&dir, tick), (1.0, 0.0), "3.5 s, {tick}");
        let _ = std::fs::remove_dir_all(&dir);
        let dir = scratch(
            "delay_long",
            "<Delay delay_msec=\"4500\">\n<AlwaysSuccess/>\n</Delay>",
        );
        assert_eq!(verify(&dir, tick), (0.0, 0.0), "4.5 s, {tick}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn a_timeout_fails_a_running_child_once_its_time_is_up() {
    // Run never finishes: a 2.5 s Timeout started at 1 s halts it at 3.5 s and the tick
    // at 4 s answers FAILURE; one of 4.5 s would fire after the run.
    let dir = scratch(
        "timeout_short",
        "<Timeout msec=\"2500\">\n<Run/>\n</Timeout>",
    );
    assert_eq!(verify(&dir, "once"), (0.0, 1.0));
    let _ = std::fs::remove_dir_all(&dir);
    let dir = scratch(
        "timeout_long",
        "<Timeout msec=\"4500\">\n<Run/>\n</Timeout>",
    );
    assert_eq!(verify(&dir, "once"), (0.0, 0.0));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn timed_nodes_are_refused_by_the_default_semantics_and_checked_under_btcpp() {
    let body = "<Sleep msec=\"1500\"/>";
    let dir = scratch("refused", body);
    let (code, _, err) = hindsight(&dir, &["validate", "main.xml"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "tree.xml:3:1: `Sleep` is a BehaviorTree.CPP 4 node that AS2FM has no model of"
        ) && err.contains("use `--bt btcpp`"),
        "{err}"
    );
    let (code, _, err) = hindsight(&dir, &["validate", "main.xml", "--bt", "btcpp"]);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
    // A duration that is not a whole number of milliseconds, at the attribute.
    let dir = scratch("bad_msec", "<Sleep msec=\"1.5\"/>");
    let (code, _, err) = hindsight(&dir, &["validate", "main.xml", "--bt", "btcpp"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("tree.xml:3:14: `msec` must be a whole number of milliseconds"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    // A clock of more than 1000 events per tick period: a period of 2^20 ns (953.674...
    // Hz) shares only 64 ns with 1 ms.
    let dir = scratch("fine", "<Sleep msec=\"1\"/>");
    let main = std::fs::read_to_string(dir.join("main.xml")).unwrap();
    std::fs::write(
        dir.join("main.xml"),
        main.replace(
            "<bt_tick_rate value=\"1.0\"/>",
            "<bt_tick_rate value=\"953.67431640625\"/>",
        ),
    )
    .unwrap();
    let (code, _, err) = hindsight(&dir, &["validate", "main.xml", "--bt", "btcpp"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("tree.xml:3:1: hindsight times the tree's timers"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
