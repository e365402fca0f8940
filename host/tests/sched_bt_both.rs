//! `verify --bt both --schedulers N`: the bounds over schedulers under each semantics, on
//! a tree whose outcome the two semantics decide differently and no order changes
//! (the IfThenElse over a condition that fails once, as in `bt_btcpp_cli.rs`).

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

/// Runs on its first tick, fails on its second, succeeds on every later one.
const FAIL_ONCE: &str = r#"<ascxml name="FailOnce" initial="first">
  <state id="first">
    <bt_tick target="second"><bt_return_status status="RUNNING"/></bt_tick>
    <bt_halt target="first"><bt_return_halted/></bt_halt>
  </state>
  <state id="second">
    <bt_tick target="later"><bt_return_status status="FAILURE"/></bt_tick>
    <bt_halt target="first"><bt_return_halted/></bt_halt>
  </state>
  <state id="later">
    <bt_tick target="later"><bt_return_status status="SUCCESS"/></bt_tick>
    <bt_halt target="later"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

const PROPS: &str = r#"{"properties": [
  {"name": "tree_success", "expression": {"op": "filter", "fun": "values",
    "values": {"op": "Pmin", "exp": {"op": "F", "exp": {"op": "=",
      "left": "bt_1000_response__status", "right": 1}}}, "states": {"op": "initial"}}}
]}"#;

const TREE: &str = "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree \
                    ID=\"Main\">\n<IfThenElse>\n  <FailOnce/>\n  <AlwaysSuccess/>\n</IfThenElse>\
                    \n</BehaviorTree>\n</root>\n";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "hindsight-sched-bt-both-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tree.xml"), TREE).unwrap();
    std::fs::write(dir.join("fail_once.ascxml"), FAIL_ONCE).unwrap();
    std::fs::write(dir.join("properties.jani"), PROPS).unwrap();
    std::fs::write(
        dir.join("main.xml"),
        r#"<roaml>
  <parameters>
    <max_time value="5" unit="s"/>
    <bt_tick_rate value="1.0"/>
    <bt_tick_if_not_running value="true"/>
  </parameters>
  <behavior_tree>
    <input type="bt.cpp-xml" src="./tree.xml"/>
    <input type="bt-plugin-ascxml" src="./fail_once.ascxml"/>
  </behavior_tree>
  <properties><input type="jani" src="./properties.jani"/></properties>
</roaml>"#,
    )
    .unwrap();
    dir
}

/// The study both tests run: `verify --bt both` over 4 sampled schedulers.
const STUDY: [&str; 10] = [
    "verify",
    "main.xml",
    "--bt",
    "both",
    "--schedulers",
    "4",
    "--selection-runs",
    "2",
    "--precision",
    "0.05",
];

#[test]
fn bt_both_bounds_each_semantics_over_the_same_schedulers() {
    let dir = scratch("bounds");
    let mut args = STUDY.to_vec();
    args.extend(["--threads", "2"]);
    let mut json = args.clone();
    json.push("--json");
    let (code, out, err) = hindsight(&dir, &json);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    // AS2FM's IfThenElse succeeds at the third tick, BT.CPP 4's never (FailOnce may
    // answer RUNNING, so it is a stateful action that keeps its FAILURE): under every
    // scheduler, so min = max and nothing is order-sensitive.
    for (semantics, p) in [("as2fm", 1.0), ("btcpp", 0.0)] {
        let s = &doc[semantics]["properties"][0]["schedulers"];
        assert_eq!(s["sampled"], 4, "{semantics}: {s}");
        assert_eq!(s["min"]["probability"], p, "{semantics}: {s}");
        assert_eq!(s["max"]["probability"], p, "{semantics}: {s}");
        assert_eq!(s["order_sensitive"], false);
    }
    let (code, table, err) = hindsight(&dir, &args);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 0, "{err}");
    assert!(table.contains("--bt as2fm:"), "{table}");
    assert!(table.contains("--bt btcpp:"), "{table}");
    assert_eq!(table.matches("bounds over 4 sampled").count(), 2, "{table}");
}

#[test]
fn report_shows_one_study_of_bt_both_and_replays_it_under_its_semantics() {
    let dir = scratch("report");
    let mut json = STUDY.to_vec();
    json.push("--json");
    let (code, out, err) = hindsight(&dir, &json);
    assert_eq!(code, 0, "{err}");
    std::fs::write(dir.join("both.json"), &out).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["btcpp"]["replay"]["bt"], "btcpp", "{doc}");
    let witness = doc["btcpp"]["properties"][0]["schedulers"]["min"]["scheduler"]
        .as_str()
        .unwrap()
        .to_string();
    let report = |extra: &[&str]| {
        let mut args = vec!["report", "--study", "both.json", "-o", "page.html"];
        args.extend_from_slice(extra);
        hindsight(&dir, &args)
    };
    // Two studies: one must be named.
    let (code, _, err) = report(&[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("give --bt as2fm or --bt btcpp"), "{err}");
    // The BT.CPP study fails in every run, and its replay runs under BT.CPP's rules: under
    // AS2FM's the same tree succeeds at the third tick, so a failing run shows only if
    // the recorded semantics were used.
    let (code, _, err) = report(&["--bt", "btcpp", "--scheduler", &witness]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(dir.join("page.html")).unwrap();
    let property = doc["btcpp"]["properties"][0]["property"].as_str().unwrap();
    assert!(
        html.contains(&format!("{property} under the scheduler {witness}, run 0")),
        "{err}"
    );
    assert!(html.contains(&format!("{property} under the uniform scheduler, run 0")));
    // The AS2FM study saw no failure: nothing to replay, and it says so.
    let (code, _, err) = report(&["--bt", "as2fm", "--scheduler", &witness]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("no run to show"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `--bt both --runs N`: a fixed-size study under each semantics, each the study `--bt
/// as2fm --runs N` / `--bt btcpp --runs N` makes alone, and the property flagged
/// semantics-sensitive (AS2FM's IfThenElse succeeds, BT.CPP 4's never does).
#[test]
fn bt_both_takes_a_fixed_number_of_runs() {
    let dir = scratch("runs");
    let base = [
        "verify", "main.xml", "--runs", "30", "--seed", "4", "--json",
    ];
    let (code, out, err) = hindsight(&dir, &[&base[..], &["--bt", "both"]].concat());
    assert_eq!(code, 0, "{err}");
    let both: serde_json::Value = serde_json::from_str(&out).unwrap();
    let strip = |mut v: serde_json::Value| {
        v["seconds"] = serde_json::Value::Null;
        v
    };
    for semantics in ["as2fm", "btcpp"] {
        let (code, out, err) = hindsight(&dir, &[&base[..], &["--bt", semantics]].concat());
        assert_eq!(code, 0, "{err}");
        let alone: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(alone["runs"], 30, "{alone}");
        assert_eq!(strip(both[semantics].clone()), strip(alone), "{semantics}");
    }
    let row = &both["properties"][0];
    assert_eq!(row["as2fm"], 1.0, "{row}");
    assert_eq!(row["btcpp"], 0.0, "{row}");
    assert_eq!(row["semantics_sensitive"], true, "{row}");
    // A shard of it is refused: `merge` would not know which semantics a part was.
    let (code, _, err) = hindsight(
        &dir,
        &[&base[..], &["--bt", "both", "--shard", "0/2"]].concat(),
    );
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--bt both: not with --shard / --plan"),
        "{err}"
    );
}
