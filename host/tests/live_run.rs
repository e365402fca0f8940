//! `hindsight run`: the museum guide runs live and its ROS topics arrive over iceoryx2 in the documented layout.

#[path = "live_common/mod.rs"]
mod live_common;

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use hindsight::live::config::Config;
use iceoryx2::prelude::*;
use live_common::{node, unique};

fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

fn hindsight(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_hindsight"));
    c.arg("run").arg(museum()).args(args);
    c
}

/// Kills the child if a test fails before it is waited for.
struct Guard(Option<Child>);

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some(c) = self.0.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Waits for the child to exit (a guard of 60 s against a hang) and returns its stderr.
fn finish(guard: &mut Guard) -> (std::process::ExitStatus, String) {
    let mut child = guard.0.take().unwrap();
    let t = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            return (status, err);
        }
        if t.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("hindsight run did not end");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
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
    let (status, err) = loop {
        drain(&sub, &mut got);
        if guard.0.as_mut().unwrap().try_wait().unwrap().is_some() {
            break finish(&mut guard);
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    drain(&sub, &mut got);
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
    let alarm = topics
        .iter()
        .find(|t| t["service"].as_str() == Some("museum/NotifyUserComponent/alarm"))
        .unwrap();
    assert_eq!(alarm["size"].as_integer(), Some(9));
    // The property file names nothing on the alarm topic: its bool field is commented out.
    assert!(alarm.get("field").is_none());
    assert!(text.contains("# type = \"bool\""), "{text}");
    // Named after the property file's ports, the whole output is a config for the
    // museum spec as it is.
    let spec_path = museum().join("../specs/museum.hspec");
    let spec_src = std::fs::read_to_string(&spec_path).unwrap();
    let spec = codegen::compile_spec(&spec_src, "museum.hspec").unwrap();
    let config = Config::parse(&text, "museum.toml", &spec).unwrap();
    assert_eq!(config.topics.len(), topics.len());
    assert_eq!(config.topics[0].layout.size, 16);
}
