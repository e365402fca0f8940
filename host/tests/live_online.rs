//! The properties written once: `hindsight monitor --model` runs the guarantees `verify`
//! compiles from a robot model's ROS-named property file, and its input logs replay.

mod live_common;

mod common;

use common::hindsight;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use hindsight::cli::monitor::guarantees_spec;
use hindsight::cli::verify::ModelArgs;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A fresh scratch directory for this process and call.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "hindsight-online-{}-{}-{tag}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::SeqCst)
    ));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// An input log with a point at every tick from 0 to `end`: a battery sample (level,
/// published) at the given times, an alarm request at `alarm`, heartbeats elsewhere.
fn museum_log(end: u64, battery: &[(u64, i64)], alarm: Option<u64>) -> String {
    let mut out = String::new();
    for t in 0..=end {
        let line = if let Some(&(_, level)) = battery.iter().find(|(at, _)| *at == t) {
            format!(
                r#"{{"kind":"sample","time":{t},"source":"museum/battery","sets":{{"battery_level":{level},"battery_published":true}}}}"#
            )
        } else if alarm == Some(t) {
            format!(
                r#"{{"kind":"request","time":{t},"source":"museum/alarm","sets":{{"alarm":true}},"filter":null}}"#
            )
        } else {
            format!(r#"{{"kind":"tick","time":{t}}}"#)
        };
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// `(property, time, verdict)` of every verdict line.
fn verdicts(stdout: &str) -> Vec<(String, u64, String)> {
    stdout
        .lines()
        .map(|l| {
            let v: hindsight::live::record::VerdictLine = serde_json::from_str(l).unwrap();
            (v.property, v.time, v.verdict)
        })
        .collect()
}

#[test]
fn the_museum_guarantees_compile_for_the_monitor_over_their_port_names() {
    let spec = guarantees_spec(&ModelArgs {
        model: root().join("examples/museum-guide"),
        props: None,
        time_unit: None,
        events: None,
        ..ModelArgs::default()
    })
    .unwrap();
    let names: Vec<&str> = spec.property_names().collect();
    assert_eq!(
        names,
        [
            "absence",
            "alarm_response",
            "battery_recurrence",
            "poi_response",
            "visitors_recurrence"
        ]
    );
    // The tick is the model's time unit, 100 ms.
    assert_eq!(spec.tick_ns(), 100_000_000);
    for var in [
        "battery_level",
        "battery_published",
        "alarm",
        "current_poi",
        "poi_done_name",
        "poi_done_value",
        "visitors_published",
    ] {
        assert!(spec.var_index(var).is_some(), "no variable {var}");
    }
}

#[test]
fn a_log_replays_against_the_museum_guarantees_with_a_late_battery_sample() {
    let dir = scratch("late");
    // Battery samples 10 ticks (1 s) apart, then 12: the tick at 31 is the first point
    // with no publication within 1 s.
    let log = write(
        &dir,
        "in.jsonl",
        &museum_log(32, &[(0, 100), (10, 99), (20, 98), (32, 97)], None),
    );
    let (code, out, err) = hindsight(&[
        "monitor",
        "--model",
        "examples/museum-guide",
        "--replay",
        &log,
    ]);
    assert_eq!(code, 0, "{err}");
    let v = verdicts(&out);
    let battery: Vec<_> = v
        .iter()
        .filter(|(p, ..)| p == "battery_recurrence")
        .collect();
    assert_eq!(
        battery,
        [
            &(
                "battery_recurrence".to_string(),
                0,
                "currently_true".to_string()
            ),
            &("battery_recurrence".to_string(), 31, "false".to_string()),
        ]
    );
    // No alarm, battery high: absence and alarm_response hold.
    for p in ["absence", "alarm_response"] {
        let last = v.iter().rfind(|(q, ..)| q == p).unwrap();
        assert_eq!(last.2, "currently_true", "{p}: {out}");
    }
    // A model given to --props reads the same way.
    let (code, same, err) = hindsight(&[
        "monitor",
        "--props",
        "examples/museum-guide",
        "--replay",
        &log,
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(same, out);
}

#[test]
fn an_alarm_too_late_after_low_battery_fails_alarm_response_on_time() {
    let dir = scratch("alarm");
    // The battery drops to 29 at tick 5 (samples every 10 ticks from 5 on); the alarm
    // comes 63 ticks later: at 5 + 62 no alarm has come for 6.2 s since a low level.
    let battery: Vec<(u64, i64)> = (0..8).map(|k| (5 + 10 * k, 29 - k as i64)).collect();
    let log = write(&dir, "in.jsonl", &museum_log(70, &battery, Some(68)));
    let (code, out, err) = hindsight(&[
        "monitor",
        "--model",
        "examples/museum-guide",
        "--replay",
        &log,
    ]);
    assert_eq!(code, 0, "{err}");
    let v = verdicts(&out);
    let alarm: Vec<_> = v.iter().filter(|(p, ..)| p == "alarm_response").collect();
    assert_eq!(alarm.len(), 2, "{out}");
    assert_eq!((alarm[1].1, alarm[1].2.as_str()), (67, "false"));
    // absence: the alarm came with the battery below 30.
    assert!(
        v.iter()
            .all(|(p, _, x)| p != "absence" || x == "currently_true"),
        "{out}"
    );
}

#[test]
fn bad_monitor_inputs_exit_2_and_say_why() {
    let dir = scratch("bad");
    let log = write(
        &dir,
        "in.jsonl",
        "{\"kind\":\"tick\",\"time\":0}\n{\"kind\":\"sample\",\"time\":1,\"source\":\"s\",\"sets\":{\"battery\":1}}\n",
    );
    let spec = write(
        &dir,
        "s.hspec",
        "unit 1ms;\nevent e;\nproperty p = H({e});\n",
    );
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec![
                "monitor",
                "--model",
                "examples/museum-guide",
                "--replay",
                &log,
            ],
            "in.jsonl:2:1: `battery` is not a variable of the spec",
        ),
        (
            vec!["monitor", "--model", "no/such/model", "--replay", &log],
            "no/such/model",
        ),
        (
            vec![
                "monitor",
                "--model",
                "examples/museum-guide",
                "--model-props",
                "examples/museum-guide/none.xml",
                "--replay",
                &log,
            ],
            "none.xml",
        ),
        (
            vec![
                "monitor",
                "--props",
                "examples/museum-guide/properties.xml",
                "--replay",
                &log,
            ],
            "hint: --props read a folder or an .xml file as a model",
        ),
        (
            vec![
                "monitor",
                "--props",
                &spec,
                "--time-unit",
                "1ms",
                "--replay",
                &log,
            ],
            "--model-props and --time-unit go with a model",
        ),
        (
            vec![
                "monitor",
                "--props",
                &spec,
                "--model",
                "examples/museum-guide",
                "--replay",
                &log,
            ],
            "cannot be used with",
        ),
    ];
    for (args, want) in cases {
        let (code, _, err) = hindsight(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: want {want}, got {err}");
    }
}

#[test]
fn the_config_clock_speed_is_read_and_checked() {
    let spec =
        codegen::compile_spec("unit 100ms;\nevent e;\nproperty p = H({e});\n", "s.hspec").unwrap();
    let topic = "[[topic]]\nservice = \"x/y\"\nsize = 1\nevent = \"e\"\n";
    let parse = |clock: &str| {
        hindsight::live::config::Config::parse(&format!("{clock}{topic}"), "c.toml", &spec)
    };
    assert_eq!(parse("").unwrap().speed, 1.0);
    assert_eq!(parse("[clock]\nspeed = 10\n").unwrap().speed, 10.0);
    assert_eq!(parse("[clock]\nspeed = 0.5\n").unwrap().speed, 0.5);
    let err = parse("[clock]\nspeed = 0\n").unwrap_err().to_string();
    assert!(
        err.starts_with("c.toml:2:9: speed 0: must be a number"),
        "{err}"
    );
}

#[test]
fn a_bad_speed_on_the_command_line_exits_2() {
    let dir = scratch("speed");
    let spec = write(
        &dir,
        "s.hspec",
        "unit 100ms;\nevent e;\nproperty p = H({e});\n",
    );
    let cfg = write(
        &dir,
        "c.toml",
        "[[topic]]\nservice = \"x/y\"\nsize = 1\nevent = \"e\"\n",
    );
    let (code, _, err) = hindsight(&[
        "monitor", "--props", &spec, "--config", &cfg, "--speed", "0",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--speed: speed 0: must be a number"), "{err}");
    // --speed means nothing to a replay.
    let (code, _, err) = hindsight(&[
        "monitor", "--props", &spec, "--replay", &cfg, "--speed", "2",
    ]);
    assert_eq!(code, 2, "{err}");
}

/// A sidecar input log with a heartbeat at every tick from 0 to `end`, then at the same
/// time the battery sample (level) and the alarm request of that tick, as the sidecar
/// writes them when a sample arrives after its tick's heartbeat.
fn heartbeat_log(
    end: u64,
    battery: &[(u64, i64)],
    alarm: Option<u64>,
    tick_at_alarm: bool,
) -> String {
    let mut out = String::new();
    for t in 0..=end {
        if alarm != Some(t) || tick_at_alarm {
            out.push_str(&format!("{{\"kind\":\"tick\",\"time\":{t}}}\n"));
        }
        if let Some(&(_, level)) = battery.iter().find(|(at, _)| *at == t) {
            out.push_str(&format!(
                "{{\"kind\":\"sample\",\"time\":{t},\"source\":\"museum/battery\",\"sets\":{{\"battery_level\":{level},\"battery_published\":true}}}}\n"
            ));
        }
        if alarm == Some(t) {
            // A filtered request: the sweep judges it as the point it would have been.
            out.push_str(&format!(
                "{{\"kind\":\"request\",\"time\":{t},\"source\":\"museum/alarm\",\"sets\":{{\"alarm\":true}},\"filter\":[\"alarm_response\"]}}\n"
            ));
        }
    }
    out
}

/// `sweep --online ... --json`: the report.
fn online_sweep(logs: &[&str], property: &str, from: &str, to: &str) -> serde_json::Value {
    let mut args = vec!["sweep", "examples/museum-guide"];
    for l in logs {
        args.extend(["--online", l]);
    }
    args.extend(["--property", property, "--from", from, "--to", to, "--json"]);
    let (code, out, err) = hindsight(&args);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).unwrap()
}

/// `(bound, successes, failures, unknown)` of every point of the report's only property.
fn rows(report: &serde_json::Value) -> Vec<(String, u64, u64, u64)> {
    report["properties"][0]["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["bound"].as_str().unwrap().to_string(),
                p["successes"].as_u64().unwrap(),
                p["failures"].as_u64().unwrap(),
                p["unknown"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn online_sweep_finds_the_battery_recurrence_threshold_of_a_recorded_run() {
    let dir = scratch("sweep-battery");
    let battery: Vec<(u64, i64)> = (0..5).map(|k| (10 * k, 100 - k as i64)).collect();
    let log = write(&dir, "rec.jsonl", &heartbeat_log(40, &battery, None, true));
    let r = online_sweep(&[&log], "battery_recurrence", "0.5s", "1.5s");
    assert_eq!(r["runs"], 1);
    assert_eq!(r["properties"][0]["threshold"], "1s");
    let rows = rows(&r);
    assert_eq!(rows.len(), 11);
    // Samples 10 ticks apart with a heartbeat before each: 0.9 s misses at the heartbeat.
    assert_eq!(rows[4], ("0.9s".to_string(), 0, 1, 0));
    assert_eq!(rows[5], ("1s".to_string(), 1, 0, 0));
    assert_eq!(rows[10], ("1.5s".to_string(), 1, 0, 0));
    // A monitor started 2 s before the system and stopped 3 s after it: its heartbeats
    // while waiting are not the run, and the same threshold comes out.
    let battery: Vec<(u64, i64)> = (2..5).map(|k| (10 * k, 100 - k as i64)).collect();
    let waiting = write(&dir, "wait.jsonl", &heartbeat_log(70, &battery, None, true));
    let again = online_sweep(&[&waiting], "battery_recurrence", "0.5s", "1.5s");
    assert_eq!(again["properties"][0]["threshold"], "1s");
    assert_eq!(self::rows(&again), rows);
}

#[test]
fn a_run_spans_its_first_to_its_last_message() {
    use hindsight::live::record::{parse_log, run_span, Input};
    let log = "{\"kind\":\"start\",\"unit_ns\":100000000,\"speed\":1.0}\n\
               {\"kind\":\"tick\",\"time\":0}\n\
               {\"kind\":\"tick\",\"time\":1}\n\
               {\"kind\":\"sample\",\"time\":1,\"source\":\"s\",\"sets\":{}}\n\
               {\"kind\":\"tick\",\"time\":2}\n\
               {\"kind\":\"request\",\"time\":3,\"source\":\"r\",\"sets\":{},\"filter\":null}\n\
               {\"kind\":\"tick\",\"time\":3}\n\
               {\"kind\":\"tick\",\"time\":4}\n";
    let records = parse_log(log, "l.jsonl").unwrap();
    let kept: Vec<usize> = run_span(&records).iter().map(|(line, _)| *line).collect();
    // The start record, the tick at the first sample's time, and everything up to the
    // last message's time; not the ticks at 0 and 4.
    assert_eq!(kept, [1, 3, 4, 5, 6, 7]);
    // Without a message the log is kept whole.
    let ticks = parse_log("{\"kind\":\"tick\",\"time\":0}\n", "t.jsonl").unwrap();
    assert_eq!(run_span(&ticks), [(1, Input::Tick { time: 0 })]);
}

#[test]
fn online_sweep_finds_the_alarm_response_threshold_with_the_offline_boundary() {
    let dir = scratch("sweep-alarm");
    let battery = [(0, 40), (5, 29), (15, 28), (25, 27)];
    // The level drops below 30 at tick 5 and the alarm comes at tick 30, 25 ticks later.
    // With the heartbeat of tick 30 before the alarm (the sidecar's order when the alarm
    // arrives after its tick began, and the off-line order: a time advance, then the
    // send), the point at 30 has gone 2.5 s without an alarm, so `since[2.5s:]` fails and
    // the threshold is one tick more: 2.6 s. Off-line alike, the museum's alarms 61 ticks
    // apart give its 6.2 s.
    let late = write(
        &dir,
        "late.jsonl",
        &heartbeat_log(30, &battery, Some(30), true),
    );
    let r = online_sweep(&[&late], "alarm_response", "2.0s", "3.0s");
    assert_eq!(r["properties"][0]["threshold"], "2.6s");
    assert_eq!(rows(&r)[5], ("2.5s".to_string(), 0, 1, 0));
    assert_eq!(rows(&r)[6], ("2.6s".to_string(), 1, 0, 0));
    // Without a heartbeat at the alarm's tick the last alarm-free point is 2.4 s after
    // the drop: the threshold is the delay itself, 2.5 s.
    let direct = write(
        &dir,
        "direct.jsonl",
        &heartbeat_log(30, &battery, Some(30), false),
    );
    let r = online_sweep(&[&direct], "alarm_response", "2.0s", "3.0s");
    assert_eq!(r["properties"][0]["threshold"], "2.5s");
    // Two logs are two runs: each bound counts both, the threshold is the later one.
    let quick = write(
        &dir,
        "quick.jsonl",
        &heartbeat_log(25, &battery, Some(25), true),
    );
    let r = online_sweep(&[&late, &quick], "alarm_response", "1.5s", "3s");
    assert_eq!(r["runs"], 2);
    assert_eq!(r["properties"][0]["threshold"], "2.6s");
    let rows = rows(&r);
    assert_eq!(rows[5], ("2s".to_string(), 0, 2, 0));
    assert_eq!(rows[6], ("2.1s".to_string(), 1, 1, 0));
    assert_eq!(rows[11], ("2.6s".to_string(), 2, 0, 0));
    let p = &r["properties"][0]["points"][6];
    assert_eq!(p["probability"], 0.5);
}

#[test]
fn online_sweep_prints_the_offline_csv_and_draws_the_chart() {
    let dir = scratch("sweep-csv");
    let battery: Vec<(u64, i64)> = (0..3).map(|k| (10 * k, 100 - k as i64)).collect();
    let log = write(&dir, "rec.jsonl", &heartbeat_log(20, &battery, None, true));
    let svg = dir.join("s.svg").display().to_string();
    let (code, out, err) = hindsight(&[
        "sweep",
        "examples/museum-guide",
        "--online",
        &log,
        "--property",
        "battery_recurrence",
        "--from",
        "0.9s",
        "--to",
        "1s",
        "--svg",
        &svg,
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        out,
        "property,bound,successes,failures,unknown,probability,lower,upper\n\
         battery_recurrence,0.9s,0,1,0,0.0000,0.0000,0.9750\n\
         battery_recurrence,1s,1,0,0,1.0000,0.0250,1.0000\n"
    );
    assert!(
        err.contains("battery_recurrence: every run succeeds from bound 1s on"),
        "{err}"
    );
    let chart = std::fs::read_to_string(&svg).unwrap();
    assert!(chart.contains("(1 recorded run)"), "{chart}");
}

#[test]
fn online_sweep_rejects_bad_logs_naming_file_and_line() {
    let dir = scratch("sweep-bad");
    let wrong_var = write(
        &dir,
        "var.jsonl",
        "{\"kind\":\"tick\",\"time\":0}\n{\"kind\":\"sample\",\"time\":1,\"source\":\"s\",\"sets\":{\"level\":3}}\n",
    );
    let bad_line = write(
        &dir,
        "line.jsonl",
        "{\"kind\":\"tick\",\"time\":0}\n\n{\"kind\":\"tock\"}\n",
    );
    let backwards = write(
        &dir,
        "back.jsonl",
        "{\"kind\":\"tick\",\"time\":5}\n{\"kind\":\"tick\",\"time\":4}\n",
    );
    let base = [
        "sweep",
        "examples/museum-guide",
        "--from",
        "1s",
        "--to",
        "2s",
    ];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--online", &wrong_var],
            "var.jsonl:2:1: `level` is not a variable of the spec",
        ),
        (vec!["--online", &bad_line], "line.jsonl:3:"),
        (vec!["--online", &backwards], "back.jsonl:2:1:"),
        (vec!["--online", "no/such.jsonl"], "no/such.jsonl"),
        (
            vec!["--online", &backwards, "--runs", "5"],
            "cannot be used with",
        ),
    ];
    for (extra, want) in cases {
        let mut args = base.to_vec();
        args.extend(extra);
        let (code, _, err) = hindsight(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: want {want}, got {err}");
    }
}

#[test]
fn a_recorded_log_starts_with_its_unit_and_replays_only_with_that_unit() {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let dir = scratch("start");
    let spec =
        codegen::compile_spec("unit 100ms;\nevent e;\nproperty p = H({e});\n", "s.hspec").unwrap();
    let service = format!(
        "hindsight-test/{}/{}/start",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::SeqCst)
    );
    let toml = format!(
        "[clock]\nspeed = 10\n[[topic]]\nservice = \"{service}\"\nsize = 1\nevent = \"e\"\n"
    );
    let config = hindsight::live::config::Config::parse(&toml, "c.toml", &spec).unwrap();
    let record = dir.join("in.jsonl");
    let sidecar = hindsight::live::Sidecar::new(&config, &spec, false).unwrap();
    let mut opts = hindsight::live::Options {
        verdicts: Box::new(std::io::sink()),
        record: Some(Box::new(std::fs::File::create(&record).unwrap())),
        every_point: false,
        poll: std::time::Duration::from_micros(100),
        log: Box::new(std::io::sink()),
        progress: None,
        probe: None,
    };
    // Stopped before the first iteration: the log holds the start record only.
    let stop = std::sync::atomic::AtomicBool::new(true);
    sidecar.run(&config, &spec, &mut opts, &stop).unwrap();
    let text = std::fs::read_to_string(&record).unwrap();
    assert_eq!(
        text,
        "{\"kind\":\"start\",\"unit_ns\":100000000,\"speed\":10.0}\n"
    );
    // It replays against its own unit, and not against the museum's spec in another unit.
    assert_eq!(
        hindsight::live::record::replay(&spec, &text, "in.jsonl", false),
        Ok(Vec::new())
    );
    let ms =
        codegen::compile_spec("unit 1ms;\nevent e;\nproperty p = H({e});\n", "t.hspec").unwrap();
    assert_eq!(
        hindsight::live::record::replay(&ms, &text, "in.jsonl", false).map_err(|e| e.to_string()),
        Err(
            "in.jsonl:1:1: the log's ticks are 100ms long, the spec's are 1ms: record and \
             replay with the same unit"
                .to_string()
        )
    );
    // The on-line sweep checks it too: the museum's unit is 100 ms.
    let other = write(
        &dir,
        "ms.jsonl",
        "{\"kind\":\"start\",\"unit_ns\":1000000,\"speed\":1.0}\n{\"kind\":\"tick\",\"time\":0}\n",
    );
    let (code, _, err) = hindsight(&[
        "sweep",
        "examples/museum-guide",
        "--online",
        &other,
        "--from",
        "1s",
        "--to",
        "2s",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("ms.jsonl:1:1: the log's ticks are 1ms long, the spec's are 100ms"),
        "{err}"
    );
}

#[test]
fn from_first_message_judges_nothing_before_the_first_sample() {
    let svc = live_common::unique("first");
    let config = format!(
        "[clock]\nfrom_first_message = true\n{}",
        live_common::battery_topic(&svc)
    );
    let run = live_common::Running::start(&config, "first");
    let node = live_common::node();
    let publisher = live_common::publisher(&node, &svc);
    live_common::send(&publisher, &live_common::battery(50, 0));
    run.wait_judged(1);
    let done = run.finish();
    let kinds: Vec<String> = done
        .record
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["kind"].to_string())
        .collect();
    // The start record, then the sample: no heartbeat while the monitor waited.
    assert_eq!(kinds[..2], ["\"start\"", "\"sample\""], "{}", done.record);
    done.assert_replay_matches();
}

#[test]
fn help_teaches_the_model_the_speed_and_the_online_sweep() {
    let (code, monitor, _) = hindsight(&["monitor", "--help"]);
    assert_eq!(code, 0);
    for want in [
        "--model examples/museum-guide",
        "Assumptions are not monitored",
        "--speed S",
        "ticks = wall-clock time * S / unit",
        "--from-first-message",
        "{\"kind\":\"start\",\"unit_ns\":..}",
        "sweep examples/museum-guide --online run.jsonl --from 0.1s --to 7s",
    ] {
        assert!(
            monitor.contains(want),
            "monitor --help lacks {want}: {monitor}"
        );
    }
    let (code, sweep, _) = hindsight(&["sweep", "--help"]);
    assert_eq!(code, 0);
    for want in [
        "--online <LOG>",
        "each input log",
        "first sample or request to its last",
        "--online run1.jsonl --online run2.jsonl",
    ] {
        assert!(sweep.contains(want), "sweep --help lacks {want}: {sweep}");
    }
}

#[test]
fn a_plain_model_is_monitored_with_its_time_unit_and_without_its_assumptions() {
    let coin = "host/tests/data/verify/coin";
    let props = "host/tests/data/verify/coin/assume-tails.xml";
    let spec = guarantees_spec(&ModelArgs {
        model: root().join(coin),
        props: Some(root().join(props)),
        time_unit: Some("100ms".into()),
        events: None,
        ..ModelArgs::default()
    })
    .unwrap();
    // The guarantee only: the assumption `tails_thrown` is not monitored.
    assert_eq!(spec.property_names().collect::<Vec<_>>(), ["no_heads"]);
    assert_eq!(spec.tick_ns(), 100_000_000);
    let dir = scratch("coin");
    let log = write(
        &dir,
        "in.jsonl",
        "{\"kind\":\"tick\",\"time\":0}\n{\"kind\":\"sample\",\"time\":3,\"source\":\"c\",\"sets\":{\"heads\":true}}\n",
    );
    let (code, out, err) = hindsight(&[
        "monitor",
        "--model",
        coin,
        "--model-props",
        props,
        "--time-unit",
        "100ms",
        "--replay",
        &log,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("1 assumption(s) not monitored"), "{err}");
    assert_eq!(
        verdicts(&out),
        [
            ("no_heads".to_string(), 0, "currently_true".to_string()),
            ("no_heads".to_string(), 3, "false".to_string())
        ]
    );
    // Without a time unit the clock has no tick.
    let (code, _, err) = hindsight(&[
        "monitor",
        "--model",
        coin,
        "--model-props",
        props,
        "--replay",
        &log,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the model has no time unit"), "{err}");
}

#[test]
fn the_recorded_museum_runs_give_the_online_thresholds() {
    // examples/museum-guide/online: three runs of the museum (`run --run K`, K = 0, 1, 2,
    // 100 s at --speed 10) recorded by scripts/record-online (`monitor --model
    // examples/museum-guide --speed 10 --from-first-message --record`). Each requirement
    // steps at its off-line threshold: the live system is the model itself, paced.
    let logs: Vec<String> = (0..3)
        .map(|k| format!("examples/museum-guide/online/run{k}.jsonl"))
        .collect();
    let mut args = vec!["sweep", "examples/museum-guide"];
    for l in &logs {
        args.extend(["--online", l.as_str()]);
    }
    args.extend(["--from", "0.1s", "--to", "7s", "--json"]);
    let (code, out, err) = hindsight(&args);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["runs"], 3);
    let thresholds: Vec<(String, String)> = r["properties"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["property"].as_str().unwrap().to_string(),
                p["threshold"].as_str().unwrap_or("none").to_string(),
            )
        })
        .collect();
    let want = [
        ("alarm_response", "6.2s"),
        ("battery_recurrence", "1s"),
        ("poi_response", "0.2s"),
        ("visitors_recurrence", "1s"),
    ];
    assert_eq!(
        thresholds,
        want.map(|(p, t)| (p.to_string(), t.to_string())).to_vec()
    );
    // Just below each step every run fails, at and above it every run holds.
    for (i, p) in r["properties"].as_array().unwrap().iter().enumerate() {
        let points = p["points"].as_array().unwrap();
        let step = points.iter().position(|x| x["bound"] == want[i].1).unwrap();
        assert_eq!(points[step]["successes"].as_u64(), Some(3), "{p}");
        assert_eq!(points[step - 1]["failures"].as_u64(), Some(3), "{p}");
    }
}
