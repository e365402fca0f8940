//! Model files that are not what they claim (issue 28, finding 5): a folder, a FIFO or
//! a device is refused by what it is (a FIFO never blocks the reader), and a file that
//! is not the source it was named as (`/proc/self/environ`, `/etc/passwd`) is refused
//! without any of its text reaching the terminal. Every source is read by one reader:
//! a byte that is not UTF-8 is located, a byte order mark accepted.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

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

/// Runs hindsight with `SECRET` in its environment; a child still running after 60 s
/// (blocked on a FIFO) is killed, and the test fails.
fn hindsight(args: &[&std::ffi::OsStr]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .args(args)
        .env("HOSTILE_SECRET", "hunter2-hostile-secret")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(60);
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("hindsight {args:?} blocked");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// The museum guide in `dir/museum`, its first node model's `src` replaced by `src`.
fn museum_with_src(dir: &Path, src: &str) -> PathBuf {
    let model = dir.join("museum");
    let _ = std::fs::remove_dir_all(&model);
    copy_dir(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide"),
        &model,
    );
    let main = model.join("main.xml");
    let text = std::fs::read_to_string(&main).unwrap();
    let text = text.replacen("./Components/BatteryComponent.scxml", src, 1);
    std::fs::write(&main, text).unwrap();
    model
}

fn refused(dir: &Path, src: &str, says: &str) -> String {
    let model = museum_with_src(dir, src);
    let out = hindsight(&["validate".as_ref(), model.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{src}: {err}");
    assert!(err.contains(says), "{src}: {err}");
    err
}

#[test]
fn special_files_are_refused_by_what_they_are() {
    let dir = scratch("hostile-special");
    refused(&dir, "./Components", "is a directory, not a file");
    refused(
        &dir,
        "/dev/zero",
        "is a character device, not a regular file",
    );
    let fifo = dir.join("pipe.scxml");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    refused(&dir, fifo.to_str().unwrap(), "is a FIFO (named pipe)");
    // The same for a file named on the command line.
    let spec = dir.join("spec.hspec");
    Command::new("mkfifo").arg(&spec).status().unwrap();
    let out = hindsight(&["compile".as_ref(), spec.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("is a FIFO"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_file_that_is_not_its_source_is_not_shown() {
    let dir = scratch("hostile-not-source");
    let err = refused(&dir, "/proc/self/environ", "not an XML file");
    assert!(!err.contains("hunter2"), "{err}");
    // `../../etc/passwd` from the model's folder.
    let up = "../".repeat(dir.join("museum").components().count() + 2);
    let err = refused(&dir, &format!("{up}etc/passwd"), "not an XML file");
    assert!(!err.contains("root:"), "{err}");
    // A property file given on the command line is no different.
    let model = museum_with_src(&dir, "./Components/BatteryComponent.scxml");
    let out = hindsight(&[
        "validate".as_ref(),
        model.as_os_str(),
        "/proc/self/environ".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("hunter2"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples")
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

#[test]
fn bad_utf8_is_located_and_a_byte_order_mark_is_accepted() {
    let dir = scratch("hostile-utf8");
    // A spec: the bad byte's line and column.
    let spec = std::fs::read(examples().join("specs/museum.hspec")).unwrap();
    let bad = dir.join("bad.hspec");
    let mut bytes = b"unit 100ms;\nstate x\xFF: int = 1;\n".to_vec();
    std::fs::write(&bad, &bytes).unwrap();
    let out = hindsight(&["compile".as_ref(), bad.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("bad.hspec:2:8: not UTF-8 text: byte 0xFF"),
        "{err}"
    );
    // A byte order mark before a spec and a trace.
    let bom = dir.join("bom.hspec");
    bytes = b"\xEF\xBB\xBF".to_vec();
    bytes.extend_from_slice(&spec);
    std::fs::write(&bom, &bytes).unwrap();
    let trace = dir.join("bom.csv");
    let mut csv = b"\xEF\xBB\xBF".to_vec();
    csv.extend_from_slice(&std::fs::read(examples().join("traces/museum.csv")).unwrap());
    std::fs::write(&trace, &csv).unwrap();
    let out = hindsight(&["replay".as_ref(), bom.as_os_str(), trace.as_os_str()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A bad byte in a trace cell.
    std::fs::write(&trace, b"time,battery_level\n0,35\n1,2\xC30\n").unwrap();
    let out = hindsight(&["replay".as_ref(), bom.as_os_str(), trace.as_os_str()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bom.csv:3:4: not UTF-8 text"), "{err}");
    // A bad byte in a ROS interface and in a BT plugin: the file and the reason.
    let model = museum_edit(
        &dir,
        "Interfaces/people_detector_filter_interfaces/msg/IsFollowed.msg",
        b"is_followed",
        b"is_\xFEfollowed",
    );
    let err = invalid(&model);
    assert!(
        err.contains("IsFollowed.msg:1:9: not UTF-8 text: byte 0xFE"),
        "{err}"
    );
    let model = museum_edit(&dir, "Plugins/ROS2Action.scxml", b"<scxml", b"<scxml\xFF");
    let err = invalid(&model);
    assert!(err.contains("ROS2Action.scxml:"), "{err}");
    assert!(err.contains("not UTF-8 text: byte 0xFF"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
