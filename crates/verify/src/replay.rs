//! Runs of a study replayed one at a time, each as the CSV [`crate::record`] writes:
//! [`replay_csv`] for `trace` (run k of a seed is stream k, whatever ran before it), the
//! failing runs a study kept for `--save-failing` and `--report` ([`failing_runs`],
//! [`save`]) and, under `--schedulers`, a failing run under each order-sensitive
//! property's witness (`witness_runs`); [`play_run`] plays one run to an observer of
//! the caller's (`hindsight run` paces it in wall-clock time). Nothing here prints: the files written come
//! back as values.
//!
//! ```
//! use hindsight_verify::load::{load, LoadOptions};
//! use hindsight_verify::replay::{file_stem, replay_csv};
//! use hindsight_verify::sim::RunConfig;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/museum-scxml");
//! let loaded = load(&LoadOptions { model: dir.into(), ..LoadOptions::default() }).unwrap();
//! let run_cfg = RunConfig { max_time: 200, events: loaded.events, ..RunConfig::default() };
//! let (csv, _) = replay_csv(&loaded.model, &loaded.set, &run_cfg, 1, 3).unwrap();
//! // The same run twice is the same text; its header names time and step first.
//! assert_eq!(csv, replay_csv(&loaded.model, &loaded.set, &run_cfg, 1, 3).unwrap().0);
//! assert!(csv.starts_with("time,step,"));
//! // A property id as a file name never leaves the folder.
//! assert_eq!(file_stem("../etc/x"), "_._etc_x");
//! ```

use std::path::{Path, PathBuf};

use crate::observe::{Judge, JudgeError, PropertySet};
use crate::record::{Culprit, Recorder};
use crate::result::Study;
// What a played run reports to and how it ends, as callers name them.
use crate::sim::{
    BadScheduler, CompiledModel, EndReason, EventSemantics, Quiescence, RunConfig, Scheduler,
    Simulator,
};
pub use crate::sim::{Observer, RunOutcome};
use crate::smc::StudyResult;

/// One failing run replayed: its property, run index, file name and CSV.
#[derive(Clone, Debug)]
pub struct Failing {
    /// The property it was kept for.
    pub property: String,
    /// Its index in the study.
    pub run: u64,
    /// The file it is written to (`--save-failing`), or, for a run that is only shown,
    /// what names it on the page.
    pub file: String,
    /// The CSV text.
    pub csv: String,
    /// Per property that turned false: the subformula that explains it, and its value.
    pub culprits: Vec<Culprit>,
}

/// Why a run could not be replayed.
#[derive(Clone, Debug)]
pub enum ReplayError {
    /// The monitors refused the compiled program (a bug, not bad input).
    Judge(JudgeError),
    /// A witness in the study names no scheduler.
    Witness(BadScheduler),
}

impl std::fmt::Display for ReplayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReplayError::Judge(e) => write!(f, "{e}"),
            ReplayError::Witness(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ReplayError {}

impl From<JudgeError> for ReplayError {
    fn from(e: JudgeError) -> Self {
        ReplayError::Judge(e)
    }
}

/// Replays run `k` of a study with `seed` and returns its CSV (see [`crate::record`])
/// and, per property that turned false, the subformula that explains it.
pub fn replay_csv(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    k: u64,
) -> Result<(String, Vec<Culprit>), JudgeError> {
    let mut judge = Judge::new(set)?;
    let mut rec = Recorder::new(&mut judge, model);
    rec.start();
    let mut rng = crate::smc::runner::stream(seed, k);
    Simulator::new(model).run(&mut rng, run_cfg, &mut rec);
    Ok((rec.csv, rec.culprits))
}

/// Plays run `k` of a study with `seed` (the run `verify --seed` numbers `k`: the same
/// choices) once, up to model time `max_time` under `events`, reporting every point to
/// `observer`. Time advances when no machine can move (the run waits for its next timer,
/// or for what `observer` posts into it), as a system running in real time does.
pub fn play_run<O: Observer + ?Sized>(
    model: &CompiledModel,
    events: EventSemantics,
    max_time: u64,
    (seed, k): (u64, u64),
    observer: &mut O,
) -> RunOutcome {
    let cfg = RunConfig {
        max_time,
        events,
        quiescence: Quiescence::AdvanceTime,
        ..RunConfig::default()
    };
    let mut rng = crate::smc::runner::stream(seed, k);
    Simulator::new(model).run(&mut rng, &cfg, observer)
}

/// Why a played run ended, as `hindsight run` says it: `reached the duration` at its
/// `max_time`, else the simulator's reason.
pub fn end_text(end: &EndReason) -> String {
    match end {
        EndReason::MaxTime => "reached the duration".to_string(),
        other => format!("{other:?}"),
    }
}

/// `id` as a file name: ids are checked where declared (`props::is_valid_id`), so this
/// changes nothing for them; any other character (a name from elsewhere) becomes `_`,
/// and a leading `.` too, so no name is a path (`../x`, `/etc/x`) or a hidden file.
pub fn file_stem(id: &str) -> String {
    let stem: String = id
        .chars()
        .enumerate()
        .map(|(i, c)| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '_' | '-' => c,
            '.' if i > 0 => c,
            _ => '_',
        })
        .take(crate::props::MAX_ID_LEN)
        .collect();
    if stem.is_empty() {
        "property".to_owned()
    } else {
        stem
    }
}

/// Replays each failing run `result` kept (run k is stream k of `seed`), each named
/// `out/PROPERTY-runK.csv`; [`save`] writes them.
pub fn failing_runs(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    result: &StudyResult,
    out: &Path,
) -> Result<Vec<Failing>, JudgeError> {
    let mut kept = Vec::new();
    for (name, p) in set.guarantee_names().iter().zip(&result.properties) {
        for &k in &p.failing_runs {
            let (csv, culprits) = replay_csv(model, set, run_cfg, seed, k)?;
            let path = out.join(format!("{}-run{k}.csv", file_stem(name)));
            kept.push(Failing {
                property: name.clone(),
                run: k,
                file: path.display().to_string(),
                csv,
                culprits,
            });
        }
    }
    Ok(kept)
}

/// Writes each of `failing` (from [`failing_runs`]) to its file, creating `out` first;
/// returns the files written, in order.
pub fn save(out: &Path, failing: &[Failing]) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out)?;
    let mut written = Vec::new();
    for f in failing {
        let path = PathBuf::from(&f.file);
        std::fs::write(&path, &f.csv)?;
        written.push(path);
    }
    Ok(written)
}

/// Runs searched for a failing one under each scheduler (`witness_runs`).
pub(crate) const SEARCH: u64 = 500;

/// For `--report` with `--schedulers`: per order-sensitive property of `study`, the first
/// failing run of `seed` under its minimising witness and the first under the uniform
/// scheduler, one after the other, named by their scheduler, so that the page shows how
/// the witness's order fails the property beside how a uniformly random one does.
/// `verify --scheduler ID --save-failing 1` writes the same runs (run k is stream k of
/// the seed whatever the scheduler). A scheduler with no failing run among the first
/// [`SEARCH`] adds none.
pub(crate) fn witness_runs(
    model: &CompiledModel,
    set: &PropertySet,
    run_cfg: &RunConfig,
    seed: u64,
    study: &Study,
) -> Result<Vec<Failing>, ReplayError> {
    let mut out = Vec::new();
    for (row, b) in study.scheduler_rows() {
        if !b.order_sensitive {
            continue;
        }
        let min: Scheduler = b.min.scheduler.parse().map_err(ReplayError::Witness)?;
        for (label, scheduler) in [
            (format!("min witness {min}"), min),
            ("uniform scheduler".to_string(), Scheduler::Uniform),
        ] {
            let cfg = RunConfig {
                scheduler,
                ..run_cfg.clone()
            };
            for k in 0..SEARCH {
                let (csv, culprits) = replay_csv(model, set, &cfg, seed, k)?;
                if culprits.iter().any(|c| c.property == row.property) {
                    out.push(Failing {
                        property: row.property.clone(),
                        run: k,
                        file: format!("{} under the {label}, run {k}", row.property),
                        csv,
                        culprits,
                    });
                    break;
                }
            }
        }
    }
    Ok(out)
}
