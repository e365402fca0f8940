//! Mutated robot models (main file, tree, node models, plugins, interfaces, properties):
//! each is an error naming a file, line and column, or loads and runs; never a panic.
//!
//! Deterministic mutation fuzzing of `examples/museum-guide`: every mutant changes one
//! file by a few byte edits or a line-level edit (delete, duplicate, swap, or an attribute
//! value replaced by another name from the model), which reaches past the XML reader into
//! the tree, the ROS lowering and the interface reader. `HINDSIGHT_ROBOT_MUTANTS=N` runs
//! more than the default.

mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use hindsight::verify::load::{load, LoadOptions};
use hindsight::verify::sim::{EventSemantics, RunConfig, Simulator};
use rand_core::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn guide() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

/// Every file of the model that the loader reads (not the recorded on-line logs).
fn model_files(dir: &Path, base: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let rel = path.strip_prefix(base).unwrap().to_path_buf();
        if rel.starts_with("online") {
            continue;
        }
        if path.is_dir() {
            model_files(&path, base, out);
        } else if matches!(
            path.extension().and_then(|e| e.to_str()),
            Some("xml" | "scxml" | "ascxml" | "msg" | "srv" | "action" | "jani" | "json")
        ) {
            out.push(rel);
        }
    }
}

/// Names and values that mean something somewhere in the model, to swap in for an
/// attribute value: ids of other nodes, types, topics, events, numbers, states.
const WORDS: &[&str] = &[
    "",
    "0",
    "-1",
    "1e9",
    "3.5",
    "true",
    "int32",
    "float64",
    "string",
    "bool",
    "int32[]",
    "std_msgs/Int32",
    "std_msgs/Bool",
    "example_interfaces/AddTwoInts",
    "navigation_interfaces_dummy/GoToPoi",
    "missing_pkg/Missing",
    "/battery_level",
    "/alarm",
    "idle",
    "nowhere",
    "Sequence",
    "Fallback",
    "Parallel",
    "Inverter",
    "ROS2Action",
    "UnknownNode",
    "{bb_key}",
    "_msg.data",
    "_req.x",
    "_res.is_ok",
    "_event.data",
    "1s",
    "0.1",
    "SUCCESS",
    "RUNNING",
];

/// Bytes a byte-level edit inserts.
const ALPHABET: &[u8] = b"<>/=\"' {}[]()._-:;&#!?abxyz019\n";

/// One mutant of `text`: a few byte edits, or one line-level edit.
fn mutate(text: &str, rng: &mut Xoshiro256PlusPlus) -> String {
    let pick = |rng: &mut Xoshiro256PlusPlus, n: usize| rng.next_u32() as usize % n.max(1);
    match rng.next_u32() % 4 {
        0 => {
            let mut t: Vec<u8> = text.bytes().collect();
            for _ in 0..1 + rng.next_u32() % 3 {
                let at = pick(rng, t.len() + 1);
                if rng.next_u32() % 2 == 0 && at < t.len() {
                    t.remove(at);
                } else {
                    t.insert(at, ALPHABET[pick(rng, ALPHABET.len())]);
                }
            }
            String::from_utf8_lossy(&t).into_owned()
        }
        1 => {
            // An attribute value replaced by another word.
            let quotes: Vec<usize> = text.match_indices("=\"").map(|(i, _)| i + 2).collect();
            if quotes.is_empty() {
                return text.to_string();
            }
            let start = quotes[pick(rng, quotes.len())];
            let end = start + text[start..].find('"').unwrap_or(0);
            let word = WORDS[pick(rng, WORDS.len())];
            format!("{}{}{}", &text[..start], word, &text[end..])
        }
        2 => {
            let mut lines: Vec<&str> = text.lines().collect();
            let at = pick(rng, lines.len());
            if rng.next_u32() % 2 == 0 {
                lines.remove(at);
            } else {
                let line = lines[at];
                lines.insert(at, line);
            }
            lines.join("\n")
        }
        _ => {
            let mut lines: Vec<&str> = text.lines().collect();
            let (a, b) = (pick(rng, lines.len()), pick(rng, lines.len()));
            lines.swap(a, b);
            lines.join("\n")
        }
    }
}

/// Whether an error message names a file with a line and column (`file.ext:L:C`).
fn has_position(message: &str) -> bool {
    message.lines().any(|line| {
        [
            ".xml:", ".scxml:", ".ascxml:", ".msg:", ".srv:", ".action:", ".jani:", ".json:",
        ]
        .iter()
        .any(|ext| {
            line.split(ext).nth(1).is_some_and(|rest| {
                let mut parts = rest.splitn(3, ':');
                let l = parts.next().unwrap_or("");
                let c = parts.next().unwrap_or("");
                !l.is_empty()
                    && l.bytes().all(|b| b.is_ascii_digit())
                    && !c.is_empty()
                    && c.bytes().all(|b| b.is_ascii_digit())
            })
        })
    })
}

#[test]
fn position_check_accepts_positions_only() {
    assert!(has_position("/a/b/policy.xml:12:7: unknown node `X`"));
    assert!(has_position("note\nSkills/A.scxml:3:1: bad"));
    assert!(!has_position("policy.xml: unknown node"));
    assert!(!has_position("policy.xml:12: unknown node"));
}

/// Mutants of the model under `base` (the files under its folders `parts`, all of it
/// when empty), loaded from `main` (relative to `base`); `favourites` get a share of the
/// mutants of their own. Panics with every problem found.
fn fuzz(name: &str, base: &Path, parts: &[&str], main: &str, favourites: &[&str], seed: u64) {
    let count: u64 = std::env::var("HINDSIGHT_ROBOT_MUTANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300);
    let mut files = Vec::new();
    if parts.is_empty() {
        model_files(base, base, &mut files);
    } else {
        for part in parts {
            model_files(&base.join(part), base, &mut files);
        }
    }
    assert!(files.len() > 2, "{files:?}");
    let dir = std::env::temp_dir().join(format!(
        "hindsight-robot-fuzz-{name}-{}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    for rel in &files {
        let to = dir.join(rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(base.join(rel), &to).unwrap();
    }
    // The model, its tree, interfaces and properties, as `hindsight verify` reads them;
    // the unmutated copy loads, so the mutants start from a working model.
    let args = LoadOptions {
        model: dir.join(main),
        ..LoadOptions::default()
    };
    if let Err(e) = load(&args) {
        panic!("{name}: {e}");
    }

    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let cfg = RunConfig {
        max_time: 30,
        max_steps: 20_000,
        events: EventSemantics::As2fm,
        ..RunConfig::default()
    };
    let (mut errors, mut loaded, mut unchanged) = (0, 0, 0);
    let mut problems = Vec::new();
    let mut reported = 0;
    for k in 0..count {
        let slot = rng.next_u32() as usize % (favourites.len() + 2);
        let rel = match favourites.get(slot) {
            Some(f) => PathBuf::from(f),
            None => files[rng.next_u32() as usize % files.len()].clone(),
        };
        let original = std::fs::read_to_string(base.join(&rel)).unwrap();
        let text = mutate(&original, &mut rng);
        if text == original {
            unchanged += 1;
            continue;
        }
        std::fs::write(dir.join(&rel), &text).unwrap();
        let outcome = catch_unwind(AssertUnwindSafe(|| match load(&args) {
            Ok(loaded) => {
                let mut sim = Simulator::new(&loaded.model);
                let mut rng = hindsight::verify::smc::runner::stream(1, k);
                sim.run(&mut rng, &cfg, &mut ());
                Ok(())
            }
            Err(e) => Err(e.to_string()),
        }));
        match outcome {
            Ok(Ok(())) => loaded += 1,
            Ok(Err(message)) => {
                errors += 1;
                // Something missing has no position: the file is named.
                let absent = message.contains("names no property file");
                if !has_position(&message) && !absent {
                    problems.push(format!(
                        "{name} mutant {k} of {}: error without file:line:col: {message}",
                        rel.display()
                    ));
                }
                // Errors speak of the user's files, not of the plain SCXML they become
                // (`ros_fields__x` is the parameter a message field turns into; JANI
                // properties are written over those names, so their errors may say them).
                // Lines indented by four spaces quote the user's file under a diagnostic.
                if message.lines().any(|l| {
                    !l.starts_with("    ") && l.contains("ros_fields__") && !l.contains(".jani:")
                }) {
                    problems.push(format!(
                        "{name} mutant {k} of {}: error about generated SCXML: {message}",
                        rel.display()
                    ));
                }
            }
            Err(_) => {
                problems.push(format!(
                    "{name} mutant {k} of {}: panicked (text kept in {})",
                    rel.display(),
                    dir.join(&rel).display()
                ));
                break; // keep the mutant on disk to look at
            }
        }
        if problems.len() > reported {
            // Keep the mutant beside the restored file, to look at.
            let keep = dir.join(format!("{}.mutant-{k}", rel.display()));
            std::fs::write(&keep, &text).unwrap();
            reported = problems.len();
        }
        std::fs::write(dir.join(&rel), &original).unwrap();
    }
    println!(
        "{name}: {count} mutants: {errors} errors, {loaded} loaded and ran, {unchanged} unchanged"
    );
    assert!(
        problems.is_empty(),
        "{}\n(mutants kept as <file>.mutant-<k> in {})",
        problems.join("\n"),
        dir.display()
    );
    // The mutations reach both outcomes, so the test exercises the error paths and the
    // lowering of models that are still valid.
    assert!(
        errors > count / 10 && loaded > count / 20,
        "{name}: {errors} errors, {loaded} loaded"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn mutated_museum_guides_are_errors_with_positions_or_run() {
    let base = guide();
    fuzz(
        "guide",
        &base,
        &[],
        "main.xml",
        &["main.xml", "policy.xml", "properties.xml"],
        5,
    );
}

/// AS2FM's own models: actions, blackboard ports, struct declarations, other tree nodes.
#[test]
fn mutated_as2fm_models_are_errors_with_positions_or_run() {
    if common::corpus_or_skip().is_none() {
        return;
    }
    let as2fm = common::corpus("as2fm");
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "examples/tutorial_fetch_and_carry",
            "main.xml",
            &["bt_tree.xml", "world.ascxml"],
        ),
        (
            "test_data/grid_robot_blackboard_simple",
            "main.xml",
            &["bt.xml"],
        ),
        (
            "test_data/fibonacci_action_example",
            "main.xml",
            &["server.ascxml", "client_1.ascxml"],
        ),
        (
            "test_data/data_structs",
            "main_xml_def.xml",
            &["my_types.xml", "sender.ascxml"],
        ),
    ];
    for (i, (case, main, favourites)) in cases.iter().enumerate() {
        let favourites: Vec<String> = favourites.iter().map(|f| format!("{case}/{f}")).collect();
        let favourites: Vec<&str> = favourites.iter().map(String::as_str).collect();
        fuzz(
            case.rsplit('/').next().unwrap(),
            &as2fm,
            &[case, "ros_support_interfaces"],
            &format!("{case}/{main}"),
            &favourites,
            100 + i as u64,
        );
    }
}
