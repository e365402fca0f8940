//! Golden snapshots of the Rust emitter: each hand-built program's emitted source,
//! compared with `tests/golden/<name>.rs`. `UPDATE_GOLDEN=1 cargo test -p
//! hindsight-codegen --test golden` rewrites the snapshots.

use std::path::{Path, PathBuf};

use codegen::emit_rust::{emit_rust, input_fields, EmitError, EmitOptions};

mod programs {
    include!("golden/programs.rs");
}

/// The header command written into every snapshot.
const COMMAND: &str = "UPDATE_GOLDEN=1 cargo test -p hindsight-codegen --test golden";

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// A line diff (longest common subsequence) of `expected` against `actual`,
/// showing changed lines with two lines of context, at most `limit` lines.
fn diff(expected: &str, actual: &str, limit: usize) -> String {
    let a: Vec<&str> = expected.lines().collect();
    let b: Vec<&str> = actual.lines().collect();
    // lcs[i][j]: length of the LCS of a[i..] and b[j..].
    let mut lcs = vec![vec![0u32; b.len() + 1]; a.len() + 1];
    for i in (0..a.len()).rev() {
        for j in (0..b.len()).rev() {
            lcs[i][j] = if a[i] == b[j] {
                lcs[i + 1][j + 1] + 1
            } else {
                lcs[i + 1][j].max(lcs[i][j + 1])
            };
        }
    }
    // Edit script: (' ' | '-' | '+', line number in its file, text).
    let mut ops = Vec::new();
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        if i < a.len() && j < b.len() && a[i] == b[j] {
            ops.push((' ', i + 1, a[i]));
            i += 1;
            j += 1;
        } else if i < a.len() && (j == b.len() || lcs[i + 1][j] >= lcs[i][j + 1]) {
            ops.push(('-', i + 1, a[i]));
            i += 1;
        } else {
            ops.push(('+', j + 1, b[j]));
            j += 1;
        }
    }
    let changed: Vec<bool> = ops.iter().map(|(c, _, _)| *c != ' ').collect();
    let near = |k: usize| (k.saturating_sub(2)..(k + 3).min(ops.len())).any(|m| changed[m]);
    let mut out = String::new();
    let mut shown = 0;
    let mut gap = false;
    for (k, (c, line, text)) in ops.iter().enumerate() {
        if !near(k) {
            gap = true;
            continue;
        }
        if gap || shown == 0 {
            out.push_str(&format!("@@ line {line} @@\n"));
            gap = false;
        }
        out.push_str(&format!("{c} {text}\n"));
        shown += 1;
        if shown >= limit {
            out.push_str("... (diff truncated)\n");
            break;
        }
    }
    out
}

#[test]
fn emitted_sources_match_snapshots() {
    let update = std::env::var_os("UPDATE_GOLDEN").is_some_and(|v| v == "1");
    let mut failures = Vec::new();
    for (name, program) in programs::all() {
        let src = emit_rust(&program, &EmitOptions::new(name, COMMAND))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let path = golden_dir().join(format!("{name}.rs"));
        if update {
            std::fs::write(&path, &src).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            continue;
        }
        match std::fs::read_to_string(&path) {
            Ok(expected) if expected == src => {}
            Ok(expected) => failures.push(format!(
                "{} is stale (- snapshot, + emitted):\n{}",
                path.display(),
                diff(&expected, &src, 60)
            )),
            Err(e) => failures.push(format!("{}: {e}", path.display())),
        }
    }
    assert!(
        failures.is_empty(),
        "{}\nrerun with UPDATE_GOLDEN=1 to accept the new output",
        failures.join("\n")
    );
}

#[test]
fn every_snapshot_has_a_program() {
    let names: Vec<String> = programs::all()
        .iter()
        .map(|(n, _)| format!("{n}.rs"))
        .collect();
    for entry in std::fs::read_dir(golden_dir()).expect("golden directory") {
        let file = entry.expect("directory entry").file_name();
        let file = file.to_string_lossy();
        if file != "programs.rs" {
            assert!(names.contains(&file.to_string()), "stale snapshot {file}");
        }
    }
}

#[test]
fn emitting_is_deterministic() {
    for (name, program) in programs::all().into_iter().chain(programs::random_all()) {
        let opts = EmitOptions::new(name, COMMAND);
        assert_eq!(emit_rust(&program, &opts), emit_rust(&program, &opts));
    }
}

#[test]
fn diff_shows_changed_lines() {
    let d = diff("a\nb\nc\n", "a\nB\nc\n", 10);
    assert!(d.contains("- b\n+ B\n"), "{d}");
    assert!(d.starts_with("@@ line 1 @@"), "{d}");
}

#[test]
fn invalid_programs_are_rejected() {
    let mut program = programs::windows();
    let mut nodes = program.nodes.to_vec();
    nodes[2].slot += 1;
    program.nodes = &*Box::leak(nodes.into_boxed_slice());
    let err = emit_rust(&program, &EmitOptions::new("bad", COMMAND)).unwrap_err();
    assert_eq!(
        err,
        EmitError::Invalid(monitor_core::TableError::Layout { node: 2 })
    );
}

#[test]
fn module_names_must_be_lower_case_identifiers() {
    let program = programs::minimal();
    for bad in ["", "Door", "9lives", "type", "a-b", "a__b", "_", "self"] {
        assert_eq!(
            emit_rust(&program, &EmitOptions::new(bad, COMMAND)),
            Err(EmitError::ModuleName(bad.to_string())),
            "{bad:?}"
        );
    }
    for good in ["door", "_door", "door_2"] {
        assert!(emit_rust(&program, &EmitOptions::new(good, COMMAND)).is_ok());
    }
}

#[test]
fn monitors_too_large_for_32_bit_targets_are_refused() {
    use monitor_core::{Op, Value};
    let bound = 1u64 << 30;
    let program = programs::build(
        vec![programs::state("x", Value::Bool(false))],
        vec![],
        vec![vec![monitor_core::Instr::Load(0)]],
        vec![(
            "wide",
            vec![
                Op::Const(true),
                Op::Atom(0),
                programs::since(0, 1, bound, Some(bound)),
            ],
        )],
    );
    let err = emit_rust(&program, &EmitOptions::new("wide", COMMAND)).unwrap_err();
    assert_eq!(
        err,
        EmitError::StateTooLarge {
            bytes: 8 + 8 + 16 * (bound + 1)
        }
    );
}

#[test]
fn field_names_are_snake_case_and_unique() {
    let program = programs::strings();
    assert_eq!(
        input_fields(&program),
        ["mode", "next_mode", "door_open", "type_"]
    );
    let program = programs::build(
        vec![
            programs::event("a.b"),
            programs::event("a_b"),
            programs::event("42"),
            programs::event("--"),
            programs::event("HTTPServer"),
        ],
        vec![],
        vec![],
        vec![("t", vec![monitor_core::Op::Const(true)])],
    );
    assert_eq!(
        input_fields(&program),
        ["a_b", "a_b_2", "v_42", "v3", "httpserver"]
    );
}
