//! `hindsight monitor` as a process: help, config errors with positions, signals, replay.

mod live_common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;
use live_common::*;

fn hindsight() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn help_teaches_the_config_and_the_verdicts() {
    let out = hindsight().args(["monitor", "--help"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for want in [
        "How it works",
        "currently_false",
        "[[topic]]",
        "--replay",
        "Exit codes",
    ] {
        assert!(text.contains(want), "missing {want}: {text}");
    }
}

#[test]
fn bad_configs_exit_2_naming_file_line_and_column() {
    let dir = scratch("badcfg");
    let spec = write(&dir, "s.hspec", SPEC);
    let cases = [
        // (config, expected message)
        (
            "[[topic]]\nservice = \"a\"\nsize = 4\n[[topic.field]]\nvar = \"battery_level\"\noffset = 0\ntype = \"i33\"\n",
            "c.toml:7:8: unknown type `i33`",
        ),
        (
            "[[topic]]\nservice = \"a\"\nsize = 4\n[[topic.field]]\nvar = \"battery_level\"\noffset = 2\ntype = \"i32\"\n",
            "c.toml:6:10: a i32 at byte 2 does not fit a 4-byte payload",
        ),
        (
            "[[topic]]\nservice = \"a\"\nsize = 4\nevent = \"battery_level\"\n",
            "c.toml:4:9: `battery_level` is a state, not an event",
        ),
        ("[[topic]]\nservice = \"a\"\nsize = 4\ncolour = 1\n", "c.toml:4:1: unknown field `colour`"),
        ("[[topic]\n", "c.toml:1:"),
    ];
    for (config, want) in cases {
        let cfg = write(&dir, "c.toml", config);
        let out = hindsight()
            .args(["monitor", "--props", &spec, "--config", &cfg])
            .output()
            .unwrap();
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(2), "{config}: {err}");
        assert!(err.contains(want), "{config}: want {want}, got {err}");
    }
}

/// Waits until the monitor's tap subscriber exists on `svc` (a sample sent earlier reaches nobody).
fn wait_for_tap(node: &Node<ipc::Service>, svc: &str) {
    let t = Instant::now();
    let name = ServiceName::new(svc).unwrap();
    loop {
        if let Ok(f) = node
            .service_builder(&name)
            .publish_subscribe::<[u8]>()
            .open()
        {
            if f.dynamic_config().number_of_subscribers() > 0 {
                return;
            }
        }
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "the monitor never subscribed to {svc}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Kills the monitor process if the test fails half way.
struct KillOnDrop(Option<std::process::Child>);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        if let Some(c) = self.0.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

#[test]
fn sigint_and_sigterm_flush_the_logs_and_exit_0_and_the_log_replays() {
    for signal in ["-INT", "-TERM"] {
        let dir = scratch("signal");
        let svc = unique("battery");
        let spec = write(&dir, "s.hspec", SPEC);
        let cfg = write(&dir, "c.toml", &battery_topic(&svc));
        let verdicts = dir.join("v.jsonl");
        let input = dir.join("in.jsonl");
        let mut guard = KillOnDrop(Some(
            hindsight()
                .args([
                    "monitor",
                    "--every-point",
                    "--props",
                    &spec,
                    "--config",
                    &cfg,
                    "-o",
                ])
                .arg(&verdicts)
                .arg("--record")
                .arg(&input)
                .stderr(Stdio::piped())
                .spawn()
                .unwrap(),
        ));
        let pid = guard.0.as_ref().unwrap().id();
        let node = node();
        wait_for_tap(&node, &svc);
        let p = publisher(&node, &svc);
        send(&p, &battery(20, 0));
        // The input log is buffered until exit; verdicts are flushed when idle, and with
        // --every-point each point writes lines naming its event: wait for the sample's.
        let t = Instant::now();
        let judged = format!("\"event\":\"{svc}\"");
        while !std::fs::read_to_string(&verdicts)
            .unwrap_or_default()
            .contains(&judged)
        {
            assert!(t.elapsed() < Duration::from_secs(30), "no verdicts written");
            std::thread::sleep(Duration::from_millis(10));
        }
        let status = Command::new("kill")
            .args([signal, &pid.to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let out = guard.0.take().unwrap().wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{signal}: {err}");
        let log = std::fs::read_to_string(&input).unwrap();
        let live = std::fs::read_to_string(&verdicts).unwrap();
        assert!(
            err.contains("1 judged, 0 lost"),
            "{signal}: {err}\n{log}\n{live}"
        );
        assert!(log.contains("\"battery_level\":20"), "{log}");
        let live = std::fs::read_to_string(&verdicts).unwrap();
        let replay = hindsight()
            .args(["monitor", "--every-point", "--props", &spec, "--replay"])
            .arg(&input)
            .output()
            .unwrap();
        assert!(replay.status.success());
        assert_eq!(String::from_utf8(replay.stdout).unwrap(), live);
    }
}
