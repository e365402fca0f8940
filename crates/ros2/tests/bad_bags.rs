//! Bad recordings and bad samples: each is an error naming the topic and the message's
//! index, never a panic; and a loop of mutated MCAP files (bytes flipped, cut, length
//! prefixes made huge) that must each read or fail cleanly.

use std::collections::BTreeMap;
use std::io::Cursor;

use std::convert::Infallible;

use hindsight_ros2::bag::BagError;
use hindsight_ros2::cdr::CdrError;
use hindsight_ros2::feed::{
    replay_mcap_bytes, MessageError, PlanError, Port, Read, ReplayError, ServiceSide, TimeSource,
};
use hindsight_ros2::schema::BuiltinDefs;
use monitor_core::{Ty, Value};

const BATTERY: &str = "std_msgs/Header header\nfloat32 percentage\nfloat32[] cell_voltage\n\
    ================================================================================\n\
    MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\
    ================================================================================\n\
    MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";

/// A CDR little-endian `test_msgs/Battery` (the schema above).
fn battery(sec: i32, frame: &str, pct: f32, cells: &[f32]) -> Vec<u8> {
    let mut m = vec![0, 1, 0, 0];
    m.extend(sec.to_le_bytes());
    m.extend(0u32.to_le_bytes());
    m.extend((frame.len() as u32 + 1).to_le_bytes());
    m.extend(frame.as_bytes());
    m.push(0);
    while (m.len() - 4) % 4 != 0 {
        m.push(0);
    }
    m.extend(pct.to_le_bytes());
    m.extend((cells.len() as u32).to_le_bytes());
    for c in cells {
        m.extend(c.to_le_bytes());
    }
    m
}

/// An MCAP file: `/level` (std_msgs/Int32) and `/battery` (test_msgs/Battery) messages.
fn mcap(messages: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let int = w
        .add_schema("std_msgs/msg/Int32", "ros2msg", b"int32 data\n")
        .unwrap();
    let bat = w
        .add_schema("test_msgs/msg/Battery", "ros2msg", BATTERY.as_bytes())
        .unwrap();
    let none = BTreeMap::new();
    let level = w.add_channel(int, "/level", "cdr", &none).unwrap();
    let battery = w.add_channel(bat, "/battery", "cdr", &none).unwrap();
    for (i, (topic, data)) in messages.iter().enumerate() {
        let channel_id = if *topic == "/level" { level } else { battery };
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: i as u32,
            log_time: 1_000 + i as u64 * 100,
            publish_time: 0,
        };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

fn int32(v: i32) -> Vec<u8> {
    let mut m = vec![0, 1, 0, 0];
    m.extend(v.to_le_bytes());
    m
}

fn ports() -> Vec<Port> {
    let p = |var, ty, topic: &str, read| Port {
        var,
        ty,
        topic: topic.into(),
        read,
        service: None,
        name: format!("v{var}"),
    };
    vec![
        p(0, Ty::Int, "/level", Read::Field("data".into())),
        p(
            1,
            Ty::Float,
            "/battery",
            Read::Field("cell_voltage[1]".into()),
        ),
        p(
            2,
            Ty::Str,
            "/battery",
            Read::Field("header.frame_id".into()),
        ),
        p(3, Ty::Bool, "/battery", Read::Event),
    ]
}

/// A point: its time and the variables it sets.
type Pt = (u64, Vec<(usize, Value)>);

/// Every point, or the error.
fn run(bytes: &[u8], ports: &[Port]) -> Result<Vec<Pt>, ReplayError<Infallible>> {
    let mut out = Vec::new();
    replay_mcap_bytes(
        bytes,
        ports,
        &BuiltinDefs::new(),
        TimeSource::Log,
        &["base".to_string()],
        &mut |p| {
            out.push((p.time_ns, p.sets.to_vec()));
            Ok::<(), Infallible>(())
        },
    )?;
    Ok(out)
}

fn good() -> Vec<(&'static str, Vec<u8>)> {
    vec![
        ("/level", int32(90)),
        ("/battery", battery(5, "base", 0.5, &[3.5, 3.25])),
        ("/level", int32(80)),
        ("/battery", battery(6, "dock", 0.25, &[3.0, 2.75, 2.5])),
    ]
}

#[test]
fn a_good_file_gives_its_points() {
    let pts = run(&mcap(&good()), &ports()).unwrap();
    assert_eq!(pts.len(), 4);
    assert_eq!(pts[0], (0, vec![(0, Value::Int(90))]));
    assert_eq!(
        pts[1],
        (
            100,
            vec![
                (1, Value::Float(3.25)),
                (2, Value::Str(0)),
                (3, Value::Bool(true))
            ]
        )
    );
    assert_eq!(pts[3].1[0], (1, Value::Float(2.75)));
    assert_eq!(pts[3].1[1], (2, Value::Str(u32::MAX)));
}

#[test]
fn bad_samples_name_topic_and_index() {
    // A cell the second battery message lacks.
    let mut m = good();
    m[3].1 = battery(6, "dock", 0.25, &[3.0]);
    let e = run(&mcap(&m), &ports()).unwrap_err();
    assert!(
        matches!(&e, ReplayError::Message { topic, index: 2, error, .. }
            if topic == "/battery"
                && matches!(&**error, MessageError::Absent { path } if path == "cell_voltage[1]")),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains("topic `/battery` message 2") && e.contains("cell_voltage[1]"),
        "{e}"
    );
    // A 4 GB length prefix.
    let mut m = good();
    let n = m[1].1.len();
    m[1].1[n - 12..n - 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = run(&mcap(&m), &ports()).unwrap_err();
    assert!(
        matches!(&e, ReplayError::Message { topic, index: 1, error, .. }
            if topic == "/battery" && matches!(**error, MessageError::Cdr(CdrError::Count { .. }))),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains("topic `/battery` message 1") && e.contains("4294967295"),
        "{e}"
    );
    // A truncated message.
    let mut m = good();
    m[2].1.truncate(6);
    let e = run(&mcap(&m), &ports()).unwrap_err().to_string();
    assert!(e.contains("topic `/level` message 2"), "{e}");
    // The wrong type: a battery's bytes on the Int32 topic.
    let mut m = good();
    m[0].1 = battery(5, "base", 0.5, &[3.5]);
    let e = run(&mcap(&m), &ports()).unwrap_err().to_string();
    assert!(
        e.contains("topic `/level` message 1") && e.contains("follow the end"),
        "{e}"
    );
    // A field the type lacks names both.
    let mut p = ports();
    p[0].read = Read::Field("value".into());
    let e = run(&mcap(&good()), &p).unwrap_err();
    assert!(
        matches!(&e, ReplayError::Topic { topic, error, .. }
            if topic == "/level" && matches!(&**error, PlanError::Port { name, .. } if name == "v0")),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains("/level") && e.contains("no field `value`") && e.contains("std_msgs/Int32"),
        "{e}"
    );
    // A service port on a topic that is not a service event.
    let mut p = ports();
    p.push(Port {
        var: 4,
        ty: Ty::Bool,
        topic: "/level".into(),
        read: Read::Event,
        service: Some(ServiceSide::Request),
        name: "x".into(),
    });
    assert!(
        run(&mcap(&good()), &p).is_ok(),
        "/level/_service_event is absent"
    );
}

#[test]
fn a_truncated_file_is_an_error() {
    let bytes = mcap(&good());
    for cut in [0, 7, 8, 20, bytes.len() / 2, bytes.len() - 1] {
        let e = run(&bytes[..cut], &ports()).unwrap_err().to_string();
        assert!(e.contains("<mcap>"), "{cut}: {e}");
    }
}

/// xorshift64 (shifts 13, 7, 17): the same mutants on every run.
fn rng(seed: u64) -> impl FnMut() -> u64 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    }
}

/// Mutated files: each reads or fails with a message; none panics. Both outcomes occur.
#[test]
fn mutants_read_or_fail_cleanly() {
    let base = mcap(&good());
    let mut next = rng(0x2545_f491_4f6c_dd1d);
    let (mut oks, mut errs) = (0, 0);
    for _ in 0..3000 {
        let mut b = base.clone();
        for _ in 0..1 + next() % 4 {
            let i = (next() % b.len() as u64) as usize;
            match next() % 4 {
                0 => b[i] ^= 1 << (next() % 8),
                1 => b[i] = 0xff,
                2 => {
                    let end = (i + 4).min(b.len());
                    b[i..end].fill(0xff);
                }
                _ => b.truncate(i.max(1)),
            }
        }
        match run(&b, &ports()) {
            Ok(_) => oks += 1,
            Err(e) => {
                assert!(e.to_string().contains("<mcap>"), "{e}");
                errs += 1
            }
        }
    }
    assert!(oks > 100 && errs > 100, "{oks} read, {errs} failed");
}

/// A rosbag2 folder: `metadata.yaml` lists its files, read in that order (not by name);
/// a message index counts on across files; a bad `metadata.yaml` names line and column.
#[test]
fn a_folder_reads_its_files_in_the_listed_order() {
    let dir = std::env::temp_dir().join(format!("hindsight-ros2-folder-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The first file's log times are 1000 and 1100, the second's 5000 and 5001.
    let first = mcap(&[("/level", int32(1)), ("/level", int32(2))]);
    let second = {
        let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
        let int = w
            .add_schema("std_msgs/msg/Int32", "ros2msg", b"int32 data\n")
            .unwrap();
        let ch = w
            .add_channel(int, "/level", "cdr", &BTreeMap::new())
            .unwrap();
        for (i, v) in [3, 4].iter().enumerate() {
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: i as u32,
                log_time: 5_000 + i as u64,
                publish_time: 0,
            };
            w.write_to_known_channel(&header, &int32(*v)).unwrap();
        }
        w.finish().unwrap();
        w.into_inner().into_inner()
    };
    std::fs::write(dir.join("z_0.mcap"), first).unwrap();
    std::fs::write(dir.join("a_1.mcap"), second).unwrap();
    std::fs::write(
        dir.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 9\n  storage_identifier: mcap\n  relative_file_paths:\n    - z_0.mcap\n    - a_1.mcap\n",
    )
    .unwrap();
    let mut seen = Vec::new();
    let summary = hindsight_ros2::feed::replay(
        &dir,
        &ports(),
        &BuiltinDefs::new(),
        TimeSource::Log,
        &[],
        &mut |p| {
            seen.push((p.time_ns, p.index, p.sets[0].1));
            Ok::<(), Infallible>(())
        },
    )
    .unwrap();
    assert_eq!(summary.messages, 4);
    assert_eq!(
        seen,
        [
            (0, 1, Value::Int(1)),
            (100, 2, Value::Int(2)),
            (4000, 3, Value::Int(3)),
            (4001, 4, Value::Int(4))
        ]
    );
    // Listed the other way round, time goes backwards: an error naming the message.
    std::fs::write(
        dir.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  storage_identifier: mcap\n  relative_file_paths: [a_1.mcap, z_0.mcap]\n",
    )
    .unwrap();
    let e = hindsight_ros2::feed::replay(
        &dir,
        &ports(),
        &BuiltinDefs::new(),
        TimeSource::Log,
        &[],
        &mut |_| Ok::<(), Infallible>(()),
    )
    .unwrap_err();
    assert!(
        matches!(&e, ReplayError::Message { topic, index: 3, error, .. }
            if topic == "/level" && matches!(**error, MessageError::Backwards { .. })),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(
        e.contains("topic `/level` message 3") && e.contains("before"),
        "{e}"
    );
    std::fs::write(
        dir.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  a: [\n",
    )
    .unwrap();
    let e = hindsight_ros2::feed::replay(
        &dir,
        &ports(),
        &BuiltinDefs::new(),
        TimeSource::Log,
        &[],
        &mut |_| Ok::<(), Infallible>(()),
    )
    .unwrap_err();
    assert!(
        matches!(&e, ReplayError::Bag(BagError::Yaml { file, .. }) if file.ends_with("metadata.yaml")),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(e.contains("metadata.yaml:"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--time header`: a point is at its message's `header.stamp`, counted from the first.
#[test]
fn header_stamps_give_the_times() {
    let bytes = mcap(&[
        ("/battery", battery(7, "base", 0.5, &[3.0, 3.5])),
        ("/battery", battery(9, "base", 0.5, &[3.0, 3.25])),
    ]);
    let ports: Vec<Port> = ports().into_iter().skip(1).collect();
    let mut times = Vec::new();
    replay_mcap_bytes(
        &bytes,
        &ports,
        &BuiltinDefs::new(),
        TimeSource::Header,
        &[],
        &mut |p| {
            times.push((p.time_ns, p.sets[0].1));
            Ok::<(), Infallible>(())
        },
    )
    .unwrap();
    assert_eq!(
        times,
        [(0, Value::Float(3.5)), (2_000_000_000, Value::Float(3.25))]
    );
}

/// A schema that does not read is an error naming the topic and the schema's line.
#[test]
fn a_bad_schema_names_the_topic() {
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let s = w
        .add_schema("std_msgs/msg/Int32", "ros2msg", b"int33 data\n")
        .unwrap();
    let c = w.add_channel(s, "/level", "cdr", &BTreeMap::new()).unwrap();
    let header = mcap::records::MessageHeader {
        channel_id: c,
        sequence: 0,
        log_time: 1,
        publish_time: 0,
    };
    w.write_to_known_channel(&header, &int32(1)).unwrap();
    w.finish().unwrap();
    let e = run(&w.into_inner().into_inner(), &ports())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("topic `/level`") && e.contains(":1:1") && e.contains("int33"),
        "{e}"
    );
}
