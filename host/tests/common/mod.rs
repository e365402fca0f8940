//! What the integration tests share: running the `hindsight` binary, where the shared corpus is, the museum model the
//! simulator tests run, and a counting allocator.
//!
//! Each test file that needs it says `mod common;`; not every file uses every helper.
#![allow(dead_code)]

pub mod alloc;
pub mod canon;

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

/// `shared/corpus`, found next to the repository or a worktree container above it (the
/// repository may be checked out at `X/repo` or `X/wt/name`, with `X/shared`).
pub fn corpus_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("shared/corpus"))
        .find(|dir| dir.is_dir())
        .expect("shared/corpus next to the repository")
}

/// `shared/corpus/<relative>`.
pub fn corpus(relative: &str) -> PathBuf {
    corpus_root().join(relative)
}

/// The museum guide's plain SCXML machines (`museum-simpar2025/model_scxml`), compiled,
/// with the one-line fix of `NavigationComponent.scxml` (`_event.thread_id` ->
/// `_event.data.thread_id`) without which it does not compile.
pub fn museum_fixed() -> hindsight::sim::CompiledModel {
    let dir = corpus("museum-simpar2025/model_scxml");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "scxml"))
        .collect();
    paths.sort();
    let files: Vec<(String, String)> = paths
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).unwrap();
            let text = if p.ends_with("NavigationComponent.scxml") {
                text.replace("_event.thread_id", "_event.data.thread_id")
            } else {
                text
            };
            (p.display().to_string(), text)
        })
        .collect();
    let src = hindsight::model::ModelSource::from_texts(
        files.iter().map(|(a, b)| (a.as_str(), b.as_str())),
    )
    .unwrap();
    hindsight::sim::CompiledModel::compile(src).unwrap()
}
