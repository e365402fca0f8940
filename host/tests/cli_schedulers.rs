//! `hindsight verify --schedulers N` and `--scheduler ID` end to end: the JSON shape, the
//! witness replayed by `verify`, `trace`, `sweep` and `report`, the same numbers on any
//! thread count, and the combinations refused with a reason.

mod common;

use common::hindsight;

const RACE: &str = "host/tests/data/schedulers/race";
const ALTERNATE: &str = "host/tests/data/schedulers/alternate";
const STARVE: &str = "host/tests/data/schedulers/starve";

fn json(args: &[&str]) -> serde_json::Value {
    let mut all = args.to_vec();
    all.push("--json");
    let (code, out, err) = hindsight(&all);
    assert_eq!(code, 0, "{args:?}: {err}");
    serde_json::from_str(&out).expect("json report")
}

fn prop<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["properties"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["property"] == name)
        .unwrap_or_else(|| panic!("no property {name}"))
}

#[test]
fn the_json_has_uniform_min_max_witnesses_and_the_flag() {
    let r = json(&["verify", RACE, "--schedulers", "16", "--threads", "2"]);
    let a = prop(&r, "a_wins");
    let s = &a["schedulers"];
    assert_eq!(s["sampled"], 16);
    assert_eq!(s["min"]["probability"], 0.0);
    assert_eq!(s["max"]["probability"], 1.0);
    let iv = s["min"]["interval"].as_array().unwrap();
    assert_eq!(iv.len(), 2);
    assert!(iv[0].as_f64().unwrap() <= 0.0 && iv[1].as_f64().unwrap() >= 0.0);
    assert_eq!(s["order_sensitive"], true);
    assert!(s["min"]["scheduler"]
        .as_str()
        .unwrap()
        .starts_with("memoryless:"));
    let p = a["probability"].as_f64().unwrap();
    assert!((p - 0.5).abs() < 0.02, "uniform {p}");
    assert_eq!(
        prop(&r, "someone_wins")["schedulers"]["order_sensitive"],
        false
    );
    // Without --schedulers the JSON has no such field, and no scheduler named.
    let plain = json(&["verify", RACE]);
    assert!(prop(&plain, "a_wins").get("schedulers").is_none());
    assert!(plain.get("scheduler").is_none());
}

#[test]
fn a_witness_replays_its_bound_in_verify_trace_and_sweep() {
    let r = json(&[
        "verify",
        ALTERNATE,
        "--max-time",
        "2",
        "--schedulers",
        "32",
        "--scheduler-memory",
        "history",
    ]);
    let s = &prop(&r, "a_then_b_first")["schedulers"];
    assert_eq!(s["max"]["probability"], 1.0);
    let w = s["max"]["scheduler"].as_str().unwrap().to_string();
    // verify under the witness: every run satisfies it, and the report names it.
    let again = json(&["verify", ALTERNATE, "--max-time", "2", "--scheduler", &w]);
    let p = prop(&again, "a_then_b_first");
    assert_eq!(p["successes"], p["runs"]);
    assert_eq!(again["scheduler"], w.as_str());
    // trace: a first at time 1, b first at time 2.
    let (code, csv, err) = hindsight(&[
        "trace",
        ALTERNATE,
        "--max-time",
        "2",
        "--scheduler",
        &w,
        "--run",
        "3",
    ]);
    assert_eq!(code, 0, "{err}");
    // (time, event) of every send, in order.
    let sends: Vec<String> = csv
        .lines()
        .filter(|l| l.contains(",send,"))
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            format!("{}{}", v[0], v[2])
        })
        .collect();
    assert_eq!(sends, ["1a", "1b", "2b", "2a"], "{csv}");
    // sweep puts every bound of `a_first_twice` at 0: "a sends first at instant 2", which
    // the memoryless witnesses decide in every run (max: always, min: never) and the
    // uniform scheduler in about half.
    let r = json(&["verify", ALTERNATE, "--max-time", "2", "--schedulers", "32"]);
    let s = &prop(&r, "a_first_twice")["schedulers"];
    let sweep = |scheduler: Option<&str>| {
        let mut args = vec![
            "sweep",
            ALTERNATE,
            "--max-time",
            "2",
            "--property",
            "a_first_twice",
            "--from",
            "0",
            "--to",
            "0",
            "--runs",
            "40",
        ];
        if let Some(s) = scheduler {
            args.extend(["--scheduler", s]);
        }
        let (code, out, err) = hindsight(&args);
        assert_eq!(code, 0, "{err}");
        out
    };
    let max = sweep(s["max"]["scheduler"].as_str());
    assert!(max.contains("a_first_twice,0,40,0,0,"), "{max}");
    let min = sweep(s["min"]["scheduler"].as_str());
    assert!(min.contains("a_first_twice,0,0,40,0,"), "{min}");
    let uniform = sweep(None);
    assert!(
        !uniform.contains(",0,40,0,0,") && !uniform.contains(",0,0,40,0,"),
        "{uniform}"
    );
}

/// The index of the first run of seed 3 (among the first 50) whose last `verdict_a_wins`
/// is false under `scheduler`, found by `trace`: another command than `report`.
fn first_failing_by_trace(scheduler: &str) -> u64 {
    (0..50u64)
        .find(|k| {
            let run = k.to_string();
            let (code, csv, err) = hindsight(&[
                "trace",
                RACE,
                "--seed",
                "3",
                "--scheduler",
                scheduler,
                "--run",
                &run,
            ]);
            assert_eq!(code, 0, "{err}");
            let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
            let col = header.iter().position(|h| *h == "verdict_a_wins").unwrap();
            let last = csv.lines().last().unwrap();
            last.split(',').nth(col) == Some("false")
        })
        .expect("a failing run among the first 50")
}

#[test]
fn report_replays_a_study_under_a_witness_from_its_json_alone() {
    let dir = std::env::temp_dir().join(format!("hindsight-sched-report-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (code, out, err) =
        hindsight(&["verify", RACE, "--schedulers", "8", "--seed", "3", "--json"]);
    assert_eq!(code, 0, "{err}");
    let study = dir.join("study.json");
    std::fs::write(&study, &out).unwrap();
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    // The study records how its model ran.
    assert_eq!(r["replay"]["model"], RACE, "{r}");
    assert_eq!(r["replay"]["events"], "queues");
    let min = prop(&r, "a_wins")["schedulers"]["min"]["scheduler"]
        .as_str()
        .unwrap()
        .to_string();
    let page = dir.join("page.html");
    let (study_arg, page_arg) = (study.to_str().unwrap(), page.to_str().unwrap());
    let (code, _, err) = hindsight(&[
        "report",
        "--study",
        study_arg,
        "--scheduler",
        &min,
        "-o",
        page_arg,
    ]);
    assert_eq!(code, 0, "{err}");
    // Each search says so first (it may replay up to 500 runs); a property the study never
    // saw fail is not searched.
    assert!(
        err.contains("the first run of seed 3 that fails a_wins under the uniform"),
        "{err}"
    );
    assert!(!err.contains("fails someone_wins"), "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    // Per property, the first failing run under the witness and under the uniform
    // scheduler, as `trace` finds them run by run.
    let under_min = first_failing_by_trace(&min);
    let under_uniform = first_failing_by_trace("uniform");
    assert!(
        html.contains(&format!(
            "a_wins under the scheduler {min}, run {under_min}"
        )),
        "{min}: run {under_min}"
    );
    assert!(
        html.contains(&format!(
            "a_wins under the uniform scheduler, run {under_uniform}"
        )),
        "uniform: run {under_uniform}"
    );
    // `someone_wins` holds in every run: nothing shown for it.
    assert!(!html.contains("someone_wins under the"));
    // Refused with a reason: a study that does not record how it ran, and one whose model
    // is not there from where `report` runs.
    for (key, value, says) in [
        (
            "replay",
            serde_json::Value::Null,
            "does not record how its model was run",
        ),
        (
            "model",
            serde_json::json!("no/such/model"),
            "is not found from here",
        ),
    ] {
        let mut edited = r.clone();
        if key == "replay" {
            edited.as_object_mut().unwrap().remove("replay");
        } else {
            edited["replay"][key] = value;
        }
        let bad = dir.join(format!("bad-{key}.json"));
        std::fs::write(&bad, edited.to_string()).unwrap();
        let (code, _, err) = hindsight(&[
            "report",
            "--study",
            bad.to_str().unwrap(),
            "--scheduler",
            &min,
            "-o",
            page_arg,
        ]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(says) && err.contains("bad-"), "{err}");
    }
    // --scheduler without --study has nothing to replay.
    let (code, _, err) = hindsight(&["report", "--scheduler", &min, "-o", page_arg]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--study"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bounds_are_the_same_on_one_and_two_threads() {
    let strip = |mut v: serde_json::Value| {
        v["seconds"] = serde_json::Value::Null;
        v
    };
    let args = |t: &'static str| {
        [
            "verify",
            ALTERNATE,
            "--max-time",
            "2",
            "--schedulers",
            "24",
            "--scheduler-memory",
            "history",
            "--threads",
            t,
        ]
    };
    assert_eq!(strip(json(&args("1"))), strip(json(&args("2"))));
}

#[test]
fn schedulers_refuse_thresholds_stray_plans_and_bad_ids_with_a_reason() {
    for (args, needle) in [
        (
            vec![
                "verify", RACE, "--runs", "10", "--shard", "0/2", "--plan", "p.json",
            ],
            "--plan: the plan of a sharded scheduler study needs --schedulers",
        ),
        (
            vec!["verify", RACE, "--schedulers", "4", "--threshold", "0.5"],
            "--schedulers: not with --threshold",
        ),
        (
            vec!["verify", RACE, "--scheduler", "sometimes:12"],
            "unknown scheduler kind `sometimes`",
        ),
        (
            vec!["verify", RACE, "--scheduler", "memoryless:xyz"],
            "not hexadecimal",
        ),
        (vec!["verify", RACE, "--schedulers", "0"], "at least 1"),
    ] {
        let (code, _, err) = hindsight(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

/// Runs every stage of `verify RACE --schedulers 8 --selection-runs 4 --runs 200` (with
/// `extra`) as `k` shards, merging each stage with `merge --next`, and returns the last
/// merge's JSON and the stages run.
fn sharded(dir: &std::path::Path, k: u64, extra: &[&str]) -> (serde_json::Value, u32) {
    sharded_study(dir, RACE, k, extra)
}

fn sharded_study(
    dir: &std::path::Path,
    model: &str,
    k: u64,
    extra: &[&str],
) -> (serde_json::Value, u32) {
    let plan = dir.join(format!("plan-{k}.json"));
    let plan = plan.to_str().unwrap().to_string();
    for stage in 0..20u32 {
        let mut parts = Vec::new();
        for i in 0..k {
            let part = dir.join(format!("k{k}-s{stage}-{i}.json"));
            let part = part.to_str().unwrap().to_string();
            let shard = format!("{i}/{k}");
            let mut args = vec![
                "verify",
                model,
                "--schedulers",
                "8",
                "--selection-runs",
                "4",
                "--runs",
                "200",
                "--shard",
                &shard,
                "--partial",
                &part,
            ];
            args.extend_from_slice(extra);
            if stage > 0 {
                args.extend(["--plan", plan.as_str()]);
            }
            let (code, _, err) = hindsight(&args);
            assert_eq!(code, 0, "stage {stage} shard {shard}: {err}");
            parts.push(part);
        }
        let mut args: Vec<&str> = vec!["merge"];
        args.extend(parts.iter().map(String::as_str));
        args.extend(["--next", plan.as_str(), "--json"]);
        let (code, out, err) = hindsight(&args);
        assert_eq!(code, 0, "merge of stage {stage}: {err}");
        if !out.trim().is_empty() {
            return (serde_json::from_str(&out).expect("json"), stage + 1);
        }
        assert!(err.contains("--plan"), "{err}");
    }
    panic!("more than 20 stages");
}

#[test]
fn a_sharded_scheduler_study_merges_to_the_unsharded_json() {
    let dir = std::env::temp_dir().join(format!("hindsight-sched-shards-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let whole = json(&[
        "verify",
        RACE,
        "--schedulers",
        "8",
        "--selection-runs",
        "4",
        "--runs",
        "200",
    ]);
    let s = &prop(&whole, "a_wins")["schedulers"];
    assert_eq!(s["min"]["probability"], 0.0, "{whole}");
    assert_eq!(s["max"]["probability"], 1.0, "{whole}");
    assert_eq!(s["min"]["runs"], 200);
    assert_eq!(s["order_sensitive"], true);
    assert_eq!(prop(&whole, "a_wins")["runs"], 200);
    let (three, stages) = sharded(&dir, 3, &[]);
    // At least one selection round (8 schedulers, 2 candidates per side), then the
    // confirmation.
    assert!(stages >= 2, "{stages} stages");
    assert_eq!(three, whole);
    let (one, _) = sharded(&dir, 1, &["--threads", "1"]);
    assert_eq!(one, whole);
    // A part of another stage is refused, naming the shard.
    let stale = dir.join("k3-s0-1.json");
    let fresh = dir.join("k3-s1-0.json");
    let (code, _, err) = hindsight(&["merge", fresh.to_str().unwrap(), stale.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("another stage"), "{err}");
    // A plan given to another study (another seed) is refused.
    let plan = dir.join("plan-3.json");
    let (code, _, err) = hindsight(&[
        "verify",
        RACE,
        "--schedulers",
        "8",
        "--selection-runs",
        "4",
        "--runs",
        "200",
        "--seed",
        "9",
        "--shard",
        "0/2",
        "--plan",
        plan.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`seed` differs"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

const STARVING: [&str; 8] = [
    "--schedulers",
    "16",
    "--selection-runs",
    "4",
    "--max-instant-steps",
    "1000",
    "--max-time",
    "3",
];

#[test]
fn unfair_schedulers_are_left_out_and_counted_unless_kept() {
    let mut args = vec!["verify", STARVE];
    args.extend(STARVING);
    let fair = json(&args);
    let w = prop(&fair, "written");
    assert_eq!(w["probability"], 1.0, "uniform: {fair}");
    let s = &w["schedulers"];
    // Every fair scheduler lets cell take the write.
    assert_eq!(s["min"]["probability"], 1.0, "{s}");
    assert_eq!(s["max"]["probability"], 1.0, "{s}");
    assert_eq!(s["order_sensitive"], false);
    let left = s["left_out"].as_u64().expect("some left out");
    assert!(left > 0 && left < 16, "{left} left out");
    let first = &s["left_out_first"][0];
    assert!(
        first["reason"].as_str().unwrap().contains(
            "machine `spin` in state `busy` keeps the model busy without letting time advance"
        ),
        "{first}"
    );
    // The run named replays the block: under that scheduler the study fails at it.
    let (code, _, err) = hindsight(&[
        "verify",
        STARVE,
        "--max-instant-steps",
        "1000",
        "--max-time",
        "3",
        "--scheduler",
        first["scheduler"].as_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("without letting time advance"), "{err}");
    // Kept, an unfair scheduler's blocked run is judged as it stands: cell never wrote,
    // a minimum no fair executor gives.
    args.push("--keep-unfair");
    let kept = json(&args);
    let s = &prop(&kept, "written")["schedulers"];
    assert_eq!(s["min"]["probability"], 0.0, "{s}");
    assert_eq!(s["max"]["probability"], 1.0, "{s}");
    assert_eq!(s["order_sensitive"], true);
    assert!(s.get("left_out").is_none(), "{s}");
    // The table says how many were left out and why.
    let mut table = vec!["verify", STARVE];
    table.extend(STARVING);
    let (code, out, err) = hindsight(&table);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(&format!(
            "left out as unfair: {left} of 16 sampled schedulers"
        )),
        "{out}"
    );
}

#[test]
fn a_sharded_study_leaves_the_same_unfair_schedulers_out() {
    let dir = std::env::temp_dir().join(format!("hindsight-sched-unfair-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut args = vec!["verify", STARVE];
    args.extend(STARVING);
    args.extend(["--runs", "200"]);
    let whole = json(&args);
    let s = &prop(&whole, "written")["schedulers"];
    assert_eq!(s["min"]["probability"], 1.0, "{s}");
    assert!(s["left_out"].as_u64().unwrap() > 0, "{s}");
    let (two, _) = sharded_study(
        &dir,
        STARVE,
        2,
        &["--max-instant-steps", "1000", "--max-time", "3"],
    );
    let _ = std::fs::remove_dir_all(&dir);
    // sharded_study gives --schedulers 8; compare with the same study unsharded.
    let mut eight = vec!["verify", STARVE];
    eight.extend([
        "--schedulers",
        "8",
        "--selection-runs",
        "4",
        "--max-instant-steps",
        "1000",
        "--max-time",
        "3",
        "--runs",
        "200",
    ]);
    assert_eq!(two, json(&eight));
}
