//! The properties written once: `hindsight monitor --model` runs the guarantees `verify`
//! compiles from a robot model's ROS-named property file, and its input logs replay.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

use hindsight::cli::monitor::guarantees_spec;
use hindsight::cli::verify::ModelArgs;

/// Runs `hindsight` from the repository root: exit code, stdout, stderr.
fn hindsight(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run hindsight");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

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
    let err = parse("[clock]\nspeed = 0\n").unwrap_err();
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
