//! What the integration tests share: where the shared corpus is.
//!
//! Each test file that needs it says `mod common;`; not every file uses every helper.
#![allow(dead_code)]

pub mod canon;

use std::path::{Path, PathBuf};

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
