//! `hindsight verify` / `validate` end to end: analytic probabilities, assumptions, determinism
//! across threads, the museum's thresholds, and bad models reported with a position.

mod common;

use common::hindsight;
use std::path::{Path, PathBuf};
use std::process::Command;

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

const COIN: &str = "host/tests/data/verify/coin";

#[test]
fn a_biased_coin_is_estimated_inside_the_reported_interval() {
    // heads with probability 0.3 (Math.random() < 0.3), across seeds and rules.
    for (seed, rule) in [("1", "wilson"), ("2", "clopper-pearson"), ("3", "adaptive")] {
        let r = json(&[
            "verify",
            COIN,
            "--seed",
            seed,
            "--rule",
            rule,
            "--precision",
            "0.03",
        ]);
        for (name, p) in [("heads", 0.3), ("tails", 0.7)] {
            let pr = prop(&r, name);
            let (lo, hi) = (pr["lower"].as_f64().unwrap(), pr["upper"].as_f64().unwrap());
            assert!(
                lo <= p && p <= hi,
                "seed {seed} {rule} {name}: [{lo}, {hi}]"
            );
            assert!(hi - lo <= 0.061, "{rule}: interval too wide: [{lo}, {hi}]");
        }
    }
}

#[test]
fn the_same_seed_gives_the_same_numbers_on_one_and_two_threads() {
    let strip = |mut v: serde_json::Value| {
        v["seconds"] = serde_json::Value::Null;
        v
    };
    let a = strip(json(&["verify", COIN, "--seed", "9", "--threads", "1"]));
    let b = strip(json(&["verify", COIN, "--seed", "9", "--threads", "2"]));
    assert_eq!(a, b);
    let c = strip(json(&["verify", COIN, "--seed", "10", "--threads", "2"]));
    assert_ne!(
        prop(&a, "heads")["successes"],
        prop(&c, "heads")["successes"]
    );
}

#[test]
fn runs_violating_an_assumption_are_discarded_and_counted() {
    let props = format!("{COIN}/assume-tails.xml");
    let r = json(&["verify", COIN, &props, "--seed", "4"]);
    let p = prop(&r, "no_heads");
    // Given tails, heads never happened: every judged run satisfies it.
    assert_eq!(p["successes"], p["runs"]);
    let (runs, discarded) = (
        r["runs"].as_u64().unwrap(),
        r["discarded"].as_u64().unwrap(),
    );
    // About 30 % of runs throw heads and are discarded.
    let share = discarded as f64 / runs as f64;
    assert!((0.22..0.38).contains(&share), "{discarded}/{runs}");
    assert_eq!(p["runs"].as_u64().unwrap() + discarded, runs);
}

fn museum() -> PathBuf {
    PathBuf::from("examples/museum-scxml")
}

/// A study that can judge no run (every run cut at a step limit set too low, or every
/// run discarded by an assumption that never holds) stops and says why; it ran forever.
#[test]
fn a_study_that_can_judge_no_run_stops_and_says_why() {
    let museum = museum();
    let museum = museum.to_str().unwrap();
    let (code, out, err) = hindsight(&["verify", museum, "--max-steps", "10", "--json"]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(r["unjudged"], true, "{r}");
    assert_eq!(r["runs"], 1000);
    assert_eq!(r["step_limit"], 1000);
    assert!(r["properties"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["probability"].is_null()));
    assert!(
        err.contains(
            "stopped after 1000 runs: not one could be judged for absence, alarm_response"
        ) && err.contains("cut at the step limit (--max-steps 10)"),
        "{err}"
    );
    // An assumption no run satisfies: every run discarded.
    let dir = std::env::temp_dir().join(format!("hindsight-unjudged-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let never = dir.join("never.xml");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/verify/coin/assume-tails.xml"
    ))
    .unwrap()
    .replace(
        "once {tails}",
        "once {tails} &amp;&amp; historically !{tails}",
    );
    std::fs::write(&never, text).unwrap();
    let (code, out, err) = hindsight(&["verify", COIN, never.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("1000 discarded by assumptions"), "{out}");
    assert!(
        err.contains("not one could be judged for no_heads")
            && err.contains("discarded because an assumption was violated"),
        "{err}"
    );
    // A study that judges runs says nothing of the kind.
    let (code, _, err) = hindsight(&["verify", COIN, "--max-runs", "50"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("could be judged"), "{err}");
}

#[test]
fn the_museum_requirements_hold_at_the_papers_bounds_and_fail_one_step_below() {
    let m = museum();
    let m = m.to_str().unwrap();
    let r = json(&["verify", m, "--seed", "5", "--max-runs", "12"]);
    for p in r["properties"].as_array().unwrap() {
        assert_eq!(p["successes"], p["runs"], "{p}");
        assert_eq!(p["runs"], 12);
    }
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-scxml/properties.xml"),
    )
    .unwrap();
    let below = text
        .replace("since[62:]", "since[61:]")
        .replace("since[2:]", "since[1:]")
        .replace("once[10:] true) -> once[:10]", "once[9:] true) -> once[:9]");
    let dir = std::env::temp_dir().join(format!("hindsight-below-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("properties.xml");
    std::fs::write(&file, below).unwrap();
    let r = json(&[
        "verify",
        m,
        file.to_str().unwrap(),
        "--seed",
        "5",
        "--max-runs",
        "12",
    ]);
    for name in [
        "alarm_response",
        "battery_recurrence",
        "poi_response",
        "visitors_recurrence",
    ] {
        assert_eq!(
            prop(&r, name)["successes"],
            0,
            "{name} should fail one step below"
        );
    }
    assert_eq!(prop(&r, "absence")["successes"], 12);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_museum_typo_is_reported_with_file_line_and_column() {
    let Some(root) = common::corpus_or_skip() else {
        return;
    };
    let corpus = root.join("museum-simpar2025/model_scxml");
    let (code, _, err) = hindsight(&["validate", corpus.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("NavigationComponent.scxml:20:30"), "{err}");
    assert!(err.contains("_event.data.thread_id"), "{err}");
    let (code, out, err) = hindsight(&["validate", "examples/museum-scxml"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("5 guarantees"), "{out}");
}

#[test]
fn bad_properties_and_arguments_exit_2() {
    let dir = std::env::temp_dir().join(format!("hindsight-badprops-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("p.xml");
    std::fs::write(
        &bad,
        "<properties>\n<ports>\n<scxml_event_send event=\"heads\" origin=\"coin\" target=\"sink\"><event_var id=\"h\"/></scxml_event_send>\n</ports>\n<guarantees>\n<property id=\"x\" logic=\"pmtl\" expr=\"once {h} &amp;&amp;\"/>\n</guarantees>\n</properties>\n",
    )
    .unwrap();
    let (code, _, err) = hindsight(&["verify", COIN, bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("p.xml:6:"), "{err}");
    // A column after entities counts the file's characters: `nope` is at column 58 of
    // the file; counting the unescaped text forward from the attribute would say 50.
    std::fs::write(
        &bad,
        "<properties>\n<ports>\n<scxml_event_send event=\"heads\" origin=\"coin\" target=\"sink\"><event_var id=\"h\"/></scxml_event_send>\n</ports>\n<guarantees>\n<property id=\"x\" logic=\"pmtl\" expr=\"once {h} &amp;&amp; {nope}\"/>\n</guarantees>\n</properties>\n",
    )
    .unwrap();
    let (code, _, err) = hindsight(&["verify", COIN, bad.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("nope"), "{err}");
    assert!(err.contains("p.xml:6:58: unknown variable `nope`"), "{err}");
    let (code, _, _) = hindsight(&["verify", COIN, "--confidence", "2"]);
    assert_eq!(code, 2);
    let (code, _, _) = hindsight(&["verify", "no/such/model"]);
    assert_eq!(code, 2);
    // A study of no runs is refused, not reported as an empty table.
    for args in [
        &["verify", COIN, "--runs", "0"][..],
        &["verify", COIN, "--max-runs", "0"],
        &["sweep", COIN, "--from", "1", "--to", "2", "--runs", "0"],
        // Runs cut before their first step judge nothing: 1,000 of them were run first.
        &["verify", COIN, "--max-steps", "0"],
        &["trace", COIN, "--max-steps", "0"],
    ] {
        let (code, out, err) = hindsight(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert!(out.is_empty(), "{args:?}: {out}");
        assert!(err.contains("must be at least 1"), "{args:?}: {err}");
    }
    // A file without guarantees estimates nothing: refused, not an empty table of 0 runs.
    let none = dir.join("none.xml");
    std::fs::write(&none, "<properties><guarantees/></properties>").unwrap();
    for runs in [&[][..], &["--runs", "3"]] {
        let mut args = vec!["verify", COIN, none.to_str().unwrap()];
        args.extend_from_slice(runs);
        let (code, out, err) = hindsight(&args);
        assert_eq!((code, out.as_str()), (2, ""), "{err}");
        assert!(err.contains("none.xml: no guarantee to verify"), "{err}");
    }
    // Arguments refused at once, with nothing on standard output: a bad rule before the
    // sweep's CSV header goes out, --max-runs beside a fixed --runs (it did nothing), and
    // a thread count past 1024 (it tried to start as many threads).
    let sweep = ["sweep", COIN, "--from", "1", "--to", "2"];
    let cases: [(Vec<&str>, &str); 4] = [
        (
            [&sweep[..], &["--confidence", "1"]].concat(),
            "confidence 1 is not in (0, 1)",
        ),
        (
            vec!["verify", COIN, "--runs", "4", "--max-runs", "3"],
            "cannot be used with",
        ),
        (
            vec!["verify", COIN, "--threads", "100000000", "--max-runs", "5"],
            "at most 1024",
        ),
        (
            [&sweep[..], &["--threads", "5000"]].concat(),
            "at most 1024",
        ),
    ];
    for (args, want) in cases {
        let (code, out, err) = hindsight(&args);
        assert_eq!((code, out.as_str()), (2, ""), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A sweep in durations on a model whose step is 200 ms: the default step (one unit of
/// `--from`'s last digit, 0.1 s) is rounded up to whole steps, and a step given that makes
/// values between steps is refused once, naming the first, instead of failing each.
#[test]
fn a_sweeps_default_step_is_whole_model_steps() {
    let args = |extra: &[&'static str]| {
        let mut a = vec![
            "sweep",
            "examples/museum-scxml",
            "--time-unit",
            "200ms",
            "--property",
            "visitors_recurrence",
            "--from",
            "0.2s",
            "--to",
            "1s",
            "--runs",
            "3",
        ];
        a.extend_from_slice(extra);
        a
    };
    let (code, out, err) = hindsight(&args(&[]));
    assert_eq!(code, 0, "{err}");
    let bounds: Vec<&str> = out
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').nth(1))
        .collect();
    assert_eq!(bounds, ["0.2s", "0.4s", "0.6s", "0.8s", "1s"], "{out}");
    let (code, out, err) = hindsight(&args(&["--step", "0.1s"]));
    assert_eq!(code, 2, "{out}");
    assert!(
        err.contains("0.3s is not a whole number of the model's time steps (200ms)"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

/// `verify --runs N` in one process: its table says the time it took and the model's time
/// unit, as a sequential study's does, while its JSON stays the document `merge` makes of
/// its shards (no wall-clock seconds, no time unit).
#[test]
fn a_fixed_size_study_table_says_its_time_and_its_json_stays_mergeable() {
    let args = [
        "verify",
        "examples/museum-scxml",
        "--time-unit",
        "100ms",
        "--runs",
        "4",
        "--seed",
        "3",
    ];
    let (code, out, err) = hindsight(&args);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("4 runs in "), "{out}");
    assert!(
        out.contains("model time: steps of 0.1 s, runs of at most"),
        "{out}"
    );
    let r = json(&args);
    assert_eq!(r["seconds"], 0.0, "{r}");
    assert!(r.get("step_seconds").is_none(), "{r}");
}

#[test]
fn sweep_shows_the_step_at_the_recurrence_threshold() {
    // visitors_recurrence swept over a range of steps, with the example's properties or
    // others.
    let sweep_over = |props: &[&str], from: &str, to: &str| {
        let mut args = vec!["sweep", "examples/museum-scxml"];
        args.extend_from_slice(props);
        args.extend_from_slice(&[
            "--property",
            "visitors_recurrence",
            "--from",
            from,
            "--to",
            to,
            "--runs",
            "10",
            "--seed",
            "2",
        ]);
        hindsight(&args)
    };
    let sweep = |props: &[&str]| sweep_over(props, "9", "10");
    let (code, out, err) = sweep(&[]);
    assert_eq!(code, 0, "{err}");
    let rows: Vec<Vec<&str>> = out
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 2, "{out}");
    // property,bound,successes,failures,unknown,probability,...
    assert_eq!(
        (rows[0][1], rows[0][2], rows[0][3]),
        ("9", "0", "10"),
        "{out}"
    );
    assert_eq!(
        (rows[1][1], rows[1][2], rows[1][3]),
        ("10", "10", "0"),
        "{out}"
    );
    assert!(
        err.contains("visitors_recurrence: every run succeeds from bound 10 on"),
        "{err}"
    );
    // Below 10 steps not one run succeeds at any bound: the sweep says so.
    let (code, _, low) = sweep_over(&[], "8", "9");
    assert_eq!(code, 0, "{low}");
    assert!(
        low.contains("visitors_recurrence: no run succeeds at any bound in the range"),
        "{low}"
    );
    // From 10 on every run succeeds at the range's first bound: the threshold may be lower.
    let (code, _, high) = sweep_over(&[], "10", "11");
    assert_eq!(code, 0, "{high}");
    assert!(
        high.contains("visitors_recurrence: every run succeeds at every bound of the range, from 10 on: the threshold is 10 or lower"),
        "{high}"
    );
    // The same deadline written as a window from now, `once[0:10]`: the sweep moves the
    // deadline and keeps the window's start (it once swept both ends, `once[X:X]`, and
    // every run failed at every bound).
    let dir = std::env::temp_dir().join(format!("hs_sweep_zero_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let props = dir.join("properties.xml");
    let museum = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/museum-scxml/properties.xml");
    let text = std::fs::read_to_string(museum)
        .unwrap()
        .replace("once[:10]", "once[0:10]");
    assert!(text.contains("once[0:10]"));
    std::fs::write(&props, text).unwrap();
    let (code, windowed, err) = sweep(&[props.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(windowed, out);
    // A window with two nonzero ends has both swept: the sweep warns before it starts.
    let text = std::fs::read_to_string(&props)
        .unwrap()
        .replace("once[0:10]", "once[1:10]");
    std::fs::write(&props, text).unwrap();
    let (code, _, err) = sweep(&[props.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "guarantee `visitors_recurrence`: both ends of the window [1:10] take each swept value"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
    let (code, _, err) = hindsight(&[
        "sweep",
        "examples/museum-scxml",
        "--property",
        "absence",
        "--from",
        "1",
        "--to",
        "2",
    ]);
    assert_eq!(code, 2, "absence has no bound: {err}");
    let (code, _, err) = hindsight(&[
        "sweep",
        "examples/museum-scxml",
        "--from",
        "1",
        "--to",
        "2s",
    ]);
    assert_eq!(code, 2, "mixed units: {err}");
}

#[test]
fn sweep_finds_every_threshold_of_the_paper_and_draws_them() {
    let dir = std::env::temp_dir().join(format!("hindsight-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("sweep.svg");
    // Every bounded requirement of the museum model around the paper's steps
    // (62, 10, 2, 10): each bound's variants are judged on the same runs.
    let (code, out, err) = hindsight(&[
        "sweep",
        "examples/museum-scxml",
        "--from",
        "1",
        "--to",
        "64",
        "--runs",
        "4",
        "--seed",
        "5",
        "--json",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).expect("one JSON object");
    let thresholds: Vec<(String, String)> = doc["properties"]
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
        ("alarm_response", "62"),
        ("battery_recurrence", "10"),
        ("poi_response", "2"),
        ("visitors_recurrence", "10"),
    ];
    let want: Vec<(String, String)> = want
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    assert_eq!(thresholds, want);
    let picture = std::fs::read_to_string(&svg).unwrap();
    assert!(picture.starts_with("<svg"));
    assert_eq!(picture.matches("<polyline").count(), 4);
    assert!(picture.contains("threshold 62"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn failing_runs_are_replayed_to_csv_with_their_verdicts() {
    let dir = std::env::temp_dir().join(format!("hindsight-failing-{}", std::process::id()));
    let (code, _, err) = hindsight(&[
        "verify",
        COIN,
        "--seed",
        "6",
        "--max-runs",
        "50",
        "--save-failing",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    // Two failing runs kept for each of heads and tails.
    assert_eq!(files.len(), 4, "{files:?}");
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
        // The last two columns are the verdicts of `heads` and `tails`.
        let verdict = |name: &str| last[header.len() - if name == "heads" { 2 } else { 1 }];
        let name = f.file_name().unwrap().to_str().unwrap();
        let (failed, other) = if name.starts_with("heads") {
            ("heads", "tails")
        } else {
            ("tails", "heads")
        };
        // The replayed run (stream k of the seed) fails the property it was kept for.
        assert_eq!(verdict(failed), "false", "{name}: {text}");
        assert_eq!(verdict(other), "true", "{name}: {text}");
        assert!(
            text.contains(&format!(",send,{other},coin,sink")),
            "{name}: {text}"
        );
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn shards_merged_equal_the_whole_study_and_gaps_are_refused() {
    let dir = std::env::temp_dir().join(format!("hindsight-shards-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let part = |shard: &str, name: &str| {
        let file = dir.join(name);
        let (code, _, err) = hindsight(&[
            "verify",
            COIN,
            "--seed",
            "5",
            "--runs",
            "300",
            "--shard",
            shard,
            "--partial",
            file.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        file.to_str().unwrap().to_string()
    };
    let (a, b, c) = (
        part("0/3", "a.json"),
        part("1/3", "b.json"),
        part("2/3", "c.json"),
    );
    let whole = part("0/1", "w.json");
    let merged = json(&["merge", &a, &b, &c]);
    let single = json(&["merge", &whole]);
    assert_eq!(merged["properties"], single["properties"]);
    assert_eq!(merged["runs"], 300);
    // `merge --json` prints the fields `verify --json` prints, and no page-only ones
    // (settings, formulas), which `hindsight report --study` reads back; `replay` (how
    // the model ran, for `report --scheduler`) comes through the shards.
    let keys = |v: &serde_json::Value| {
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    let study_keys = "confidence decided discarded model precision properties properties_file \
                      quiescent replay runs seconds seed step_limit time_horizon";
    let row_keys = "cut_short decision lower probability property runs successes upper";
    for report in [&merged, &json(&["verify", COIN, "--precision", "0.1"])] {
        assert_eq!(keys(report).join(" "), study_keys);
        assert_eq!(keys(prop(report, "heads")).join(" "), row_keys);
    }
    let (code, _, err) = hindsight(&["merge", &a, &c]);
    assert_eq!(code, 2);
    assert!(err.contains("missing"), "{err}");
    // A shard given twice, identical (a re-run), counts once; examples/cluster's test
    // covers two different copies, which are refused.
    let (code, _, err) = hindsight(&["merge", &a, &a, &b, &c]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("identical"), "{err}");
    assert_eq!(
        json(&["merge", &a, &a, &b, &c])["properties"],
        merged["properties"]
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_partial_file_without_a_shard_is_refused_not_ignored() {
    let file = std::env::temp_dir().join(format!("hindsight-partial-{}.json", std::process::id()));
    let partial = file.to_str().unwrap();
    let (code, out, err) = hindsight(&["verify", COIN, "--runs", "50", "--partial", partial]);
    assert_eq!(code, 2, "{out}");
    assert!(err.contains("--shard"), "{err}");
    assert!(!file.exists(), "nothing is written without --shard");
}

#[test]
fn racing_timers_split_fairly_and_timing_is_exact() {
    // a and b fire together after 2 units: which sends first is a fair choice (p = 1/2);
    // c fires after 3 units, always last; a is sent exactly at time 2.
    for seed in ["1", "2"] {
        let r = json(&[
            "verify",
            "host/tests/data/verify/race",
            "--rule",
            "wilson",
            "--precision",
            "0.03",
            "--seed",
            seed,
        ]);
        let p = prop(&r, "a_before_b");
        let (lo, hi) = (p["lower"].as_f64().unwrap(), p["upper"].as_f64().unwrap());
        assert!(lo <= 0.5 && 0.5 <= hi, "seed {seed}: [{lo}, {hi}]");
        for name in ["c_last", "a_at_2"] {
            let p = prop(&r, name);
            assert_eq!(p["successes"], p["runs"], "{name}");
        }
    }
}

#[test]
fn trace_replays_one_run_as_csv() {
    let (code, out, err) = hindsight(&[
        "trace",
        "host/tests/data/verify/race",
        "--run",
        "3",
        "--seed",
        "1",
    ]);
    assert_eq!(code, 0, "{err}");
    let header = out.lines().next().unwrap();
    assert!(
        header.starts_with("time,step,event,origin,target,params,a,b,c,verdict_a_before_b"),
        "{header}"
    );
    // Every send of the race appears, at its time.
    assert!(out.contains("\n2,send,a_done,a,judge,"), "{out}");
    assert!(out.contains("\n2,send,b_done,b,judge,"), "{out}");
    assert!(out.contains("\n3,send,c_done,c,judge,"), "{out}");
    // How the run ended goes to standard error: the race's machines stop after their
    // sends, so it goes quiet at time 3.
    assert!(
        err.contains("run 3 of seed 1: went quiet at time 3 after "),
        "{err}"
    );
    // The same run twice gives the same text.
    let (_, again, _) = hindsight(&[
        "trace",
        "host/tests/data/verify/race",
        "--run",
        "3",
        "--seed",
        "1",
    ]);
    assert_eq!(out, again);
}

#[test]
fn the_sequential_test_answers_threshold_questions() {
    // P(heads) = 0.3: at least 0.2 is accepted, at least 0.5 rejected.
    let r = json(&[
        "verify",
        COIN,
        "--threshold",
        "0.2",
        "--precision",
        "0.05",
        "--seed",
        "8",
    ]);
    assert_eq!(prop(&r, "heads")["decision"], "accept");
    let r = json(&[
        "verify",
        COIN,
        "--threshold",
        "0.5",
        "--precision",
        "0.05",
        "--seed",
        "8",
    ]);
    assert_eq!(prop(&r, "heads")["decision"], "reject");
}

#[test]
fn a_traced_run_replays_with_the_recorded_verdicts() {
    let (code, csv, err) = hindsight(&[
        "trace",
        "host/tests/data/verify/race",
        "--run",
        "3",
        "--seed",
        "1",
    ]);
    assert_eq!(code, 0, "{err}");
    let dir = std::env::temp_dir().join(format!("hindsight-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("race.csv");
    std::fs::write(&trace, &csv).unwrap();
    let spec = dir.join("race.hspec");
    std::fs::write(
        &spec,
        "unit 1s;\nevent a;\nevent b;\nevent c;\n\
         property a_before_b = P({b} && P {a});\n\
         property c_last = P({c} && P {a} && P {b});\n",
    )
    .unwrap();
    let (code, out, err) = hindsight(&["replay", spec.to_str().unwrap(), trace.to_str().unwrap()]);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(code, 0, "{err}");
    // The replay's verdicts are the recorded `verdict_` columns, row for row.
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ab, cl) = (col("verdict_a_before_b"), col("verdict_c_last"));
    let recorded: Vec<String> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            format!("{},{},{}", cells[0], cells[ab], cells[cl])
        })
        .collect();
    let replayed: Vec<&str> = out.lines().skip(1).collect();
    assert_eq!(out.lines().next(), Some("time,a_before_b,c_last"));
    assert_eq!(replayed, recorded);
    // Run 3 sends b first: c_last turns true, a_before_b never does.
    assert!(recorded.last().unwrap().ends_with(",false,true"), "{csv}");
}

#[test]
fn replay_refuses_a_bad_trace_naming_file_line_and_column() {
    let dir = std::env::temp_dir().join(format!("hindsight-replay-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("s.hspec");
    std::fs::write(
        &spec,
        "unit 1s;\nstate p: bool = false;\nstate x: int = 0;\n\
         property f = H({x < 5} -> P[0:3] {p});\n",
    )
    .unwrap();
    let cases = [
        (
            "int.csv",
            "time,p,x\n0,1,3\n1,0,99999999999999999999\n",
            "int.csv:3:5: `99999999999999999999` is not a value of type `int` for `x`",
        ),
        (
            "bool.csv",
            "time,p,x\n0,true,3\n1,yes,3\n",
            "bool.csv:3:3: `yes` is not a value of type `bool` for `p`",
        ),
        (
            "time.csv",
            "time,p,x\n0,1,3\n-1,0,2\n",
            "time.csv:3:1: `-1` is not a timestamp",
        ),
        (
            "back.csv",
            "time,p,x\n5,1,3\n2,0,2\n",
            "back.csv:3:1: timestamp 2 is before the previous point's 5",
        ),
        (
            "twice.csv",
            "time,p,x,x\n5,1,3,3\n",
            "twice.csv:1:10: column `x` repeated",
        ),
        ("empty.csv", "", "empty.csv:1:1: empty trace"),
        (
            "unknown.csv",
            "time,p,y\n0,1,3\n",
            "unknown.csv:1:8: `y` is not a variable of the spec",
        ),
    ];
    for (name, text, want) in cases {
        let trace = dir.join(name);
        std::fs::write(&trace, text).unwrap();
        let (code, out, err) =
            hindsight(&["replay", spec.to_str().unwrap(), trace.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {out}{err}");
        assert!(
            out.is_empty(),
            "{name}: no verdict printed before the error: {out}"
        );
        assert!(err.contains(want), "{name}: {err}");
    }
    // A step that fails names the row's line (after a comment and a blank line) and
    // the atom by its text.
    std::fs::write(
        &spec,
        "unit 1s;\nstate p: bool = false;\nstate x: int = 0;\n\
         property f = H({x + 1 > 0} -> {p});\n",
    )
    .unwrap();
    let trace = dir.join("max.csv");
    std::fs::write(
        &trace,
        format!("time,p,x\n0,1,3\n# next\n\n1,1,{}\n", i64::MAX),
    )
    .unwrap();
    let (code, out, err) = hindsight(&["replay", spec.to_str().unwrap(), trace.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.contains(
            "max.csv:5: point 2: atom `{(x + 1) > 0}`: integer overflow or division by zero"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn robot_model_runs_end_at_the_time_horizon() {
    // The museum guide's global timer stops at `max_time`: its runs lasted their whole
    // length and are counted at the horizon, not as quiescent (which names a deadlock).
    let r = json(&[
        "verify",
        "examples/museum-guide",
        "--runs",
        "5",
        "--seed",
        "4",
    ]);
    assert_eq!(
        (r["time_horizon"].as_u64(), r["quiescent"].as_u64()),
        (Some(5), Some(0)),
        "{r}"
    );
}

#[test]
fn with_a_time_unit_bounds_and_sweeps_are_in_seconds() {
    // The museum translation steps 100 ms; its requirements written over ROS names with
    // bounds in seconds hold, and the sweep's thresholds come out in seconds.
    let props = "examples/museum-guide/properties.xml";
    let r = json(&[
        "verify",
        "examples/museum-scxml",
        props,
        "--time-unit",
        "100ms",
        "--max-time",
        "400s",
        "--max-runs",
        "6",
        "--seed",
        "2",
    ]);
    for p in r["properties"].as_array().unwrap() {
        assert_eq!(p["successes"], 6, "{p}");
    }
    let (code, out, err) = hindsight(&[
        "sweep",
        "examples/museum-scxml",
        props,
        "--time-unit",
        "100ms",
        "--from",
        "0.1s",
        "--to",
        "1.2s",
        "--property",
        "poi_response",
        "--property",
        "battery_recurrence",
        "--runs",
        "4",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let thresholds: Vec<&str> = doc["properties"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["threshold"].as_str().unwrap_or("none"))
        .collect();
    assert_eq!(thresholds, ["0.2s", "1s"]);
    // Durations that are not whole steps, or without a unit to convert them, are input errors.
    let (code, _, err) = hindsight(&["verify", "examples/museum-scxml", props]);
    assert_eq!(code, 2);
    assert!(err.contains("properties.xml"), "{err}");
    // The units are codegen's everywhere: `sec` is rejected with the list of units.
    let cases: [(&[&str], &str); 5] = [
        (
            &["--time-unit", "100ms", "--max-time", "150ms"],
            "--max-time: 150ms is not a whole number of model steps of 100ms",
        ),
        // A zero length would judge every property on the first instant alone.
        (
            &["--max-time", "0"],
            "--max-time: 0 would end every run before model time moves",
        ),
        (
            &["--time-unit", "100ms", "--max-time", "0s"],
            "--max-time: 0s would end every run before model time moves",
        ),
        (
            &["--time-unit", "1sec"],
            "--time-unit 1sec: unknown time unit `sec` (use ns, us, ms, s or min)",
        ),
        (
            &["--time-unit", "100ms", "--max-time", "2.5"],
            "`2.5` has a fraction but no time unit",
        ),
    ];
    for (flags, want) in cases {
        let mut args = vec!["verify", "examples/museum-scxml"];
        args.extend_from_slice(flags);
        let (code, _, err) = hindsight(&args);
        assert_eq!(code, 2, "{flags:?}");
        assert!(err.contains(want), "{flags:?}: {err}");
    }
}

/// A model that fails at run time (an index out of bounds) stops the study at once with
/// the failure, file-free as it is, instead of running failing runs forever: without
/// `--max-runs` the adaptive rule never gets the verdicts it waits for.
#[test]
fn a_model_failing_at_run_time_stops_the_study_at_once() {
    let dir = std::env::temp_dir().join(format!("hindsight-run-error-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/sim/run_error");
    std::fs::copy(data.join("oob.scxml"), dir.join("oob.scxml")).unwrap();
    std::fs::write(
        dir.join("properties.xml"),
        r#"<properties>
  <ports>
    <scxml_event_send event="v" origin="Oob" target="NONE"><state_var id="x" type="int32" expr="0" param="v"/></scxml_event_send>
  </ports>
  <guarantees>
    <property id="small" logic="pmtl" expr="historically {x &lt; 4}"/>
  </guarantees>
</properties>"#,
    )
    .unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .arg("verify")
        .arg(&dir)
        .args(["--threads", "2"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run hindsight");
    let started = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if started.elapsed() > std::time::Duration::from_secs(120) {
            let _ = child.kill();
            panic!("the study did not stop at the model's failure");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(status.code(), Some(2), "{err}");
    assert!(
        err.contains("the model failed during simulation: run ") && err.contains("index"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// UC3's full museum model (278 machines, 19 guarantees; the reference checker judges all
/// true in every run): its `battery_level` port is declared int32 over a float32 field,
/// which is read as a float with a warning (as SCAN does) instead of failing every run.
#[test]
fn the_uc3_scale_model_holds_every_guarantee() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let uc3 = common::corpus("uc3-plain");
    let (code, out, err) = hindsight(&[
        "verify",
        uc3.to_str().unwrap(),
        "--seed",
        "3",
        "--max-runs",
        "12",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "properties.xml:8:7: port `battery_level` is declared int32 but \
             `ros_fields__percentage` is a float: it is read as a float"
        ),
        "{err}"
    );
    let report: serde_json::Value = serde_json::from_str(&out).unwrap();
    let props = report["properties"].as_array().unwrap();
    assert_eq!(props.len(), 19);
    for p in props {
        assert_eq!(p["successes"], 12, "{p}");
    }
}

/// A plain SCXML model that writes its delays as durations (`delay="1s"`,
/// `delayexpr="ms + 'ms'"`) runs with `--time-unit`, which converts them, and without it
/// is refused with the way out.
#[test]
fn durations_in_delays_take_the_time_unit() {
    let dir = std::env::temp_dir().join(format!("hindsight-delays-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("a.scxml"),
        r#"<scxml name="a" initial="s" version="1.0" datamodel="ecmascript"><datamodel><data id="ms" expr="1500"/></datamodel>
  <state id="s"><onentry><send event="tick" target="NONE" delay="1s"/><send event="tock" target="NONE" delayexpr="ms + 'ms'"/></onentry></state></scxml>"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("properties.xml"),
        r#"<properties><ports><scxml_event_send event="tock" origin="a" target="NONE"><event_var id="tock"/></scxml_event_send></ports>
<guarantees><property id="tocked" logic="pmtl" expr="once {tock}"/></guarantees></properties>"#,
    )
    .unwrap();
    let model = dir.to_str().unwrap();
    let (code, out, err) = hindsight(&["trace", model, "--time-unit", "100ms"]);
    assert_eq!(code, 0, "{err}");
    let sends: Vec<String> = out
        .lines()
        .filter(|l| l.contains(",send,"))
        .map(|l| l.split(',').take(3).collect::<Vec<_>>().join(","))
        .collect();
    // 1 s is 10 steps of 100 ms; the second send waits its 1.5 s after the first.
    assert_eq!(sends, ["10,send,tick", "25,send,tock"], "{out}");
    let (code, _, err) = hindsight(&["verify", model, "--runs", "2"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("a.scxml:2:66: delay 1s is a duration: it needs the model's time unit: give --time-unit"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
