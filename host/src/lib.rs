//! hindsight's command line as a library (`cli`), behind the `hindsight` binary.
//!
//! The pipeline is crates of their own (`crates/`): Cargo keeps each from importing
//! anything above it, and this crate depends on the top three only: `hindsight-verify`,
//! `hindsight-report` and `hindsight-live`, whose library functions do the work (`cli/`
//! parses arguments, calls them and prints). `cli/` names items of those three crates
//! only: the types a study's settings are made of (a scheduler, the event semantics, a
//! stopping rule) are part of `hindsight-verify`'s API (`verify::options`,
//! `verify::load`, `verify::study`, `verify::replay`, `verify::spec`), and `codegen`,
//! the language every layer's diagnostics and durations are written in, comes through
//! it as `crate::codegen`. The tests reach the crates below as
//! `hindsight::verify::sim`, `hindsight::verify::robot`, ... (or as dev-dependencies).

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod cli;

pub use hindsight_live as live;
pub use hindsight_report as report;
pub use hindsight_verify as verify;
pub use hindsight_verify::codegen;
