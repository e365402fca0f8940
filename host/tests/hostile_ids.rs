//! Names that become paths and CSV (issue 28, finding 4): a property or port id is
//! checked where it is declared (no `/`, `..`, `,` ...), at its file:line:col; and
//! traces are read by the same RFC 4180 grammar `trace` and `--save-failing` write.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hindsight(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(args)
        .output()
        .unwrap()
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples")
}

/// The museum's plain model in `dir/m`, its property file with `from` replaced by `to`;
/// returns the model and the 1-based line of the replacement.
fn museum_props(dir: &Path, from: &str, to: &str) -> (PathBuf, usize) {
    let model = dir.join("m");
    std::fs::create_dir_all(&model).unwrap();
    for e in std::fs::read_dir(examples().join("museum-scxml")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), model.join(e.file_name())).unwrap();
    }
    let props = model.join("properties.xml");
    let text = std::fs::read_to_string(&props).unwrap();
    let at = text.find(from).expect("text to replace");
    let line = text[..at].matches('\n').count() + 1;
    std::fs::write(&props, text.replacen(from, to, 1)).unwrap();
    (model, line)
}

#[test]
fn ids_that_are_paths_or_need_quoting_are_refused_where_declared() {
    let dir = scratch("hostile-ids");
    for bad in [
        "../x",
        "/tmp/hostile-abs",
        "a,b",
        "say \"hi\"",
        ".hidden",
        "é",
    ] {
        let escaped = bad.replace('"', "&quot;");
        // A guarantee's id, then a port's.
        for from in ["id=\"absence\"", "id=\"alarm\""] {
            let (model, line) = museum_props(&dir, from, &format!("id=\"{escaped}\""));
            let out = hindsight(&["validate".as_ref(), model.as_os_str()]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
            assert!(
                err.contains(&format!("properties.xml:{line}:")),
                "{bad} at line {line}: {err}"
            );
            assert!(err.contains("ASCII letters, digits"), "{bad}: {err}");
            std::fs::remove_dir_all(dir.join("m")).unwrap();
        }
    }
    // The corpus's spellings stay valid: `-` and `.` inside an id.
    let (model, _) = museum_props(&dir, "id=\"absence\"", "id=\"absence-v1.2\"");
    let out = hindsight(&["validate".as_ref(), model.as_os_str()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_trace_is_read_with_the_grammar_trace_writes() {
    let dir = scratch("hostile-csv");
    // A recorder's `params` cell quoted over two lines, with a comma and a doubled
    // quote, as `verify::record::field` writes it: the line-by-line reader refused it.
    let trace = dir.join("t.csv");
    std::fs::write(
        &trace,
        "time,step,params,battery_level,alarm\n\
         0,init,,35,\n\
         1,send,\"text=a, \"\"b\"\"\nsecond line\",20,true\n\
         2,time,,,\n",
    )
    .unwrap();
    let spec = examples().join("specs/museum.hspec");
    let out = hindsight(&["replay".as_ref(), spec.as_os_str(), trace.as_os_str()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(text.lines().count(), 4, "{text}");
    assert!(text.lines().nth(3).unwrap().starts_with("2,"), "{text}");
    // A quote left open is an error at the cell where it opens.
    std::fs::write(&trace, "time,battery_level\n0,35\n1,\"20\n").unwrap();
    let out = hindsight(&["replay".as_ref(), spec.as_os_str(), trace.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("t.csv:3:3: unterminated quoted field"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
