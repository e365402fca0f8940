//! `hindsight verify --schedulers N` and `--scheduler ID` end to end: the JSON shape, the
//! witness replayed by `verify`, `trace` and `sweep`, the same numbers on any thread
//! count, and the combinations refused with a reason.

mod common;

use common::hindsight;

const RACE: &str = "host/tests/data/schedulers/race";
const ALTERNATE: &str = "host/tests/data/schedulers/alternate";

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
fn schedulers_refuse_shards_thresholds_and_bad_ids_with_a_reason() {
    for (args, needle) in [
        (
            vec![
                "verify",
                RACE,
                "--schedulers",
                "4",
                "--runs",
                "10",
                "--shard",
                "0/2",
            ],
            "--schedulers: not with --runs / --shard",
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
