//! The whole robot pipeline on every corpus main file: read, lower, compile.

use std::path::{Path, PathBuf};

use hindsight::robot::load::{load, main_file_of};

fn corpus_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("shared/corpus"))
        .find(|dir| dir.is_dir())
        .expect("shared/corpus next to the repository")
}

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

#[test]
fn every_corpus_main_file_loads() {
    let root = corpus_root().join("as2fm");
    let text = std::fs::read_to_string(root.join("expected.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let mut failed = Vec::new();
    for (case, v) in doc.as_object().unwrap() {
        let main = root.join(v["main"].as_str().unwrap());
        match load(&main) {
            Ok(m) => eprintln!(
                "{case}: {} machines, unit {} ns, max_time {} steps",
                m.model.machine_count(),
                m.time_unit_ns,
                m.max_time_steps
            ),
            Err(e) => failed.push(format!("{case}: {e}")),
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn the_museum_guide_example_loads() {
    let main = main_file_of(&repo("examples/museum-guide")).unwrap();
    let m = load(&main).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.time_unit_ns, 100_000_000);
}
