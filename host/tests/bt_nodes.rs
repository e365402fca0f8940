//! The behavior-tree node set and both tree formats: BTCPP_format 3 and 4, SetBlackboard
//! and the BlackboardCheck nodes with their entry types, statuses as names or AS2FM's
//! numbers, and bad trees refused with file:line:col (through the library and the
//! `hindsight` command, exit code 2).

use hindsight::verify::model::source::SourceMap;
use hindsight::verify::model::Diagnostics;
use hindsight::verify::robot::bt::{self, BtInput, Halts};
use hindsight::verify::robot::write;
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

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bt")
        .join(rel)
}

/// A leaf that succeeds with probability 0.7.
const ATTEMPT: &str = r#"<ascxml name="Attempt" initial="idle">
  <state id="idle">
    <bt_tick>
      <target id="idle" prob="0.7"><bt_return_status status="SUCCESS"/></target>
      <target id="idle" prob="0.3"><bt_return_status status="FAILURE"/></target>
    </bt_tick>
    <bt_halt target="idle"><bt_return_halted/></bt_halt>
  </state>
</ascxml>"#;

/// A leaf that answers RUNNING until halted, and counts its halts on no topic: halting
/// it is visible only as the `bt_<id>_halt` event.
const RUN: &str = r#"<ascxml name="Run" initial="idle">
  <state id="idle">
    <bt_tick target="idle"><bt_return_status status="RUNNING"/></bt_tick>
    <bt_halt target="idle"><bt_return_halted/></bt_halt>
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

/// A scratch model: `tree.xml` (the text given), the Attempt and Run plugins, a main file
/// ticking at 1 Hz for 10 s without ticking again after an answer, and PROPS.
fn scratch_model(name: &str, tree: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("hindsight-bt-nodes-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("tree.xml"), tree).unwrap();
    std::fs::write(dir.join("attempt.ascxml"), ATTEMPT).unwrap();
    std::fs::write(dir.join("run.ascxml"), RUN).unwrap();
    std::fs::write(dir.join("properties.jani"), PROPS).unwrap();
    std::fs::write(
        dir.join("main.xml"),
        r#"<roaml>
  <parameters>
    <max_time value="10" unit="s"/>
    <bt_tick_rate value="1.0"/>
    <bt_tick_if_not_running value="false"/>
  </parameters>
  <behavior_tree>
    <input type="bt.cpp-xml" src="./tree.xml"/>
    <input type="bt-plugin-ascxml" src="./attempt.ascxml"/>
    <input type="bt-plugin-ascxml" src="./run.ascxml"/>
  </behavior_tree>
  <properties><input type="jani" src="./properties.jani"/></properties>
</roaml>"#,
    )
    .unwrap();
    dir
}

/// `(P(tree answers SUCCESS), P(tree answers FAILURE))` over `runs` runs.
fn verify(dir: &Path, runs: u32) -> (f64, f64) {
    let (code, out, err) = hindsight(
        dir,
        &[
            "verify",
            "main.xml",
            "--seed",
            "3",
            "--max-runs",
            &runs.to_string(),
            "--json",
        ],
    );
    assert_eq!(code, 0, "{}: {err}", dir.display());
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let p = |i: usize| doc["properties"][i]["probability"].as_f64().unwrap();
    (p(0), p(1))
}

/// `hindsight validate` of a tree expected to be refused: exit code 2, and stderr names
/// `tree.xml:<line>:<col>` of `needle` (its first occurrence) with `words` in the message.
fn refused(name: &str, tree: &str, needle: &str, words: &str) {
    let dir = scratch_model(name, tree);
    let (code, out, err) = hindsight(&dir, &["validate", "main.xml"]);
    assert_eq!(code, 2, "{name}: exit code; stdout {out} stderr {err}");
    let (line, col) = pos(tree, needle);
    let at = format!("tree.xml:{line}:{col}: ");
    assert!(
        err.lines().any(|l| l.contains(&at) && l.contains(words)),
        "{name}: expected `{at}` ... `{words}` in:\n{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// 1-based line and column of the first `needle` in `text`.
fn pos(text: &str, needle: &str) -> (usize, usize) {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("`{needle}` in the text"));
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let col = at - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

fn v3(body: &str) -> String {
    format!("<root BTCPP_format=\"3\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n</root>\n")
}

fn v4(body: &str) -> String {
    format!(
        "<root BTCPP_format=\"4\" main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{body}\n</BehaviorTree>\n</root>\n"
    )
}

/// The machines of `tree` (plugins Attempt and Run) as XML texts, or the errors.
fn lower(tree: &str) -> Result<Vec<String>, String> {
    lower_with(tree, Halts::As2fm)
}

fn lower_with(tree: &str, halts: Halts) -> Result<Vec<String>, String> {
    let mut sm = SourceMap::new();
    let t = sm.add("tree.xml", tree.to_string());
    let plugins = vec![
        sm.add("attempt.ascxml", ATTEMPT.to_string()),
        sm.add("run.ascxml", RUN.to_string()),
    ];
    bt::lower(
        &sm,
        &BtInput {
            tree: t,
            plugins,
            tick_rate_hz: 1.0,
            tick_if_not_running: false,
            halts,
            semantics: Default::default(),
        },
    )
    .map(|ms| ms.iter().map(write::to_xml).collect())
    .map_err(|ds| Diagnostics(ds).to_string())
}

#[test]
fn the_format_3_mission_verifies_to_the_probability_worked_out_by_hand() {
    // host/tests/data/bt/format3_mission: a SequenceStar sets {mission_stage} to 0, a
    // Fallback either runs Attempt (SUCCESS with probability 0.7) and sets the stage to 1,
    // or (Attempt failed, 0.3) sets it to 10; then BlackboardCheckInt compares the stage
    // with 1: equal ticks AlwaysFailure (the tree fails), different answers
    // return_on_mismatch="1", AS2FM's number for SUCCESS. So the tree succeeds exactly
    // when Attempt fails: 0.3, and fails with 0.7, at the first tick (the root is ticked
    // once). Read as BT.CPP's enum, 1 would be RUNNING, and the tree would never succeed.
    let dir = data("format3_mission");
    let (ok, fail) = verify(&dir, 4000);
    // 4000 runs: the standard error is 0.0072; 0.03 is four of them.
    assert!((ok - 0.3).abs() < 0.03, "success {ok}");
    assert!((fail - 0.7).abs() < 0.03, "failure {fail}");
    assert!(
        (ok + fail - 1.0).abs() < 1e-9,
        "every run answers once: {ok} + {fail}"
    );
}

#[test]
fn the_format_3_mission_types_its_entries_from_what_is_written() {
    let tree = std::fs::read_to_string(data("format3_mission/mission.xml")).unwrap();
    let ms = lower(&tree).unwrap_or_else(|e| panic!("{e}"));
    let bb = ms
        .iter()
        .find(|m| m.contains("name=\"bt_blackboard_fsm\""))
        .expect("a blackboard machine");
    // {mission_stage}: read by BlackboardCheckInt (int32) and written 0, 1, 10;
    // {progress}: only written, 2.5, so a float.
    assert!(bb.contains("TYPE mission_stage:int32"), "{bb}");
    assert!(bb.contains("TYPE progress:float64"), "{bb}");
    // Both spellings of output_key write the same entry.
    let writes = ms
        .iter()
        .filter(|m| m.contains("bt_blackboard_set_mission_stage"))
        .count();
    assert_eq!(writes, 4, "three SetBlackboard nodes and the blackboard");
}

#[test]
fn return_on_mismatch_takes_names_and_as2fm_numbers() {
    let tree = |s: &str| {
        v3(&format!(
            "<BlackboardCheckInt value_A=\"1\" value_B=\"2\" {s}><Attempt/></BlackboardCheckInt>"
        ))
    };
    for (name, number) in [("SUCCESS", "1"), ("FAILURE", "2"), ("RUNNING", "3")] {
        let a = lower(&tree(&format!("return_on_mismatch=\"{name}\""))).unwrap();
        let b = lower(&tree(&format!("return_on_mismatch=\"{number}\""))).unwrap();
        assert_eq!(a, b, "{name} and {number}");
    }
    // BT.CPP's default is FAILURE.
    assert_eq!(
        lower(&tree("")).unwrap(),
        lower(&tree("return_on_mismatch=\"FAILURE\"")).unwrap()
    );
    // The status a mismatch answers, as sent.
    let ms = lower(&tree("return_on_mismatch=\"3\"")).unwrap();
    assert!(ms[1].contains("name=\"status\" expr=\"3\""), "{}", ms[1]);
}

#[test]
fn statuses_that_are_not_statuses_are_refused() {
    for (i, bad) in ["0", "4", "IDLE", "SKIPPED", "Success", "-1"]
        .iter()
        .enumerate()
    {
        let t = v3(&format!(
            "<BlackboardCheckInt value_A=\"1\" value_B=\"1\" return_on_mismatch=\"{bad}\">\n<AlwaysSuccess/>\n</BlackboardCheckInt>"
        ));
        refused(
            &format!("status{i}"),
            &t,
            &format!("{bad}\""),
            "return_on_mismatch",
        );
    }
}

#[test]
fn a_mismatch_halts_the_child_before_answering_as_as2fm_does() {
    let t = v3("<BlackboardCheckInt value_A=\"1\" value_B=\"2\" return_on_mismatch=\"SUCCESS\"><Run/></BlackboardCheckInt>");
    let ms = lower(&t).unwrap();
    let check = &ms[1];
    let mismatch = check
        .split("<state id=\"value_mismatch\">")
        .nth(1)
        .expect("a value_mismatch state");
    let halt = mismatch.find("bt_1001_halt\"").expect("halts the child");
    let answer = mismatch.find("bt_1000_response").expect("then answers");
    assert!(halt < answer, "{check}");
    // BT.CPP halts the child only if that can change something (`haltChild` while it
    // runs): with Halts::WhenNeeded a child whose halt never matters is not halted ...
    let t =
        v3("<BlackboardCheckInt value_A=\"1\" value_B=\"2\"><AlwaysSuccess/></BlackboardCheckInt>");
    let ms = lower_with(&t, Halts::WhenNeeded).unwrap();
    assert!(!ms[1].contains("value_mismatch"), "{}", ms[1]);
    let exec = ms[1]
        .split("<state id=\"exec_tick\">")
        .nth(1)
        .and_then(|r| r.split("</state>").next())
        .expect("an exec_tick state");
    assert!(
        exec.contains("bt_1000_response") && !exec.contains("_halt"),
        "{exec}"
    );
    // ... and one with halt code still is.
    let ms = lower_with(&t.replace("AlwaysSuccess", "Run"), Halts::WhenNeeded).unwrap();
    assert!(ms[1].contains("<state id=\"value_mismatch\">"), "{}", ms[1]);
}

#[test]
fn blackboard_checks_compare_as_behaviortree_cpp_does() {
    let cases = [
        // Int, with the entry written by SetBlackboard.
        ("int_eq", "<SetBlackboard output_key=\"n\" value=\"10\"/><BlackboardCheckInt value_A=\"{n}\" value_B=\"10\"><AlwaysSuccess/></BlackboardCheckInt>", 1.0),
        ("int_ne", "<SetBlackboard output_key=\"n\" value=\"10\"/><BlackboardCheckInt value_A=\"{n}\" value_B=\"1\"><AlwaysSuccess/></BlackboardCheckInt>", 0.0),
        // Double: equal within float epsilon (2^-23), not beyond.
        ("double_eps", "<SetBlackboard output_key=\"d\" value=\"0.1\"/><BlackboardCheckDouble value_A=\"{d}\" value_B=\"0.10000005\"><AlwaysSuccess/></BlackboardCheckDouble>", 1.0),
        ("double_ne", "<SetBlackboard output_key=\"d\" value=\"0.1\"/><BlackboardCheckDouble value_A=\"{d}\" value_B=\"0.1001\"><AlwaysSuccess/></BlackboardCheckDouble>", 0.0),
        ("string_eq", "<SetBlackboard output_key=\"s\" value=\"hello\"/><BlackboardCheckString value_A=\"{s}\" value_B=\"hello\"><AlwaysSuccess/></BlackboardCheckString>", 1.0),
        ("string_ne", "<SetBlackboard output_key=\"s\" value=\"hello\"/><BlackboardCheckString value_A=\"world\" value_B=\"{s}\"><AlwaysSuccess/></BlackboardCheckString>", 0.0),
        ("bool_eq", "<SetBlackboard output_key=\"b\" value=\"true\"/><BlackboardCheckBool value_A=\"{b}\" value_B=\"true\"><AlwaysSuccess/></BlackboardCheckBool>", 1.0),
        // A copy has its source's value.
        ("copy", "<SetBlackboard output_key=\"a\" value=\"5\"/><SetBlackboard output_key=\"b\" value=\"{a}\"/><BlackboardCheckInt value_A=\"{b}\" value_B=\"5\"><AlwaysSuccess/></BlackboardCheckInt>", 1.0),
        // Matching ticks the child and answers as it does.
        ("child", "<SetBlackboard output_key=\"n\" value=\"1\"/><BlackboardCheckInt value_A=\"{n}\" value_B=\"1\" return_on_mismatch=\"SUCCESS\"><AlwaysFailure/></BlackboardCheckInt>", 0.0),
    ];
    for (name, body, success) in cases {
        let dir = scratch_model(name, &v3(&format!("<SequenceStar>{body}</SequenceStar>")));
        let (ok, fail) = verify(&dir, 5);
        assert_eq!((ok, fail), (success, 1.0 - success), "{name}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn format_3_subtrees_remap_by_entry_name_and_format_4_by_braces() {
    let writes = |tree: &str, entry: &str| {
        let ms = lower(tree).unwrap_or_else(|e| panic!("{e}"));
        ms.iter().any(|m| {
            m.contains("BT_plugin_") && m.contains(&format!("bt_blackboard_set_{entry}\""))
        })
    };
    let sub = "<BehaviorTree ID=\"Sub\">\n<SetBlackboard output_key=\"param\" value=\"3\"/>\n</BehaviorTree>\n";
    let with_sub = |format: &str, call: &str| {
        format!("<root {format} main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n{call}\n</BehaviorTree>\n{sub}</root>\n")
    };
    // Format 3: `param="outer"` is the caller's entry `outer` (BT.CPP 3.8
    // gtest_subtree.cpp, SubTree.SiblingPorts_Issue_72).
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"3\"",
            "<SubTree ID=\"Sub\" param=\"outer\"/>"
        ),
        "outer"
    ));
    // ... and SubTreePlus reads braces, as format 4's SubTree does.
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"3\"",
            "<SubTreePlus ID=\"Sub\" param=\"{outer}\"/>"
        ),
        "outer"
    ));
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"4\"",
            "<SubTree ID=\"Sub\" param=\"{outer}\"/>"
        ),
        "outer"
    ));
    // Sharing every entry: __shared_blackboard (3), __autoremap (3, SubTreePlus),
    // _autoremap (4).
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"3\"",
            "<SubTree ID=\"Sub\" __shared_blackboard=\"true\"/>"
        ),
        "param"
    ));
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"3\"",
            "<SubTreePlus ID=\"Sub\" __autoremap=\"1\"/>"
        ),
        "param"
    ));
    assert!(writes(
        &with_sub(
            "BTCPP_format=\"4\"",
            "<SubTree ID=\"Sub\" _autoremap=\"true\"/>"
        ),
        "param"
    ));
    // Unmapped, the entry a SetBlackboard names without braces is private to the SubTree.
    assert!(!writes(
        &with_sub("BTCPP_format=\"4\"", "<SubTree ID=\"Sub\"/>"),
        "param"
    ));
    assert!(writes(
        &with_sub("BTCPP_format=\"4\"", "<SubTree ID=\"Sub\"/>"),
        "Sub_1_param"
    ));
    // Format 4's constant remapping: a private entry, not the caller's.
    let t = with_sub(
        "BTCPP_format=\"4\"",
        "<SubTree ID=\"Sub\" param=\"outer\"/>",
    );
    assert!(lower(&t).is_err(), "SetBlackboard into a constant");
}

#[test]
fn each_format_has_its_own_names() {
    // SequenceStar is 3's name; SequenceWithMemory (AS2FM's model) is read in both.
    assert!(lower(&v3("<SequenceStar><AlwaysSuccess/></SequenceStar>")).is_ok());
    assert!(lower(&v3(
        "<SequenceWithMemory><AlwaysSuccess/></SequenceWithMemory>"
    ))
    .is_ok());
    // The same machines (the node's machine is named after the name written).
    let star: Vec<String> = lower(&v3("<SequenceStar><AlwaysSuccess/></SequenceStar>"))
        .unwrap()
        .iter()
        .map(|m| m.replace("SequenceStar", "SequenceWithMemory"))
        .collect();
    assert_eq!(
        star,
        lower(&v4(
            "<SequenceWithMemory><AlwaysSuccess/></SequenceWithMemory>"
        ))
        .unwrap()
    );
    let t = v4("<SequenceStar>\n<AlwaysSuccess/>\n</SequenceStar>");
    refused(
        "v3name",
        &t,
        "<SequenceStar",
        "in BTCPP_format 4 it is `SequenceWithMemory`",
    );
    let t = v4("<Sequence>\n<SubTreePlus ID=\"Main\"/>\n</Sequence>");
    refused("v3plus", &t, "<SubTreePlus", "BehaviorTree.CPP 3's node");
    let t = v4("<SubTree ID=\"Other\" __shared_blackboard=\"true\"/>").replace(
        "</root>",
        "<BehaviorTree ID=\"Other\"><AlwaysSuccess/></BehaviorTree></root>",
    );
    refused("v3flag", &t, "__shared_blackboard", "use `_autoremap`");
    // Without BTCPP_format, a plain SubTree value reads differently in 3 and 4.
    let t = "<root main_tree_to_execute=\"Main\">\n<BehaviorTree ID=\"Main\">\n<SubTree ID=\"Other\" goal=\"target\"/>\n</BehaviorTree>\n<BehaviorTree ID=\"Other\"><AlwaysSuccess/></BehaviorTree>\n</root>\n";
    refused("ambiguous", t, "target\"", "set BTCPP_format");
    // Formats other than 3 and 4.
    let t = v4("<AlwaysSuccess/>").replace("\"4\"", "\"2\"");
    refused("format2", &t, "2\"", "unsupported BTCPP_format `2`");
}

#[test]
fn blackboard_type_conflicts_name_both_places() {
    // A constant that is not an integer, into an entry BlackboardCheckInt reads.
    let t = v3("<Sequence>\n<SetBlackboard output_key=\"n\" value=\"1.5\"/>\n<BlackboardCheckInt value_A=\"{n}\" value_B=\"1\">\n<AlwaysSuccess/>\n</BlackboardCheckInt>\n</Sequence>");
    let (l, c) = pos(&t, "{n}\"");
    refused("conflict1", &t, "1.5\"", &format!("tree.xml:{l}:{c}"));
    // Two constants of different types into an entry nothing reads.
    let t = v3("<Sequence>\n<SetBlackboard output_key=\"m\" value=\"0\"/>\n<SetBlackboard output_key=\"m\" value=\"zero\"/>\n</Sequence>");
    let (l, c) = pos(&t, "0\"");
    refused(
        "conflict2",
        &t,
        "zero\"",
        &format!("used as string here but as int32 at tree.xml:{l}:{c}"),
    );
    // A copy between entries of different types names where each got its type.
    let t = v3("<Sequence>\n<SetBlackboard output_key=\"a\" value=\"1\"/>\n<SetBlackboard output_key=\"b\" value=\"x\"/>\n<SetBlackboard output_key=\"b\" value=\"{a}\"/>\n</Sequence>");
    let (la, ca) = pos(&t, "1\"");
    let (lb, cb) = pos(&t, "x\"");
    let dir = scratch_model("conflict3", &t);
    let (code, _, err) = hindsight(&dir, &["validate", "main.xml"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!("tree.xml:{la}:{ca}"))
            && err.contains(&format!("tree.xml:{lb}:{cb}")),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_trees_exit_2_with_their_position() {
    refused(
        "unknown",
        &v4("<Sequence>\n  <Frobnicate/>\n</Sequence>"),
        "<Frobnicate",
        "unknown node `Frobnicate`",
    );
    refused(
        "children",
        &v4("<Inverter>\n<AlwaysSuccess/>\n<AlwaysSuccess/>\n</Inverter>"),
        "<Inverter",
        "Inverter needs 1 children, found 2",
    );
    refused(
        "leafkids",
        &v4("<AlwaysSuccess>\n<AlwaysFailure/>\n</AlwaysSuccess>"),
        "<AlwaysSuccess",
        "needs 0 children, found 1",
    );
    refused(
        "porttype",
        &v4("<BlackboardCheckInt value_A=\"1\" value_B=\"one\">\n<AlwaysSuccess/>\n</BlackboardCheckInt>"),
        "one\"",
        "not a valid int32",
    );
    refused(
        "retry",
        &v4("<RetryUntilSuccessful num_attempts=\"x\">\n<AlwaysSuccess/>\n</RetryUntilSuccessful>"),
        "x\"",
        "must be a whole number",
    );
    refused(
        "threshold",
        &v4("<Parallel success_count=\"1\" success_threshold=\"2\">\n<AlwaysSuccess/>\n<AlwaysSuccess/>\n</Parallel>"),
        "2\"",
        "the same threshold",
    );
    // A BT.CPP node hindsight does not support: named as such, with the reason.
    refused(
        "unsupported",
        &v4("<Sequence>\n<ManualSelector>\n<AlwaysSuccess/>\n</ManualSelector>\n</Sequence>"),
        "<ManualSelector",
        "BehaviorTree.CPP built-in node `ManualSelector` is not supported by hindsight: it asks a person",
    );
    // A timed node has no AS2FM model: the default semantics refuses it, naming the one
    // that lowers it.
    refused(
        "timed",
        &v4("<Sequence>\n<Delay delay_msec=\"10\">\n<AlwaysSuccess/>\n</Delay>\n</Sequence>"),
        "<Delay",
        "`Delay` is a BehaviorTree.CPP 4 node that AS2FM has no model of, so the default semantics (`--bt as2fm`) cannot lower it: use `--bt btcpp`",
    );
    // `hindsight verify` refuses the same way.
    let t = v4("<Sequence>\n  <Frobnicate/>\n</Sequence>");
    let dir = scratch_model("verify_bad", &t);
    let (code, _, err) = hindsight(&dir, &["verify", "main.xml", "--max-runs", "2"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("tree.xml:4:3: unknown node `Frobnicate`"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
