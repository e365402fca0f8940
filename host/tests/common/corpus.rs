//! Where the external corpus is (models other people wrote: AS2FM's test data and plain
//! translations, the paper's museum model, UC3), and what a test that needs it does on a
//! clone without it.
//!
//! The corpus is not part of the repository. It is `$HINDSIGHT_CORPUS` when that is set,
//! else `shared/corpus` in a folder above this crate (next to the repository, or next to
//! a folder of worktrees holding it). A test that needs it starts with
//! `let Some(root) = common::corpus_or_skip() else { return };`: without the corpus the
//! test notes that it was skipped and passes, except under `CI=true`, where it fails.
//! `scripts/test` sets `HINDSIGHT_SKIP_LOG` to a file, each skip appends one line to it,
//! and the script prints how many tests were skipped (cargo shows a passing test's output
//! only with `--nocapture`, so a line on stderr alone would be lost).
//!
//! This file is also included by `host/benches/museum.rs` (`#[path]`), which only uses
//! [`find`].
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};

/// Why a test that needs the corpus did not run, and how to make it run.
pub const SKIP_REASON: &str =
    "needs the external corpus (set HINDSIGHT_CORPUS or put shared/corpus next to the repository)";

/// The corpus folder, if there is one. A `HINDSIGHT_CORPUS` that is not a folder is a
/// mistake, never a reason to skip: it panics.
pub fn find() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("HINDSIGHT_CORPUS") {
        let dir = PathBuf::from(dir);
        assert!(
            dir.is_dir(),
            "HINDSIGHT_CORPUS={} is not a folder",
            dir.display()
        );
        return Some(dir);
    }
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|dir| dir.join("shared/corpus"))
        .find(|dir| dir.is_dir())
}

/// The corpus for a test that needs it, or `None` after noting that the calling test was
/// skipped (one line on stderr and, when `HINDSIGHT_SKIP_LOG` names a file, one line
/// appended to it). Under `CI=true` a missing corpus panics, giving the same reason.
pub fn corpus_or_skip() -> Option<PathBuf> {
    if let Some(dir) = find() {
        return Some(dir);
    }
    // libtest runs each test on a thread named after it.
    let test = std::thread::current().name().unwrap_or("?").to_owned();
    let test = format!("{}::{test}", env!("CARGO_CRATE_NAME"));
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{test} {SKIP_REASON}; under CI=true a missing corpus is a failure");
    }
    let line = format!("{test}: skipped: {SKIP_REASON}");
    eprintln!("{line}");
    if let Some(log) = std::env::var_os("HINDSIGHT_SKIP_LOG") {
        // One short write in append mode: lines from tests running at the same time
        // do not interleave.
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&log)
            .unwrap_or_else(|e| panic!("HINDSIGHT_SKIP_LOG={}: {e}", Path::new(&log).display()));
        f.write_all(format!("{line}\n").as_bytes())
            .unwrap_or_else(|e| panic!("HINDSIGHT_SKIP_LOG: {e}"));
    }
    None
}

/// The corpus folder for code that runs only after [`corpus_or_skip`] found it.
pub fn root() -> PathBuf {
    find().unwrap_or_else(|| panic!("{SKIP_REASON}: call common::corpus_or_skip() first"))
}
