//! Shared helpers of the `live_*` tests (included with `#[path]`, not a test target of its own).
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use hindsight::live::config::Config;
use hindsight::live::{Options, Report, Sidecar};
use iceoryx2::prelude::*;

/// The test spec: the museum's battery requirements, in 10 ms ticks, with a request event.
pub const SPEC: &str = "unit 10ms;
state battery_level: int = 100;
event battery_published;
event alarm;
event poi_request;
state poi: int = 0;
property absence = H({battery_level >= 30} -> H(!{alarm}));
property battery_recurrence = H(P[30:] true -> P[:30] {battery_published});
property poi_needs_battery = H({poi_request} -> {battery_level >= 30});
";

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A service-name prefix no other test (or test process) uses.
pub fn unique(tag: &str) -> String {
    format!(
        "hindsight-test/{}/{}/{tag}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::SeqCst)
    )
}

/// A fresh scratch directory.
pub fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(unique(tag).replace('/', "_"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The config of one battery topic `svc` (16 bytes: level i32 at 0, seq u64 at 8).
pub fn battery_topic(svc: &str) -> String {
    format!(
        "[[topic]]\nservice = \"{svc}\"\nsize = 16\nevent = \"battery_published\"\n\
         seq = {{ offset = 8, type = \"u64\" }}\n\
         [[topic.field]]\nname = \"level\"\nvar = \"battery_level\"\noffset = 0\ntype = \"i32\"\n"
    )
}

/// A 16-byte battery sample.
pub fn battery(level: i32, seq: u64) -> [u8; 16] {
    let mut b = [0u8; 16];
    b[0..4].copy_from_slice(&level.to_le_bytes());
    b[8..16].copy_from_slice(&seq.to_le_bytes());
    b
}

/// A running in-process sidecar writing to files.
pub struct Running {
    stop: Arc<AtomicBool>,
    handle: JoinHandle<Report>,
    /// Samples and requests judged so far.
    pub progress: Arc<AtomicU64>,
    verdicts: PathBuf,
    record: PathBuf,
    /// Diagnostics the sidecar wrote.
    pub log: Arc<Mutex<Vec<u8>>>,
}

struct Shared(Arc<Mutex<Vec<u8>>>);

impl std::io::Write for Shared {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.0.lock().unwrap().extend_from_slice(b);
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// What a stopped sidecar produced.
pub struct Finished {
    /// What `run` returned.
    pub report: Report,
    /// Verdict lines.
    pub lines: Vec<String>,
    /// The input log.
    pub record: String,
    /// Diagnostics.
    pub log: String,
}

impl Running {
    /// Starts the sidecar on `config` (TOML text) once its ports exist.
    pub fn start(config: &str, tag: &str) -> Running {
        iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
        let dir = scratch(tag);
        let (verdicts, record) = (dir.join("verdicts.jsonl"), dir.join("input.jsonl"));
        let stop = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(AtomicU64::new(0));
        let log = Arc::new(Mutex::new(Vec::new()));
        let ready = Arc::new(AtomicBool::new(false));
        let handle = {
            let (stop, progress, log, ready) =
                (stop.clone(), progress.clone(), log.clone(), ready.clone());
            let (verdicts, record, config) = (verdicts.clone(), record.clone(), config.to_string());
            std::thread::spawn(move || {
                let spec = codegen::compile_spec(SPEC, "test.hspec").unwrap();
                let config = Config::parse(&config, "test.toml", &spec).unwrap();
                let sidecar = Sidecar::new(&config, &spec, false).unwrap();
                ready.store(true, Ordering::SeqCst);
                let mut opts = Options {
                    verdicts: Box::new(std::fs::File::create(&verdicts).unwrap()),
                    record: Some(Box::new(std::io::BufWriter::new(
                        std::fs::File::create(&record).unwrap(),
                    ))),
                    every_point: false,
                    poll: Duration::from_micros(200),
                    log: Box::new(Shared(log)),
                    probe: None,
                    progress: Some(progress),
                };
                sidecar.run(&config, &spec, &mut opts, &stop).unwrap()
            })
        };
        while !ready.load(Ordering::SeqCst) {
            assert!(!handle.is_finished(), "the sidecar stopped while starting");
            std::thread::sleep(Duration::from_millis(2));
        }
        Running {
            stop,
            handle,
            progress,
            verdicts,
            record,
            log,
        }
    }

    /// Waits until at least `n` samples or requests were judged (a guard of 20 s against a hang).
    pub fn wait_judged(&self, n: u64) {
        let t = Instant::now();
        while self.progress.load(Ordering::SeqCst) < n {
            assert!(
                t.elapsed() < Duration::from_secs(20),
                "judged {} of {n}",
                self.progress.load(Ordering::SeqCst)
            );
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Stops the sidecar and reads what it wrote.
    pub fn finish(self) -> Finished {
        self.stop.store(true, Ordering::SeqCst);
        let report = self.handle.join().unwrap();
        let lines = std::fs::read_to_string(&self.verdicts)
            .unwrap()
            .lines()
            .map(str::to_string)
            .collect();
        let record = std::fs::read_to_string(&self.record).unwrap();
        let log = String::from_utf8(self.log.lock().unwrap().clone()).unwrap();
        Finished {
            report,
            lines,
            record,
            log,
        }
    }
}

impl Finished {
    /// The verdicts of `prop`, in order.
    pub fn verdicts_of(&self, prop: &str) -> Vec<String> {
        self.lines
            .iter()
            .map(|l| serde_json::from_str::<hindsight::live::record::VerdictLine>(l).unwrap())
            .filter(|v| v.property == prop)
            .map(|v| v.verdict)
            .collect()
    }

    /// Replaying the input log gives exactly the live verdict lines.
    pub fn assert_replay_matches(&self) {
        let spec = codegen::compile_spec(SPEC, "test.hspec").unwrap();
        let replayed =
            hindsight::live::record::replay(&spec, &self.record, "input.jsonl", false).unwrap();
        assert_eq!(replayed, self.lines, "replay differs from the live run");
    }
}

/// A test node (no signal handlers).
pub fn node() -> Node<ipc::Service> {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .unwrap()
}

/// Sends `bytes` on `publisher`.
pub fn send(p: &iceoryx2::port::publisher::Publisher<ipc::Service, [u8], ()>, bytes: &[u8]) {
    let s = p.loan_slice_uninit(bytes.len()).unwrap();
    s.write_from_slice(bytes).send().unwrap();
}

/// A `[u8]` publisher on `svc` (opened: the sidecar created the service).
pub fn publisher(
    node: &Node<ipc::Service>,
    svc: &str,
) -> iceoryx2::port::publisher::Publisher<ipc::Service, [u8], ()> {
    let f = node
        .service_builder(&ServiceName::new(svc).unwrap())
        .publish_subscribe::<[u8]>()
        .open_or_create()
        .unwrap();
    f.publisher_builder()
        .initial_max_slice_len(64)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .unwrap()
}

/// A child process (`hindsight run`, `hindsight monitor`) killed if a test fails before
/// it is waited for.
pub struct Guard(pub Option<std::process::Child>);

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some(c) = self.0.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Waits for the child to exit (a guard of 60 s against a hang) and returns its stderr.
pub fn finish(guard: &mut Guard) -> (std::process::ExitStatus, String) {
    finish_polling(guard, || {})
}

/// [`finish`], calling `poll` every few milliseconds while the child runs (samples of a
/// process that exits are gone: a subscriber must read them while it lives).
pub fn finish_polling(
    guard: &mut Guard,
    mut poll: impl FnMut(),
) -> (std::process::ExitStatus, String) {
    let mut child = guard.0.take().unwrap();
    let t = Instant::now();
    loop {
        poll();
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            // A child whose stderr goes to a file has nothing to read here.
            if let Some(mut e) = child.stderr.take() {
                e.read_to_string(&mut err).unwrap();
            }
            return (status, err);
        }
        if t.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the child process did not end");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// `target/<profile>/examples/<name>`, built by `cargo test` with the tests.
pub fn example(name: &str) -> std::path::PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().parent().unwrap();
    let path = dir.join("examples").join(name);
    assert!(
        path.exists(),
        "{} is missing: `cargo test` builds examples, `cargo test --test X` does not \
         (cargo build -p hindsight --example {name})",
        path.display()
    );
    path
}

/// A subscriber, with iceoryx2's defaults, to the `[u8]` publish-subscribe service `name`
/// (opened, or created before its publisher exists).
pub fn raw_subscriber(
    node: &Node<ipc::Service>,
    name: &str,
) -> iceoryx2::port::subscriber::Subscriber<ipc::Service, [u8], ()> {
    node.service_builder(&ServiceName::new(name).unwrap())
        .publish_subscribe::<[u8]>()
        .open_or_create()
        .unwrap()
        .subscriber_builder()
        .create()
        .unwrap()
}

/// The `hindsight` binary of this build.
pub fn hindsight() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_hindsight"))
}

/// The museum guide example.
pub fn museum() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/museum-guide")
}

/// Writes the sidecar's config for the museum run under service prefix `prefix`
/// (`hindsight run --layout`) to `dir/museum.toml`; its path.
pub fn museum_config(dir: &std::path::Path, prefix: &str) -> PathBuf {
    let layout = hindsight()
        .arg("run")
        .arg(museum())
        .args(["--layout", "--prefix", prefix])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&layout.stderr);
    assert!(layout.status.success(), "run --layout: {err}");
    let config = dir.join("museum.toml");
    std::fs::write(&config, &layout.stdout).unwrap();
    config
}
