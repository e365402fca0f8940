//! `hindsight` on robot models: the museum guide in its high-level form (verify, sweep in
//! seconds, convert), and bad robot models rejected with positions and exit code 2.

mod common;

use common::hindsight;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-robot-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

const GUIDE: &str = "examples/museum-guide";

/// A server that answers every request to `/svc` at once (for [`service_robot`]).
const ANSWERING: &str = r#"<scxml version="1.0" datamodel="ecmascript" name="server" initial="on">
  <ros_service_server service_name="/svc" type="std_srvs/Trigger"/>
  <state id="on"><ros_service_handle_request name="/svc" target="on">
    <ros_service_send_response name="/svc"><field name="success" expr="true"/></ros_service_send_response>
  </ros_service_handle_request></state>
</scxml>"#;

/// A robot in `scratch(name)`: a client that calls `/svc` every second and `server`
/// (the machine that serves it), judged on whether `/svc` was asked within 2 s of the
/// first request (`once[0:2s] {asked} || !once {asked}`, never final, so a run goes
/// on until it ends). Returns the folder.
fn service_robot(name: &str, server: &str) -> PathBuf {
    let dir = scratch(name);
    let files = [
        (
            "main.xml",
            r#"<roaml><parameters><max_time value="10" unit="s"/></parameters>
  <node_models><input type="ros-scxml" src="./client.scxml"/><input type="ros-scxml" src="./server.scxml"/></node_models>
  <properties><input type="xml" src="./properties.xml"/></properties></roaml>"#,
        ),
        (
            "client.scxml",
            r#"<scxml version="1.0" datamodel="ecmascript" name="client" initial="wait">
  <ros_service_client service_name="/svc" type="std_srvs/Trigger"/>
  <ros_time_rate name="t" rate_hz="1"/>
  <state id="wait"><ros_rate_callback name="t" target="call"/></state>
  <state id="call"><onentry><ros_service_send_request name="/svc"/></onentry>
    <ros_service_handle_response name="/svc" target="wait"/></state>
</scxml>"#,
        ),
        ("server.scxml", server),
        (
            "properties.xml",
            r#"<properties><ports>
  <ros_service service_name="/svc" type="std_srvs/Trigger" event="request"><event_var id="asked"/></ros_service>
</ports><guarantees>
  <property id="answered" logic="pmtl" expr="once[0:2s] {asked} || !once {asked}"/>
</guarantees></properties>"#,
        ),
    ];
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

#[test]
fn a_robot_that_deadlocks_is_told_so() {
    // The client calls `/svc` after 1 s; the server waits for a topic nobody publishes
    // and never handles the request, which nobody may drop: time stops at 1 s of 10.
    let dir = service_robot(
        "deadlock",
        r#"<scxml version="1.0" datamodel="ecmascript" name="server" initial="off">
  <ros_service_server service_name="/svc" type="std_srvs/Trigger"/>
  <ros_topic_subscriber topic="/never" type="std_msgs/Bool"/>
  <state id="off"><ros_topic_callback name="/never" target="on"/></state>
  <state id="on"><ros_service_handle_request name="/svc" target="on">
    <ros_service_send_response name="/svc"><field name="success" expr="true"/></ros_service_send_response>
  </ros_service_handle_request></state>
</scxml>"#,
    );
    let model = dir.to_str().unwrap();
    let (code, out, err) = hindsight(&["verify", model, "--runs", "5", "--json"]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        (r["quiescent"].as_u64(), r["time_horizon"].as_u64()),
        (Some(5), Some(0))
    );
    assert!(
        err.contains("note: 5 of 5 runs went quiet before the time horizon"),
        "{err}"
    );
    let (code, _, err) = hindsight(&["trace", model, "--run", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("run 2 of seed 0: went quiet at time 1 (1s) after "),
        "{err}"
    );
    // A shorter run says its length in the command, which replays the same run.
    let (code, _, err) = hindsight(&["verify", model, "--runs", "5", "--max-time", "5s"]);
    assert_eq!(code, 0, "{err}");
    let command = err
        .split('`')
        .nth(1)
        .unwrap_or_else(|| panic!("no command in {err}"));
    assert!(command.ends_with("--seed 0 --max-time 5"), "{command}");
    let args: Vec<&str> = command
        .split(' ')
        .skip(1)
        .map(|a| if a == "K" { "3" } else { a })
        .collect();
    let (code, _, err) = hindsight(&args);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("run 3 of seed 0: went quiet at time 1 (1s)"),
        "{err}"
    );
    // `sweep` runs the same runs, and says so once.
    let (code, _, err) = hindsight(&[
        "sweep", model, "--from", "1s", "--to", "3s", "--runs", "5", "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        err.matches("note: 5 of 5 runs went quiet").count(),
        1,
        "{err}"
    );
    // Run past the model's own length, quiet runs are not called deadlocks: a plain
    // timer may have stopped there.
    let (_, _, err) = hindsight(&["verify", model, "--runs", "5", "--max-time", "20s"]);
    assert!(!err.contains("went quiet"), "{err}");
    // A healthy robot gets no such note.
    let (_, _, err) = hindsight(&["verify", GUIDE, "--runs", "3"]);
    assert!(!err.contains("went quiet"), "{err}");
    // Nor does one without timers: with no global timer, a run ends when its machines
    // are done (here: one message, taken).
    std::fs::write(
        dir.join("client.scxml"),
        r#"<scxml version="1.0" datamodel="ecmascript" name="client" initial="s">
  <ros_topic_publisher topic="/never" type="std_msgs/Bool"/>
  <state id="s"><onentry><ros_topic_publish name="/never"><field name="data" expr="true"/></ros_topic_publish></onentry></state>
</scxml>"#,
    )
    .unwrap();
    let (code, out, err) = hindsight(&["verify", model, "--runs", "3", "--json"]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["quiescent"].as_u64(), Some(3), "{out}");
    assert!(!err.contains("went quiet"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

/// A `<send delay>` in a node model: AS2FM drops it, hindsight waits for it, and a
/// request that reaches the machine meanwhile blocks time under AS2FM's events. Each of
/// the three is said: the warning at the attribute, then the deadlock note.
#[test]
fn a_delayed_send_in_a_node_model_is_warned_about() {
    let dir = service_robot(
        "delayed-send",
        r#"<scxml version="1.0" datamodel="ecmascript" name="server" initial="on">
  <ros_service_server service_name="/svc" type="std_srvs/Trigger"/>
  <state id="on"><ros_service_handle_request name="/svc" target="cool">
    <ros_service_send_response name="/svc"><field name="success" expr="true"/></ros_service_send_response>
  </ros_service_handle_request></state>
  <state id="cool"><onentry><send event="cooled" target="server" delay="2s"/></onentry>
    <transition event="cooled" target="on"/></state>
</scxml>"#,
    );
    let model = dir.to_str().unwrap();
    let (code, _, err) = hindsight(&["verify", model, "--runs", "3"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("server.scxml:6:66: `delay` on <send>: AS2FM drops it"),
        "{err}"
    );
    // The second request (at 2 s) finds the server waiting until 3 s: time stops.
    assert!(
        err.contains("note: 3 of 3 runs went quiet before the time horizon"),
        "{err}"
    );
    // A delay the 1 s timer does not divide makes the model's step finer (0.5 s), not an
    // error: the client still calls each second, and the server still waits.
    let server = std::fs::read_to_string(dir.join("server.scxml")).unwrap();
    std::fs::write(
        dir.join("server.scxml"),
        server.replace("delay=\"2s\"", "delay=\"1500ms\""),
    )
    .unwrap();
    let (code, out, err) = hindsight(&["verify", model, "--runs", "3"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("model time: steps of 0.5 s, runs of at most 10.5 s"),
        "{out}"
    );
    assert!(
        err.contains("note: 3 of 3 runs went quiet before the time horizon"),
        "{err}"
    );
    let (code, _, err) = hindsight(&["trace", model, "--run", "0"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("went quiet at time 4 (2s)"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_museum_guide_verifies_from_its_main_file() {
    let (code, out, err) =
        hindsight(&["verify", GUIDE, "--seed", "4", "--max-runs", "8", "--json"]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    let props = report["properties"].as_array().unwrap();
    assert_eq!(props.len(), 5);
    for p in props {
        assert_eq!(p["successes"], 8, "{p}");
    }
    // The table says how long a run is, in seconds.
    let (code, out, err) = hindsight(&["verify", GUIDE, "--seed", "4", "--max-runs", "2"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("model time: steps of 0.1 s, runs of at most 100.1 s"),
        "{out}"
    );
}

#[test]
fn sweeping_the_museum_guide_finds_thresholds_in_seconds() {
    let (code, out, err) = hindsight(&[
        "sweep",
        GUIDE,
        "--property",
        "poi_response",
        "--from",
        "0.1s",
        "--to",
        "0.3s",
        "--runs",
        "3",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(doc["properties"][0]["threshold"], "0.2s");
}

#[test]
fn converted_plain_scxml_runs_exactly_like_the_robot_model() {
    let dir = scratch("convert");
    let out_dir = dir.join("plain");
    let (code, _, err) = hindsight(&["convert", GUIDE, "--out", out_dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out_dir.join("model.xml").is_file());
    let props = std::fs::read_to_string(out_dir.join("properties.xml")).unwrap();
    // ROS names became machines, seconds became 100 ms steps.
    assert!(props.contains("origin=\"BatteryComponent\""), "{props}");
    assert!(props.contains("since[62:]"), "{props}");
    let model = out_dir.join("model.xml");
    let (code, high, err) = hindsight(&["trace", GUIDE, "--run", "1", "--seed", "9"]);
    assert_eq!(code, 0, "{err}");
    // The guide's global timer runs to `max_time` (100 s): the run lasts its whole length.
    assert!(
        err.contains("run 1 of seed 9: reached the time horizon, time 1001 (100.1s), after "),
        "{err}"
    );
    let (code, plain, err) = hindsight(&[
        "trace",
        model.to_str().unwrap(),
        "--events",
        "as2fm",
        "--time-unit",
        "100ms",
        "--max-time",
        "1001",
        "--run",
        "1",
        "--seed",
        "9",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(high.lines().count() > 1000);
    // Both name their unit first, for `replay`.
    assert!(high.starts_with("# time unit: 100ms\n"), "{}", &high[..80]);
    assert!(high == plain, "the converted model runs differently");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_robot_models_name_file_line_and_column() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide");
    // (what to change, file, line, old, new, expected in the message)
    let cases: &[(&str, &str, usize, &str, &str, &str)] = &[
        (
            "unknown plugin",
            "policy.xml",
            6,
            "ID=\"ROS2Condition\"",
            "ID=\"ROS2Conditio\"",
            "policy.xml:6:32: unknown node `ROS2Conditio`",
        ),
        (
            "unknown node",
            "policy.xml",
            12,
            "<Inverter>",
            "<Invertr>",
            "policy.xml:12:21: unknown node `Invertr`",
        ),
        (
            "port of the wrong type",
            "policy.xml",
            12,
            "<Inverter>",
            "<Repeat num_cycles=\"many\">",
            "policy.xml:12:41: `num_cycles` must be a whole number",
        ),
        (
            "subscriber type differs from the publisher's",
            "Skills/BatteryLevelSkill.scxml",
            18,
            "std_msgs/Int32",
            "std_msgs/Bool",
            "BatteryLevelSkill.scxml:18:73: topic `BatteryComponent__battery_level` is subscribed with type `std_msgs/Bool`",
        ),
        (
            // The plugin reads the name from the tree's port: the error is at the port.
            "a BT node's service that nothing serves",
            "policy.xml",
            6,
            "service_name=\"/BatteryLevelSkill/tick\"",
            "service_name=\"/BatteryLevelSkil/tick\"",
            "policy.xml:6:81: service `/BatteryLevelSkil/tick` has no server (no node model declares a <ros_service_server> for it; requested by <ros_service_send_request> at ",
        ),
        (
            "unsupported tag",
            "Components/BatteryComponent.scxml",
            14,
            "type=\"std_msgs/Int32\" />",
            "type=\"std_msgs/Int32\" /><ros_parameter name=\"level\" />",
            "BatteryComponent.scxml:14:88: unsupported ROS tag <ros_parameter>",
        ),
        (
            "misspelled tag",
            "Components/BatteryComponent.scxml",
            14,
            "<ros_topic_publisher",
            "<ros_topic_publisher_x",
            "BatteryComponent.scxml:14:3: unsupported ROS tag <ros_topic_publisher_x>",
        ),
    ];
    for (what, file, line, old, new, expected) in cases {
        let dir = scratch("bad");
        let model = dir.join("guide");
        copy_dir(&root, &model);
        let path = model.join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        assert!(
            lines[line - 1].contains(old),
            "{what}: line {line} of {file}"
        );
        lines[line - 1] = lines[line - 1].replacen(old, new, 1);
        if *new == "<Repeat num_cycles=\"many\">" {
            lines[line + 1] = lines[line + 1].replacen("</Inverter>", "</Repeat>", 1);
        }
        if *new == "<Invertr>" {
            lines[line + 1] = lines[line + 1].replacen("</Inverter>", "</Invertr>", 1);
        }
        std::fs::write(&path, lines.join("\n")).unwrap();
        let (code, _, err) = hindsight(&["validate", model.to_str().unwrap()]);
        assert_eq!(code, 2, "{what}: {err}");
        assert!(err.contains(expected), "{what}: {err}");
        let _ = std::fs::remove_dir_all(dir);
    }
    // A missing interface file: the service type is reported where it is used.
    let dir = scratch("iface");
    let model = dir.join("guide");
    copy_dir(&root, &model);
    std::fs::remove_file(model.join("Interfaces/notify_user_interfaces_dummy/srv/StartAlarm.srv"))
        .unwrap();
    let (code, _, err) = hindsight(&["validate", model.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("NotifyUserComponent.scxml:13:76: no service type `notify_user_interfaces_dummy/StartAlarm`"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// `--only` and `--skip` pick properties of an XML property file by name.
#[test]
fn verify_checks_the_properties_named() {
    let (code, out, err) = hindsight(&[
        "verify",
        GUIDE,
        "--only",
        "alarm_response",
        "--only",
        "absence",
        "--max-runs",
        "2",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    let names: Vec<&str> = report["properties"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["property"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["absence", "alarm_response"]);
    let (code, out, err) = hindsight(&[
        "verify",
        GUIDE,
        "--skip",
        "absence",
        "--max-runs",
        "2",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(report["properties"].as_array().unwrap().len(), 4);
    let (code, _, err) = hindsight(&["verify", GUIDE, "--skip", "absense"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--skip absense: ")
            && err.contains("has no property `absense` (properties: absence, alarm_response,"),
        "{err}"
    );
}

#[test]
fn a_model_without_properties_validates_and_traces_but_does_not_verify() {
    // A model alone: validate checks it, trace shows its messages (no property
    // columns); verify, sweep and report have nothing to estimate and refuse.
    let robot = service_robot("noprops", ANSWERING);
    let main = robot.join("main.xml");
    let text = std::fs::read_to_string(&main).unwrap();
    std::fs::write(
        &main,
        text.replace(
            r#"<properties><input type="xml" src="./properties.xml"/></properties>"#,
            "",
        ),
    )
    .unwrap();
    let plain = scratch("noprops-plain");
    std::fs::write(
        plain.join("m.scxml"),
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" name="M" initial="a" datamodel="ecmascript">
  <state id="a"><onentry><send event="e" target="M" delay="1"/></onentry><transition event="e" target="a"/></state>
</scxml>"#,
    )
    .unwrap();
    for (dir, why) in [
        (&robot, "main.xml: the main file names no property file"),
        (&plain, "no property file given and none found"),
    ] {
        let model = dir.to_str().unwrap();
        let (code, out, err) = hindsight(&["validate", model]);
        assert_eq!(code, 0, "{err}");
        assert!(
            out.contains(why) && out.ends_with("the model alone is ok\n"),
            "{out}"
        );
        let (code, out, err) = hindsight(&["trace", model, "--max-time", "3"]);
        assert_eq!(code, 0, "{err}");
        assert!(err.contains("the trace has no property columns"), "{err}");
        assert!(
            out.lines().find(|l| !l.starts_with('#'))
                == Some("time,step,event,origin,target,params"),
            "{out}"
        );
        assert!(out.lines().count() > 2, "{out}");
        let (code, _, err) = hindsight(&["verify", model]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("property file"), "{err}");
    }
}

#[test]
fn a_robot_trace_replays_in_its_own_time_unit() {
    // `trace` writes the model's unit first (`# time unit: 1s`), and `replay` of a
    // property file with bounds in seconds reads the trace's times in it: `young` turns
    // false at 3 s there. Read as nanoseconds (replay's default) it would stay true.
    let dir = service_robot("replay-unit", ANSWERING);
    let props = dir.join("properties.xml");
    std::fs::write(
        &props,
        r#"<properties><ports>
  <ros_service service_name="/svc" type="std_srvs/Trigger" event="request"><event_var id="asked"/></ros_service>
</ports><guarantees>
  <property id="young" logic="pmtl" expr="historically(!(once[3s:] true))"/>
</guarantees></properties>"#,
    )
    .unwrap();
    let (code, csv, err) = hindsight(&["trace", dir.to_str().unwrap(), "--max-time", "5s"]);
    assert_eq!(code, 0, "{err}");
    assert!(csv.starts_with("# time unit: 1s\n"), "{csv}");
    let trace = dir.join("run.csv");
    std::fs::write(&trace, &csv).unwrap();
    let last = |text: &str| {
        text.lines()
            .last()
            .unwrap()
            .rsplit(',')
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(last(&csv), "false", "{csv}");
    let (p, t) = (props.to_str().unwrap(), trace.to_str().unwrap());
    let (code, out, err) = hindsight(&["replay", p, t, "--changes"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().last(), Some("3,false"), "{out}");
    // The same unit given is fine; another is refused rather than misread.
    let (code, out, _) = hindsight(&["replay", p, t, "--changes", "--time-unit", "1000ms"]);
    assert_eq!((code, out.lines().last()), (0, Some("3,false")));
    let (code, _, err) = hindsight(&["replay", p, t, "--time-unit", "100ms"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("says its times are in units of 1s"), "{err}");
}

#[test]
fn a_bound_without_unit_on_a_robot_model_is_warned_about() {
    // A robot model's step is its timers' common period (1 s here): `[0:2]` is 2 s now
    // and would be 1 s if a 2 Hz timer were added. Said at the bound; durations and an
    // index inside an atom are not bounds.
    let dir = service_robot("unitless", ANSWERING);
    std::fs::write(
        dir.join("properties.xml"),
        r#"<properties><ports>
  <ros_service service_name="/svc" type="std_srvs/Trigger" event="request"><event_var id="asked"/></ros_service>
</ports><guarantees>
  <property id="steps" logic="pmtl" expr="historically(once[0:2] {asked} || !once[1s:] true)"/>
</guarantees></properties>"#,
    )
    .unwrap();
    let (code, _, err) = hindsight(&["validate", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let warned: Vec<&str> = err.lines().filter(|l| l.contains("has no unit")).collect();
    assert_eq!(warned.len(), 1, "{err}");
    assert!(
        warned[0].contains("properties.xml:4:63: property `steps`: the bound `2` has no unit, so it counts model steps, here of 1s"),
        "{err}"
    );
    assert!(warned[0].contains("2 steps = 2s"), "{err}");
}

#[test]
fn a_tree_or_property_file_given_as_the_model_says_what_to_give() {
    let dir = scratch("wrong-model");
    let tree = dir.join("tree.xml");
    std::fs::write(
        &tree,
        r#"<root BTCPP_format="4"><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>"#,
    )
    .unwrap();
    let props = dir.join("props.xml");
    std::fs::write(&props, "<properties><ports/><guarantees/></properties>").unwrap();
    for (file, want) in [
        (
            &tree,
            "found <root>: this is a BehaviorTree.CPP tree; give the robot model's main file",
        ),
        (
            &props,
            "found <properties>: this is a property file; give the model first",
        ),
    ] {
        let (code, _, err) = hindsight(&["validate", file.to_str().unwrap()]);
        assert_eq!(code, 2, "{err}");
        assert!(
            err.contains(":1:1: expected <specification>, ") && err.contains(want),
            "{err}"
        );
    }
    // `convert --out` a file: bad input, said as such.
    let (code, _, err) = hindsight(&["convert", GUIDE, "--out", props.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("props.xml: not a folder"), "{err}");
}
