//! The BehaviorTree.CPP semantics on the command line: `--bt` / `--bt-tick` refused where
//! they mean nothing, `validate` warning at the nodes where AS2FM's models and BT.CPP 4
//! differ, and `verify --bt both` reporting both probabilities and the
//! semantics-sensitive properties (table and JSON).

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

/// Fails on its first tick, succeeds on every later one.
const FAIL_ONCE: &str = r#"<ascxml name="FailOnce" initial="first">
  <state id="first">
    <bt_tick target="later"><bt_return_status status="FAILURE"/></bt_tick>
    <bt_halt target="first"><bt_return_halted/></bt_halt>
  </state>
  <state id="later">
    <bt_tick target="later"><bt_return_status status="SUCCESS"/></bt_tick>
    <bt_halt target="later"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

/// A stateful action (it may answer RUNNING, so BT.CPP 4 runs it as a
/// `StatefulActionNode`): RUNNING on its first tick, FAILURE on its second, SUCCESS on
/// every later one.
const SLOW_FAIL_ONCE: &str = r#"<ascxml name="SlowFailOnce" initial="first">
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
      "left": "bt_1000_response__status", "right": 1}}}, "states": {"op": "initial"}}},
  {"name": "tree_failure", "expression": {"op": "filter", "fun": "values",
    "values": {"op": "Pmin", "exp": {"op": "F", "exp": {"op": "=",
      "left": "bt_1000_response__status", "right": 2}}}, "states": {"op": "initial"}}}
]}"#;

/// A scratch model: `tree.xml`, the FailOnce and SlowFailOnce plugins, ticked at 1 Hz for 5 s, again after
/// every answer.
fn scratch(name: &str, tree: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("hindsight-bt-btcpp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tree.xml"), tree).unwrap();
    std::fs::write(dir.join("fail_once.ascxml"), FAIL_ONCE).unwrap();
    std::fs::write(dir.join("slow_fail_once.ascxml"), SLOW_FAIL_ONCE).unwrap();
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
    <input type="bt-plugin-ascxml" src="./slow_fail_once.ascxml"/>
  </behavior_tree>
  <properties><input type="jani" src="./properties.jani"/></properties>
</roaml>"#,
    )
    .unwrap();
    dir
}

fn v4(body: &str) -> String {
    format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n</root>\n"
    )
}

/// 1-based line and column of the first `needle` in `text`.
fn pos(text: &str, needle: &str) -> (usize, usize) {
    let at = text.find(needle).expect("needle in the text");
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = at - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

/// The two-child IfThenElse over a stateful condition that runs, fails once, then
/// succeeds: AS2FM's model ticks the condition again and succeeds; BT.CPP 4 keeps the
/// failed condition's status, and a stateful action answers it again, so the tree never
/// succeeds. (Over FailOnce, which never answers RUNNING and so is synchronous, the two
/// agree: BT.CPP runs it again.)
const STALE: &str = "<IfThenElse>\n  <SlowFailOnce/>\n  <AlwaysSuccess/>\n</IfThenElse>";

#[test]
fn verify_both_reports_both_probabilities_and_the_sensitive_properties() {
    let dir = scratch("both", &v4(STALE));
    let (code, out, err) = hindsight(
        &dir,
        &[
            "verify",
            "main.xml",
            "--bt",
            "both",
            "--json",
            "--max-runs",
            "50",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["bt"], "both");
    let rows = doc["properties"].as_array().unwrap();
    let row = |name: &str| rows.iter().find(|r| r["property"] == name).unwrap();
    let s = row("tree_success");
    assert_eq!(
        (s["as2fm"].as_f64(), s["btcpp"].as_f64()),
        (Some(1.0), Some(0.0))
    );
    assert_eq!(s["semantics_sensitive"], true);
    assert_eq!(s["difference"].as_f64(), Some(-1.0));
    let f = row("tree_failure");
    assert_eq!(
        (f["as2fm"].as_f64(), f["btcpp"].as_f64()),
        (Some(1.0), Some(1.0))
    );
    assert_eq!(f["semantics_sensitive"], false);
    // Each study is there whole, as `verify --json` writes one.
    assert_eq!(doc["as2fm"]["properties"][0]["property"], "tree_success");
    assert_eq!(doc["btcpp"]["settings"][0][1], "btcpp");

    let (code, out, err) = hindsight(
        &dir,
        &["verify", "main.xml", "--bt", "both", "--max-runs", "50"],
    );
    assert_eq!(code, 0, "{err}");
    let line = out.lines().find(|l| l.starts_with("tree_success")).unwrap();
    assert!(
        line.contains("1.0000") && line.contains("0.0000") && line.ends_with("yes"),
        "{out}"
    );
    assert!(
        out.lines()
            .any(|l| l.starts_with("tree_failure") && l.ends_with("no")),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_default_json_is_unchanged_and_btcpp_is_named() {
    let dir = scratch("json", &v4(STALE));
    let (code, out, err) = hindsight(&dir, &["verify", "main.xml", "--json", "--max-runs", "20"]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(
        doc.get("settings").is_none() && doc.get("bt").is_none(),
        "{out}"
    );
    assert_eq!(doc["properties"][0]["probability"].as_f64(), Some(1.0));
    let (code, out, err) = hindsight(
        &dir,
        &[
            "verify",
            "main.xml",
            "--json",
            "--max-runs",
            "20",
            "--bt",
            "btcpp",
            "--bt-tick",
            "exactly-once",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["settings"][0][1], "btcpp-exactly-once");
    assert_eq!(doc["properties"][0]["probability"].as_f64(), Some(0.0));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bt_options_are_refused_where_they_mean_nothing() {
    let dir = scratch("refused", &v4(STALE));
    for (args, words) in [
        (
            &["trace", "main.xml", "--bt", "both"][..],
            "--bt both: only `verify` and `validate`",
        ),
        (
            &["verify", "main.xml", "--bt-tick", "once"][..],
            "--bt-tick: only BehaviorTree.CPP's executor",
        ),
        (
            &[
                "verify", "main.xml", "--bt", "both", "--runs", "10", "--shard", "0/2",
            ][..],
            "--bt both: not with --shard / --plan",
        ),
        (
            &["convert", "main.xml", "--out", "out", "--bt", "both"][..],
            "--bt both: convert writes one model",
        ),
        (
            &["validate", "properties.jani", "--bt", "btcpp"][..],
            "is not a robot model",
        ),
    ] {
        let (code, out, err) = hindsight(&dir, args);
        assert_eq!(code, 2, "{args:?}: {out} {err}");
        assert!(err.contains(words), "{args:?}: expected `{words}` in {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn validate_warns_at_the_nodes_where_the_semantics_differ() {
    let tree = v4("<ReactiveSequence>\n  <FailOnce/>\n  <SequenceWithMemory>\n    <FailOnce/>\n    <Repeat num_cycles=\"3\">\n      <FailOnce/>\n    </Repeat>\n    <Parallel success_count=\"1\" failure_count=\"1\">\n      <FailOnce/>\n      <AlwaysSuccess/>\n    </Parallel>\n    <IfThenElse>\n      <SlowFailOnce/>\n      <AlwaysSuccess/>\n    </IfThenElse>\n  </SequenceWithMemory>\n</ReactiveSequence>");
    let dir = scratch("warn", &tree);
    let (code, out, err) = hindsight(&dir, &["validate", "main.xml"]);
    assert_eq!(code, 0, "{out} {err}");
    for (needle, words) in [
        ("<SequenceWithMemory>", "a wake-up yield"),
        (
            "<SequenceWithMemory>",
            "SequenceWithMemory under a ReactiveSequence (at 3:1)",
        ),
        ("<Repeat", "Repeat: under BehaviorTree.CPP 4"),
        (
            "<Parallel",
            "Parallel: BehaviorTree.CPP 4 does not tick again",
        ),
        ("<IfThenElse>", "IfThenElse with two children"),
    ] {
        let (l, c) = pos(&tree, needle);
        let at = format!("tree.xml:{l}:{c}: ");
        assert!(
            err.lines()
                .any(|x| x.starts_with("warning: ") && x.contains(&at) && x.contains(words)),
            "expected `{at}` ... `{words}` in:\n{err}"
        );
    }
    assert!(err.contains("hindsight verify --bt both"), "{err}");
    // Both lowerings are checked with --bt both.
    let (code, out, err) = hindsight(&dir, &["validate", "main.xml", "--bt", "both"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("(--bt as2fm)") && out.contains("(--bt btcpp)"),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn validate_is_quiet_where_the_semantics_agree() {
    let dir = scratch(
        "quiet",
        &v4("<Sequence>\n  <FailOnce/>\n  <Repeat num_cycles=\"1\">\n    <FailOnce/>\n  </Repeat>\n</Sequence>"),
    );
    let (code, out, err) = hindsight(&dir, &["validate", "main.xml"]);
    assert_eq!(code, 0, "{out} {err}");
    assert!(!err.contains("warning"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn btcpp4_nodes_lower_under_bt_btcpp_and_are_refused_under_as2fm() {
    // RunOnce keeps its child's first answer: FailOnce fails once, so the tree fails on
    // every tick (the child is never ticked again).
    let dir = scratch(
        "btcpp4",
        &v4("<RunOnce then_skip=\"false\">\n  <FailOnce/>\n</RunOnce>"),
    );
    let (code, out, err) = hindsight(
        &dir,
        &[
            "verify",
            "main.xml",
            "--json",
            "--max-runs",
            "20",
            "--bt",
            "btcpp",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["properties"][0]["property"], "tree_success");
    assert_eq!(doc["properties"][0]["probability"].as_f64(), Some(0.0));
    assert_eq!(doc["properties"][1]["probability"].as_f64(), Some(1.0));
    let _ = std::fs::remove_dir_all(&dir);

    // Refused, each at its place: the node under AS2FM's rules, bad ports under BT.CPP's.
    for (name, bt, tree, needle, words) in [
        (
            "as2fm",
            "as2fm",
            "<Sequence>\n  <WhileDoElse>\n    <FailOnce/>\n    <AlwaysSuccess/>\n  </WhileDoElse>\n</Sequence>",
            "<WhileDoElse>",
            "`WhileDoElse` is a BehaviorTree.CPP 4 node that AS2FM has no model of",
        ),
        (
            "skip",
            "btcpp",
            "<BlackboardCheckInt value_A=\"{k}\" value_B=\"1\">\n  <RunOnce>\n    <FailOnce/>\n  </RunOnce>\n</BlackboardCheckInt>",
            "<RunOnce>",
            "its parent, a BlackboardCheck, is a BehaviorTree.CPP 3 node",
        ),
        (
            "case",
            "btcpp",
            "<Sequence>\n  <SetBlackboard output_key=\"mode\" value=\"a\"/>\n  <Switch2 variable=\"{mode}\" case_1=\"1\" case_2=\"b\">\n    <FailOnce/>\n    <FailOnce/>\n    <AlwaysSuccess/>\n  </Switch2>\n</Sequence>",
            "1\" case_2",
            "`case_1` of Switch2 is the number `1`",
        ),
        (
            "failures",
            "btcpp",
            "<ParallelAll max_failures=\"3\">\n  <FailOnce/>\n  <AlwaysSuccess/>\n</ParallelAll>",
            "3\">",
            "`max_failures` 3 is more than the 2 children",
        ),
    ] {
        let tree = v4(tree);
        let dir = scratch(name, &tree);
        let (code, out, err) = hindsight(&dir, &["validate", "main.xml", "--bt", bt]);
        assert_eq!(code, 2, "{name}: {out} {err}");
        let (l, c) = pos(&tree, needle);
        let at = format!("tree.xml:{l}:{c}: ");
        assert!(
            err.lines().any(|x| x.contains(&at) && x.contains(words)),
            "{name}: expected `{at}` ... `{words}` in:\n{err}"
        );
        if bt == "as2fm" {
            assert!(err.contains("use `--bt btcpp`"), "{err}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn scripts_and_conditions_lower_under_bt_btcpp_and_are_refused_under_as2fm() {
    // Every tick: `failures := 0`; FailOnce fails on the first tick only, its
    // `_onFailure` counts it, and AlwaysFailure's `_successIf` then answers SUCCESS
    // without ticking it: the tree succeeds on every tick and never fails. Without the
    // post-condition the `_successIf` script would read an entry that holds no value
    // (BT.CPP throws) and the tree would stop.
    let tree = v4("<Sequence>\n  <Script code=\"failures := 0\"/>\n  <Fallback>\n    <FailOnce _onFailure=\"failures += 1\"/>\n    <AlwaysFailure _successIf=\"failures == 1\"/>\n  </Fallback>\n</Sequence>");
    let dir = scratch("script", &tree);
    let (code, out, err) = hindsight(
        &dir,
        &[
            "verify",
            "main.xml",
            "--json",
            "--max-runs",
            "20",
            "--bt",
            "btcpp",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["properties"][0]["property"], "tree_success");
    assert_eq!(doc["properties"][0]["probability"].as_f64(), Some(1.0));
    assert_eq!(doc["properties"][1]["probability"].as_f64(), Some(0.0));
    let _ = std::fs::remove_dir_all(&dir);

    // Refused, each at its place: the script nodes and conditions under AS2FM's rules,
    // what BT.CPP's lowering does not model yet under BT.CPP's.
    for (name, bt, tree, needle, words) in [
        (
            "as2fm-script",
            "as2fm",
            "<Sequence>\n  <Script code=\"x := 1\"/>\n  <FailOnce/>\n</Sequence>",
            "<Script",
            "`Script` is a BehaviorTree.CPP 4 node that AS2FM has no model of",
        ),
        (
            "as2fm-cond",
            "as2fm",
            "<Sequence>\n  <FailOnce _skipIf=\"true\"/>\n</Sequence>",
            "_skipIf",
            "`_skipIf` (a BehaviorTree.CPP 4 pre/post condition) is not supported: AS2FM has no model",
        ),
        (
            "skip",
            "btcpp",
            "<BlackboardCheckInt value_A=\"{k}\" value_B=\"1\">\n  <FailOnce _skipIf=\"true\"/>\n</BlackboardCheckInt>",
            "<FailOnce _skipIf",
            "its parent, a BlackboardCheck, is a BehaviorTree.CPP 3 node",
        ),
        (
            "string",
            "btcpp",
            "<Sequence>\n  <Script code=\"msg := 'hi'\"/>\n  <Script code=\"msg := msg .. '!'\"/>\n</Sequence>",
            "msg := msg .. '!'",
            "the texts `msg` can hold do not settle",
        ),
        (
            "text",
            "btcpp",
            "<Sequence>\n  <SetBlackboard output_key=\"n\" value=\"1\"/>\n  <Script code=\"n += 1\"/>\n</Sequence>",
            "n += 1",
            "a script writing `n`, which a SetBlackboard writes",
        ),
        (
            "else",
            "btcpp",
            "<Precondition if=\"true\" else=\"IDLE\">\n  <FailOnce/>\n</Precondition>",
            "IDLE\"",
            "`IDLE` is not SUCCESS, FAILURE, RUNNING or SKIPPED",
        ),
        (
            "stale",
            "btcpp",
            "<BlackboardCheckInt value_A=\"{k}\" value_B=\"1\">\n  <FailOnce _onFailure=\"x := 1\"/>\n</BlackboardCheckInt>",
            "_onFailure",
            "no BehaviorTree.CPP runs this tree",
        ),
    ] {
        let tree = v4(tree);
        let dir = scratch(name, &tree);
        let (code, out, err) = hindsight(&dir, &["validate", "main.xml", "--bt", bt]);
        assert_eq!(code, 2, "{name}: {out} {err}");
        let (l, c) = pos(&tree, needle);
        let at = format!("tree.xml:{l}:{c}: ");
        assert!(
            err.lines().any(|x| x.contains(&at) && x.contains(words)),
            "{name}: expected `{at}` ... `{words}` in:\n{err}"
        );
        if bt == "as2fm" {
            assert!(err.contains("`--bt btcpp`"), "{err}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// A leaf whose `string` input port `message` it reads: SUCCESS on `hello`, else FAILURE.
const SAY: &str = r#"<ascxml name="Say" initial="s">
  <bt_declare_port_in key="message" type="string"/>
  <datamodel><data id="m" type="string" expr="''"/></datamodel>
  <state id="s">
    <bt_tick target="s">
      <assign location="m"><expr><bt_get_input key="message"/></expr></assign>
      <if cond="m == 'hello'"><bt_return_status status="SUCCESS"/>
      <else/><bt_return_status status="FAILURE"/></if>
    </bt_tick>
  </state>
</ascxml>"#;

#[test]
fn a_script_sets_the_text_a_plugin_reads_under_btcpp() {
    // The script sets an action's parameter, the plugin reads it (`getInput<std::string>`);
    // `=` too, as the port created the entry when the tree was loaded.
    for (code, p) in [
        ("msg := 'hello'", 1.0),
        ("msg := 'bye'", 0.0),
        ("msg = 'hel'; msg += 'lo'", 1.0),
        ("n := 2; msg := n &gt; 1 ? 'hello' : 'bye'", 1.0),
    ] {
        let tree = v4(&format!(
            "<Sequence><Script code=\"{code}\"/><Say message=\"{{msg}}\"/></Sequence>"
        ));
        let dir = scratch("say", &tree);
        std::fs::write(dir.join("say.ascxml"), SAY).unwrap();
        let main = std::fs::read_to_string(dir.join("main.xml"))
            .unwrap()
            .replace(
                "<input type=\"bt-plugin-ascxml\" src=\"./fail_once.ascxml\"/>",
                "<input type=\"bt-plugin-ascxml\" src=\"./say.ascxml\"/>",
            );
        std::fs::write(dir.join("main.xml"), main).unwrap();
        let (code_, out, err) = hindsight(
            &dir,
            &[
                "verify", "main.xml", "--bt", "btcpp", "--json", "--runs", "20",
            ],
        );
        assert_eq!(code_, 0, "{code}: {err}");
        let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
        let rows = doc["properties"].as_array().unwrap();
        let s = rows
            .iter()
            .find(|r| r["property"] == "tree_success")
            .unwrap();
        assert_eq!(s["probability"].as_f64(), Some(p), "{code}: {s}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn btcpp_warns_where_bt_cpp_4_would_not_load_the_tree() {
    let tree = "<root BTCPP_format=\"3\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n<SequenceStar><SetBlackboard output_key=\"n\" value=\"1\"/><BlackboardCheckInt value_A=\"{n}\" value_B=\"1\"><FailOnce/></BlackboardCheckInt></SequenceStar>\n</BehaviorTree>\n</root>\n";
    let dir = scratch("v3warn", tree);
    let (code, _, err) = hindsight(
        &dir,
        &["verify", "main.xml", "--bt", "btcpp", "--runs", "5"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: tree.xml:1:1: `--bt btcpp` runs this BTCPP_format 3 tree")
            && err.contains("warning: tree.xml:3:56: BlackboardCheckInt: BehaviorTree.CPP 4 does not register this BehaviorTree.CPP 3 node"),
        "{err}"
    );
    // AS2FM's semantics models the tree as written: nothing to warn about.
    let (code, _, err) = hindsight(&dir, &["verify", "main.xml", "--runs", "5"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
