//! Messages per second of `replay` over an MCAP recording against the same points as a CSV
//! trace, in one run: decoded (CDR) and judged, or parsed and judged.
//!
//! `cargo bench -p hindsight --bench replay [-- --messages N --reps R]`
//!
//! Issue 25 asks for at least 1 M small messages per second decoded and judged. The
//! recording has N `std_msgs/Int32` messages on `/level` (1 ms apart, every fourth one
//! also a `std_msgs/Bool` on `/followed`), written in memory with the `mcap` crate
//! (zstd chunks, as rosbag2 writes them); the CSV holds the same points. Both go through
//! the code `hindsight replay` runs (`hindsight_ros2::feed` and `hindsight::verify::tracefile`,
//! then one `Monitor::try_step` a point) with a spec of two properties, from bytes in
//! memory (reading the file is left out of both). Passes alternate and the median of R
//! is reported, so that load on a shared machine falls on both alike.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::time::Instant;

use monitor_core::{valuation, Monitor, Value};
use ros2::feed::{replay_mcap_bytes, Port, Read, TimeSource};
use ros2::schema::BuiltinDefs;

const SPEC: &str =
    "unit 1ms;\nstate level: int = 100;\nevent published;\nstate followed: bool = false;\n\
    property positive = H({level > -1000000});\n\
    property every_second = H(P[1s:] true -> P[:1s] {published});\n\
    property followed_lately = P[:5s] {followed} || !P[5s:] true;\n";

/// Judges one point: its time and the variables it sets.
type Step<'a> = dyn FnMut(u64, &[(usize, Value)]) + 'a;

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let n = arg("--messages", 1_000_000);
    let reps = arg("--reps", 5).max(1);
    let compiled = codegen::compile_spec(SPEC, "bench.hspec").expect("the bench spec compiles");
    let (level, published, followed) = (
        compiled.var_index("level").unwrap(),
        compiled.var_index("published").unwrap(),
        compiled.var_index("followed").unwrap(),
    );

    // The recording and the CSV of the same points.
    let mut w = mcap::Writer::new(Cursor::new(Vec::new())).unwrap();
    let int = w
        .add_schema("std_msgs/msg/Int32", "ros2msg", b"int32 data\n")
        .unwrap();
    let boolean = w
        .add_schema("std_msgs/msg/Bool", "ros2msg", b"bool data\n")
        .unwrap();
    let none = BTreeMap::new();
    let c_level = w.add_channel(int, "/level", "cdr", &none).unwrap();
    let c_followed = w.add_channel(boolean, "/followed", "cdr", &none).unwrap();
    let mut csv = String::from("time,level,published,followed\n");
    let t0 = 1_700_000_000_000_000_000u64;
    let mut points = 0usize;
    for i in 0..n as u64 {
        let t = i * 1_000_000;
        let v = (i % 200) as i32;
        let mut data = vec![0, 1, 0, 0];
        data.extend(v.to_le_bytes());
        let header = |channel_id| mcap::records::MessageHeader {
            channel_id,
            sequence: i as u32,
            log_time: t0 + t,
            publish_time: t0 + t,
        };
        w.write_to_known_channel(&header(c_level), &data).unwrap();
        csv.push_str(&format!("{},{v},true,\n", t / 1_000_000));
        points += 1;
        if i % 4 == 0 {
            let f = (i / 4) % 2 == 0;
            w.write_to_known_channel(&header(c_followed), &[0, 1, 0, 0, f as u8])
                .unwrap();
            csv.push_str(&format!("{},,,{f}\n", t / 1_000_000));
            points += 1;
        }
    }
    w.finish().unwrap();
    let bag = w.into_inner().into_inner();
    let ports = [
        Port {
            var: level,
            ty: compiled.vars()[level].ty,
            topic: "/level".into(),
            read: Read::Field("data".into()),
            service: None,
            name: "level".into(),
        },
        Port {
            var: published,
            ty: compiled.vars()[published].ty,
            topic: "/level".into(),
            read: Read::Event,
            service: None,
            name: "published".into(),
        },
        Port {
            var: followed,
            ty: compiled.vars()[followed].ty,
            topic: "/followed".into(),
            read: Read::Field("data".into()),
            service: None,
            name: "followed".into(),
        },
    ];
    let defs = BuiltinDefs::new();
    let program = compiled.program();
    let monitor = Monitor::try_new(program).unwrap();
    let tick = compiled.tick_ns();

    // One pass: all points judged; returns (seconds, points, verdicts at the end).
    let judge = |feed: &mut dyn FnMut(&mut Step<'_>)| {
        let mut state = vec![0u64; monitor.state_words()];
        let mut vals = vec![Value::Bool(false); program.vars.len()];
        valuation::init(program.vars, &mut vals);
        let mut verdicts = vec![false; monitor.properties()];
        let mut count = 0usize;
        let start = Instant::now();
        feed(&mut |time, sets| {
            valuation::begin_point(program.vars, &mut vals);
            for &(var, v) in sets {
                vals[var] = v;
            }
            monitor
                .try_step(&mut state, time, &vals, &mut verdicts)
                .unwrap();
            count += 1;
        });
        (start.elapsed().as_secs_f64(), count, verdicts)
    };
    let mut mcap_times = Vec::new();
    let mut csv_times = Vec::new();
    for _ in 0..reps {
        let (s, count, v_mcap) = judge(&mut |step| {
            replay_mcap_bytes(
                &bag,
                &ports,
                &defs,
                TimeSource::Log,
                compiled.strings(),
                &mut |p| {
                    step(p.time_ns / tick, p.sets);
                    Ok::<(), std::convert::Infallible>(())
                },
            )
            .unwrap();
        });
        assert_eq!(count, points);
        mcap_times.push(s);
        let (s, count, v_csv) = judge(&mut |step| {
            let trace =
                hindsight::verify::tracefile::parse_csv(&csv, "bench.csv", &compiled).unwrap();
            for p in &trace {
                step(p.time, &p.sets);
            }
        });
        assert_eq!(count, points);
        assert_eq!(v_mcap, v_csv, "the same verdicts from both");
        csv_times.push(s);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (m, c) = (median(&mut mcap_times), median(&mut csv_times));
    println!(
        "{points} messages ({n} std_msgs/Int32 + {} std_msgs/Bool), {} bytes of MCAP, median of {reps}:",
        points - n,
        bag.len()
    );
    println!(
        "  MCAP replay (decode CDR + judge): {:>6.2} M messages/s ({:.0} ns each)",
        points as f64 / m / 1e6,
        m * 1e9 / points as f64
    );
    println!(
        "  CSV replay (parse + judge):       {:>6.2} M points/s ({:.0} ns each)",
        points as f64 / c / 1e6,
        c * 1e9 / points as f64
    );
    println!("  MCAP / CSV speed: {:.2}x", c / m);
}
