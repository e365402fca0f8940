//! Where the order comes from (`verify --schedulers`, issue 26 part 3): the witnesses
//! re-estimated with one kind of choice put back to uniform, on two small models whose
//! answers are derived by hand in their property files and below: a race decided only by
//! which machine moves first (`race`, queue semantics) and one decided by which pending
//! event is delivered first (`delivery`, AS2FM's semantics). The witnesses are those of
//! seed 0; every bound asserted holds for any witness (the derivations say why).

mod common;

use common::hindsight;

const RACE: &str = "host/tests/data/schedulers/race";
const DELIVERY: &str = "host/tests/data/schedulers/delivery";

fn verify(args: &[&str]) -> (serde_json::Value, String) {
    let mut all = args.to_vec();
    all.extend(["--precision", "0.03", "--threads", "2"]);
    let (code, table, err) = hindsight(&all);
    assert_eq!(code, 0, "{args:?}: {err}");
    all.push("--json");
    let (code, out, err) = hindsight(&all);
    assert_eq!(code, 0, "{args:?}: {err}");
    (serde_json::from_str(&out).expect("json report"), table)
}

fn prop<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["properties"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["property"] == name)
        .unwrap_or_else(|| panic!("no property {name}"))
}

/// The source of `witness` with `choice` put back, for `item` (a machine's or event's
/// name) or for the whole kind (`None`).
fn source<'a>(
    s: &'a serde_json::Value,
    witness: &str,
    choice: &str,
    item: Option<&str>,
) -> Option<&'a serde_json::Value> {
    s["sources"].as_array()?.iter().find(|x| {
        x["witness"] == witness
            && x["choice"] == choice
            && match item {
                None => x.get("machine").is_none() && x.get("event").is_none(),
                Some(n) => x["machine"] == n || x["event"] == n,
            }
    })
}

fn p(x: &serde_json::Value) -> f64 {
    x["probability"].as_f64().expect("a probability")
}

/// The race's sources (`a_wins`'s bounds `s`), derived by hand: they hold for any witness.
fn race_sources(s: &serde_json::Value) {
    for (w, base) in [("min", 0.0), ("max", 1.0)] {
        // Which machine moves put back to uniform: there is no other choice in a run under
        // queue semantics, so the runs are the uniform scheduler's: a first half the time.
        let kind = source(s, w, "machine", None).expect("machine order");
        assert!((p(kind) - 0.5).abs() < 0.07, "{w}: {kind}");
        assert!((kind["shift"].as_f64().unwrap() - (0.5 - base)).abs() < 0.07);
        // Queue semantics: no deliveries to put back.
        assert!(source(s, w, "delivery", None).is_none());
    }
    // One racer's position alone: at the first choice (a, b and cell's first step are
    // runnable) a moves with probability at least 1/3, and a's write is then first in
    // cell's queue: the min witness's 0 rises by at least 1/3. Likewise b's position
    // takes the max witness's 1 down by at least 1/3. (cell's position can move them
    // too: a memoryless witness decides later choices by the state, and cell moving
    // earlier changes the states it sees.)
    let a = source(s, "min", "machine", Some("a")).expect("a on the min witness");
    assert!(a["shift"].as_f64().unwrap() > 0.3, "{a}");
    let b = source(s, "max", "machine", Some("b")).expect("b on the max witness");
    assert!(b["shift"].as_f64().unwrap() < -0.3, "{b}");
}

#[test]
fn a_race_of_machines_is_put_down_to_the_machine_order_and_its_two_racers() {
    let (r, table) = verify(&["verify", RACE, "--schedulers", "16"]);
    let s = &prop(&r, "a_wins")["schedulers"];
    assert_eq!(s["min"]["probability"], 0.0);
    assert_eq!(s["max"]["probability"], 1.0);
    race_sources(s);
    // The replayable name of a source runs it again.
    let again = source(s, "min", "machine", None).unwrap()["scheduler"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(again.ends_with("+machines"), "{again}");
    let (replay, _) = verify(&["verify", RACE, "--scheduler", &again]);
    let a = prop(&replay, "a_wins");
    assert!((p(a) - 0.5).abs() < 0.07, "{a}");
    // A property no order changes has no sources.
    assert!(prop(&r, "someone_wins")["schedulers"]
        .get("sources")
        .is_none());
    let line = table
        .lines()
        .find(|l| l.contains("a_wins") && l.contains("depends on"))
        .unwrap_or_else(|| panic!("{table}"));
    assert!(line.contains("moves first"), "{line}");
    assert!(line.contains(" a ") && line.contains(" b "), "{line}");
}

#[test]
fn a_race_of_deliveries_is_put_down_to_the_delivery_order_not_the_machine_order() {
    let (r, table) = verify(&[
        "verify",
        DELIVERY,
        "--events",
        "as2fm",
        "--schedulers",
        "16",
    ]);
    let a = prop(&r, "a_wins");
    // 11/16 (derived in the property file).
    assert!((p(a) - 11.0 / 16.0).abs() < 0.04, "uniform {a}");
    let s = &a["schedulers"];
    assert_eq!(s["min"]["probability"], 0.0);
    assert_eq!(s["max"]["probability"], 1.0);
    // The min witness lets src send both, then delivers eb first. With the delivery
    // order uniform, ea goes first half the time.
    let kind = source(s, "min", "delivery", None).expect("delivery order");
    assert!((p(kind) - 0.5).abs() < 0.07, "{kind}");
    for e in ["ea", "eb"] {
        let one = source(s, "min", "delivery", Some(e)).expect("an event");
        assert!((p(one) - 0.5).abs() < 0.07, "{e}: {one}");
    }
    // The max witness delivers ea first, either before src sends eb (the delivery order
    // never had a choice: still 1) or after (1/2 with it put back).
    let max = source(s, "max", "delivery", None).expect("delivery order");
    assert!(p(max) == 1.0 || (p(max) - 0.5).abs() < 0.07, "{max}");
    let line = table
        .lines()
        .find(|l| l.contains("a_wins") && l.contains("depends on"))
        .unwrap_or_else(|| panic!("{table}"));
    assert!(
        line.contains("whether ea or eb is delivered first")
            || line.contains("whether eb or ea is delivered first"),
        "{line}"
    );
}

/// A fixed-size study (`--runs R`, which also runs as shards) estimates where the order
/// comes from in two more stages, `R` runs per witness and choice: the same hand-derived
/// answers as the sequential study's.
#[test]
fn a_fixed_size_study_finds_where_the_order_comes_from_too() {
    let (r, table) = verify(&["verify", RACE, "--schedulers", "16", "--runs", "600"]);
    let s = &prop(&r, "a_wins")["schedulers"];
    assert_eq!(s["order_sensitive"], true, "{s}");
    race_sources(s);
    assert!(prop(&r, "someone_wins")["schedulers"]
        .get("sources")
        .is_none());
    assert!(table.contains("moves first"), "{table}");

    let (r, _) = verify(&[
        "verify",
        DELIVERY,
        "--events",
        "as2fm",
        "--schedulers",
        "16",
        "--runs",
        "600",
    ]);
    let s = &prop(&r, "a_wins")["schedulers"];
    let kind = source(s, "min", "delivery", None).expect("delivery order");
    assert!((p(kind) - 0.5).abs() < 0.07, "{kind}");
    for e in ["ea", "eb"] {
        let one = source(s, "min", "delivery", Some(e)).expect("an event");
        assert!((p(one) - 0.5).abs() < 0.07, "{e}: {one}");
    }
}

#[test]
fn a_bad_override_in_a_scheduler_id_is_refused_with_the_forms_it_takes() {
    let (code, _, err) = hindsight(&["verify", RACE, "--scheduler", "memoryless:12+sideways"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("unknown override `+sideways`"), "{err}");
    let (code, _, err) = hindsight(&["verify", RACE, "--scheduler", "memoryless:12+machine=x"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is not an index"), "{err}");
}

#[test]
fn the_report_page_shows_a_failing_run_under_the_min_witness_beside_a_uniform_one() {
    let dir = std::env::temp_dir().join(format!("hindsight-sched-report-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("page.html");
    let page_arg = page.display().to_string();
    let (code, _, err) = hindsight(&[
        "verify",
        RACE,
        "--schedulers",
        "8",
        "--precision",
        "0.05",
        "--report",
        &page_arg,
    ]);
    assert_eq!(code, 0, "{err}");
    let html = std::fs::read_to_string(&page).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    // a_wins is order-sensitive: its min witness fails every run (b always first), the
    // uniform scheduler about half of them; someone_wins never fails.
    let w = html
        .find("a_wins under the min witness memoryless:")
        .unwrap_or_else(|| panic!("no witness run in the page"));
    let u = html
        .find("a_wins under the uniform scheduler, run ")
        .expect("no uniform run in the page");
    assert!(w < u, "the witness's run comes first");
    assert!(!html.contains("someone_wins under the"));
    // The bounds table, with the witnesses and where a_wins's order comes from.
    let b = html
        .find("<h2>Orders the model leaves open</h2>")
        .expect("the bounds section");
    let rest = &html[b..];
    assert!(rest.contains("order-sensitive"), "{rest}");
    assert!(rest.contains("moves first"), "{rest}");
}
