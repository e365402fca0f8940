//! The smaller findings of issue 28 (finding 6), one test each: tick rates the time unit
//! cannot hold, a JANI `op` that is no string, a record cut mid-line, NaN in a trace, a
//! report page written whole or not at all, a port type that names no interface. (Bad
//! UTF-8 and byte order marks are in `hostile_sources.rs`, with the one source reader.)

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_hindsight")
}

fn hindsight(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(bin()).args(args).output().unwrap()
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

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// The museum guide copied to `dir/museum` with `file`'s `from` replaced by `to` (bytes).
fn museum_edit(dir: &Path, file: &str, from: &[u8], to: &[u8]) -> PathBuf {
    let model = dir.join("museum");
    let _ = std::fs::remove_dir_all(&model);
    copy_dir(&examples().join("museum-guide"), &model);
    let path = model.join(file);
    let bytes = std::fs::read(&path).unwrap();
    let at = bytes
        .windows(from.len())
        .position(|w| w == from)
        .expect("text to replace");
    let mut out = bytes[..at].to_vec();
    out.extend_from_slice(to);
    out.extend_from_slice(&bytes[at + from.len()..]);
    std::fs::write(&path, out).unwrap();
    model
}

/// `validate` of `model` fails with exit 2; returns standard error.
fn invalid(model: &Path) -> String {
    let out = hindsight(&["validate".as_ref(), model.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{err}");
    err
}

fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).unwrap()].matches('\n').count() + 1
}

#[test]
fn tick_rates_the_time_unit_cannot_hold_are_refused_at_the_attribute() {
    let dir = scratch("hostile-tick");
    let main = std::fs::read_to_string(examples().join("museum-guide/main.xml")).unwrap();
    let line = line_of(&main, "<bt_tick_rate");
    // 3 Hz: a period of 333333333.3 ns made the time step 1 ns (every run cut short).
    let model = museum_edit(&dir, "main.xml", b"value=\"10.0\"", b"value=\"3\"");
    let err = invalid(&model);
    assert!(err.contains(&format!("main.xml:{line}:")), "{err}");
    assert!(err.contains("not a whole number of nanoseconds"), "{err}");
    // 1e-12 Hz: reported at the attribute, not in another file.
    let model = museum_edit(&dir, "main.xml", b"value=\"10.0\"", b"value=\"1e-12\"");
    let err = invalid(&model);
    assert!(
        err.starts_with(&format!("{}:{line}:", model.join("main.xml").display())),
        "{err}"
    );
    assert_eq!(
        err.lines().filter(|l| l.contains(".xml:")).count(),
        1,
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_jani_op_that_is_no_string_is_named() {
    let dir = scratch("hostile-jani");
    let model = dir.join("mission");
    copy_dir(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/bt/format3_mission"),
        &model,
    );
    let props = model.join("properties.jani");
    let text = std::fs::read_to_string(&props).unwrap();
    let line = line_of(&text, "\"op\": \"F\"");
    std::fs::write(&props, text.replacen("\"op\": \"F\"", "\"op\": 3", 1)).unwrap();
    let err = invalid(&model);
    assert!(err.contains(&format!("properties.jani:{line}:")), "{err}");
    assert!(
        err.contains("`op` must be a string naming an operator, not the number 3"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_record_cut_mid_line_replays_its_complete_lines() {
    let dir = scratch("hostile-cut");
    let log = std::fs::read_to_string(examples().join("museum-guide/online/run0.jsonl")).unwrap();
    let whole = dir.join("whole.jsonl");
    let lines: Vec<&str> = log.lines().take(40).collect();
    std::fs::write(&whole, lines.join("\n") + "\n").unwrap();
    // The same records, then half of the next one.
    let cut = dir.join("cut.jsonl");
    let next = log.lines().nth(40).unwrap();
    std::fs::write(&cut, lines.join("\n") + "\n" + &next[..next.len() / 2]).unwrap();
    let replay = |f: &Path| {
        Command::new(bin())
            .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(".."))
            .args(["monitor", "--model", "examples/museum-guide", "--replay"])
            .arg(f)
            .output()
            .unwrap()
    };
    let a = replay(&whole);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = replay(&cut);
    let err = String::from_utf8_lossy(&b.stderr);
    assert!(b.status.success(), "{err}");
    assert!(
        err.contains("cut.jsonl:41:1: warning: the last record is cut short"),
        "{err}"
    );
    assert_eq!(a.stdout, b.stdout);
    assert!(!a.stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn non_finite_floats_in_a_trace_are_refused_at_their_cell() {
    let dir = scratch("hostile-nan");
    let spec = dir.join("f.hspec");
    std::fs::write(
        &spec,
        "state speed: f64 = 0.0;\nproperty slow = H({speed < 2.0});\n",
    )
    .unwrap();
    for cell in ["NaN", "inf", "-infinity"] {
        let trace = dir.join("t.csv");
        std::fs::write(&trace, format!("time,speed\n0,1.5\n1,{cell}\n")).unwrap();
        let out = hindsight(&["replay".as_ref(), spec.as_os_str(), trace.as_os_str()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cell}: {err}");
        assert!(err.contains("t.csv:3:3:"), "{err}");
        assert!(err.contains("not a finite number"), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_interrupted_report_leaves_the_page_it_had() {
    let dir = scratch("hostile-report");
    let page = dir.join("report.html");
    let verify = |limit: &str| {
        Command::new("sh")
            .arg("-c")
            .arg(format!("{limit} exec \"$@\""))
            .arg("sh")
            .arg(bin())
            .arg("verify")
            .arg(examples().join("museum-scxml"))
            .args(["--max-runs", "2", "--report"])
            .arg(&page)
            .output()
            .unwrap()
    };
    let out = verify("");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let before = std::fs::read(&page).unwrap();
    assert!(before.len() > 20 * 1024);
    // A file-size limit of 8 KB stops the next write half way (SIGXFSZ).
    let out = verify("ulimit -f 16;");
    assert!(!out.status.success());
    assert_eq!(std::fs::read(&page).unwrap(), before, "the page was cut");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_port_type_that_names_no_interface_is_refused_at_the_attribute() {
    let dir = scratch("hostile-ros-type");
    let props = std::fs::read_to_string(examples().join("museum-guide/properties.xml")).unwrap();
    let line = line_of(&props, "type=\"std_msgs/Int32\"");
    let model = museum_edit(
        &dir,
        "properties.xml",
        b"type=\"std_msgs/Int32\"",
        b"type=\"no_such_pkg/Nope\"",
    );
    let err = invalid(&model);
    assert!(err.contains(&format!("properties.xml:{line}:")), "{err}");
    assert!(err.contains("no_such_pkg/Nope"), "{err}");
    // A service type where a message type is needed is refused too.
    let model = museum_edit(
        &dir,
        "properties.xml",
        b"type=\"std_msgs/Int32\"",
        b"type=\"blackboard_interfaces_dummy/SetIntBlackboard\"",
    );
    let err = invalid(&model);
    assert!(err.contains(&format!("properties.xml:{line}:")), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
