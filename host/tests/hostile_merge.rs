//! `merge` checks each shard file's counts against its own runs (issue 28, finding 3): a
//! forged or corrupted shard is refused, naming its file, and no sum wraps around.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::{json, Value};

fn hindsight() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs shard `i` of 2 of a study of the museum model with `study` (its size, ...) and
/// returns the part as written.
fn part(dir: &Path, i: u64, study: &[&str]) -> String {
    let file = dir.join(format!("real-{i}.json"));
    let out = hindsight()
        .arg("verify")
        .arg(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-scxml"))
        .args(study)
        .args(["--threads", "1", "--shard", &format!("{i}/2")])
        .arg("--partial")
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(file).unwrap()
}

/// Shard `i` of 2 of a 10-run study of the museum model, as JSON.
fn shard(dir: &Path, i: u64) -> Value {
    serde_json::from_str(&part(dir, i, &["--seed", "3", "--runs", "10"])).unwrap()
}

fn merge(dir: &Path, parts: &[(&str, &Value)]) -> Output {
    let files: Vec<PathBuf> = parts
        .iter()
        .map(|(name, v)| {
            let f = dir.join(name);
            std::fs::write(&f, serde_json::to_string(v).unwrap()).unwrap();
            f
        })
        .collect();
    hindsight()
        .arg("merge")
        .args(&files)
        .arg("--json")
        .output()
        .unwrap()
}

/// `merge` refuses `forged` (in place of shard 0) with exit 2, naming its file and
/// saying `what`.
fn refused(dir: &Path, forged: &Value, good: &Value, what: &str) {
    let out = merge(dir, &[("forged.json", forged), ("good.json", good)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("forged.json"), "{err}");
    assert!(!err.contains("good.json"), "{err}");
    assert!(err.contains(what), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn forged_counts_are_refused_naming_the_shard_file() {
    let dir = scratch("hostile-merge");
    let (zero, one) = (shard(&dir, 0), shard(&dir, 1));
    // The real shards merge.
    let out = merge(&dir, &[("a.json", &zero), ("b.json", &one)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // 1e18 failures in a 5-run shard.
    let mut f = zero.clone();
    f["properties"][0]["counts"]["failures"] = json!(1_000_000_000_000_000_000u64);
    refused(&dir, &f, &one, "do not sum to its");

    // Two shards of 2^63 failures each (the sum wrapped to 0 before), and unknown
    // verdicts that cancel them out modulo 2^64.
    let mut a = zero.clone();
    let mut b = one.clone();
    for v in [&mut a, &mut b] {
        let c = &mut v["properties"][0]["counts"];
        c["failures"] = json!(1u64 << 63);
        c["unknown"] = json!(1u64 << 63);
    }
    refused(&dir, &a, &b, "do not sum to its");

    // More unknown verdicts than runs.
    let mut f = zero.clone();
    let c = &mut f["properties"][0]["counts"];
    c["unknown"] = json!(c["unknown"].as_u64().unwrap() + 1);
    refused(&dir, &f, &one, "unknown");

    // A failing run outside the shard's range (shard 0 of 10 runs is 0..5).
    let mut f = zero.clone();
    let c = &mut f["properties"][0];
    c["counts"]["successes"] = json!(0);
    c["counts"]["unknown"] = json!(0);
    c["counts"]["failures"] = json!(5);
    c["failing_runs"] = json!([0, 7]);
    refused(&dir, &f, &one, "failing run 7");

    // More discarded runs than runs.
    let mut f = zero.clone();
    f["runs"]["discarded"] = json!(6);
    refused(&dir, &f, &one, "discarded");

    // Steps summing past 2^64 over the two shards.
    let mut a = zero.clone();
    let mut b = one.clone();
    a["runs"]["steps"] = json!(u64::MAX);
    b["runs"]["steps"] = json!(2);
    let out = merge(&dir, &[("forged.json", &a), ("other.json", &b)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("64 bits"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A file cut short beside a scheduler study's stage part is said to be cut short (its
/// JSON error), not "not a part of a stage".
#[test]
fn a_truncated_part_beside_a_stage_part_is_named_as_not_json() {
    let dir = scratch("merge-truncated");
    let stage = ["--schedulers", "2", "--runs", "4"];
    let (first, second) = (part(&dir, 0, &stage), part(&dir, 1, &stage));
    let cut = dir.join("cut.json");
    std::fs::write(&cut, &first[..first.len() / 2]).unwrap();
    let whole = dir.join("whole.json");
    std::fs::write(&whole, second).unwrap();
    let out = hindsight()
        .arg("merge")
        .arg(&cut)
        .arg(&whole)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("cut.json: EOF while parsing"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}
