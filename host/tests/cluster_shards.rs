//! A study run as concurrent shard processes (as `examples/cluster/` runs it on Slurm or
//! Kubernetes) merges into the same numbers and the same report page as one process;
//! `merge` names a missing shard, accepts it once re-run, and counts a shard given twice
//! (identical) once.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const RUNS: &str = "120";
const SEED: &str = "5";
const SHARDS: u64 = 4;

fn hindsight() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
}

fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn shard_command(dir: &Path, i: u64) -> Command {
    let mut c = hindsight();
    c.arg("verify")
        .arg(museum())
        .args(["--seed", SEED, "--runs", RUNS, "--threads", "1"])
        .args(["--shard", &format!("{i}/{SHARDS}")])
        .arg("--partial")
        .arg(part(dir, i));
    c
}

fn part(dir: &Path, i: u64) -> PathBuf {
    dir.join(format!("part-{i}.json"))
}

fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn merge(parts: &[PathBuf]) -> Output {
    hindsight()
        .arg("merge")
        .args(parts)
        .arg("--json")
        .output()
        .unwrap()
}

/// The numbers of a report: everything but the time it took and the names it was given.
fn numbers(json: &[u8]) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
    let o = v.as_object_mut().unwrap();
    for k in ["seconds", "model", "properties_file"] {
        o.remove(k);
    }
    v
}

#[test]
fn concurrent_shards_merge_into_the_study_of_one_process() {
    let dir = scratch("cluster");
    // Every shard at once, as an array job starts them.
    let mut running: Vec<_> = (0..SHARDS)
        .map(|i| shard_command(&dir, i).spawn().unwrap())
        .collect();
    for c in &mut running {
        assert!(c.wait().unwrap().success());
    }
    let parts: Vec<PathBuf> = (0..SHARDS).map(|i| part(&dir, i)).collect();
    let merged = ok(merge(&parts));
    let whole = ok(hindsight()
        .arg("verify")
        .arg(museum())
        .args(["--seed", SEED, "--runs", RUNS, "--json"])
        .output()
        .unwrap());
    // The same document, model and property file named as the shards' command line did.
    assert_eq!(
        String::from_utf8_lossy(&merged.stdout),
        String::from_utf8_lossy(&whole.stdout)
    );
    let (m, w) = (numbers(&merged.stdout), numbers(&whole.stdout));
    // And the same report page.
    let page = |json: &[u8], name: &str| {
        let study = dir.join(format!("{name}.json"));
        std::fs::write(&study, json).unwrap();
        let html = dir.join(format!("{name}.html"));
        ok(hindsight()
            .arg("report")
            .arg("--study")
            .arg(&study)
            .args(["--title", "museum"])
            .arg("-o")
            .arg(&html)
            .output()
            .unwrap());
        std::fs::read_to_string(html).unwrap()
    };
    let merged_page = page(&merged.stdout, "merged");
    assert!(merged_page.contains("battery_recurrence"), "{merged_page}");
    assert_eq!(merged_page, page(&whole.stdout, "whole"));
    assert_eq!(m["runs"].as_u64(), Some(120), "{m}");
    assert!(!m["properties"].as_array().unwrap().is_empty(), "{m}");

    // A lost shard is named, with what to do.
    let lost = merge(&[parts[0].clone(), parts[1].clone(), parts[3].clone()]);
    assert_eq!(lost.status.code(), Some(2));
    let err = String::from_utf8_lossy(&lost.stderr);
    assert!(err.contains("shard 2/4 is missing"), "{err}");
    // Re-run alone, it completes the study with the same numbers.
    std::fs::remove_file(&parts[2]).unwrap();
    ok(shard_command(&dir, 2).output().unwrap());
    assert_eq!(numbers(&ok(merge(&parts)).stdout), w);

    // A shard the batch system ran twice: identical, counted once, and said.
    let again = dir.join("part-1-again.json");
    std::fs::copy(&parts[1], &again).unwrap();
    let mut with_copy = parts.clone();
    with_copy.push(again.clone());
    let twice = ok(merge(&with_copy));
    assert_eq!(numbers(&twice.stdout), w);
    let note = String::from_utf8_lossy(&twice.stderr);
    assert!(
        note.contains("shard 1/4 is given more than once, identical"),
        "{note}"
    );
    // Two different copies of one shard: an error naming both files.
    let text = std::fs::read_to_string(&again).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["runs"]["discarded"] = serde_json::json!(v["runs"]["discarded"].as_u64().unwrap() + 1);
    std::fs::write(&again, v.to_string()).unwrap();
    let differ = merge(&with_copy);
    assert_eq!(differ.status.code(), Some(2));
    let err = String::from_utf8_lossy(&differ.stderr);
    assert!(
        err.contains("shard 1/4 is given twice with different counts"),
        "{err}"
    );
    assert!(err.contains("part-1-again.json"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn runs_and_save_failing_are_refused_together() {
    let out = hindsight()
        .arg("verify")
        .arg(museum())
        .args(["--runs", "10", "--save-failing", "2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--save-failing"), "{err}");
}
