//! hindsight's command line as a library (`cli`), behind the `hindsight` binary.
//!
//! The pipeline is crates of their own (`crates/`): Cargo keeps each from importing
//! anything above it. Re-exported so that `crate::expr::…`, `crate::model::…`,
//! `crate::sim::…`, `crate::props::…`, `crate::robot::…`, `crate::smc::…`,
//! `crate::verify::…`, `crate::report::…` and `crate::live::…` name their items.

pub mod cli;

pub use hindsight_expr as expr;
pub use hindsight_live as live;
pub use hindsight_props as props;
pub use hindsight_report as report;
pub use hindsight_robot as robot;
pub use hindsight_sim::{model, sim};
pub use hindsight_smc as smc;
pub use hindsight_verify as verify;
