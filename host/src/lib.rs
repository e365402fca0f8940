//! hindsight's command line as a library (`cli`), behind the `hindsight` binary.
//!
//! The pipeline is crates of their own (`crates/`): Cargo keeps each from importing
//! anything above it, and this crate depends on the top three only: `hindsight-verify`,
//! `hindsight-report` and `hindsight-live`. The crates below them are named through
//! their re-exports, listed here, so that `crate::expr::…`, `crate::model::…`,
//! `crate::sim::…`, `crate::props::…`, `crate::robot::…`, `crate::smc::…`,
//! `crate::codegen::…`, `crate::monitor_core::…` (from `hindsight-verify`),
//! `crate::ros2::…` and `crate::iceoryx2::…` (from `hindsight-live`) name their items.

pub mod cli;

pub use hindsight_live as live;
pub use hindsight_live::{iceoryx2, ros2};
pub use hindsight_report as report;
pub use hindsight_verify as verify;
pub use hindsight_verify::{codegen, expr, model, monitor_core, props, robot, sim, smc};
