//! Statistical model checking glue: properties observed on simulated runs, judged by monitors.
//!
//! The off-line pipeline as a library: [`pipeline`] runs a whole `verify` in its order
//! (the study, its failing runs, the bounds over schedulers, `merge`), from parts that
//! are modules of their own: [`load`] reads a model (plain SCXML or a robot
//! model) and its property file, [`observe`] judges a simulated run with the compiled
//! monitors, [`options`] holds a study's settings (set once, turned into the
//! simulator's and the runner's configurations), [`study`] runs studies under stopping
//! rules (sequential, or one shard of a fixed-size study: every study goes through its
//! `Runner`), [`fixed`] identifies a fixed-size study across its shards, [`schedulers`]
//! and [`sched_fixed`] bound the probabilities over schedulers, [`sweep`] sweeps a
//! guarantee's time bounds, [`record`] writes a run as CSV, [`replay`] replays the runs a
//! study kept (and the witnesses' failing runs) as such CSV, and [`result`] is a study's
//! result as `verify --json` prints it, assembled there; [`tracefile`] reads such a CSV
//! (or any trace) back as points for `replay`, and [`trace_judge`] judges them. [`spec`]
//! compiles properties without a model (`compile`, `replay`, `monitor --ros2`) and
//! [`convert`] writes a robot model as plain SCXML. Nothing here prints: errors are values
//! ([`load::LoadError`] carries the files' diagnostics), warnings come back with what was
//! loaded ([`load::Loaded::warnings`]), files written come back as their paths and
//! progress goes to a callback.
//!
//! # Crate
//!
//! `hindsight-verify` depends on `monitor-core`, `codegen` and the crates below it in the
//! pipeline, re-exported here under the paths its modules name them by: [`expr`],
//! [`model`], [`sim`], [`props`], [`robot`] and [`smc`]; on no other crate of the project.
//! The types a study's settings are made of come from those crates and are re-exported
//! where this crate's API takes them ([`options`], [`load`], [`study`], [`replay`],
//! [`spec`]), so that `hindsight`'s command line names this crate's items (and
//! [`codegen`]'s, the language of every diagnostic) and no crate below it; the whole
//! crates are re-exported for the tests.
//!
//! One run of the museum example, judged by its five requirements:
//!
//! ```
//! use hindsight_verify::load::{load, LoadOptions};
//! use hindsight_verify::sim::RunConfig;
//! use hindsight_verify::smc::{stream, RunEnd};
//! use hindsight_verify::study::Runner;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/museum-scxml");
//! let loaded = load(&LoadOptions { model: dir.into(), ..LoadOptions::default() }).unwrap();
//! let run_cfg = RunConfig { max_time: 1000, events: loaded.events, ..RunConfig::default() };
//! let runner = Runner::new(&loaded.model, &loaded.set, &run_cfg);
//! let run = runner.run(0, &mut stream(1, 0));
//! assert_eq!(run.verdicts.len(), loaded.set.guarantee_names().len());
//! assert!(!matches!(run.end, RunEnd::Failed));
//! runner.finish().unwrap();
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod convert;
pub mod fixed;
pub mod load;
pub mod observe;
pub mod options;
pub mod pipeline;
pub mod record;
pub mod replay;
pub mod result;
pub mod sched_fixed;
pub mod schedulers;
pub mod spec;
mod split;
pub mod study;
pub mod sweep;
pub mod trace_judge;
pub mod tracefile;

// The crates below this one, under the paths its modules name them by.
pub use hindsight_expr as expr;
pub use hindsight_props as props;
pub use hindsight_robot as robot;
pub use hindsight_sim::{model, sim};
pub use hindsight_smc as smc;
// The compiler and the monitors' runtime, for the command line (`compile`, `replay`),
// which depends on this crate instead of on them.
pub use codegen;
pub use monitor_core;
