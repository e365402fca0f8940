//! BehaviorTree.CPP's own unit tests, transcribed into `tests/bt/btcpp/*.toml`, run
//! through the oracle (BT.CPP 4's reading, or 3.8's for the `v3.8/` tests; nodes built by
//! hand, or a tree the factory built from XML, with the wake-up signal, as the gtest
//! did: `built`) and through hindsight's lowering; and the
//! regression cases the differential test found (`tests/bt/regressions/*.toml`), run
//! through the oracle (AS2FM's reading) and the lowering under both `Halts` rules.

mod bt_common;

use bt_common::{diff, lowered, reference, running_halts_only, Run};
use hindsight::verify::robot::bt::Halts;
use hindsight_tests::bt::oracle::{run_with, LeafEvent, Options, Reading, Scripts, TickMode};
use hindsight_tests::bt::tree::{self, Kind, Status};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Deserialize)]
struct File {
    case: Vec<Case>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    /// Where it comes from: the file and TEST name, or the differential seed.
    test: String,
    /// The `<BehaviorTree>` body, or a whole `<root>` document.
    tree: String,
    /// Root status at each tick (BT.CPP's facts), under [`Case::reading`]; may be empty
    /// in a regression case, which then gives `ticks`.
    #[serde(default)]
    statuses: Vec<String>,
    /// How many root ticks, when `statuses` is empty.
    #[serde(default)]
    ticks: Option<usize>,
    scripts: BTreeMap<String, Vec<String>>,
    /// (ticks, halts) per leaf type after the last tick (halts as BT.CPP delivers them).
    #[serde(default)]
    leaves: BTreeMap<String, (usize, usize)>,
    /// `btcpp` (default for transcribed cases) or `as2fm`: which reading the expected
    /// statuses are stated in. Where the readings differ the lowering follows AS2FM.
    #[serde(default)]
    reading: Option<String>,
    /// Why AS2FM's reading (and so the lowering) gives other facts here: the lowering is
    /// then checked against the oracle's AS2FM reading only.
    #[serde(default)]
    as2fm_differs: Option<String>,
    /// `xml` when the gtest built the tree with `createTreeFromText` (every node has the
    /// wake-up signal; its `tickWhileRunning` / `tickOnce` re-tick while a wake-up is
    /// pending); else the nodes were built by hand and ticked with `executeTick`.
    #[serde(default)]
    built: Option<String>,
}

fn doc(tree: &str) -> String {
    if tree.trim_start().starts_with("<root") {
        tree.to_string()
    } else {
        format!("<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\">{tree}</BehaviorTree></root>")
    }
}

fn scripts(c: &Case) -> Scripts {
    c.scripts
        .iter()
        .map(|(k, v)| {
            let s = v
                .iter()
                .map(|x| Status::parse(x).unwrap_or_else(|| panic!("{}: status {x}", c.test)))
                .collect();
            (k.clone(), s)
        })
        .collect()
}

fn load(dir: &str) -> Vec<(String, Case)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out = Vec::new();
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    for p in files {
        let text = std::fs::read_to_string(&p).expect("read");
        let f: File = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        out.extend(f.case.into_iter().map(|c| (name.clone(), c)));
    }
    out
}

/// The per-leaf-type (ticks, halts) of a log.
fn counts(xml: &str, log: &[LeafEvent]) -> BTreeMap<String, (usize, usize)> {
    let t = tree::read(xml).expect("tree");
    let ty: BTreeMap<u32, String> = t
        .nodes
        .iter()
        .filter_map(|n| match &n.kind {
            Kind::Leaf(ty) => Some((n.id, ty.clone())),
            _ => None,
        })
        .collect();
    let mut out: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for e in log {
        match e {
            LeafEvent::Tick(id) => out.entry(ty[id].clone()).or_default().0 += 1,
            LeafEvent::Halt(id) => out.entry(ty[id].clone()).or_default().1 += 1,
        }
    }
    out
}

/// The log with only the halts BT.CPP delivers (to a leaf whose last answer was RUNNING).
fn btcpp_halts(xml: &str, s: &Scripts, log: &[LeafEvent]) -> Vec<LeafEvent> {
    let t = tree::read(xml).expect("tree");
    let ty: BTreeMap<u32, Vec<Status>> = t
        .nodes
        .iter()
        .filter_map(|n| match &n.kind {
            Kind::Leaf(ty) => Some((n.id, s[ty].clone())),
            _ => None,
        })
        .collect();
    running_halts_only(log, |id, k| ty[&id][k % ty[&id].len()])
}

fn check_expected(c: &Case, xml: &str, run: &Run, who: &str) -> Option<String> {
    let got: Vec<&str> = run.0.iter().map(|s| s.name()).collect();
    if got != c.statuses {
        return Some(format!(
            "{who}: statuses {got:?}, BT.CPP says {:?}",
            c.statuses
        ));
    }
    let all = counts(xml, &run.1);
    for (leaf, want) in &c.leaves {
        let have = all.get(leaf).copied().unwrap_or_default();
        if have != *want {
            return Some(format!(
                "{who}: leaf {leaf} (ticks, halts) {have:?}, want {want:?}"
            ));
        }
    }
    None
}

#[test]
fn btcpp_unit_tests_hold_in_the_oracle_and_the_lowering() {
    let cases = load("bt/btcpp");
    assert!(cases.len() >= 98, "{} cases", cases.len());
    let mut fails = Vec::new();
    let mut lowering_agrees = 0;
    for (file, c) in &cases {
        let xml = doc(&c.tree);
        let s = scripts(c);
        let n = c.statuses.len();
        let reading = match c.reading.as_deref() {
            Some("as2fm") => Reading::As2fm,
            _ if c.test.starts_with("v3.8/") => Reading::Btcpp3,
            _ => Reading::Btcpp,
        };
        let opts = match c.built.as_deref() {
            Some("xml") if reading == Reading::Btcpp => Options::xml4(TickMode::Once),
            None => Options::of(reading),
            Some(b) => panic!("{file} {}: built = {b:?}", c.test),
        };
        // The oracle's BT.CPP reading reproduces BT.CPP's facts.
        let tree = tree::read(&xml).expect("tree");
        let bt = match run_with(&tree, &s, opts, n) {
            Ok(o) if o.end.is_none() => (o.statuses, o.log),
            Ok(o) => {
                fails.push(format!("{file} {}: oracle ends {:?}", c.test, o.end));
                continue;
            }
            Err(e) => {
                fails.push(format!("{file} {}: oracle: {e}", c.test));
                continue;
            }
        };
        if let Some(p) = check_expected(c, &xml, &bt, "oracle") {
            fails.push(format!("{file} {}: {p}", c.test));
        }
        // The lowering follows AS2FM's reading: equal to the oracle's, and to BT.CPP's
        // facts once the halts BT.CPP would not deliver are dropped.
        let as2 = reference(&xml, &s, n, Reading::As2fm).expect("as2fm reading");
        for halts in [Halts::As2fm, Halts::WhenNeeded] {
            match lowered(&xml, &s, n, halts) {
                Ok(low) => {
                    if let Some(d) = diff(&as2, &low) {
                        fails.push(format!(
                            "{file} {} ({halts:?}): oracle vs lowering: {d}",
                            c.test
                        ));
                    } else {
                        let filtered = (low.0.clone(), btcpp_halts(&xml, &s, &low.1));
                        if reading != Reading::As2fm && c.as2fm_differs.is_none() {
                            if let Some(p) = check_expected(c, &xml, &filtered, "lowering") {
                                fails.push(format!("{file} {} ({halts:?}): {p}", c.test));
                                continue;
                            }
                        }
                        lowering_agrees += 1;
                    }
                }
                Err(e) => fails.push(format!("{file} {}: lowering: {e}", c.test)),
            }
        }
    }
    eprintln!(
        "{} BT.CPP cases; the lowering agrees on {} of {} runs",
        cases.len(),
        lowering_agrees,
        2 * cases.len()
    );
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn differential_regressions_stay_fixed() {
    let cases = load("bt/regressions");
    for (file, c) in &cases {
        let xml = doc(&c.tree);
        let s = scripts(c);
        let n = c.ticks.unwrap_or(c.statuses.len());
        assert!(n > 0, "{file} {}: no ticks", c.test);
        let want = reference(&xml, &s, n, Reading::As2fm).unwrap_or_else(|e| panic!("{file}: {e}"));
        let got: Vec<&str> = want.0.iter().map(|s| s.name()).collect();
        if !c.statuses.is_empty() {
            assert_eq!(got, c.statuses, "{file} {}: the oracle's statuses", c.test);
        }
        for halts in [Halts::As2fm, Halts::WhenNeeded] {
            let low = lowered(&xml, &s, n, halts).unwrap_or_else(|e| panic!("{file}: {e}"));
            if let Some(d) = diff(&want, &low) {
                panic!("{file} {} ({halts:?}): {d}", c.test);
            }
        }
    }
}
