//! The museum guide's properties compiled by hindsight-codegen at build time (generated Rust and a postcard table), the replayed run of the museum model, and their byte encodings.
//!
//! # Pipeline
//!
//! `build.rs` compiles `museum.hspec` (the five requirements of
//! `examples/museum-scxml/properties.xml` plus four observers whose verdicts
//! change along the run) with `codegen::compile_spec`, and reads
//! `museum-run0.csv`, a run of the museum model recorded by `hindsight trace`
//! (the command is the file's first line; `scripts/firmware` checks that it
//! still prints the same). From them it generates:
//!
//! - [`museum`]: the monitor as straight-line Rust (`codegen::emit_rust`),
//!   stepped by [`step`]; what `monitor-static` links.
//! - [`TABLE`]: the same program as a postcard table, what `monitor-table`
//!   decodes at run time and what the host interpreter runs.
//! - [`FINAL_TABLE`]: `final.hspec` as a postcard table, properties that
//!   all become final during the run, what `monitor-final` decodes.
//! - [`TRACE`]: the run as a `static` array of points, one per CSV row.
//! - The compiler's figures: [`STATE_BYTES`], [`PROPERTY_STATE_BYTES`],
//!   [`FORMULAS`].
//!
//! [`trace`] is a small byte format for traces, so that firmware can replay a
//! trace it was not compiled for; [`table_bytes`] / [`trace_bytes`] (feature
//! `encode`) give the table and the trace as bytes.
//!
//! The firmware (`monitor-static`, `monitor-table`) and the host check use the
//! same items, so the verdicts they compare come from one source.
//!
//! # Crate features
//!
//! - `encode`: [`table_bytes`] and [`trace_bytes`], for build scripts and host tools (needs `alloc`).
#![no_std]

#[cfg(feature = "encode")]
extern crate alloc;

pub mod trace;

use monitor_core::Value;

include!(concat!(env!("OUT_DIR"), "/museum.rs"));
include!(concat!(env!("OUT_DIR"), "/museum_data.rs"));

/// The postcard table of the compiled spec (`monitor_core::table::Table::from_bytes` reads it).
pub static TABLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/museum.postcard"));

/// The postcard table of `final.hspec`: the same variables, properties whose
/// verdicts all become final during the run (`monitor-final` stops there).
pub static FINAL_TABLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/final.postcard"));

/// One point of a replayed trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Timestamp in the spec's time unit (model steps of 100 ms); non-decreasing.
    pub time: u64,
    /// The value of every variable at this point, in the spec's declaration order.
    pub values: [Value; VARS],
}

/// One step of the generated monitor over `point`; never inlined, so that the
/// image has a symbol to start the panic-path analysis from.
#[inline(never)]
pub fn step(
    monitor: &mut museum::Monitor,
    point: &Point,
) -> Result<[bool; PROPS], museum::StepError> {
    monitor.step(point.time, &input(&point.values))
}

/// [`TABLE`] as an owned vector.
#[cfg(feature = "encode")]
pub fn table_bytes() -> alloc::vec::Vec<u8> {
    TABLE.to_vec()
}

/// [`TRACE`] in the [`trace`] byte format.
#[cfg(feature = "encode")]
pub fn trace_bytes() -> alloc::vec::Vec<u8> {
    // Every point of TRACE has VARS values, so encoding cannot fail.
    trace::encode(TRACE.iter().map(|p| (p.time, &p.values[..])))
        .unwrap_or_else(|e| panic!("encoding the museum trace: {e}"))
}
