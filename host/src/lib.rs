//! hindsight's host side: models, simulation, SMC and the CLI.

pub mod cli;
pub mod tracefile;
pub mod verify;
pub mod props;
pub mod smc;
