//! What the DDS tests (`dds_live.rs`, `dds_run.rs`) share: the Cyclone DDS peer
//! (`host/tests/data/dds/cyclone.py`) and the Python that runs it, a random ROS domain per
//! test, scratch folders, and child processes (ours or the peer) whose output is
//! collected while they run.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The repository's root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("host/ has a parent")
        .to_path_buf()
}

/// A file of `host/tests/data/dds`.
pub fn data(name: &str) -> PathBuf {
    repo().join("host/tests/data/dds").join(name)
}

/// The Cyclone DDS peer.
pub fn cyclone_py() -> PathBuf {
    data("cyclone.py")
}

/// The Python of the project's environment, if it has what the DDS tests need (else the
/// test is skipped, or fails under `CI=true`: [`super::pyenv::python_with`]).
pub fn python() -> Option<PathBuf> {
    super::pyenv::python_with(
        &["cyclonedds.domain", "mcap", "mcap_ros2"],
        "cyclonedds, mcap and mcap-ros2-support",
    )
}

/// A domain for one test: random, from the process, the test (`salt`) and the clock,
/// from 1 to 232 (0 is everyone's default, so it is left out). Tests running in parallel
/// (and other DDS traffic on the machine) do not meet.
pub fn domain(salt: u64) -> u16 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64;
    let mut x = nanos ^ (u64::from(std::process::id()) << 20) ^ salt.wrapping_mul(0x9E37_79B9);
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    1 + (x % 232) as u16
}

/// An empty scratch folder `hindsight-<what>-<pid>-<name>` under the system's temporary
/// folder.
pub fn scratch(what: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hindsight-{what}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `hindsight` binary under test.
pub fn hindsight() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hindsight"))
}

/// A child process whose standard output and error are collected by threads; killed
/// when dropped.
pub struct Proc {
    child: Child,
    out: Arc<Mutex<String>>,
    err: Arc<Mutex<String>>,
    what: String,
}

fn collect(pipe: impl std::io::Read + Send + 'static) -> Arc<Mutex<String>> {
    let sink = Arc::new(Mutex::new(String::new()));
    let s = sink.clone();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            let mut g = s.lock().unwrap();
            g.push_str(&line);
            g.push('\n');
        }
    });
    sink
}

impl Proc {
    /// Starts `c`, named `what` in failures.
    pub fn start(mut c: Command, what: &str) -> Proc {
        let mut child = c
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let out = collect(child.stdout.take().unwrap());
        let err = collect(child.stderr.take().unwrap());
        Proc {
            child,
            out,
            err,
            what: what.to_string(),
        }
    }

    /// `hindsight monitor ARGS` on `domain`, once it said it is ready.
    pub fn monitor(domain: u16, args: &[&std::ffi::OsStr]) -> Proc {
        let mut c = hindsight();
        c.arg("monitor")
            .args(args)
            .env("ROS_DOMAIN_ID", domain.to_string());
        let p = Proc::start(c, "hindsight monitor");
        p.wait_for("monitor: ready", Duration::from_secs(60));
        p
    }

    /// Its standard output so far.
    pub fn out(&self) -> String {
        self.out.lock().unwrap().clone()
    }

    /// Its standard error so far.
    pub fn err(&self) -> String {
        self.err.lock().unwrap().clone()
    }

    /// Waits until `text` is in its standard output or error.
    pub fn wait_for(&self, text: &str, timeout: Duration) {
        let start = Instant::now();
        while !self.out().contains(text) && !self.err().contains(text) {
            assert!(
                start.elapsed() < timeout,
                "no `{text}` from {} within {timeout:?}:\n{}\n{}",
                self.what,
                self.out(),
                self.err()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Waits for the process to end (killing it after `timeout`); its exit status.
    pub fn wait(&mut self, timeout: Duration) -> std::process::ExitStatus {
        let start = Instant::now();
        let status = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break s;
            }
            if start.elapsed() > timeout {
                let _ = self.child.kill();
                panic!(
                    "{} did not end within {timeout:?}:\n{}\n{}",
                    self.what,
                    self.out(),
                    self.err()
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        // The reader threads end with the pipes.
        std::thread::sleep(Duration::from_millis(200));
        status
    }

    /// SIGINT, then [`Proc::wait`].
    pub fn interrupt(&mut self, timeout: Duration) -> std::process::ExitStatus {
        let pid = self.child.id().to_string();
        assert!(Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .unwrap()
            .success());
        self.wait(timeout)
    }

    /// The JSON lines it printed on its standard output.
    pub fn json_lines(&self) -> Vec<serde_json::Value> {
        self.out()
            .lines()
            .filter(|l| l.starts_with('{'))
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The Cyclone DDS peer `cyclone.py CMD DOMAIN JSON` running in the background.
pub fn cyclone(py: &Path, cmd: &str, domain: u16, json: &str) -> Proc {
    let mut c = Command::new(py);
    c.arg(cyclone_py()).args([cmd, &domain.to_string(), json]);
    Proc::start(c, &format!("cyclone.py {cmd}"))
}
