//! ARCHITECTURE.md's layering invariant of `host`, checked on the source: a module uses only
//! modules before it in the pipeline, `tracefile` serves `cli` only, `live/` does not use
//! `verify/`, and nothing outside `cli/` takes clap types.
//!
//! `crate::expr`, `crate::model`, `crate::sim`, `crate::props`, `crate::robot`,
//! `crate::verify` and `crate::smc` are re-exports of the crates `hindsight-expr`,
//! `hindsight-sim`, `hindsight-props`, `hindsight-robot`, `hindsight-verify` and
//! `hindsight-smc` (`crates/`): Cargo checks that
//! they import nothing of `host` (and that `hindsight-sim` imports nothing of
//! `hindsight-props` or `hindsight-robot`), and any module may use them, as any module may
//! use `codegen`. This test checks what remains of `host`.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The pipeline's order: a module may use the ones before it (and itself).
const ORDER: [&str; 3] = ["report", "live", "cli"];

fn src() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The top-level module a file of `host/src` belongs to (`lib`/`main` for the roots).
fn module_of(path: &Path) -> String {
    let rel = path.strip_prefix(src()).unwrap();
    let first = rel.components().next().unwrap().as_os_str();
    first.to_string_lossy().trim_end_matches(".rs").to_string()
}

/// The top-level modules `text` names as `crate::X` outside comments, with the line.
fn uses(text: &str) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            // `hindsight_crate::` or the like is not a path of this crate.
            let before = rest[..i].chars().next_back();
            let after = &rest[i + "crate::".len()..];
            rest = after;
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let name: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                out.push((name, n + 1));
            }
        }
    }
    out
}

fn rank(m: &str) -> Option<usize> {
    ORDER.iter().position(|x| *x == m)
}

#[test]
fn every_module_uses_only_modules_before_it() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    let mut broken = Vec::new();
    let mut seen = BTreeSet::new();
    for f in &files {
        let from = module_of(f);
        let text = std::fs::read_to_string(f).unwrap();
        for (to, line) in uses(&text) {
            seen.insert(to.clone());
            let where_ = format!("{}:{line}", f.display());
            match (from.as_str(), to.as_str()) {
                (a, b) if a == b => {}
                ("lib" | "main", _) => {}
                (_, "expr" | "model" | "sim" | "props" | "robot" | "smc") => {}
                ("live", "verify") => broken.push(format!("{where_}: live uses verify")),
                (_, "verify") => {}
                (a, "tracefile") if a != "cli" => {
                    broken.push(format!("{where_}: {a} uses tracefile (cli only)"))
                }
                ("cli", "tracefile") => {}
                (a, b) => match (rank(a), rank(b)) {
                    (Some(x), Some(y)) if y < x => {}
                    (Some(_), Some(_)) => broken.push(format!("{where_}: {a} uses {b}, after it")),
                    _ => broken.push(format!("{where_}: {a} uses {b}, not in the order")),
                },
            }
        }
        if from != "cli" && from != "main" && text.contains("clap::") {
            broken.push(format!("{}: clap outside cli/", f.display()));
        }
    }
    assert!(broken.is_empty(), "layering broken:\n{}", broken.join("\n"));
    // The scan saw real uses: it is not vacuously true.
    for m in ["robot", "verify", "report", "live"] {
        assert!(seen.contains(m), "no use of crate::{m} found: {seen:?}");
    }
}

#[test]
fn the_scan_finds_a_use_and_skips_comments() {
    let text = "use crate::sim::Simulator;\n// crate::cli is a comment\nlet x = my_crate::y; crate::expr::f();\n";
    assert_eq!(
        uses(text),
        vec![("sim".to_string(), 1), ("expr".to_string(), 3)]
    );
}
