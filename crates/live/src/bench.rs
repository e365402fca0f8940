//! `hindsight monitor --bench`: samples per second the sidecar sustains and the latency it adds.
//!
//! One process, three threads on one topic: a publisher stamps each 24-byte sample
//! (`level: i32` at 0, `seq: u64` at 8, send time `u64` ns at 16), a plain
//! busy-polling subscriber measures publish-to-receive latency, and the sidecar
//! (busy polling, every verdict change written to a sink) measures
//! publish-to-verdict latency for the same samples. The difference of the two
//! distributions is what the sidecar adds. A second phase floods the topic
//! as fast as the publisher can send and counts what the sidecar judged and lost.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

use super::config::Config;
use super::{LiveError, Options, Probe, Sidecar};

/// The spec the benchmark monitors: the museum's battery requirements.
pub const SPEC: &str =
    "unit 1ms;\nstate battery_level: int = 100;\nevent battery_published;\nevent alarm;\n\
property absence = H({battery_level >= 30} -> H(!{alarm}));\n\
property battery_recurrence = H(P[1s:] true -> P[:1s] {battery_published});\n";

/// Measured numbers of one benchmark run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BenchReport {
    /// Samples sent in the paced phase.
    pub paced: u64,
    /// Paced rate asked for, samples per second.
    pub rate: f64,
    /// Paced phase: samples the sidecar counted lost (0: it kept up with the rate).
    pub paced_lost: u64,
    /// Plain subscriber latency, p50 and p99, nanoseconds.
    pub plain_ns: (u64, u64),
    /// Sidecar publish-to-verdict latency, p50 and p99, nanoseconds.
    pub sidecar_ns: (u64, u64),
    /// Flood phase: samples the publisher sent.
    pub flood_sent: u64,
    /// Flood phase: publisher rate, samples per second.
    pub flood_send_rate: f64,
    /// Flood phase: samples the sidecar judged.
    pub flood_judged: u64,
    /// Flood phase: samples the sidecar counted lost.
    pub flood_lost: u64,
    /// Flood phase: judged samples per second of sidecar time.
    pub flood_judged_rate: f64,
}

impl std::fmt::Display for BenchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let us = |n: u64| n as f64 / 1000.0;
        writeln!(
            f,
            "paced: {} samples at {:.0}/s, sidecar lost {}",
            self.paced, self.rate, self.paced_lost
        )?;
        writeln!(
            f,
            "  plain subscriber latency: p50 {:.1} us, p99 {:.1} us",
            us(self.plain_ns.0),
            us(self.plain_ns.1)
        )?;
        writeln!(
            f,
            "  sidecar to verdict:       p50 {:.1} us, p99 {:.1} us (adds p50 {:.1} us, p99 {:.1} us)",
            us(self.sidecar_ns.0),
            us(self.sidecar_ns.1),
            us(self.sidecar_ns.0.saturating_sub(self.plain_ns.0)),
            us(self.sidecar_ns.1.saturating_sub(self.plain_ns.1))
        )?;
        writeln!(
            f,
            "flood: {} sent at {:.0}/s; sidecar judged {} ({:.0}/s), lost {}",
            self.flood_sent,
            self.flood_send_rate,
            self.flood_judged,
            self.flood_judged_rate,
            self.flood_lost
        )
    }
}

fn percentile(v: &mut [u64], q: f64) -> u64 {
    if v.is_empty() {
        return 0;
    }
    v.sort_unstable();
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i.min(v.len() - 1)]
}

fn config_text(service: &str) -> String {
    format!(
        "[clock]\nheartbeat = 0\n[[topic]]\nservice = \"{service}\"\nsize = 24\nevent = \"battery_published\"\n\
         buffer = 1024\nseq = {{ offset = 8, type = \"u64\" }}\n\
         [[topic.field]]\nvar = \"battery_level\"\noffset = 0\ntype = \"i32\"\n"
    )
}

struct Phase {
    plain: Vec<u64>,
    sidecar: Vec<(u64, u64)>,
    judged: u64,
    lost: u64,
    send_secs: f64,
}

fn phase(service: &str, n: u64, rate: Option<f64>) -> Result<Phase, LiveError> {
    // The benchmark's own spec and config: an error in either is a bug.
    let spec = codegen::compile_spec(SPEC, "bench.hspec").map_err(LiveError::Spec)?;
    let config =
        Config::parse(&config_text(service), "bench.toml", &spec).map_err(LiveError::Spec)?;
    let epoch = Instant::now();
    let stop = Arc::new(AtomicBool::new(false));
    let ready = Arc::new(AtomicU64::new(0));
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| LiveError::ipc(service, e))?;
    let name = super::service_name(service)?;
    let factory = node
        .service_builder(&name)
        .publish_subscribe::<[u8]>()
        .subscriber_max_buffer_size(1024)
        .open_or_create()
        .map_err(|e| LiveError::ipc(service, e))?;
    let publisher = factory
        .publisher_builder()
        .initial_max_slice_len(24)
        .create()
        .map_err(|e| LiveError::ipc(service, e))?;
    let plain = {
        let (stop, ready, service) = (stop.clone(), ready.clone(), service.to_string());
        std::thread::spawn(move || -> Result<Vec<u64>, LiveError> {
            let node = NodeBuilder::new()
                .signal_handling_mode(SignalHandlingMode::Disabled)
                .create::<ipc::Service>()
                .map_err(|e| LiveError::ipc(service.as_str(), e))?;
            let f = node
                .service_builder(&super::service_name(&service)?)
                .publish_subscribe::<[u8]>()
                .open()
                .map_err(|e| LiveError::ipc(service.as_str(), e))?;
            let sub = f
                .subscriber_builder()
                .create()
                .map_err(|e| LiveError::ipc(service.as_str(), e))?;
            ready.fetch_add(1, Ordering::SeqCst);
            let mut lat = Vec::new();
            while !stop.load(Ordering::Relaxed) {
                while let Ok(Some(s)) = sub.receive() {
                    let now = epoch.elapsed().as_nanos() as u64;
                    let mut w = [0u8; 8];
                    w.copy_from_slice(&s.payload()[16..24]);
                    lat.push(now.saturating_sub(u64::from_le_bytes(w)));
                }
                std::thread::yield_now();
            }
            Ok(lat)
        })
    };
    let side = {
        let (stop, ready) = (stop.clone(), ready.clone());
        std::thread::spawn(move || -> Result<super::Report, LiveError> {
            let sidecar = Sidecar::new(&config, &spec, false)?;
            ready.fetch_add(1, Ordering::SeqCst);
            let mut opts = Options {
                verdicts: Box::new(std::io::sink()),
                record: None,
                every_point: false,
                poll: Duration::ZERO,
                log: Box::new(std::io::sink()),
                probe: Some(Probe { offset: 16, epoch }),
                progress: None,
            };
            sidecar.run(&config, &spec, &mut opts, &stop)
        })
    };
    while ready.load(Ordering::SeqCst) < 2 {
        std::thread::sleep(Duration::from_millis(5));
    }
    // Let both subscribers connect to the publisher before the first sample.
    std::thread::sleep(Duration::from_millis(100));
    let start = Instant::now();
    let mut buf = [0u8; 24];
    for i in 0..n {
        if let Some(r) = rate {
            let due = start + Duration::from_secs_f64(i as f64 / r);
            while Instant::now() < due {
                // Yield, not spin: on a loaded machine the receivers need the core.
                std::thread::yield_now();
            }
        }
        buf[0..4].copy_from_slice(&(50i32 + (i % 50) as i32).to_le_bytes());
        buf[8..16].copy_from_slice(&i.to_le_bytes());
        buf[16..24].copy_from_slice(&(epoch.elapsed().as_nanos() as u64).to_le_bytes());
        let s = publisher
            .loan_slice_uninit(24)
            .map_err(|e| LiveError::ipc(service, e))?;
        s.write_from_slice(&buf)
            .send()
            .map_err(|e| LiveError::ipc(service, e))?;
    }
    let send_secs = start.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_millis(300));
    stop.store(true, Ordering::SeqCst);
    let plain = plain
        .join()
        .map_err(|_| LiveError::Thread("the plain subscriber"))??;
    let report = side
        .join()
        .map_err(|_| LiveError::Thread("the sidecar"))??;
    let st = &report.sources[0];
    Ok(Phase {
        plain,
        sidecar: report.probed,
        judged: st.samples,
        lost: st.lost,
        send_secs,
    })
}

/// Runs both phases on fresh service names derived from `prefix`.
pub fn run(prefix: &str, paced: u64, rate: f64, flood: u64) -> Result<BenchReport, LiveError> {
    let a = phase(&format!("{prefix}/paced"), paced, Some(rate))?;
    let mut plain = a.plain;
    let mut side: Vec<u64> = a
        .sidecar
        .iter()
        .map(|(s, d)| d.saturating_sub(*s))
        .collect();
    let b = phase(&format!("{prefix}/flood"), flood, None)?;
    let span = match (b.sidecar.first(), b.sidecar.last()) {
        (Some(f), Some(l)) if l.1 > f.1 => (l.1 - f.1) as f64 / 1e9,
        _ => b.send_secs.max(1e-9),
    };
    Ok(BenchReport {
        paced,
        rate,
        paced_lost: a.lost,
        plain_ns: (percentile(&mut plain, 0.5), percentile(&mut plain, 0.99)),
        sidecar_ns: (percentile(&mut side, 0.5), percentile(&mut side, 0.99)),
        flood_sent: flood,
        flood_send_rate: flood as f64 / b.send_secs.max(1e-9),
        flood_judged: b.judged,
        flood_lost: b.lost,
        flood_judged_rate: b.judged as f64 / span,
    })
}
