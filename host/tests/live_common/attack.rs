//! The hostile-client attack on the live page (`monitor --serve`), shared by the test
//! `live_serve_hostile.rs` and the example `live_serve_attack.rs` (included with `#[path]`,
//! so it names the `hindsight` binary it is given rather than the test's own).
//!
//! A sidecar process (`monitor --serve :0 --every-point` on one battery topic) is fed a
//! flood of samples until the page's history is full, then gets, in turn: one client
//! sending a request line of `line_bytes` bytes, `stalled` `/events` clients that never
//! read, and `slow` clients that send a request line and then a header byte a second,
//! for `seconds`. Measured: the sidecar's peak resident memory (`VmHWM`), how much of the
//! long line it took, the verdict points it wrote meanwhile (a heartbeat point every
//! 10 ms tick, three lines each) and the largest gap between their times.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

/// The spec: three properties of a battery level in 10 ms ticks.
const SPEC: &str = "unit 10ms;
state battery_level: int = 100;
event battery_published;
event alarm;
property absence = H({battery_level >= 30} -> H(!{alarm}));
property battery_recurrence = H(P[30:] true -> P[:30] {battery_published});
property low = H({battery_level >= 30});
";

/// The sizes of the attack.
#[derive(Clone, Debug)]
pub struct Sizes {
    /// Clients trickling a request a byte a second.
    pub slow: usize,
    /// `/events` clients that never read.
    pub stalled: usize,
    /// Bytes of the long request line.
    pub line_bytes: u64,
    /// How long the slow and stalled clients stay.
    pub seconds: u64,
}

/// What was measured.
#[derive(Clone, Debug)]
pub struct Measured {
    /// The sidecar's peak resident memory (`VmHWM`), kB.
    pub peak_kb: u64,
    /// Its resident memory before the attack, kB.
    pub before_kb: u64,
    /// Bytes of the long line the sidecar's socket took before it was closed.
    pub line_taken: u64,
    /// Verdict lines written during the attack.
    pub lines: usize,
    /// The largest gap between two successive verdict points during the attack, ticks.
    pub gap: u64,
    /// Slow and stalled clients whose connection was accepted (a connect that succeeded).
    pub connected: usize,
    /// When the largest gap ended, seconds after the attack began.
    pub gap_at_s: f64,
    /// CPU time the sidecar used during the attack, seconds.
    pub cpu_s: f64,
    /// The attack's length, seconds.
    pub wall_s: f64,
}

/// A running `--serve :0 --every-point` sidecar; its page's address and the verdict
/// times (ticks) as its standard output gives them.
pub struct Sidecar {
    child: Option<Child>,
    pub addr: String,
    pub svc: String,
    times: Arc<Mutex<Vec<(Instant, u64)>>>,
}

impl Drop for Sidecar {
    fn drop(&mut self) {
        if let Some(c) = self.child.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

impl Sidecar {
    /// Starts `exe monitor` in a fresh folder under `dir`, on service `svc`.
    pub fn start(exe: &Path, dir: &Path, svc: &str) -> Sidecar {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join("spec.hspec"), SPEC).unwrap();
        let config = format!(
            "[[topic]]\nservice = \"{svc}\"\nsize = 16\nevent = \"battery_published\"\n\
             [[topic.field]]\nvar = \"battery_level\"\noffset = 0\ntype = \"i32\"\n"
        );
        std::fs::write(dir.join("config.toml"), config).unwrap();
        let err = dir.join("monitor.err");
        let mut child = Command::new(exe)
            .arg("monitor")
            .arg("--props")
            .arg(dir.join("spec.hspec"))
            .arg("--config")
            .arg(dir.join("config.toml"))
            .args(["--serve", ":0", "--every-point"])
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(&err).unwrap())
            .spawn()
            .unwrap();
        let out = child.stdout.take().unwrap();
        let mut sc = Sidecar {
            child: Some(child),
            addr: String::new(),
            svc: svc.to_string(),
            times: Arc::new(Mutex::new(Vec::new())),
        };
        let t = sc.times.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                let Ok(line) = line else { return };
                let v: serde_json::Value = serde_json::from_str(&line).unwrap();
                t.lock()
                    .unwrap()
                    .push((Instant::now(), v["time"].as_u64().unwrap()));
            }
        });
        let start = Instant::now();
        sc.addr = loop {
            let log = std::fs::read_to_string(&err).unwrap_or_default();
            if log.contains("monitor: ready") {
                let at =
                    log.find("live page at http://").expect(&log) + "live page at http://".len();
                break log[at..at + log[at..].find('/').unwrap()].to_string();
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "never ready: {log}"
            );
            std::thread::sleep(Duration::from_millis(10));
        };
        sc
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().unwrap().id()
    }

    /// A field of `/proc/PID/status` in kB (`VmHWM`, `VmRSS`).
    pub fn status_kb(&self, field: &str) -> u64 {
        let s = std::fs::read_to_string(format!("/proc/{}/status", self.pid())).unwrap();
        let line = s.lines().find(|l| l.starts_with(field)).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    }

    /// CPU time the sidecar used so far (user + system), seconds.
    pub fn cpu_s(&self) -> f64 {
        let s = std::fs::read_to_string(format!("/proc/{}/stat", self.pid())).unwrap();
        // After the command's `)`: state is field 3, utime 14, stime 15 (clock ticks).
        let rest = &s[s.rfind(')').unwrap() + 2..];
        let f: Vec<&str> = rest.split_whitespace().collect();
        (f[11].parse::<u64>().unwrap() + f[12].parse::<u64>().unwrap()) as f64 / 100.0
    }

    /// The descriptors the sidecar has open.
    pub fn open_fds(&self) -> Vec<u32> {
        std::fs::read_dir(format!("/proc/{}/fd", self.pid()))
            .unwrap()
            .filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
            .collect()
    }

    /// The largest gap between two successive verdict points from line `from` on, ticks.
    pub fn largest_gap(&self, from: usize) -> u64 {
        let t = self.times.lock().unwrap();
        t[from.min(t.len())..]
            .windows(2)
            .map(|w| w[1].1.saturating_sub(w[0].1))
            .max()
            .unwrap_or(0)
    }

    /// Where the largest gap from line `from` on is: its ticks, and the seconds after
    /// `t0` when the line after it arrived.
    pub fn gap_at(&self, from: usize, t0: Instant) -> (u64, f64) {
        let t = self.times.lock().unwrap();
        t[from.min(t.len())..]
            .windows(2)
            .map(|w| {
                (
                    w[1].1.saturating_sub(w[0].1),
                    w[1].0.duration_since(t0).as_secs_f64(),
                )
            })
            .max_by_key(|g| g.0)
            .unwrap_or((0, 0.0))
    }

    /// Verdict lines written so far.
    pub fn lines(&self) -> usize {
        self.times.lock().unwrap().len()
    }

    /// Whether the process still runs.
    pub fn alive(&mut self) -> bool {
        self.child.as_mut().unwrap().try_wait().unwrap().is_none()
    }

    /// Feeds samples (levels 50 and 20 in turn) until `lines` verdict lines were written.
    pub fn flood(&self, lines: usize) {
        let node = NodeBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .unwrap();
        let tx = node
            .service_builder(&ServiceName::new(&self.svc).unwrap())
            .publish_subscribe::<[u8]>()
            .open_or_create()
            .unwrap()
            .publisher_builder()
            .initial_max_slice_len(16)
            .create()
            .unwrap();
        let t = Instant::now();
        let mut n = 0u64;
        while self.lines() < lines {
            for _ in 0..1000 {
                let level: i32 = if n % 2 == 0 { 50 } else { 20 };
                let mut b = [0u8; 16];
                b[0..4].copy_from_slice(&level.to_le_bytes());
                let s = tx.loan_slice_uninit(16).unwrap();
                s.write_from_slice(&b).send().unwrap();
                n += 1;
            }
            std::thread::sleep(Duration::from_millis(2));
            assert!(
                t.elapsed() < Duration::from_secs(60),
                "the flood gave {} verdict lines",
                self.lines()
            );
        }
    }
}

/// A plain GET of `path`: the status line.
pub fn status(addr: &str, path: &str) -> String {
    let Ok(mut s) = TcpStream::connect(addr) else {
        return "connect failed".into();
    };
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n");
    let mut text = String::new();
    let _ = s.read_to_string(&mut text);
    text.lines().next().unwrap_or("").to_string()
}

/// Runs the attack on a sidecar whose history is full; what it measured.
pub fn attack(sc: &mut Sidecar, sizes: &Sizes) -> Measured {
    let before_kb = sc.status_kb("VmRSS");
    let from = sc.lines();
    let (cpu0, t0) = (sc.cpu_s(), Instant::now());
    // The long request line first and alone, so that a connection slot is free for it.
    let line_taken = {
        let (addr, n) = (sc.addr.clone(), sizes.line_bytes);
        std::thread::spawn(move || {
            let mut s = TcpStream::connect(&addr).unwrap();
            let _ = s.write_all(b"GET /");
            let block = vec![b'a'; 1 << 20];
            let mut sent = 0u64;
            while sent < n {
                let k = (n - sent).min(block.len() as u64) as usize;
                if s.write_all(&block[..k]).is_err() {
                    break;
                }
                sent += k as u64;
            }
            sent
        })
        .join()
        .unwrap()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let connected = Arc::new(AtomicUsize::new(0));
    let mut stalled = Vec::new();
    for _ in 0..sizes.stalled {
        if let Ok(mut s) = TcpStream::connect(&sc.addr) {
            let _ = write!(s, "GET /events HTTP/1.1\r\nHost: {}\r\n\r\n", sc.addr);
            stalled.push(s);
        }
    }
    connected.fetch_add(stalled.len(), Ordering::SeqCst);
    let slow = {
        let (addr, stop, connected, n) =
            (sc.addr.clone(), stop.clone(), connected.clone(), sizes.slow);
        std::thread::spawn(move || {
            let mut slow: Vec<TcpStream> = (0..n)
                .filter_map(|_| TcpStream::connect(&addr).ok())
                .collect();
            connected.fetch_add(slow.len(), Ordering::SeqCst);
            for s in &mut slow {
                let _ = s.set_nonblocking(true);
                let _ = s.write(b"GET / HTTP/1.1\r\nX-Slow: ");
            }
            while !stop.load(Ordering::SeqCst) {
                for s in &mut slow {
                    let _ = s.write(b"a");
                }
                std::thread::sleep(Duration::from_secs(1));
            }
        })
    };
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(sizes.seconds) {
        assert!(sc.alive(), "the sidecar died");
        std::thread::sleep(Duration::from_millis(100));
    }
    let measured = Measured {
        peak_kb: sc.status_kb("VmHWM"),
        before_kb,
        line_taken,
        lines: sc.lines() - from,
        gap: sc.largest_gap(from),
        gap_at_s: sc.gap_at(from, t0).1,
        connected: connected.load(Ordering::SeqCst),
        cpu_s: sc.cpu_s() - cpu0,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    stop.store(true, Ordering::SeqCst);
    slow.join().unwrap();
    drop(stalled);
    measured
}
