//! The real BehaviorTree.CPP as the oracle's oracle: `tests/bt/real/harness.py` runs
//! cases in the `behaviortreepy` bindings (BT.CPP 4.8.2 compiled in) in one Python
//! process per [`Real`], fed JSON lines; a case whose tick never returns with no Python
//! callback to stop it (a loop of built-in nodes) is caught by a watchdog here, which
//! kills the process, starts a new one and reports the case as [`End::Hang`].

use super::oracle::{End, LeafEvent, Outcome, Scripts, TickMode};
use super::tree::{Status, Tree};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::time::Duration;

/// The repository's root (the tests crate's parent).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ has a parent")
        .to_path_buf()
}

/// The Python of the project's environment (`$HINDSIGHT_PYENV`, else `.venv` at the
/// repository root, as `scripts/pyenv` makes it), if it exists.
pub fn python() -> Option<PathBuf> {
    let dir = match std::env::var_os("HINDSIGHT_PYENV") {
        Some(d) => {
            let d = PathBuf::from(d);
            if d.is_absolute() {
                d
            } else {
                root().join(d)
            }
        }
        None => root().join(".venv"),
    };
    let py = dir.join("bin").join("python");
    py.is_file().then_some(py)
}

/// One case for the real library.
#[derive(Clone, Debug)]
pub struct Request {
    /// The tree document.
    pub xml: String,
    /// The leaf types' scripts.
    pub scripts: Scripts,
    /// Root ticks.
    pub ticks: usize,
    /// `tickOnce` or `tickExactlyOnce`.
    pub mode: TickMode,
    /// Leaf callbacks per root tick before the harness calls it a livelock.
    pub budget: usize,
    /// Root blackboard entries to read (as integers) after the last tick.
    pub read: Vec<String>,
}

/// What the real library did, leaves named by BT.CPP's UIDs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Answer {
    /// Root status per finished tick.
    pub statuses: Vec<Status>,
    /// (`true` for a tick, `false` for a halt, UID, leaf type).
    pub log: Vec<(bool, u32, String)>,
    /// How it ended early: `(kind, tick, text)` with kind `load`, `tick`, `livelock` or
    /// `hang` (the watchdog's).
    pub end: Option<(String, usize, String)>,
    /// The entries [`Request::read`] named, those that hold a number.
    pub vars: std::collections::BTreeMap<String, i64>,
}

/// A running harness.
pub struct Real {
    python: PathBuf,
    child: Child,
    to: Sender<String>,
    from: Receiver<String>,
    /// BT.CPP's version (`BT::LibraryVersionString`).
    pub version: String,
    /// The bindings' version.
    pub binding: String,
    /// How long an answer may take before the case counts as a hang.
    pub timeout: Duration,
    /// Harness processes started (1 + hangs).
    pub starts: usize,
    /// Ticks paced this many milliseconds apart ([`Real::run_paced`]), or as fast as
    /// they go.
    pace: Option<u64>,
}

fn spawn(python: &Path) -> Result<(Child, Sender<String>, Receiver<String>), String> {
    let script = root().join("tests/bt/real/harness.py");
    let mut child = Command::new(python)
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    let mut stdin = child.stdin.take().expect("piped");
    let stdout = child.stdout.take().expect("piped");
    let (to, rx) = channel::<String>();
    std::thread::spawn(move || {
        for line in rx {
            if stdin.write_all(line.as_bytes()).is_err() || stdin.flush().is_err() {
                break;
            }
        }
    });
    let (tx, from) = channel::<String>();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    Ok((child, to, from))
}

fn status(s: &str) -> Result<Status, String> {
    Status::parse(s).ok_or(format!("harness answered status {s}"))
}

impl Real {
    /// Starts the harness with `python` and reads the versions it announces.
    pub fn start(python: &Path) -> Result<Real, String> {
        let (child, to, from) = spawn(python)?;
        let mut r = Real {
            python: python.to_path_buf(),
            child,
            to,
            from,
            version: String::new(),
            binding: String::new(),
            timeout: Duration::from_secs(5),
            starts: 1,
            pace: None,
        };
        r.hello()?;
        r.timeout = Duration::from_secs(2);
        Ok(r)
    }

    fn hello(&mut self) -> Result<(), String> {
        let line = self
            .from
            .recv_timeout(Duration::from_secs(60))
            .map_err(|_| "the harness did not start (is behaviortreepy installed?)")?;
        let v: serde_json::Value =
            serde_json::from_str(&line).map_err(|e| format!("harness: {e}: {line}"))?;
        self.version = v["version"].as_str().unwrap_or("?").to_string();
        self.binding = v["binding"].as_str().unwrap_or("?").to_string();
        Ok(())
    }

    fn restart(&mut self) -> Result<(), String> {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let (child, to, from) = spawn(&self.python)?;
        self.child = child;
        self.to = to;
        self.from = from;
        self.starts += 1;
        self.hello()
    }

    fn line(r: &Request, pace: Option<u64>) -> String {
        let scripts: serde_json::Map<String, serde_json::Value> = r
            .scripts
            .iter()
            .map(|(k, v)| {
                let names = v.iter().map(|s| s.name().into()).collect();
                (k.clone(), serde_json::Value::Array(names))
            })
            .collect();
        let mode = match r.mode {
            TickMode::Once => "once",
            TickMode::ExactlyOnce => "exactly_once",
        };
        let mut v = serde_json::json!({
            "xml": r.xml, "scripts": scripts, "ticks": r.ticks, "mode": mode, "budget": r.budget,
            "read": r.read,
        });
        if let Some(p) = pace {
            v["period_ms"] = p.into();
        }
        // What the leaves with ports write and read (`model::has_out`, `has_in_text`):
        // the harness takes them from here, so the two cannot drift apart.
        let out: Vec<f64> = (super::model::OUT_VALUES.iter())
            .map(|x| x.parse().expect("OUT_VALUES are numbers"))
            .collect();
        v["out_values"] = out.into();
        v["in_text"] = super::model::IN_TEXT.into();
        format!("{v}\n")
    }

    fn parse(line: &str) -> Result<Answer, String> {
        let v: serde_json::Value =
            serde_json::from_str(line).map_err(|e| format!("harness: {e}: {line}"))?;
        let statuses = v["statuses"]
            .as_array()
            .ok_or("no statuses")?
            .iter()
            .map(|s| status(s.as_str().unwrap_or("")))
            .collect::<Result<_, _>>()?;
        let mut log = Vec::new();
        for e in v["log"].as_array().ok_or("no log")? {
            let tick = e[0].as_str() == Some("T");
            let uid = e[1].as_u64().ok_or("uid")? as u32;
            log.push((tick, uid, e[2].as_str().unwrap_or("").to_string()));
        }
        let end = match &v["end"] {
            serde_json::Value::Null => None,
            e => Some((
                e["kind"].as_str().unwrap_or("").to_string(),
                e["tick"].as_u64().unwrap_or(0) as usize,
                e["text"].as_str().unwrap_or("").to_string(),
            )),
        };
        let vars = v["vars"]
            .as_object()
            .map(|m| {
                m.iter()
                    .filter_map(|(k, x)| Some((k.clone(), x.as_i64()?)))
                    .collect()
            })
            .unwrap_or_default();
        Ok(Answer {
            statuses,
            log,
            end,
            vars,
        })
    }

    /// Runs the cases (streamed: all written, then all read); a case that takes longer
    /// than [`Real::timeout`] is a hang, and the cases after it go to a new process.
    pub fn run(&mut self, reqs: &[Request]) -> Result<Vec<Answer>, String> {
        let mut out = Vec::with_capacity(reqs.len());
        let mut sent = 0;
        while out.len() < reqs.len() {
            while sent < reqs.len() {
                if self.to.send(Self::line(&reqs[sent], self.pace)).is_err() {
                    return Err("the harness's stdin closed".into());
                }
                sent += 1;
            }
            match self.from.recv_timeout(self.timeout) {
                Ok(line) => out.push(Self::parse(&line)?),
                Err(RecvTimeoutError::Timeout) => {
                    out.push(Answer {
                        statuses: Vec::new(),
                        log: Vec::new(),
                        end: Some(("hang".into(), 0, "no answer in time".into())),
                        vars: Default::default(),
                    });
                    self.restart()?;
                    sent = out.len();
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(format!(
                        "the harness died on case {} of the batch:\n{}",
                        out.len(),
                        reqs[out.len()].xml
                    ));
                }
            }
        }
        Ok(out)
    }
}

impl Real {
    /// Runs the cases as [`Real::run`] does, each tick `period_ms` after the one before
    /// (the harness's `period_ms`): the wall-clock timers of Timeout, Delay and Sleep then
    /// fire between the ticks as the durations say. A case whose ticks the harness could
    /// not keep within a quarter period of their time ends as `("late", tick, ..)`.
    pub fn run_paced(&mut self, reqs: &[Request], period_ms: u64) -> Result<Vec<Answer>, String> {
        let (pace, timeout) = (self.pace, self.timeout);
        self.pace = Some(period_ms);
        let longest = reqs.iter().map(|r| r.ticks as u64).max().unwrap_or(0) * period_ms;
        self.timeout = timeout + Duration::from_millis(2 * longest);
        let out = self.run(reqs);
        self.pace = pace;
        self.timeout = timeout;
        out
    }
}

impl Drop for Real {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The real library's answer in the oracle's terms: UIDs mapped to node ids (checking
/// the leaf type agrees), the end as an [`End`] (a hang's tick is unknown: 0).
pub fn outcome(tree: Option<&Tree>, a: &Answer) -> Result<Outcome, String> {
    let mut log = Vec::with_capacity(a.log.len());
    for (tick, uid, ty) in &a.log {
        let tree = tree.ok_or("a log from a tree the oracle cannot read")?;
        let node = tree
            .nodes
            .iter()
            .find(|n| n.uid == *uid)
            .ok_or(format!("no node with BT.CPP UID {uid}"))?;
        if node.tag != *ty {
            return Err(format!(
                "UID {uid} is a {ty} in BT.CPP, a {} in the oracle",
                node.tag
            ));
        }
        log.push(if *tick {
            LeafEvent::Tick(node.id)
        } else {
            LeafEvent::Halt(node.id)
        });
    }
    let end = a
        .end
        .as_ref()
        .map(|(kind, tick, text)| match kind.as_str() {
            "load" => End::Refused(text.clone()),
            "livelock" => End::Livelock { tick: *tick },
            "hang" => End::Hang { tick: 0 },
            _ => End::Error {
                tick: *tick,
                text: text.clone(),
            },
        });
    Ok(Outcome {
        statuses: a.statuses.clone(),
        log,
        end,
        vars: a.vars.clone(),
    })
}
