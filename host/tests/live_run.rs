//! `hindsight run`: the museum guide runs live and its ROS topics arrive over iceoryx2 in the documented layout.

#[path = "live_common/mod.rs"]
mod live_common;

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use hindsight::live::config::Config;
use iceoryx2::prelude::*;
use live_common::{finish, finish_polling, node, unique, Guard};

fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

fn hindsight(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hindsight"));
    c.arg("run").arg(museum()).args(args);
    c
}

type Sub = iceoryx2::port::subscriber::Subscriber<ipc::Service, [u8], ()>;

fn battery_subscriber(node: &Node<ipc::Service>, prefix: &str) -> Sub {
    let name = ServiceName::new(&format!("{prefix}/BatteryComponent/battery_level")).unwrap();
    let svc = node
        .service_builder(&name)
        .publish_subscribe::<[u8]>()
        .subscriber_max_buffer_size(256)
        .open_or_create()
        .unwrap();
    svc.subscriber_builder().buffer_size(256).create().unwrap()
}

/// (data, seq) of every battery sample received so far.
fn drain(sub: &Sub, out: &mut Vec<(i64, u64)>) {
    while let Some(s) = sub.receive().unwrap() {
        let p = s.payload();
        assert_eq!(p.len(), 16, "std_msgs/Int32: data i64 + seq u64");
        let data = i64::from_le_bytes(p[0..8].try_into().unwrap());
        let seq = u64::from_le_bytes(p[8..16].try_into().unwrap());
        out.push((data, seq));
    }
}

#[test]
fn battery_level_is_published_once_per_model_second() {
    let node = node();
    let prefix = unique("run");
    let sub = battery_subscriber(&node, &prefix);
    let child = hindsight(&["--speed", "20", "--duration", "5s", "--prefix", &prefix])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut guard = Guard(Some(child));
    let mut got = Vec::new();
    let (status, err) = finish_polling(&mut guard, || drain(&sub, &mut got));
    assert!(status.success(), "{err}");
    assert!(err.contains("reached the duration"), "{err}");
    // The battery publishes at t = 0 s, 1 s, ..., 5 s: 100, 99, ..., 95.
    assert_eq!(
        got,
        (0..6).map(|k| (100 - k as i64, k)).collect::<Vec<_>>(),
        "{err}"
    );
}

#[test]
fn sigterm_stops_a_run_cleanly() {
    let node = node();
    let prefix = unique("run-term");
    let sub = battery_subscriber(&node, &prefix);
    let child = hindsight(&["--speed", "1", "--duration", "100s", "--prefix", &prefix])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let pid = child.id();
    let mut guard = Guard(Some(child));
    let mut got = Vec::new();
    let t = Instant::now();
    while got.is_empty() {
        assert!(t.elapsed() < Duration::from_secs(30), "no sample arrived");
        drain(&sub, &mut got);
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(got[0], (100, 0));
    let killed = Command::new("kill")
        .args(["-TERM", &pid.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let (status, err) = finish(&mut guard);
    assert!(status.success(), "{err}");
    assert!(err.contains("stopped by a signal"), "{err}");
}

#[test]
fn layout_is_a_monitor_config() {
    let out = hindsight(&["--layout", "--prefix", "museum"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    // Valid TOML as a whole, with the documented offsets.
    let doc: toml::Table = toml::from_str(&text).unwrap();
    // The clock of a run at the default speed: model time is wall-clock time, from the
    // run's first message.
    assert_eq!(doc["clock"]["speed"].as_float(), Some(1.0));
    assert_eq!(doc["clock"]["from_first_message"].as_bool(), Some(true));
    let topics = doc["topic"].as_array().unwrap();
    let battery = topics
        .iter()
        .find(|t| t["service"].as_str() == Some("museum/BatteryComponent/battery_level"))
        .unwrap();
    assert_eq!(battery["size"].as_integer(), Some(16));
    assert_eq!(battery["seq"]["offset"].as_integer(), Some(8));
    let field = &battery["field"].as_array().unwrap()[0];
    assert_eq!(field["name"].as_str(), Some("data"));
    assert_eq!(field["var"].as_str(), Some("battery_level"));
    assert_eq!(battery["event"].as_str(), Some("battery_published"));
    assert_eq!(field["offset"].as_integer(), Some(0));
    assert_eq!(field["type"].as_str(), Some("i64"));
    // The property file names nothing on the alarm topic: its table is commented out
    // whole (ready to be named and uncommented), so the sidecar does not tap it.
    assert!(!topics
        .iter()
        .any(|t| t["service"].as_str() == Some("museum/NotifyUserComponent/alarm")));
    assert!(
        text.contains(
            "# [[topic]]\n# service = \"museum/NotifyUserComponent/alarm\"\n# size = 9\n"
        ),
        "{text}"
    );
    assert!(text.contains("# type = \"bool\""), "{text}");
    assert_eq!(
        topics.len(),
        5,
        "battery, alarm request, SetPoi, SetInt, visitors"
    );
    // Services are published as the server sees them, named after the property file too.
    let alarm_request = topics
        .iter()
        .find(|t| t["service"].as_str() == Some("museum/NotifyUserComponent/StartAlarm/request"))
        .unwrap();
    assert_eq!(alarm_request["event"].as_str(), Some("alarm"));
    // Named after the property file's ports, the whole output is a config for the
    // monitors `verify` compiles from the model's own properties.
    let args = hindsight::verify::load::LoadOptions {
        model: museum(),
        ..Default::default()
    };
    let loaded = hindsight::verify::load::load(&args).unwrap_or_else(|e| panic!("{e}"));
    let spec = loaded.set.compiled();
    let config = Config::parse(&text, "museum.toml", spec).unwrap();
    assert_eq!(config.topics.len(), topics.len());
}

const DEMO: &str = r#"<scxml name="Demo" initial="s" xmlns="http://www.w3.org/2005/07/scxml">
  <datamodel><!-- TYPE n:int32 --><data id="n" expr="0"/><!-- TYPE x:float64 --><data id="x" expr="0.5"/></datamodel>
  <state id="s">
    <onexit><send event="topic_demo__pose_msg" target="NONE" delay="1">
      <param name="ros_fields__x" expr="x"/><param name="ros_fields__ok" expr="n % 2 == 0"/>
      <param name="ros_fields__name" expr="'hi'"/><param name="ros_fields__n" expr="n"/>
    </send></onexit>
    <transition target="s"><assign location="n" expr="n + 1"/><assign location="x" expr="x * 2"/></transition>
  </state>
</scxml>
"#;

const DEMO_PROPS: &str = r#"<properties>
  <ports>
    <scxml_event_send event="topic_demo__pose_msg" origin="Demo" target="NONE">
      <state_var id="px" param="ros_fields__x" type="float64" expr="0.0"/>
      <event_var id="pose"/>
    </scxml_event_send>
  </ports>
  <guarantees>
    <property id="p" logic="pmtl" expr="historically({px &gt;= 0.0})"/>
  </guarantees>
</properties>
"#;

#[test]
fn bool_int_and_float_fields_are_packed_and_strings_left_out() {
    let dir = live_common::scratch("run-demo");
    std::fs::write(dir.join("demo.scxml"), DEMO).unwrap();
    std::fs::write(dir.join("properties.xml"), DEMO_PROPS).unwrap();
    let run = |extra: &[&str]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_hindsight"));
        c.arg("run").arg(&dir).args(extra);
        c
    };
    // Without a time unit a plain SCXML model cannot be paced: a clear error, exit 2.
    let out = run(&["--duration", "3"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--time-unit"));

    let out = run(&["--speed", "0", "--time-unit", "100ms"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--speed: speed 0: must be a number"));

    let node = node();
    let prefix = unique("run-demo");
    let name = ServiceName::new(&format!("{prefix}/demo/pose")).unwrap();
    let svc = node
        .service_builder(&name)
        .publish_subscribe::<[u8]>()
        .subscriber_max_buffer_size(64)
        .open_or_create()
        .unwrap();
    let sub = svc.subscriber_builder().buffer_size(64).create().unwrap();
    let child = run(&[
        "--time-unit",
        "100ms",
        "--speed",
        "100",
        "--duration",
        "3",
        "--prefix",
        &prefix,
    ])
    .stdout(Stdio::null())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    let mut guard = Guard(Some(child));
    // Samples are read while the publisher lives (its memory goes with it).
    let mut got = Vec::new();
    let mut drain = || {
        while let Some(s) = sub.receive().unwrap() {
            let p = s.payload();
            assert_eq!(p.len(), 25);
            got.push((
                i64::from_le_bytes(p[0..8].try_into().unwrap()),
                p[8],
                f64::from_le_bytes(p[9..17].try_into().unwrap()),
                u64::from_le_bytes(p[17..25].try_into().unwrap()),
            ));
        }
    };
    let (status, err) = loop {
        drain();
        if guard.0.as_mut().unwrap().try_wait().unwrap().is_some() {
            break finish(&mut guard);
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    drain();
    assert!(status.success(), "{err}");
    assert!(err.contains("field `name` (Str) is not published"), "{err}");
    // Parameters n (i64 @0), ok (bool @8), x (f64 @9), seq (u64 @17): 25 bytes.
    assert_eq!(
        got,
        vec![(0, 1, 0.5, 0), (1, 0, 1.0, 1), (2, 1, 2.0, 2)],
        "{err}"
    );

    let layout = run(&["--layout", "--prefix", "d"]).output().unwrap();
    let text = String::from_utf8(layout.stdout).unwrap();
    let doc: toml::Table = toml::from_str(&text).unwrap();
    let topic = &doc["topic"][0];
    assert_eq!(topic["size"].as_integer(), Some(25));
    assert_eq!(topic["event"].as_str(), Some("pose"));
    assert_eq!(topic["seq"]["offset"].as_integer(), Some(17));
    let field = &topic["field"][0];
    assert_eq!(field["var"].as_str(), Some("px"));
    assert_eq!(field["offset"].as_integer(), Some(9));
    assert_eq!(field["type"].as_str(), Some("f64"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_sidecar_judges_every_battery_sample_of_a_live_run() {
    let prefix = unique("run-sidecar");
    // The battery table of `--layout`, as the test spec names its variables.
    let out = hindsight(&["--layout", "--prefix", &prefix])
        .output()
        .unwrap();
    let text = String::from_utf8(out.stdout).unwrap();
    let block = text
        .split("\n\n")
        .find(|b| b.contains("BatteryComponent/battery_level\""))
        .unwrap()
        .to_string();
    let sidecar = live_common::Running::start(&block, "run-sidecar");
    let child = hindsight(&["--speed", "20", "--duration", "5s", "--prefix", &prefix])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut guard = Guard(Some(child));
    // The sidecar judges while the run lives (samples go with their publisher).
    sidecar.wait_judged(6);
    let (status, err) = finish(&mut guard);
    assert!(status.success(), "{err}");
    let done = sidecar.finish();
    let battery = &done.report.sources[0];
    assert_eq!(
        (battery.samples, battery.lost, battery.malformed),
        (6, 0, 0)
    );
    let absence = done.verdicts_of("absence");
    assert!(!absence.is_empty());
    assert!(absence.iter().all(|v| v.contains("true")), "{absence:?}");
    done.assert_replay_matches();
}
