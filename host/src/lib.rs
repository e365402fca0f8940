//! hindsight's host side: models, simulation, SMC and the CLI.
