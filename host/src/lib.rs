//! hindsight's host side: models, simulation, SMC and the CLI.

pub mod expr;
pub mod model;
pub mod sim;
