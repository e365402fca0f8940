//! hindsight's host side: models, simulation, SMC and the CLI.

pub mod cli;
pub mod expr;
pub mod live;
pub mod model;
pub mod props;
pub mod report;
pub mod robot;
pub mod sim;
pub mod smc;
pub mod tracefile;
pub mod verify;
