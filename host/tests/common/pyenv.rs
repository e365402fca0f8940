//! The project's Python environment (`scripts/pyenv`) for the interoperability tests:
//! its interpreter when it has the packages a test needs, or a skip that says how to get
//! it (a failure under `CI=true`, where `.ci/run` has created it).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python of the environment (`HINDSIGHT_PYENV`, or `.venv` at the repository root)
/// if it imports every module of `modules`; otherwise `None` after printing why the
/// test is skipped. `packages` names them as a user installs them.
pub fn python_with(modules: &[&str], packages: &str) -> Option<PathBuf> {
    let env = std::env::var_os("HINDSIGHT_PYENV").map_or_else(
        || {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .parent()
                .expect("host/ has a parent")
                .join(".venv")
        },
        PathBuf::from,
    );
    let py = env.join("bin/python");
    let ok = Command::new(&py)
        .args(["-c", &format!("import {}", modules.join(", "))])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(py);
    }
    let why = format!(
        "skipped: no Python environment with {packages} at {}: run `bash scripts/pyenv`",
        env.display()
    );
    assert!(std::env::var("CI").as_deref() != Ok("true"), "{why}");
    eprintln!("{why}");
    None
}
