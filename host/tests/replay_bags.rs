//! `hindsight replay` over ROS 2 recordings written by software other teams wrote: the
//! `rosbags` writer (a rosbag2 folder with MCAP, and one with SQLite `.db3`) and the
//! `mcap` / `mcap-ros2-support` writers (one MCAP file), each holding the same messages as
//! a CSV trace (`host/tests/data/ros2/write_bags.py`); the verdicts must be the CSV's.
//!
//! The writers live in the project's Python environment (`bash scripts/pyenv`, at
//! `$HINDSIGHT_PYENV` or `.venv`). Without it these tests say they were skipped and pass,
//! except under `CI=true`, where `.ci/run` has created it and they fail.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host/ has a parent")
        .to_path_buf()
}

fn data(name: &str) -> PathBuf {
    repo().join("host/tests/data/ros2").join(name)
}

/// The Python of the project's environment, if it has what these tests need.
fn python() -> Option<PathBuf> {
    common::pyenv::python_with(
        &["rosbags", "mcap", "mcap_ros2"],
        "rosbags, mcap and mcap-ros2-support",
    )
}

/// The recordings and the CSV, written once per test process.
fn recordings() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    DIR.get_or_init(|| {
        let py = python()?;
        let dir =
            std::env::temp_dir().join(format!("hindsight-replay-bags-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let out = Command::new(py)
            .arg(data("write_bags.py"))
            .arg(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "write_bags.py failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Some(dir)
    })
    .as_deref()
}

fn replay(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
        .arg("replay")
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "exit {:?}: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// Every recording gives the CSV's verdicts, point for point, and the verdicts are not
/// trivial: every property is false at some point and true at some other.
#[test]
fn recordings_by_other_writers_give_the_csv_verdicts() {
    let Some(dir) = recordings() else { return };
    let props = data("properties.xml");
    let csv = ok(&replay(&[
        props.as_os_str(),
        dir.join("points.csv").as_os_str(),
    ]));
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 1 + 87, "a header and one row per message");
    let names: Vec<&str> = rows[0].split(',').skip(1).collect();
    assert_eq!(names.len(), 10);
    for (k, name) in names.iter().enumerate() {
        let column: Vec<&str> = rows[1..]
            .iter()
            .map(|r| r.split(',').nth(k + 1).unwrap())
            .collect();
        assert!(
            column.contains(&"true") && column.contains(&"false"),
            "{name} is always {}",
            column[0]
        );
    }
    for input in ["rosbags_mcap", "rosbags_db3", "mcap_ros2.mcap"] {
        let bag = dir.join(input);
        assert_eq!(
            ok(&replay(&[props.as_os_str(), bag.as_os_str()])),
            csv,
            "{input}"
        );
        // The same with only the changes.
        let changes = ok(&replay(&[
            props.as_os_str(),
            bag.as_os_str(),
            "--changes".as_ref(),
        ]));
        let want = ok(&replay(&[
            props.as_os_str(),
            dir.join("points.csv").as_os_str(),
            "--changes".as_ref(),
        ]));
        assert_eq!(changes, want, "{input} --changes");
    }
    // One file of a rosbag2 folder, named directly.
    let file = dir.join("rosbags_mcap/rosbags_mcap.mcap");
    assert_eq!(ok(&replay(&[props.as_os_str(), file.as_os_str()])), csv);
}

/// `--time-unit 1ms` rounds the recording's times down to milliseconds; the CSV's points
/// are at whole milliseconds, so the verdicts are the same with the times in ms.
#[test]
fn a_coarser_unit_divides_the_times() {
    let Some(dir) = recordings() else { return };
    let props = data("properties.xml");
    let ns = ok(&replay(&[
        props.as_os_str(),
        dir.join("mcap_ros2.mcap").as_os_str(),
    ]));
    let ms = ok(&replay(&[
        props.as_os_str(),
        dir.join("mcap_ros2.mcap").as_os_str(),
        "--time-unit".as_ref(),
        "1ms".as_ref(),
    ]));
    let scaled: Vec<String> = ns
        .lines()
        .skip(1)
        .map(|l| {
            let (t, rest) = l.split_once(',').unwrap();
            format!("{},{rest}", t.parse::<u64>().unwrap() / 1_000_000)
        })
        .collect();
    assert_eq!(ms.lines().skip(1).collect::<Vec<_>>(), scaled);
}

/// `--time header` needs a header on every message: `/battery_level` (std_msgs/Int32)
/// has none, and the error says so, naming the topic.
#[test]
fn header_time_needs_headers() {
    let Some(dir) = recordings() else { return };
    let out = replay(&[
        data("properties.xml").as_os_str(),
        dir.join("rosbags_mcap").as_os_str(),
        "--time".as_ref(),
        "header".as_ref(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("topic `/battery_level`") && err.contains("header"),
        "{err}"
    );
}

/// A `.hspec` spec over a recording, its variables bound with `--bind`.
#[test]
fn a_spec_with_bindings() {
    let Some(dir) = recordings() else { return };
    let spec_dir =
        std::env::temp_dir().join(format!("hindsight-replay-bind-{}", std::process::id()));
    std::fs::create_dir_all(&spec_dir).unwrap();
    let spec = spec_dir.join("s.hspec");
    std::fs::write(
        &spec,
        "unit 1ms;\nstate level: int = 100;\nevent req;\nstate a: int = 0;\n\
         property low = H({level > 20});\nproperty req_ok = H({req} -> {a >= 0});\n",
    )
    .unwrap();
    let out = ok(&replay(&[
        spec.as_os_str(),
        dir.join("rosbags_db3").as_os_str(),
        "--bind".as_ref(),
        "level=/battery_level.data".as_ref(),
        "--bind".as_ref(),
        "req=/add:request".as_ref(),
        "--bind".as_ref(),
        "a=/add:request.a".as_ref(),
        "--changes".as_ref(),
    ]));
    // The property file's `level_above_20` and `a_nonnegative`, in ms.
    let props = ok(&replay(&[
        data("properties.xml").as_os_str(),
        dir.join("points.csv").as_os_str(),
    ]));
    let mut want = vec!["time,low,req_ok".to_string()];
    let mut last = None;
    for l in props.lines().skip(1) {
        let c: Vec<&str> = l.split(',').collect();
        let v = (c[1], c[10]);
        if last != Some(v) {
            want.push(format!(
                "{},{},{}",
                c[0].parse::<u64>().unwrap() / 1_000_000,
                v.0,
                v.1
            ));
            last = Some(v);
        }
    }
    assert_eq!(out.lines().collect::<Vec<_>>(), want);
    let _ = std::fs::remove_dir_all(&spec_dir);
}

/// An MCAP file of `std_msgs/Int32` messages on `/battery_level`, written with the `mcap`
/// crate (no Python needed).
fn int32_mcap(messages: &[Vec<u8>]) -> Vec<u8> {
    mcap_of("ros2msg", "int32 data\n", messages)
}

/// An MCAP file of messages on `/battery_level` of type `std_msgs/msg/Int32` as the schema
/// (`encoding`, `text`) says it is.
fn mcap_of(encoding: &str, text: &str, messages: &[Vec<u8>]) -> Vec<u8> {
    let mut w = mcap::Writer::new(std::io::Cursor::new(Vec::new())).unwrap();
    let s = w
        .add_schema("std_msgs/msg/Int32", encoding, text.as_bytes())
        .unwrap();
    let c = w
        .add_channel(s, "/battery_level", "cdr", &Default::default())
        .unwrap();
    for (i, data) in messages.iter().enumerate() {
        let header = mcap::records::MessageHeader {
            channel_id: c,
            sequence: i as u32,
            log_time: 1_000_000_000 + i as u64 * 1_000,
            publish_time: 0,
        };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// A bad sample, a 4 GB length prefix, a truncated file, a chunk claiming 4 GB, a schema
/// we do not read or that does not parse, a `.db3` that is not SQLite and a field the type
/// lacks exit 2, naming the file and the topic and the message's index (or the field and
/// the type).
#[test]
fn bad_bags_exit_2_naming_topic_and_index() {
    let dir = std::env::temp_dir().join(format!("hindsight-bad-bags-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = |v: i32| {
        let mut m = vec![0, 1, 0, 0];
        m.extend(v.to_le_bytes());
        m
    };
    let props = data("properties.xml");
    let check = |name: &str, bytes: &[u8], props: &Path, wants: &[&str]| {
        let file = dir.join(name);
        std::fs::write(&file, bytes).unwrap();
        let out = replay(&[props.as_os_str(), file.as_os_str()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        for w in wants {
            assert!(err.contains(w), "{name}: `{w}` not in {err}");
        }
    };
    let ok_file = int32_mcap(&[good(50), good(40)]);
    let file = dir.join("ok.mcap");
    std::fs::write(&file, &ok_file).unwrap();
    let out = ok(&replay(&[props.as_os_str(), file.as_os_str()]));
    assert_eq!(out.lines().count(), 3, "{out}");
    check(
        "short.mcap",
        &int32_mcap(&[good(50), vec![0, 1, 0, 0, 7], good(30)]),
        &props,
        &["topic `/battery_level` message 2", "std_msgs/msg/Int32"],
    );
    check(
        "huge.mcap",
        &int32_mcap(&[good(50), good(40), vec![0, 7, 0, 0, 1, 2, 3, 4]]),
        &props,
        &["topic `/battery_level` message 3", "encapsulation"],
    );
    check(
        "cut.mcap",
        &ok_file[..ok_file.len() * 2 / 3],
        &props,
        &["cut.mcap"],
    );
    // A length prefix of 4 G in a 16-byte message: an error at once, nothing allocated.
    let mut huge_string = vec![0, 1, 0, 0];
    huge_string.extend(u32::MAX.to_le_bytes());
    huge_string.extend(7i32.to_le_bytes());
    check(
        "prefix.mcap",
        &mcap_of("ros2msg", "string name\nint32 data\n", &[huge_string]),
        &props,
        &[
            "topic `/battery_level` message 1",
            "claims 4294967295 element(s)",
        ],
    );
    // A chunk whose header claims 4 GB uncompressed: refused before the `mcap` crate
    // reserves that much.
    let mut chunked = ok_file.clone();
    let mut at = 8;
    let mut patched = false;
    while at + 9 <= chunked.len() {
        let len = u64::from_le_bytes(chunked[at + 1..at + 9].try_into().unwrap()) as usize;
        if chunked[at] == 0x06 {
            chunked[at + 9 + 16..at + 9 + 24].copy_from_slice(&(1u64 << 32).to_le_bytes());
            patched = true;
            break;
        }
        at += 9 + len;
    }
    assert!(patched, "the mcap writer writes chunks");
    check(
        "chunk.mcap",
        &chunked,
        &props,
        &["chunk.mcap", "claims 4294967296 uncompressed bytes"],
    );
    // Wrong schemas: one in a form we do not read, one whose text does not parse.
    check(
        "idl.mcap",
        &mcap_of("ros2idl", "module std_msgs { };", &[good(1)]),
        &props,
        &["message 1", "/battery_level", "schema encoding `ros2idl`"],
    );
    check(
        "schema.mcap",
        &mcap_of("ros2msg", "int32 data\n=====\nint8 x\n", &[good(1)]),
        &props,
        &["topic `/battery_level`", "no `MSG: package/Type` line"],
    );
    // A `.db3` that is not SQLite, and a .db3 without rosbag2's tables.
    check(
        "junk.db3",
        b"not a database at all, not even close to one",
        &props,
        &["junk.db3", "not a rosbag2 SQLite file"],
    );
    let wrong = dir.join("wrong.xml");
    std::fs::write(
        &wrong,
        std::fs::read_to_string(&props).unwrap().replace(
            "field=\"data\" expr=\"100\"",
            "field=\"value\" expr=\"100\"",
        ),
    )
    .unwrap();
    check(
        "ok2.mcap",
        &ok_file,
        &wrong,
        &["/battery_level", "no field `value`", "std_msgs/Int32"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}
