//! hindsight's host side: models, simulation, SMC and the CLI.

pub mod cli;
pub mod live;
pub mod model;
pub mod props;
pub mod report;
pub mod robot;
pub mod sim;
pub mod tracefile;
pub mod verify;

// The leaves of the pipeline are crates of their own (`crates/expr`, `crates/smc`); they
// import nothing of this crate. Re-exported so that `crate::expr::…` and `crate::smc::…`
// name the same items as before the split.
pub use hindsight_expr as expr;
pub use hindsight_smc as smc;
