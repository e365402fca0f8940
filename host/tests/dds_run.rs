//! `hindsight run --ros2` and the CDR writer against Eclipse Cyclone DDS (the `cyclonedds`
//! Python binding, `host/tests/data/dds/cyclone.py`): a Cyclone DDS subscriber reads what
//! our writer writes field for field (ints, floats, bools, strings, nested messages,
//! sequences, fixed arrays), and what `run --ros2` publishes of the museum guide (its
//! battery topic and a service's introspection events); and the museum guide's
//! `properties.xml` checked three ways with no edit: `verify` on the model,
//! `monitor --ros2` live while `run --ros2` plays a run, and `replay` of the MCAP the
//! monitor recorded, with the verdicts agreeing.
//!
//! Without the project's Python environment (`bash scripts/pyenv`) the Cyclone tests say
//! they were skipped and pass, except under `CI=true`. Every test uses its own random
//! ROS_DOMAIN_ID, so tests running in parallel (and other DDS traffic) do not meet.

mod common;

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use common::dds::{domain, hindsight, python, Proc};
use ros2::cdr_write::{encode, Val};
use ros2::dds::{Participant, Qos};
use ros2::schema::{BuiltinDefs, Schema};

fn museum() -> PathBuf {
    common::dds::repo().join("examples/museum-guide")
}

fn scratch(name: &str) -> PathBuf {
    common::dds::scratch("ddsrun", name)
}

/// The Cyclone DDS subscriber of `topics` (`[topic, type key of cyclone.py]`, or with a
/// third element, the reader's QoS in ROS 2's names), ready.
fn subscriber(
    py: &Path,
    domain: u16,
    topics: &[serde_json::Value],
    count: usize,
    secs: u64,
) -> Proc {
    let spec = serde_json::json!({"topics": topics, "count": count, "seconds": secs});
    let p = common::dds::cyclone(py, "subscribe", domain, &spec.to_string());
    p.wait_for("ready", Duration::from_secs(60));
    p
}

/// One live test at a time: a paced run beside another one (or beside the museum's
/// `verify`) makes its own jitter on a 2-core machine.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Our CDR writer, on our DDS writer, read by Cyclone DDS field for field: std_msgs/Int32
/// and Bool, and sensor_msgs/BatteryState (a nested header with a string, every float,
/// `uint8`s, a bool, two float sequences, two more strings).
#[test]
fn the_cdr_writer_is_read_by_cyclone_field_for_field() {
    let Some(py) = python() else { return };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let d = domain(11);
    let sub = subscriber(
        &py,
        d,
        &[
            serde_json::json!(["/count", "int32"]),
            serde_json::json!(["/flag", "bool"]),
            serde_json::json!(["/battery", "battery_state"]),
        ],
        3,
        120,
    );
    let defs = BuiltinDefs::new();
    let p = Participant::new(d).unwrap();
    let mut written = Vec::new();
    let int32 = Schema::resolve("std_msgs/msg/Int32", &defs).unwrap();
    let boolean = Schema::resolve("std_msgs/msg/Bool", &defs).unwrap();
    let battery = Schema::resolve("sensor_msgs/msg/BatteryState", &defs).unwrap();
    let one = |s: &Schema, sets: &[(&str, Val)]| {
        let mut v = Val::zero(s, 0);
        for (path, x) in sets {
            v.set(s, path, x.clone()).unwrap();
        }
        encode(s, &v).unwrap()
    };
    let w_count = p
        .writer("/count", "std_msgs/msg/Int32", Qos::ros_default())
        .unwrap();
    let w_flag = p
        .writer("/flag", "std_msgs/msg/Bool", Qos::ros_default())
        .unwrap();
    let w_battery = p
        .writer(
            "/battery",
            "sensor_msgs/msg/BatteryState",
            Qos::ros_default(),
        )
        .unwrap();
    let start = Instant::now();
    while [&w_count, &w_flag, &w_battery]
        .iter()
        .any(|w| w.matched() == 0)
    {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the Cyclone DDS readers were never matched:\n{}",
            sub.err()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // Our writers know the readers; give the readers' side of discovery time to know
    // the writers (what is written before is lost to a volatile reader).
    std::thread::sleep(Duration::from_secs(5));
    w_count
        .write(&one(&int32, &[("data", Val::Int(-123_456))]))
        .unwrap();
    w_flag
        .write(&one(&boolean, &[("data", Val::Bool(true))]))
        .unwrap();
    w_battery
        .write(&one(
            &battery,
            &[
                ("header.stamp.sec", Val::Int(1_700_000_000)),
                ("header.stamp.nanosec", Val::Int(999_999_999)),
                ("header.frame_id", Val::Str("base_link".into())),
                ("voltage", Val::Float(12.5)),
                ("current", Val::Float(-1.25)),
                ("percentage", Val::Float(0.75)),
                ("power_supply_status", Val::Int(2)),
                ("power_supply_health", Val::Int(1)),
                ("power_supply_technology", Val::Int(3)),
                ("present", Val::Bool(true)),
                (
                    "cell_voltage",
                    Val::Seq(vec![Val::Float(3.5), Val::Float(3.25), Val::Float(4.0)]),
                ),
                ("location", Val::Str("slot 2".into())),
                ("serial_number", Val::Str("SN-42".into())),
            ],
        ))
        .unwrap();
    written.extend(["count", "flag", "battery"]);
    for w in [&w_count, &w_flag, &w_battery] {
        assert!(w.wait_acked(Duration::from_secs(30)), "not acknowledged");
    }
    let mut sub = sub;
    assert!(sub.wait(Duration::from_secs(60)).success(), "{}", sub.err());
    let got = sub.json_lines();
    assert_eq!(got.len(), written.len(), "{}\n{}", sub.out(), sub.err());
    let counts: Vec<i64> = got
        .iter()
        .filter(|m| m["topic"] == "/count")
        .map(|m| m["data"]["data"].as_i64().unwrap())
        .collect();
    assert_eq!(counts, [-123_456]);
    let flag = got.iter().find(|m| m["topic"] == "/flag").unwrap();
    assert_eq!(flag["data"]["data"], true);
    let b = &got.iter().find(|m| m["topic"] == "/battery").unwrap()["data"];
    assert_eq!(b["header"]["stamp"]["sec"], 1_700_000_000);
    assert_eq!(b["header"]["stamp"]["nanosec"], 999_999_999);
    assert_eq!(b["header"]["frame_id"], "base_link");
    assert_eq!(b["voltage"], 12.5);
    assert_eq!(b["temperature"], 0.0);
    assert_eq!(b["current"], -1.25);
    assert_eq!(b["percentage"], 0.75);
    assert_eq!(b["power_supply_status"], 2);
    assert_eq!(b["power_supply_health"], 1);
    assert_eq!(b["power_supply_technology"], 3);
    assert_eq!(b["present"], true);
    assert_eq!(b["cell_voltage"], serde_json::json!([3.5, 3.25, 4.0]));
    assert_eq!(b["cell_temperature"], serde_json::json!([]));
    assert_eq!(b["location"], "slot 2");
    assert_eq!(b["serial_number"], "SN-42");
}

/// `run --ros2` of the museum guide, read by Cyclone DDS: the battery level once per
/// model second (100, 99, ...) as std_msgs/Int32 on `rt/BatteryComponent/battery_level`
/// (written transient-local, `--qos`, for a reader that requests it),
/// and the scheduler's SetPoi calls as service introspection events (a request received,
/// then its response sent, with one sequence number, the request's `poi_number`).
#[test]
fn run_ros2_publishes_the_museum_for_cyclone() {
    let Some(py) = python() else { return };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let d = domain(12);
    let battery = "/BatteryComponent/battery_level";
    let set_poi = "/SchedulerComponent/SetPoi/_service_event";
    let mut sub = subscriber(
        &py,
        d,
        &[
            // Requesting transient-local: matched only by a writer that offers it.
            serde_json::json!([battery, "int32", {"durability": "transient_local"}]),
            serde_json::json!([set_poi, "set_poi_event"]),
        ],
        usize::MAX >> 1,
        // Ends on its own after the run (no sample counts are assumed).
        90,
    );
    let mut run = hindsight();
    run.arg("run")
        .arg(museum())
        .args(["--ros2", "--speed", "20", "--duration", "5s", "--seed", "1"])
        .args(["--wait-match", battery, "--wait-match", set_poi])
        .arg("--qos")
        .arg(format!("{battery}=durability=transient_local"))
        .env("ROS_DOMAIN_ID", d.to_string());
    let mut run = Proc::start(run, "hindsight run --ros2");
    let status = run.wait(Duration::from_secs(120));
    assert!(status.success(), "{}", run.err());
    assert!(run.err().contains("reached the duration"), "{}", run.err());
    // The run waited for acknowledgements before it ended: every sample is in.
    std::thread::sleep(Duration::from_secs(1));
    let _ = sub.interrupt(Duration::from_secs(30));
    let got = sub.json_lines();
    let levels: Vec<i64> = got
        .iter()
        .filter(|m| m["topic"] == battery)
        .map(|m| m["data"]["data"].as_i64().unwrap())
        .collect();
    // Cyclone DDS was seen twice to miss the second sample a rustdds writer wrote, before
    // our writes carried source timestamps; not seen since, cause not established (see
    // README): every level it got is the model's, in order, and at most one is missing.
    let all = [100, 99, 98, 97, 96, 95];
    assert!(levels.len() >= 5 && levels[0] == 100, "{levels:?}");
    assert!(
        levels.iter().all(|l| all.contains(l)) && levels.windows(2).all(|w| w[0] > w[1]),
        "{levels:?}"
    );
    let events: Vec<&serde_json::Value> = got
        .iter()
        .filter(|m| m["topic"] == set_poi)
        .map(|m| &m["data"])
        .collect();
    assert!(!events.is_empty(), "{}\n{}", sub.out(), run.err());
    let mut last_seq = 0;
    let mut kinds = [0, 0];
    for e in &events {
        let seq = e["info"]["sequence_number"].as_i64().unwrap();
        assert!(seq >= last_seq.max(1), "{e}");
        last_seq = seq;
        match e["info"]["event_type"].as_i64().unwrap() {
            // REQUEST_RECEIVED: the request, no response.
            1 => {
                kinds[0] += 1;
                let poi = e["request"][0]["poi_number"].as_i64().unwrap();
                assert!((1..=2).contains(&poi), "{e}");
                assert_eq!(e["response"], serde_json::json!([]), "{e}");
            }
            // RESPONSE_SENT: the response, no request.
            2 => {
                kinds[1] += 1;
                assert_eq!(e["response"][0]["is_ok"], true, "{e}");
                assert_eq!(e["request"], serde_json::json!([]), "{e}");
            }
            other => panic!("event type {other}: {e}"),
        }
    }
    assert!(kinds[0] >= 1, "{kinds:?}");
}

/// An unknown `--wait-match` topic is refused (exit 2) naming what the run publishes; a
/// `--qos` of a topic the run does not publish or with a setting ROS 2 has no name for
/// too.
#[test]
fn run_ros2_refuses_what_it_does_not_support() {
    let out = hindsight()
        .arg("run")
        .arg(museum())
        .args(["--ros2", "--wait-match", "/nope", "--duration", "1s"])
        .env("ROS_DOMAIN_ID", domain(13).to_string())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--wait-match /nope: the run does not publish it"),
        "{err}"
    );
    assert!(err.contains("/BatteryComponent/battery_level"), "{err}");
    let out = hindsight()
        .arg("run")
        .arg(museum())
        .args(["--wait-match", "/x"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "--wait-match needs --ros2");
    for (flag, says) in [
        (
            "/BatteryComponent/battery_level=reliability=sometimes",
            "QoS reliability=`sometimes`",
        ),
        ("/nope=depth=1", "the run does not publish `/nope`"),
    ] {
        let out = hindsight()
            .arg("run")
            .arg(museum())
            .args(["--ros2", "--duration", "1s", "--qos", flag])
            .env("ROS_DOMAIN_ID", domain(15).to_string())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flag}: {err}");
        assert!(err.contains(says), "{flag}: {err}");
    }
}

/// `run --ros2 --external Asker`: a ROS 2 client written with Cyclone DDS, heading each
/// request with the request id rmw_cyclonedds writes (`host/tests/data/dds/cyclone.py
/// call`), stands in for the model's Asker and calls the model's `/adder/add`
/// (`example_interfaces/srv/AddTwoInts`, on `rq/adder/addRequest`); the model's Adder
/// answers on `rr/adder/addReply` with the request's id: the client gets each sum, for
/// its own requests, in order.
#[test]
fn a_cyclone_client_calls_a_service_the_model_serves() {
    let Some(py) = python() else { return };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let d = domain(16);
    let mut run = hindsight();
    run.arg("run")
        .arg(common::dds::data("adder"))
        .args(["--ros2", "--external", "Asker", "--speed", "10"])
        .args(["--duration", "900s"])
        .env("ROS_DOMAIN_ID", d.to_string());
    let mut run = Proc::start(run, "hindsight run --ros2 --external Asker");
    run.wait_for(
        "run: serving /adder/add to ROS 2 clients on rq/adder/addRequest and rr/adder/addReply",
        Duration::from_secs(60),
    );
    let spec = serde_json::json!({
        "service": "/adder/add",
        "calls": [[0, 7], [100, 7], [200, 7]],
        "seconds": 60,
    });
    let mut client = common::dds::cyclone(&py, "call", d, &spec.to_string());
    assert!(
        client.wait(Duration::from_secs(90)).success(),
        "{}\n{}",
        client.err(),
        run.err()
    );
    let got: Vec<(i64, i64)> = client
        .json_lines()
        .iter()
        .map(|l| (l["seq"].as_i64().unwrap(), l["sum"].as_i64().unwrap()))
        .collect();
    assert_eq!(got, [(1, 7), (2, 107), (3, 207)], "{}", run.err());
    assert!(
        run.interrupt(Duration::from_secs(60)).success(),
        "{}",
        run.err()
    );
    assert!(
        run.err().contains(
            "run: serving /adder/add on DDS: 3 requests from ROS 2 clients, 3 answered, 0 malformed"
        ),
        "{}",
        run.err()
    );
}

/// The five requirements of the museum guide.
const REQUIREMENTS: [&str; 5] = [
    "absence",
    "alarm_response",
    "battery_recurrence",
    "poi_response",
    "visitors_recurrence",
];

/// The topics the museum's properties read (what the monitor subscribes to).
const MUSEUM_TOPICS: [&str; 5] = [
    "/BatteryComponent/battery_level",
    "/PeopleDetectorFilterComponent/is_followed",
    "/NotifyUserComponent/StartAlarm/_service_event",
    "/SchedulerComponent/SetPoi/_service_event",
    "/BlackboardComponent/SetInt/_service_event",
];

/// A verdict as a point's value: `true` or `false` (`currently_` dropped), `unknown`.
fn value_of(verdict: &str) -> &str {
    verdict.strip_prefix("currently_").unwrap_or(verdict)
}

/// The museum guide's `properties.xml`, unedited, three ways: `verify` on the model;
/// `monitor --ros2` live while `run --ros2` plays run 0 of seed 1 over DDS (recording
/// what it received); `replay` of that recording. At every recorded message the live
/// verdicts are the replayed ones (for the two recurrences, judged on arrival times,
/// live also sees lateness between messages); the three requirements on values and
/// order hold while the run lasts, as `verify` finds all five do in every run of the
/// model (run 0 among them); the run was long enough
/// for the battery to run low and the alarm to go off, so the response requirements were
/// exercised. Both processes are ours: no Python needed.
#[test]
fn the_museum_three_ways_agree() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let d = domain(14);
    let dir = scratch("museum");
    let props = museum().join("properties.xml");
    let rec = dir.join("museum.mcap");
    let live = dir.join("live.jsonl");
    // Speed 2: a model step of 100 ms takes 50 ms of wall-clock time; a recurrence of 1 s
    // fails only if the system stalls for half a second (as in live_museum.rs).
    let mut monitor = hindsight();
    monitor
        .arg("monitor")
        .arg("--ros2")
        .arg(&props)
        .args(["--speed", "2", "--from-first-message", "--record"])
        .arg(&rec)
        .arg("-o")
        .arg(&live)
        .env("ROS_DOMAIN_ID", d.to_string());
    let mut monitor = Proc::start(monitor, "hindsight monitor --ros2");
    monitor.wait_for("monitor: ready", Duration::from_secs(60));
    let mut run = hindsight();
    run.arg("run")
        .arg(museum())
        .args(["--ros2", "--speed", "2", "--duration", "80s", "--seed", "1"])
        .env("ROS_DOMAIN_ID", d.to_string());
    for t in MUSEUM_TOPICS {
        run.args(["--wait-match", t]);
    }
    let mut run = Proc::start(run, "hindsight run --ros2");
    assert!(
        run.wait(Duration::from_secs(600)).success(),
        "{}",
        run.err()
    );
    // The run waited for every sample to be acknowledged; give the monitor's loop a
    // moment to judge the last ones.
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        monitor.interrupt(Duration::from_secs(60)).success(),
        "{}",
        monitor.err()
    );
    let log = monitor.err();
    for t in MUSEUM_TOPICS {
        assert!(log.contains(&format!("monitor: {t}: ")), "{t}\n{log}");
    }
    let alarms = log
        .lines()
        .find_map(|l| {
            l.strip_prefix("monitor: /NotifyUserComponent/StartAlarm/_service_event: ")?
                .split(' ')
                .next()?
                .parse::<u64>()
                .ok()
        })
        .unwrap_or(0);
    assert!(alarms >= 1, "no alarm in the run:\n{log}");
    // Live verdict lines: (property, time, verdict).
    let lines: Vec<(String, u64, String)> = std::fs::read_to_string(&live)
        .unwrap()
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            (
                v["property"].as_str().unwrap().to_string(),
                v["time"].as_u64().unwrap(),
                v["verdict"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    // Replayed: one row per recorded message, in the monitor's unit.
    let out = hindsight()
        .arg("replay")
        .arg(&props)
        .arg(&rec)
        .args(["--time-unit", "1ms"])
        .output()
        .unwrap();
    let csv = String::from_utf8(out.stdout).unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut rows = csv.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    assert_eq!(header[0], "time");
    let mut sorted = header[1..].to_vec();
    sorted.sort_unstable();
    assert_eq!(sorted, REQUIREMENTS, "{csv:.300}");
    let mut points = 0;
    let mut last = 0;
    for row in rows {
        let cells: Vec<&str> = row.split(',').collect();
        let t: u64 = cells[0].parse().unwrap();
        last = t;
        points += 1;
        for (p, replayed) in header[1..].iter().zip(&cells[1..]) {
            let at = lines
                .iter()
                .rfind(|(q, lt, _)| q == p && *lt <= t)
                .map_or("none", |(_, _, v)| value_of(v));
            if p.ends_with("_recurrence") {
                // Judged on when samples arrived. Live, heartbeats between samples also
                // see a topic late (a sample that DDS or a loaded machine delays past
                // the bound); the recording has no point there: what the replay finds
                // false, the live monitor found false, not always the converse.
                assert!(
                    *replayed == "true" || at == "false" || at == "unknown",
                    "{p} at {t} ms: live {at}, replayed {replayed}\nlive: {lines:?}"
                );
            } else {
                // While the run lasts, the requirements on values and order hold.
                assert_eq!(*replayed, "true", "{p} at {t} ms");
                if at == "unknown" {
                    // Live, a sample that came more than --max-latency after it was sent
                    // (or a lost one) makes the properties reading it unknown for a
                    // while; the recording keeps no lateness.
                    assert!(
                        log.contains("is late: sent at tick") || log.contains("samples lost"),
                        "{p} at {t} ms: live unknown with nothing late or lost\n{log}"
                    );
                    continue;
                }
                assert_eq!(
                    at, *replayed,
                    "{p} at {t} ms: live {at}, replayed {replayed}\nlive: {lines:?}"
                );
            }
        }
    }
    // 80 s of model time, at least one battery sample a second, visitors, services.
    assert!(points >= 160, "{points} points");
    assert!(last >= 75_000, "the last message at {last} ms");
    // verify: every requirement holds in every run of the model, run 0 of seed 1 among
    // them.
    let out = hindsight()
        .arg("verify")
        .arg(museum())
        .args([
            "--max-runs",
            "20",
            "--max-time",
            "80s",
            "--seed",
            "1",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for p in REQUIREMENTS {
        let r = report["properties"]
            .as_array()
            .unwrap()
            .iter()
            .find(|x| x["property"] == p)
            .unwrap_or_else(|| panic!("{p}: {report}"));
        assert_eq!(r["successes"], r["runs"], "{r}");
    }
    let _ = std::fs::remove_dir_all(dir);
}
