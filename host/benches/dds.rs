//! Samples per second and added latency of `monitor --ros2` on loopback, against a plain
//! DDS subscriber of the same samples.
//!
//! `cargo bench -p hindsight --bench dds [-- --paced N --flood M]`
//!
//! One process, three DDS participants on a domain of its own (all `rustdds`, over UDP
//! on this machine): a writer of `std_msgs/msg/Int32` on `rt/level`, a plain reader, and
//! the monitor (`hindsight::live::dds::run`, busy polling, one property reading the
//! value and one recurrence). Paced phase: N samples one at a time, each timed from the
//! write until the plain reader has it, then (a second writer, same pacing) until the
//! monitor has judged it (its progress counter moved); the added latency is the
//! difference of the medians. Flood phase: M samples written back to back (reliable,
//! keep last 10, so a writer that outruns the reader overwrites and the monitor counts
//! the gap as lost); samples judged per second from the first write to the last
//! judgement.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use hindsight::live::dds::{Settings, TopicSource};
use hindsight::live::Options;
use ros2::dds::{Participant, Qos, Received};
use ros2::feed::{Port, Read, TopicFeed};
use ros2::schema::BuiltinDefs;

const SPEC: &str = "unit 1ms;\nstate level: int = 0;\nevent published;\n\
    property positive = H({level >= 0});\n\
    property every_second = H(P[1s:] true -> P[:1s] {published});\n";

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn cdr(v: i32) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0];
    b.extend_from_slice(&v.to_le_bytes());
    b
}

fn median_us(mut v: Vec<Duration>) -> (f64, f64) {
    v.sort();
    let at = |q: f64| v[((v.len() - 1) as f64 * q) as usize].as_secs_f64() * 1e6;
    (at(0.5), at(0.99))
}

fn main() {
    let paced = arg("--paced", 2000);
    let flood = arg("--flood", 100_000);
    let domain = 150 + (std::process::id() % 80) as u16;
    let spec = codegen::compile_spec(SPEC, "bench.hspec").expect("spec compiles");
    let level = spec.var_index("level").unwrap();
    let published = spec.var_index("published").unwrap();
    let ports = [
        Port {
            var: level,
            ty: spec.vars()[level].ty,
            topic: "/level".into(),
            read: Read::Field("data".into()),
            service: None,
            name: "level".into(),
        },
        Port {
            var: published,
            ty: spec.vars()[published].ty,
            topic: "/level".into(),
            read: Read::Event,
            service: None,
            name: "published".into(),
        },
    ];
    let defs = BuiltinDefs::new();
    let ty = "std_msgs/msg/Int32";
    let source = TopicSource {
        topic: "/level".into(),
        type_name: ty.into(),
        feed: TopicFeed::new("/level", ty, &ports, &defs, spec.strings()).unwrap(),
        vars: vec!["level".into(), "published".into()],
        schema_text: "int32 data\n".into(),
        qos: Qos::ros_default(),
    };

    // The plain subscriber.
    let writer_side = Participant::new(domain).unwrap();
    let reader_side = Participant::new(domain).unwrap();
    let plain_w = writer_side
        .writer("/plain", ty, Qos::ros_default())
        .unwrap();
    let mut plain_r = reader_side
        .reader("/plain", ty, Qos::ros_default())
        .unwrap();
    let mut got: Vec<Received> = Vec::new();
    let wait_plain = |r: &mut ros2::dds::Reader, got: &mut Vec<Received>, limit: Duration| {
        let t = Instant::now();
        loop {
            r.take(got).unwrap();
            if !got.is_empty() {
                got.clear();
                return true;
            }
            if t.elapsed() > limit {
                return false;
            }
            std::hint::spin_loop();
        }
    };
    // Discovery: write until the reader has one.
    while {
        plain_w.write(&cdr(0)).unwrap();
        !wait_plain(&mut plain_r, &mut got, Duration::from_millis(200))
    } {}
    std::thread::sleep(Duration::from_millis(200));
    plain_r.take(&mut got).unwrap();
    got.clear();
    let mut plain = Vec::with_capacity(paced);
    for i in 0..paced {
        let t = Instant::now();
        plain_w.write(&cdr(i as i32)).unwrap();
        assert!(wait_plain(&mut plain_r, &mut got, Duration::from_secs(5)));
        plain.push(t.elapsed());
    }

    // The monitor, on its own thread.
    let progress = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(AtomicBool::new(false));
    let settings = Settings {
        domain,
        heartbeat: 1,
        speed: 1.0,
        from_first_message: true,
        // The latency measured is not judged: no sample is late.
        max_latency: Duration::ZERO,
    };
    let mon = {
        let progress = progress.clone();
        let stop = stop.clone();
        std::thread::spawn(move || {
            let mut opts = Options {
                verdicts: Box::new(std::io::sink()),
                record: None,
                every_point: false,
                poll: Duration::ZERO,
                log: Box::new(std::io::sink()),
                probe: None,
                progress: Some(progress),
            };
            hindsight::live::dds::run(&spec, vec![source], &settings, &mut opts, None, &stop)
                .unwrap()
        })
    };
    let w = writer_side
        .writer("/level", ty, Qos::ros_default())
        .unwrap();
    let wait_mon = |n: u64, limit: Duration| {
        let t = Instant::now();
        while progress.load(Ordering::SeqCst) < n {
            if t.elapsed() > limit {
                return false;
            }
            std::hint::spin_loop();
        }
        true
    };
    let mut written = 0u64;
    while {
        w.write(&cdr(0)).unwrap();
        written += 1;
        !wait_mon(1, Duration::from_millis(200))
    } {}
    std::thread::sleep(Duration::from_millis(200));
    let mut judged = Vec::with_capacity(paced);
    for i in 0..paced {
        let before = progress.load(Ordering::SeqCst);
        let t = Instant::now();
        w.write(&cdr(i as i32)).unwrap();
        written += 1;
        assert!(wait_mon(before + 1, Duration::from_secs(5)));
        judged.push(t.elapsed());
    }

    // Flood.
    let before = written;
    let t = Instant::now();
    for i in 0..flood {
        w.write(&cdr(i as i32)).unwrap();
    }
    let write_s = t.elapsed().as_secs_f64();
    let mut last = (progress.load(Ordering::SeqCst), Instant::now());
    loop {
        std::thread::sleep(Duration::from_millis(50));
        let now = progress.load(Ordering::SeqCst);
        if now != last.0 {
            last = (now, Instant::now());
        } else if last.1.elapsed() > Duration::from_secs(1) {
            break;
        }
    }
    let flood_s = (last.1 - t).as_secs_f64();
    stop.store(true, Ordering::SeqCst);
    let report = mon.join().unwrap();
    let src = &report.sources[0];
    let (p50, p99) = median_us(plain);
    let (m50, m99) = median_us(judged);
    println!("monitor --ros2 on loopback (rustdds, one process, domain {domain})");
    println!("  paced, {paced} samples one at a time, write -> received:");
    println!("    plain DDS subscriber     median {p50:8.1} us   p99 {p99:8.1} us");
    println!("    monitor (judged)         median {m50:8.1} us   p99 {m99:8.1} us");
    println!("    added by the monitor     median {:8.1} us", m50 - p50);
    println!(
        "  flood, {flood} samples written back to back in {:.2} s ({:.0}/s written):",
        write_s,
        flood as f64 / write_s
    );
    // The paced phase lost nothing (one sample at a time), so every sample judged
    // beyond the ones written before the flood was judged in it.
    let flood_judged = src.samples.saturating_sub(before);
    println!(
        "    judged {flood_judged} ({:.0} samples/s), {} counted lost from sequence gaps; \
         in all {} written, {} judged + {} lost",
        flood_judged as f64 / flood_s,
        src.lost,
        before + flood as u64,
        src.samples,
        src.lost
    );
}
