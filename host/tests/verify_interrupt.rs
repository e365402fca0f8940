//! Ctrl-C (SIGINT) and SIGTERM on `hindsight verify`: the study stops, the runs done are
//! printed as a partial study (table and JSON, marked as such), the exit code is 130, and
//! the partial study is the study of the first N runs (`--max-runs N` gives the same
//! numbers), so no finished run is lost and none is taken out of order. The runner's
//! stop flag itself is tested without signals, on 1 and 4 threads.
#![cfg(target_os = "linux")]

use std::io::Read;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::sleep;
use std::time::{Duration, Instant};

use hindsight::verify::smc::{
    run_study, run_study_until, RuleConfig, RuleKind, RunEnd, RunOutcome, StoppingRule,
    StudyConfig, Verdict,
};
use rand_core::Rng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// How long the test waits for anything (the handler to be installed, the process to end)
/// before it kills the process and fails: a bound, so that the test cannot hang.
const BOUND: Duration = Duration::from_secs(120);

/// The Okamoto rule's run count for confidence 0.95 and precision 0.002:
/// ceil(ln(2 / 0.05) / (2 * 0.002^2)), far more runs than the test waits for.
const FULL_RUNS: u64 = 461_110;

fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

/// `verify` of the museum guide under a fixed-run rule that takes very long.
fn study_args(extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = [
        "verify",
        "--seed",
        "1",
        "--threads",
        "2",
        "--rule",
        "okamoto",
        "--precision",
        "0.002",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.insert(1, museum().display().to_string());
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// Kills the child (if still running) when dropped, so a failed assertion leaves no
/// process behind.
struct Guard(Child);

impl Drop for Guard {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Whether the process runs ctrlc's handler thread (named `ctrl-c`): the handler is
/// installed, so a signal now stops the study instead of killing the process.
fn handler_installed(pid: u32) -> bool {
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return false;
    };
    tasks.flatten().any(|task| {
        std::fs::read_to_string(task.path().join("comm")).is_ok_and(|name| name.trim() == "ctrl-c")
    })
}

/// Starts the study, waits until its handler is installed and some runs are done, sends
/// `signal`, and returns (exit code, stdout, stderr).
fn interrupted(signal: &str, extra: &[&str]) -> (Option<i32>, String, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(study_args(extra))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start hindsight");
    let mut guard = Guard(child);
    let pid = guard.0.id();
    let start = Instant::now();
    while !handler_installed(pid) {
        assert!(
            guard.0.try_wait().expect("poll hindsight").is_none(),
            "hindsight ended before its study started"
        );
        assert!(
            start.elapsed() < BOUND,
            "the study did not start in {BOUND:?}"
        );
        sleep(Duration::from_millis(20));
    }
    // Let some runs finish (a debug build runs the museum at tens of runs per second).
    sleep(Duration::from_millis(1500));
    let sent = Command::new("kill")
        .args([signal, &pid.to_string()])
        .status()
        .expect("run kill");
    assert!(sent.success(), "kill {signal} {pid} failed");
    let signalled = Instant::now();
    let status = loop {
        if let Some(status) = guard.0.try_wait().expect("poll hindsight") {
            break status;
        }
        assert!(
            signalled.elapsed() < BOUND,
            "hindsight did not stop within {BOUND:?} of {signal}"
        );
        sleep(Duration::from_millis(20));
    };
    let (mut stdout, mut stderr) = (String::new(), String::new());
    if let Some(out) = guard.0.stdout.as_mut() {
        out.read_to_string(&mut stdout).expect("read stdout");
    }
    if let Some(err) = guard.0.stderr.as_mut() {
        err.read_to_string(&mut stderr).expect("read stderr");
    }
    (status.code(), stdout, stderr)
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("not JSON ({e}):\n{text}"))
}

#[test]
fn sigint_prints_the_partial_table_and_exits_130() {
    let (code, stdout, stderr) = interrupted("-INT", &[]);
    assert_eq!(code, Some(130), "stdout:\n{stdout}\nstderr:\n{stderr}");
    let first = stdout.lines().next().unwrap_or("");
    let runs: u64 = first
        .strip_prefix("interrupted after ")
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no partial-study line first:\n{stdout}"));
    assert!(
        first.ends_with(
            "the numbers below are a partial study, their intervals are those of the runs done"
        ),
        "{first}"
    );
    assert!(runs > 0 && runs < FULL_RUNS, "{runs} runs:\n{stdout}");
    // The table follows, with its summary line counting the same runs.
    assert!(stdout.contains("property"), "{stdout}");
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with(&format!("{runs} runs"))),
        "{stdout}"
    );
    assert!(
        stderr.contains(&format!("interrupted after {runs} runs")),
        "{stderr}"
    );
}

#[test]
fn sigterm_prints_partial_json_equal_to_the_first_runs() {
    let (code, stdout, stderr) = interrupted("-TERM", &["--json"]);
    assert_eq!(code, Some(130), "stdout:\n{stdout}\nstderr:\n{stderr}");
    let partial = json(&stdout);
    assert_eq!(partial["interrupted"], true, "{stdout}");
    let runs = partial["runs"].as_u64().expect("runs");
    assert!(runs > 0 && runs < FULL_RUNS, "{runs} runs");
    let properties = partial["properties"].as_array().expect("properties");
    assert!(!properties.is_empty());
    for p in properties {
        assert!(p["runs"].as_u64().expect("judged runs") <= runs, "{p}");
    }

    // The partial study is the study of runs 0..runs, consumed in order: the same
    // numbers as a study capped there, which is not marked as interrupted.
    let capped = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(study_args(&["--json", "--max-runs", &runs.to_string()]))
        .output()
        .expect("run hindsight");
    assert!(capped.status.success(), "{capped:?}");
    let capped = json(&String::from_utf8_lossy(&capped.stdout));
    assert!(capped.get("interrupted").is_none(), "{capped}");
    assert_eq!(capped["runs"], partial["runs"]);
    assert_eq!(capped["properties"], partial["properties"]);
}

/// A run whose one property holds with probability 1/2, from its stream.
fn coin(_: u64, rng: &mut Xoshiro256PlusPlus) -> RunOutcome {
    RunOutcome {
        verdicts: vec![Verdict::from(rng.next_u64() % 2 == 0)],
        assumptions: Verdict::True,
        end: RunEnd::Quiescent,
        steps: 1,
        time: 1,
    }
}

fn okamoto() -> Vec<Box<dyn StoppingRule>> {
    vec![RuleConfig {
        kind: RuleKind::Okamoto,
        confidence: 0.95,
        precision: 0.002,
    }
    .build()
    .expect("valid rule")]
}

#[test]
fn a_stop_flag_ends_the_study_on_a_prefix_of_the_runs() {
    for threads in [1, 4] {
        let config = StudyConfig {
            seed: 7,
            threads,
            ..StudyConfig::default()
        };
        // Set while run 500 runs: later runs may still start before the workers see it.
        let stop = AtomicBool::new(false);
        let partial = run_study_until(
            &config,
            &okamoto(),
            |k, rng| {
                if k == 500 {
                    stop.store(true, Ordering::Relaxed);
                }
                coin(k, rng)
            },
            &mut |_| {},
            &stop,
        );
        assert!(partial.interrupted && partial.capped, "{threads} threads");
        let n = partial.runs.runs;
        assert!(
            (501..FULL_RUNS).contains(&n),
            "{threads} threads: {n} runs consumed"
        );
        // Exactly the study of runs 0..n: nothing lost, nothing out of order.
        let capped = run_study(
            &StudyConfig {
                max_runs: Some(n),
                ..config.clone()
            },
            &okamoto(),
            coin,
            &mut |_| {},
        );
        assert!(!capped.interrupted && capped.capped);
        assert_eq!(capped.runs, partial.runs, "{threads} threads");
        assert_eq!(capped.properties, partial.properties, "{threads} threads");
    }
    // A flag set before the study: no run at all.
    let stop = AtomicBool::new(true);
    let none = run_study_until(
        &StudyConfig {
            threads: 2,
            ..StudyConfig::default()
        },
        &okamoto(),
        coin,
        &mut |_| {},
        &stop,
    );
    assert_eq!(none.runs.runs, 0);
    assert!(none.interrupted);
}
