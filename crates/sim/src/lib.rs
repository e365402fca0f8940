//! Plain SCXML models and their simulator: SCAN's model reader and the seeded simulator.
//!
//! `hindsight-sim` is the second crate of hindsight's off-line pipeline: it depends on
//! `codegen` (source map, diagnostics, scalar names) and `hindsight-expr` (the expression
//! language, re-exported as [`expr`]), on no other crate of the project. `hindsight-props`
//! reads property files against its models, and `hindsight`'s `robot` lowers robot models
//! to the element trees [`model`] reads; `verify` runs studies of its [`sim::Simulator`].
//!
//! # Public API
//!
//! - [`model`]: [`model::load`] reads a folder of `.scxml` files or a SCAN `model.xml`
//!   into a [`model::ModelSource`] ([`model::ModelSource::from_texts`] from memory);
//!   [`model::xml`] is the project's one XML element tree, [`model::source`] its source
//!   map and diagnostics (codegen's `diag`), [`model::types`] the data types.
//! - [`sim`]: [`sim::CompiledModel::compile`] turns a model into flat tables;
//!   [`sim::Simulator::run`] runs it once from a seeded random stream, reporting every
//!   point to an [`sim::Observer`] ([`sim::TraceRecorder`] keeps the messages).
//!
//! ```
//! use hindsight_sim::model::ModelSource;
//! use hindsight_sim::sim::{CompiledModel, EndReason, RunConfig, Simulator, TraceRecorder};
//! use rand_core::SeedableRng;
//! use rand_xoshiro::Xoshiro256PlusPlus;
//!
//! // A machine that sends `ping` to itself once, then waits for an event nobody sends.
//! let scxml = r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0"
//!     name="Pinger" initial="a" datamodel="ecmascript">
//!   <state id="a">
//!     <onentry><send event="ping" target="Pinger"/></onentry>
//!     <transition event="ping" target="b"/>
//!   </state>
//!   <state id="b"><transition event="never" target="a"/></state>
//! </scxml>"#;
//! let source = ModelSource::from_texts([("pinger.scxml", scxml)]).unwrap();
//! let model = CompiledModel::compile(source).unwrap();
//!
//! let mut sim = Simulator::new(&model);
//! let mut trace = TraceRecorder::new();
//! let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
//! let outcome = sim.run(&mut rng, &RunConfig::default(), &mut trace);
//! assert_eq!(outcome.end, EndReason::Quiescent);
//! assert_eq!(trace.rows.len(), 1);
//! assert_eq!(model.event_name(trace.rows[0].event), "ping");
//!
//! // Errors name the file, line and column.
//! let bad = ModelSource::from_texts([("bad.scxml", "<scxml name=\"M\"><state id=\"a\"></scxml>")]);
//! assert!(bad.unwrap_err().to_string().contains("bad.scxml:1:"));
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod model;
pub mod sim;

// Inside this crate the expression language is `crate::expr`, as it was inside `hindsight`.
pub use hindsight_expr as expr;
