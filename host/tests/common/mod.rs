//! What the integration tests share: running the `hindsight` binary, where the external
//! corpus is (and skipping a test without it: `corpus.rs`), the project's Python
//! environment for the interoperability tests (`pyenv.rs`), the DDS tests' processes and
//! domains (`dds.rs`), the museum model the
//! simulator tests run, and a counting allocator.
//!
//! Each test file that needs it says `mod common;`; not every file uses every helper.
#![allow(dead_code)]

pub mod alloc;
pub mod bt;
pub mod canon;
pub mod corpus;
pub mod dds;
pub mod pyenv;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs hindsight from the repository root; returns the exit code, stdout and stderr.
pub fn hindsight(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("run hindsight");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The external corpus for a test that needs it, or `None` after noting that the test
/// was skipped ([`corpus::corpus_or_skip`]); a test starts with
/// `if common::corpus_or_skip().is_none() { return; }`.
pub fn corpus_or_skip() -> Option<PathBuf> {
    corpus::corpus_or_skip()
}

/// The external corpus, for a test that has called [`corpus_or_skip`].
pub fn corpus_root() -> PathBuf {
    corpus::root()
}

/// `<corpus>/<relative>`, for a test that has called [`corpus_or_skip`].
pub fn corpus(relative: &str) -> PathBuf {
    corpus_root().join(relative)
}

/// The museum guide's plain SCXML machines, compiled: `examples/museum-scxml`, the
/// corpus's `museum-simpar2025/model_scxml` with the one-line fix of
/// `NavigationComponent.scxml` (`_event.thread_id` -> `_event.data.thread_id`) without
/// which it does not compile. In the repository, so tests using it run on any clone.
pub fn museum_fixed() -> hindsight::verify::sim::CompiledModel {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-scxml");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "scxml"))
        .collect();
    paths.sort();
    let files: Vec<(String, String)> = paths
        .iter()
        .map(|p| (p.display().to_string(), std::fs::read_to_string(p).unwrap()))
        .collect();
    let src = hindsight::verify::model::ModelSource::from_texts(
        files.iter().map(|(a, b)| (a.as_str(), b.as_str())),
    )
    .unwrap();
    hindsight::verify::sim::CompiledModel::compile(src).unwrap()
}
