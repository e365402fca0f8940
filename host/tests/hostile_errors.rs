//! Errors stay linear in the input (issue 28, finding 1): a file with tens of thousands
//! of problems, or one huge line, is reported in bounded memory and output, checked
//! with the address-space and CPU limits the harness sets on the child (`ulimit`), not
//! by timing (warnings too); and a closed output ends the program quietly, never with a
//! panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_hindsight")
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
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

/// The museum guide copied to `dir`, its policy's first `<Sequence>` given `attrs`.
fn museum_with(dir: &Path, attrs: &str) -> PathBuf {
    let model = dir.join("museum");
    copy_dir(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide"),
        &model,
    );
    let policy = model.join("policy.xml");
    let text = std::fs::read_to_string(&policy).unwrap();
    let text = text.replacen("<Sequence>", &format!("<Sequence {attrs}>"), 2);
    std::fs::write(&policy, text).unwrap();
    model
}

/// Runs `hindsight ARGS` with at most `mb` MB of address space and `secs` s of CPU.
fn limited(mb: u64, secs: u64, args: &[&std::ffi::OsStr]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {}; ulimit -t {secs}; exec \"$@\"",
            mb * 1024
        ))
        .arg("sh")
        .arg(bin())
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn many_problems_take_linear_memory_and_print_a_bounded_list() {
    let dir = scratch("hostile-errors");
    // Two nodes with 20 000 unknown attributes each (a 460 KB file): one problem per
    // attribute, each showing a line of 230 000 characters. Before, every problem held
    // its whole line (about 12 GB, an abort); now 1 GB of address space is plenty.
    let attrs: String = (0..20_000).map(|i| format!("a{i}=\"1\" ")).collect();
    let model = museum_with(&dir, &attrs);
    let out = limited(1024, 60, &["validate".as_ref(), model.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        &err[..err.len().min(2000)]
    );
    assert!(err.contains("unknown attribute `a0` on Sequence"), "{err}");
    assert!(err.contains("... and 39980 more: 39980 errors"), "{err}");
    assert!(err.len() < 64 * 1024, "{} bytes of errors", err.len());
    // Every excerpt is cut to a window around its caret.
    assert!(err.lines().all(|l| l.chars().count() < 1200), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_huge_attribute_prints_a_bounded_error() {
    let dir = scratch("hostile-huge-attr");
    let name = "b".repeat(4_000_000);
    let model = museum_with(&dir, &format!("{name}=\"1\""));
    let out = limited(1024, 60, &["validate".as_ref(), model.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        &err[..err.len().min(2000)]
    );
    assert!(
        err.contains("unknown attribute `bbbb"),
        "{}",
        &err[..err.len().min(2000)]
    );
    assert!(
        err.contains("characters cut"),
        "{}",
        &err[..err.len().min(2000)]
    );
    assert!(err.len() < 16 * 1024, "{} bytes of errors", err.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_closed_output_ends_quietly() {
    let dir = scratch("hostile-closed");
    let museum = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-scxml");
    // stdout read by nobody: `trace` writes well over a pipe's 64 KB buffer, so its
    // writes fail with a broken pipe whatever the timing.
    let status = dir.join("status");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("\"$0\" trace \"$1\" --run 0 --seed 1; echo $? > \"$2\"")
        .arg(bin())
        .arg(&museum)
        .arg(&status)
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    assert!(child.wait().unwrap().success());
    let code = std::fs::read_to_string(&status).unwrap();
    assert_eq!(code.trim(), "1", "exit code of a write to a closed pipe");
    // Bad input with standard error closed: still exit 2, no panic.
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("m.scxml"), "<scxml").unwrap();
    for redirect in ["2>&-", "2>/dev/full"] {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!("\"$0\" validate \"$1\" {redirect}"))
            .arg(bin())
            .arg(&bad)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{redirect}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn many_warnings_print_a_bounded_list() {
    let dir = scratch("hostile-warnings");
    let model = dir.join("museum");
    copy_dir(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide"),
        &model,
    );
    // 5 000 attributes AS2FM ignores on <roaml>: one warning each, the model still loads.
    let main = model.join("main.xml");
    let attrs: String = (0..5_000).map(|i| format!(" x{i}=\"1\"")).collect();
    let text = std::fs::read_to_string(&main).unwrap();
    std::fs::write(
        &main,
        text.replacen("<roaml>", &format!("<roaml{attrs}>"), 1),
    )
    .unwrap();
    let out = limited(1024, 60, &["validate".as_ref(), model.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}", &err[..err.len().min(2000)]);
    assert!(
        err.contains("attribute `x0` on <roaml> is ignored"),
        "{err}"
    );
    assert!(err.contains("warning: ... and 4980 more warnings"), "{err}");
    assert!(err.len() < 64 * 1024, "{} bytes of warnings", err.len());
    let _ = std::fs::remove_dir_all(&dir);
}
