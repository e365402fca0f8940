//! hindsight's host side: models, simulation, SMC and the CLI.

pub mod cli;
pub mod live;
pub mod report;
pub mod tracefile;

// The first stages of the pipeline are crates of their own (`crates/expr`, `crates/smc`,
// `crates/sim`, `crates/props`); Cargo keeps them from importing anything of this crate.
// Re-exported so that `crate::expr::…`, `crate::model::…`, `crate::sim::…`,
// `crate::props::…` and `crate::smc::…` name the same items as before the split.
pub use hindsight_expr as expr;
pub use hindsight_props as props;
pub use hindsight_robot as robot;
pub use hindsight_sim::{model, sim};
pub use hindsight_smc as smc;
pub use hindsight_verify as verify;
