//! BT.CPP 4's blackboard nodes in the oracle: the cases of `tests/bt/btcpp4/*.toml` (the
//! Loop nodes' unit tests transcribed from BT.CPP 4.10 `tests/gtest_loop.cpp`, and facts
//! of the real library for UnsetBlackboard and the entry-updated nodes) hold in the
//! oracle's BT.CPP 4 reading on a tree built from XML and ticked with `tickOnce`: root
//! status per tick, ticks and halts per leaf type, script entries at the end, and the
//! tick BT.CPP throws in. `tests/tests/bt_real.rs` runs the same cases in the real
//! library against the oracle.

use hindsight_tests::bt::oracle::{run_with, End, LeafEvent, Options, Scripts, TickMode};
use hindsight_tests::bt::tree::{self, Status};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Deserialize)]
struct File {
    case: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    test: String,
    tree: String,
    #[serde(default)]
    statuses: Vec<String>,
    #[serde(default)]
    ticks: Option<usize>,
    scripts: BTreeMap<String, Vec<String>>,
    /// (ticks, halts) per leaf type after the last tick.
    #[serde(default)]
    leaves: BTreeMap<String, (usize, usize)>,
    /// Script entries at the end (those named).
    #[serde(default)]
    vars: BTreeMap<String, i64>,
    /// BT.CPP throws in this tick ...
    #[serde(default)]
    error_at: Option<usize>,
    /// ... with this in its message.
    #[serde(default)]
    error: Option<String>,
}

fn load() -> Vec<(String, Case)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("bt/btcpp4");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let mut out = Vec::new();
    for p in files {
        let text = std::fs::read_to_string(&p).expect("read");
        let f: File = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        out.extend(f.case.into_iter().map(|c| (name.clone(), c)));
    }
    out
}

/// Where the oracle departs from the case's facts, if anywhere.
fn check(c: &Case) -> Result<(), String> {
    // A case with SubTrees is a whole document (`subtree.toml`).
    let xml = if c.tree.trim_start().starts_with("<root") {
        c.tree.clone()
    } else {
        format!(
            "<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\">{}</BehaviorTree></root>",
            c.tree
        )
    };
    let scripts: Scripts = c
        .scripts
        .iter()
        .map(|(k, v)| {
            let s = v
                .iter()
                .map(|x| Status::parse(x).expect("status"))
                .collect();
            (k.clone(), s)
        })
        .collect();
    let t = tree::read(&xml)?;
    let ticks = c.ticks.unwrap_or(c.statuses.len());
    let o = run_with(&t, &scripts, Options::xml4(TickMode::Once), ticks)?;
    let want: Vec<Status> = c
        .statuses
        .iter()
        .map(|s| Status::parse(s).expect("status"))
        .collect();
    if o.statuses != want {
        return Err(format!("statuses {:?}, expected {want:?}", o.statuses));
    }
    match (&o.end, c.error_at) {
        (None, None) => {}
        (Some(End::Error { tick, text }), Some(at)) => {
            let msg = c.error.as_deref().unwrap_or("");
            if *tick != at || !text.contains(msg) && !msg.contains(text.as_str()) {
                return Err(format!("throws at {tick} ({text}), expected {at} ({msg})"));
            }
        }
        (e, at) => return Err(format!("ends {e:?}, expected an error at {at:?}")),
    }
    for (ty, want) in &c.leaves {
        let mut got = (0, 0);
        for ev in &o.log {
            let (id, tick) = match *ev {
                LeafEvent::Tick(id) => (id, true),
                LeafEvent::Halt(id) => (id, false),
            };
            if t.nodes[(id - 1000) as usize].tag == *ty {
                if tick {
                    got.0 += 1;
                } else {
                    got.1 += 1;
                }
            }
        }
        if got != *want {
            return Err(format!("{ty}: (ticks, halts) {got:?}, expected {want:?}"));
        }
    }
    for (k, v) in &c.vars {
        if o.vars.get(k) != Some(v) {
            return Err(format!("entry {k}: {:?}, expected {v}", o.vars.get(k)));
        }
    }
    Ok(())
}

#[test]
fn blackboard_node_cases_hold_in_the_oracle() {
    let cases = load();
    assert!(cases.len() >= 28, "{} cases", cases.len());
    let fails: Vec<String> = cases
        .iter()
        .filter_map(|(f, c)| check(c).err().map(|e| format!("{f} {}: {e}", c.test)))
        .collect();
    eprintln!("{} cases, {} disagree", cases.len(), fails.len());
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// The oracle refuses what it does not model rather than guessing: a Loop over a queue
/// entry, UnsetBlackboard inside a SubTree, a `key` in braces, a queue item that does
/// not convert.
#[test]
fn unmodelled_blackboard_uses_are_refused() {
    let body = |b: &str| {
        format!("<root BTCPP_format=\"4\"><BehaviorTree ID=\"Main\">{b}</BehaviorTree><BehaviorTree ID=\"S\"><UnsetBlackboard key=\"x\"/></BehaviorTree></root>")
    };
    for (b, why) in [
        ("<LoopInt queue=\"{q}\"><A/></LoopInt>", "queue entry"),
        (
            "<SubTree ID=\"S\" _autoremap=\"true\"/>",
            "inside a SubTree",
        ),
        ("<UnsetBlackboard key=\"{x}\"/>", "in {}"),
        ("<LoopInt queue=\"1; 2\"><A/></LoopInt>", "is not a Int"),
        ("<LoopBool queue=\"yes\"><A/></LoopBool>", "is not a Bool"),
    ] {
        let e = tree::read(&body(b)).err().unwrap_or_default();
        assert!(e.contains(why), "{b}: {e:?}");
    }
}
