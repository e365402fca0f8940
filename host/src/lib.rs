//! hindsight's command line as a library (`cli`), behind the `hindsight` binary.
//!
//! The pipeline is crates of their own (`crates/`): Cargo keeps each from importing
//! anything above it, and this crate depends on the top three only: `hindsight-verify`,
//! `hindsight-report` and `hindsight-live`, whose library functions do the work (`cli/`
//! parses arguments, calls them and prints). The items of the crates below that a command
//! still names (an option's type, a diagnostic, a progress report) are reached through
//! `hindsight-verify`'s re-exports, listed here: `crate::sim::…`, `crate::props::…`,
//! `crate::robot::…`, `crate::smc::…` and `crate::codegen::…`. `expr`, `model`,
//! `monitor_core`, `ros2` and `iceoryx2` are not re-exported: no command names them (the
//! tests reach `expr` and `model` as `hindsight::verify::expr` and
//! `hindsight::verify::model`, the others as dev-dependencies).

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod cli;

pub use hindsight_live as live;
pub use hindsight_report as report;
pub use hindsight_verify as verify;
pub use hindsight_verify::{codegen, props, robot, sim, smc};
