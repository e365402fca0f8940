//! `hindsight monitor --ros2` against Eclipse Cyclone DDS, ROS 2's tier-1 middleware: a
//! Cyclone DDS participant (the `cyclonedds` Python binding, its wheel carrying the C
//! library; `host/tests/data/dds/cyclone.py`) publishes ROS 2-typed samples
//! (`std_msgs/msg/Int32` and `Bool` on `rt/<topic>`), and the monitor must judge them:
//! values, a topic that goes silent, a malformed sample, a publisher that restarts; its
//! `--record` MCAP must be read by the `mcap` Python reader and by `hindsight replay`.
//!
//! The Python side lives in the project's environment (`bash scripts/pyenv`, at
//! `$HINDSIGHT_PYENV` or `.venv`). Without it these tests say they were skipped and pass,
//! except under `CI=true`, where `.ci/run` has created it and they fail.
//!
//! Every test uses its own random ROS_DOMAIN_ID, so tests running in parallel (and other
//! DDS traffic on the machine) do not meet.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use common::dds::{data, domain, python, Proc};

fn scratch(name: &str) -> PathBuf {
    common::dds::scratch("dds", name)
}

/// SIGINT to the monitor, then its exit status and its whole standard error.
fn stop(mut m: Proc) -> (std::process::ExitStatus, String) {
    let status = m.interrupt(Duration::from_secs(30));
    (status, m.err())
}

/// Runs the Cyclone DDS publisher with `steps` (see cyclone.py) and checks it succeeded.
fn publish(py: &Path, domain: u16, steps: &str) -> String {
    let out = Command::new(py)
        .arg(data("cyclone.py"))
        .args(["publish", &domain.to_string(), steps])
        .output()
        .unwrap();
    ok(&out, "cyclone.py publish")
}

fn ok(out: &Output, what: &str) -> String {
    assert!(
        out.status.success(),
        "{what}: exit {:?}\n{}{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// Verdict lines as (property, time, verdict, event).
fn verdicts(path: &Path) -> Vec<(String, u64, String, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (
                v["property"].as_str().unwrap().to_string(),
                v["time"].as_u64().unwrap(),
                v["verdict"].as_str().unwrap().to_string(),
                v["event"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// The last verdict of `property` at or before `time` (ticks), if any.
fn verdict_at(lines: &[(String, u64, String, String)], property: &str, time: u64) -> String {
    lines
        .iter()
        .rfind(|(p, t, _, _)| p == property && *t <= time)
        .map_or_else(|| "none".to_string(), |(_, _, v, _)| v.clone())
}

/// Values judged, a topic that goes silent failing on time through heartbeats, and a
/// malformed sample counted as a loss naming topic and index.
#[test]
fn cyclone_samples_are_judged_and_a_silent_topic_fails_on_time() {
    let Some(py) = python() else { return };
    let d = domain(1);
    let dir = scratch("judged");
    let out = dir.join("verdicts.jsonl");
    let props = data("props.xml");
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "--from-first-message".as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
            "--record".as_ref(),
            dir.join("run.mcap").as_os_str(),
        ],
    );
    // /alive every 50 ms for 1 s with the battery at 50, then the battery at 10, then
    // /alive goes silent; then one malformed battery sample.
    let mut steps = vec![
        r#"["wait_match", "/alive", 30, "bool"]"#.to_string(),
        r#"["wait_match", "/battery", 30, "int32"]"#.to_string(),
    ];
    for i in 0..20 {
        steps.push(r#"["bool", "/alive", true]"#.into());
        if i % 5 == 0 {
            steps.push(r#"["int32", "/battery", 50]"#.into());
        }
        steps.push(r#"["sleep", 0.05]"#.into());
    }
    steps.push(r#"["int32", "/battery", 10]"#.into());
    steps.push(r#"["sleep", 1.0]"#.into());
    steps.push(r#"["wait_match", "/cells", 30, "bad"]"#.into());
    steps.push(r#"["bad", "/cells"]"#.into());
    let said = publish(&py, d, &format!("[{}]", steps.join(",")));
    assert!(said.contains("sent 26"), "{said}");
    m.wait_for("is malformed", Duration::from_secs(30));
    let (status, stderr) = stop(m);
    assert!(status.success(), "exit {status:?}\n{stderr}");
    let lines = verdicts(&out);
    assert!(!lines.is_empty(), "no verdict line\n{stderr}");
    // Every sample judged: 20 on /alive, 5 on /battery, and the malformed one on /cells.
    for (topic, counts) in [
        ("/alive", "20 judged, 0 lost, 0 malformed"),
        ("/battery", "5 judged, 0 lost, 0 malformed"),
        ("/cells", "0 judged, 0 lost, 1 malformed"),
    ] {
        let want = format!("monitor: {topic}: {counts}, 0 restarts");
        assert!(stderr.contains(&want), "{want}\n{stderr}");
    }
    assert!(
        stderr.contains("/cells: sample 1 (type `std_msgs/msg/Int32MultiArray`) is malformed"),
        "{stderr}"
    );
    // level_ok: currently true while the battery is at 50, false from the sample at 10.
    let low = lines
        .iter()
        .find(|(p, _, v, _)| p == "level_ok" && v == "false")
        .unwrap_or_else(|| panic!("level_ok never false: {lines:?}"));
    assert_eq!(low.3, "/battery", "{lines:?}");
    assert_eq!(verdict_at(&lines, "level_ok", low.1 - 1), "currently_true");
    // alive_recurrence: false 300 ms (ticks of 1 ms) after the first /alive that is not
    // followed by another within 300 ms, by a heartbeat, not by a message. When the
    // monitor received each sample is in its recording (log times, ns): the clock's 0 is
    // the first sample received (--from-first-message).
    let read = ok(
        &Command::new(&py)
            .arg(data("cyclone.py"))
            .arg("read_mcap")
            .arg(dir.join("run.mcap"))
            .output()
            .unwrap(),
        "cyclone.py read_mcap",
    );
    let msgs: Vec<serde_json::Value> = read
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let origin = msgs
        .iter()
        .map(|m| m["log_time"].as_u64().unwrap())
        .min()
        .unwrap();
    let alive: Vec<u64> = msgs
        .iter()
        .filter(|m| m["topic"] == "/alive")
        .map(|m| (m["log_time"].as_u64().unwrap() - origin) / 1_000_000)
        .collect();
    assert_eq!(alive.len(), 20, "{read}");
    // The malformed sample is recorded as it came, and does not decode there either.
    let cells: Vec<&serde_json::Value> = msgs.iter().filter(|m| m["topic"] == "/cells").collect();
    assert_eq!(cells.len(), 1, "{read}");
    assert!(cells[0].get("error").is_some(), "{read}");
    let due = alive
        .windows(2)
        .find(|w| w[1] - w[0] > 300)
        .map_or(alive[19], |w| w[0])
        + 300;
    let fail = lines
        .iter()
        .find(|(p, _, v, _)| p == "alive_recurrence" && v.ends_with("false"))
        .unwrap_or_else(|| panic!("alive_recurrence never false: {lines:?}"));
    // Never early (one tick of rounding between the two clocks); late only by as much as
    // a loaded machine delays a heartbeat.
    assert!(fail.1 + 1 >= due, "failed before {due}: {fail:?}\n{read}");
    assert!(
        fail.1 <= due + 1000,
        "failed long after {due}: {fail:?} {lines:?}"
    );
    assert_ne!(fail.3, "/alive", "{fail:?}");
    assert_eq!(
        verdict_at(&lines, "alive_recurrence", fail.1 - 1),
        "currently_true"
    );
    // The malformed sample made cell_ok unknown; level_ok keeps its final false
    // (nothing lost can undo a violation seen).
    assert_eq!(verdict_at(&lines, "cell_ok", fail.1), "currently_true");
    assert!(
        lines.iter().any(|(p, t, v, e)| p == "cell_ok"
            && v == "unknown"
            && *t > fail.1
            && e == "lost /cells"),
        "{lines:?}"
    );
    assert_eq!(
        lines
            .iter()
            .rfind(|(p, _, _, _)| p == "level_ok")
            .unwrap()
            .2,
        "false"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// A publisher that stops and a new one (a new process: a new DDS writer) on the same
/// topic: the monitor keeps judging and reports the restart.
#[test]
fn a_restarted_publisher_is_picked_up() {
    let Some(py) = python() else { return };
    let d = domain(2);
    let dir = scratch("restart");
    let out = dir.join("verdicts.jsonl");
    let props = data("props.xml");
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ],
    );
    let first =
        r#"[["wait_match", "/battery", 30], ["int32", "/battery", 60], ["int32", "/battery", 40]]"#;
    assert!(publish(&py, d, first).contains("sent 2"));
    let second =
        r#"[["wait_match", "/battery", 30], ["int32", "/battery", 30], ["int32", "/battery", 5]]"#;
    assert!(publish(&py, d, second).contains("sent 2"));
    m.wait_for("new publisher after a gap", Duration::from_secs(30));
    let (status, stderr) = stop(m);
    assert!(status.success(), "exit {status:?}\n{stderr}");
    assert!(
        stderr.contains("monitor: /battery: 4 judged, 0 lost, 0 malformed, 1 restarts"),
        "{stderr}"
    );
    let lines = verdicts(&out);
    // The restarted publisher's 5 is judged: level_ok turns false.
    assert!(
        lines
            .iter()
            .any(|(p, _, v, e)| p == "level_ok" && v == "false" && e == "/battery"),
        "{lines:?}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// `--record FILE.mcap`: what was received, read back by the `mcap` Python reader (with
/// `mcap-ros2-support` decoding the embedded schemas) and by `hindsight replay`, which
/// gives the verdicts the monitor gave.
#[test]
fn the_record_is_read_by_python_mcap_and_by_replay() {
    let Some(py) = python() else { return };
    let d = domain(3);
    let dir = scratch("record");
    let rec = dir.join("run.mcap");
    let props = data("props.xml");
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "--record".as_ref(),
            rec.as_os_str(),
            "-o".as_ref(),
            dir.join("verdicts.jsonl").as_os_str(),
        ],
    );
    let values = [70, 45, 21, 19, 33];
    let mut steps = vec![
        r#"["wait_match", "/battery", 30]"#.to_string(),
        r#"["wait_match", "/alive", 30, "bool"]"#.to_string(),
    ];
    for v in values {
        steps.push(format!(r#"["int32", "/battery", {v}]"#));
        steps.push(r#"["bool", "/alive", false]"#.into());
        steps.push(r#"["sleep", 0.02]"#.into());
    }
    assert!(publish(&py, d, &format!("[{}]", steps.join(","))).contains("sent 10"));
    // The publisher waited for every sample to be acknowledged, so each is in the
    // monitor's reader; give its loop a moment to take and judge them before SIGINT.
    std::thread::sleep(Duration::from_millis(500));
    let (status, stderr) = stop(m);
    assert!(status.success(), "exit {status:?}\n{stderr}");
    assert!(stderr.contains("monitor: /battery: 5 judged"), "{stderr}");
    let read = ok(
        &Command::new(&py)
            .arg(data("cyclone.py"))
            .arg("read_mcap")
            .arg(&rec)
            .output()
            .unwrap(),
        "cyclone.py read_mcap",
    );
    let msgs: Vec<serde_json::Value> = read
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let battery: Vec<i64> = msgs
        .iter()
        .filter(|m| m["topic"] == "/battery")
        .map(|m| {
            assert_eq!(m["schema"], "std_msgs/msg/Int32");
            assert_eq!(m["encoding"], "ros2msg");
            assert_eq!(m["message_encoding"], "cdr");
            m["data"].as_i64().unwrap()
        })
        .collect();
    assert_eq!(battery, values, "{read}");
    let alive: Vec<&serde_json::Value> = msgs.iter().filter(|m| m["topic"] == "/alive").collect();
    assert_eq!(alive.len(), 5, "{read}");
    assert!(alive
        .iter()
        .all(|m| m["schema"] == "std_msgs/msg/Bool" && m["data"] == false));
    // replay reads it: level_ok is true until the 19, false from there on.
    let csv = ok(
        &Command::new(env!("CARGO_BIN_EXE_hindsight"))
            .args(["replay".as_ref(), props.as_os_str(), rec.as_os_str()])
            .args(["--time-unit", "1ms"])
            .output()
            .unwrap(),
        "replay",
    );
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows[0], "time,level_ok,alive_recurrence,cell_ok", "{csv}");
    assert_eq!(rows.len(), 1 + 10, "{csv}");
    let level: Vec<&str> = rows[1..]
        .iter()
        .map(|r| r.split(',').nth(1).unwrap())
        .collect();
    let first_false = level.iter().position(|v| *v == "false").unwrap();
    assert!(level[..first_false].iter().all(|v| *v == "true"), "{csv}");
    assert!(level[first_false..].iter().all(|v| *v == "false"), "{csv}");
    let _ = std::fs::remove_dir_all(dir);
}

/// A sample whose source timestamp is older than points the monitor has already judged
/// (Cyclone DDS writes it with a timestamp 1 s in the past, while heartbeats were judged
/// every millisecond) makes the properties reading its topic `unknown`, with the event
/// `late /battery`, and they judge again after it; samples on time do not.
#[test]
fn a_late_sample_makes_its_properties_unknown() {
    let Some(py) = python() else { return };
    let d = domain(4);
    let dir = scratch("late");
    let out = dir.join("verdicts.jsonl");
    let props = data("props.xml");
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "--max-latency".as_ref(),
            "300ms".as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
        ],
    );
    // The late sample's sending falls after the monitor started and after the writer's
    // first sample reached it (1.5 s before): the monitor knew of the writer and judged
    // heartbeats without the sample.
    let steps = r#"[["wait_match", "/battery", 30], ["sleep", 1.0],
        ["int32", "/battery", 50], ["sleep", 1.5],
        ["int32", "/battery", 60, {"age": 1.0}], ["sleep", 0.5],
        ["int32", "/battery", 70]]"#;
    assert!(publish(&py, d, steps).contains("sent 3"));
    m.wait_for("is late", Duration::from_secs(30));
    std::thread::sleep(Duration::from_millis(500));
    let (status, stderr) = stop(m);
    assert!(status.success(), "exit {status:?}\n{stderr}");
    assert!(
        stderr.contains("monitor: /battery: 3 judged, 0 lost, 0 malformed, 0 restarts, 1 late"),
        "{stderr}"
    );
    assert!(
        stderr.contains("monitor: /battery: sample 2 is late: sent at tick"),
        "{stderr}"
    );
    let lines = verdicts(&out);
    let unknown: Vec<_> = lines.iter().filter(|(_, _, v, _)| v == "unknown").collect();
    // Only level_ok reads /battery; it is unknown once, at the late sample.
    assert_eq!(unknown.len(), 1, "{lines:?}");
    let (p, t, _, e) = unknown[0];
    assert_eq!((p.as_str(), e.as_str()), ("level_ok", "late /battery"));
    assert_eq!(verdict_at(&lines, "level_ok", t - 1), "currently_true");
    // Judged again from the next point on.
    assert!(
        lines
            .iter()
            .any(|(q, u, v, _)| q == "level_ok" && u > t && v == "currently_true"),
        "{lines:?}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// The QoS a `<ros_topic>` port names (`props_qos.xml`): a monitor that joins after a
/// transient-local Cyclone DDS publisher wrote gets the last sample it kept (depth 1:
/// the 15, not the 30 before it), and a best-effort publisher is matched (a reliable
/// reader, ROS 2's default, would not match it) and judged.
#[test]
fn ports_name_their_qos_transient_local_and_best_effort() {
    let Some(py) = python() else { return };
    let d = domain(5);
    let dir = scratch("qos");
    let out = dir.join("verdicts.jsonl");
    let props = data("props_qos.xml");
    let steps = r#"[
        ["qos", "/battery", {"durability": "transient_local", "depth": 1}],
        ["int32", "/battery", 30], ["int32", "/battery", 15], ["say", "written"],
        ["qos", "/alive", {"reliability": "best_effort"}],
        ["wait_match", "/alive", 60, "bool"], ["sleep", 1.0],
        ["bool", "/alive", true], ["sleep", 0.05], ["bool", "/alive", true], ["sleep", 0.05],
        ["bool", "/alive", true], ["sleep", 0.05], ["bool", "/alive", true], ["sleep", 0.05],
        ["bool", "/alive", true], ["say", "alive sent"], ["sleep", 60]]"#;
    let publisher = common::dds::cyclone(&py, "publish", d, steps);
    publisher.wait_for("written", Duration::from_secs(60));
    // The publisher has written both samples before the monitor exists.
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
        ],
    );
    publisher.wait_for("alive sent", Duration::from_secs(60));
    std::thread::sleep(Duration::from_millis(500));
    let (status, stderr) = stop(m);
    drop(publisher);
    assert!(status.success(), "exit {status:?}\n{stderr}");
    assert!(
        stderr.contains("monitor: /battery: 1 judged, 0 lost, 0 malformed, 0 restarts, 0 late"),
        "{stderr}"
    );
    let alive: u64 = stderr
        .lines()
        .find_map(|l| {
            l.strip_prefix("monitor: /alive: ")?
                .split(' ')
                .next()?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("{stderr}"));
    // Best effort on loopback: all five, or nearly.
    assert!((3..=5).contains(&alive), "{stderr}");
    let lines = verdicts(&out);
    // The kept sample is the 15: level_ok false, at a /battery sample.
    assert!(
        lines
            .iter()
            .any(|(p, _, v, e)| p == "level_ok" && v == "false" && e == "/battery"),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|(p, _, v, e)| p == "alive_seen" && v == "true" && e == "/alive"),
        "{lines:?}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// Bad input exits 2 with a message, before any DDS traffic.
#[test]
fn bad_arguments_exit_2() {
    let props = data("props.xml");
    let run = |args: &[&std::ffi::OsStr], env: Option<&str>| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_hindsight"));
        c.arg("monitor").args(args);
        if let Some(d) = env {
            c.env("ROS_DOMAIN_ID", d);
        }
        c.output().unwrap()
    };
    let out = run(&["--ros2".as_ref(), props.as_os_str()], Some("300"));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("ROS_DOMAIN_ID=300"));
    let dir = scratch("bad");
    let spec = dir.join("s.hspec");
    std::fs::write(
        &spec,
        "unit 1ms;\nstate level: int = 0;\nproperty p = H({level >= 0});\n",
    )
    .unwrap();
    let out = run(
        &[
            "--ros2".as_ref(),
            spec.as_os_str(),
            "--bind".as_ref(),
            "level=/battery.data".as_ref(),
        ],
        None,
    );
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--topic-type /battery=pkg/msg/Type"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(
        &[
            "--ros2".as_ref(),
            spec.as_os_str(),
            "--bind".as_ref(),
            "level=/battery.nope".as_ref(),
            "--topic-type".as_ref(),
            "/battery=std_msgs/Int32".as_ref(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("nope"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A QoS attribute with a value ROS 2 has no name for: the file, line and column.
    let bad_qos = dir.join("bad_qos.xml");
    std::fs::write(
        &bad_qos,
        std::fs::read_to_string(data("props_qos.xml"))
            .unwrap()
            .replace("reliability=\"best_effort\"", "reliability=\"sometimes\""),
    )
    .unwrap();
    let out = run(&["--ros2".as_ref(), bad_qos.as_os_str()], None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("bad_qos.xml:") && err.contains("sometimes") && err.contains("best_effort"),
        "{err}"
    );
    for (flag, says) in [
        ("/battery=depth=0", "QoS depth=`0`"),
        ("/nope=depth=1", "no port reads `/nope`"),
        ("/battery", "expected /topic="),
    ] {
        let out = run(
            &[
                "--ros2".as_ref(),
                props.as_os_str(),
                "--qos".as_ref(),
                flag.as_ref(),
            ],
            None,
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains(says), "{flag}: {err}");
    }
    let out = run(
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "--max-latency".as_ref(),
            "soon".as_ref(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--max-latency soon"));
    let _ = std::fs::remove_dir_all(dir);
}

/// A plain GET of the monitor's own server, status line and all.
fn get(addr: &str, path: &str) -> String {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    text
}

/// `--serve` beside `--ros2`: the live page is served, and so are the verdict lines, here
/// those the heartbeats give while nothing publishes (`/alive` silent past 0.3 s turns its
/// recurrence false). No publisher is needed, so this runs without the Python side.
#[test]
fn serve_gives_the_live_page_and_the_verdicts() {
    let d = domain(7);
    let props = data("props.xml");
    let m = Proc::monitor(
        d,
        &[
            "--ros2".as_ref(),
            props.as_os_str(),
            "--serve".as_ref(),
            ":0".as_ref(),
        ],
    );
    m.wait_for("live page at http://", Duration::from_secs(30));
    let err = m.err();
    let addr = err
        .split("live page at http://")
        .nth(1)
        .and_then(|r| r.split('/').next())
        .unwrap()
        .to_string();
    let page = get(&addr, "/");
    assert!(page.starts_with("HTTP/1.1 200"), "{page}");
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    loop {
        let body = get(&addr, "/verdicts.jsonl");
        let body = &body[body.find("\r\n\r\n").unwrap() + 4..];
        let turned_false = body.lines().any(|l| {
            serde_json::from_str::<serde_json::Value>(l).is_ok_and(|v| {
                v["property"] == "alive_recurrence"
                    && (v["verdict"] == "false" || v["verdict"] == "currently_false")
            })
        });
        if turned_false {
            break;
        }
        assert!(
            std::time::Instant::now() < deadline,
            "no false alive_recurrence served:\n{body}\n{}",
            m.err()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let (status, stderr) = stop(m);
    assert!(status.success(), "exit {status:?}\n{stderr}");
}
