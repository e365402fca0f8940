//! hindsight's specification language: Past-MTL formulas over typed atoms, compiled to monitors.
//!
//! # Pipeline
//!
//! What goes in: a `.hspec` text (time unit, event and state variables, named
//! Past-MTL properties; format in [`parse`]), or the same as parts with
//! positions in another file ([`SpecInput`], for formulas read from XML).
//!
//! The stages, each a type state of [`Spec`] and each `-> Result<Next, Diagnostics>`:
//!
//! 1. **Parse** ([`Spec::parse`], [`Spec::from_input`]) -> `Spec<`[`Parsed`]`>`:
//!    nom parsers build a syntax tree with a [`Span`] on every node; errors are
//!    collected (one per statement), and chains of binary operators that SCAN
//!    would group differently get a warning.
//! 2. **Check** ([`Spec::check`]) -> `Spec<`[`Checked`]`>`: names resolved to
//!    indices, atoms typed (int/float mixes get explicit conversions), bounds
//!    converted exactly to ticks. The result, [`ast::CheckedSpec`], is public:
//!    it is what a reference evaluator works on.
//! 3. **Size** ([`Spec::size`]) -> `Spec<`[`Measured`]`>`: every property
//!    lowered to a sequential network (`P`/`H` to `S`, identical subformulas
//!    shared), atoms deduplicated and compiled to stack code, state laid out
//!    exactly as [`monitor_core::layout`] requires and checked against [`Limits`].
//! 4. **Compile** ([`Spec::compile`]) -> [`Compiled`]: an owned
//!    [`monitor_core::Program`], validated by [`monitor_core::Monitor::try_new`].
//!
//! What comes out: [`Compiled::program`] to run in `monitor_core`,
//! [`Compiled::to_table_bytes`] for firmware (`monitor_core::table::Table`),
//! the state size per property and in total, the variables for emitters and
//! hosts, and [`Compiled::ir`], a printable form.
//!
//! # Which entry point
//!
//! - A `.hspec` file with default limits: [`compile_spec`].
//! - Formulas and declarations from XML: [`compile_input`] (or
//!   [`Spec::from_input`] for custom limits).
//! - Custom [`Limits`], or the checked AST: walk the stages of [`Spec`] yourself.
//!
//! Every failure is a [`Diagnostics`] value that prints as
//! `file:line:col: message` (`warning: ` before the message of a warning) with the
//! source line and a caret line, the rendering of every reader of the project
//! ([`diag`]); no input string makes any stage panic.
//!
//! # Crate features
//!
//! None: the crate always builds with `std`.

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod ast;
pub mod bounds;
mod check;
mod compile;
pub mod csv;
pub mod diag;
pub mod duration;
pub mod emit_rust;
mod lower;
pub mod parse;
pub mod print;
pub mod scalar;
mod spec;
mod syntax;

pub use compile::{Compiled, PropertyInfo};
pub use diag::{
    Diagnostic, Diagnostics, FileId, LineIndex, Location, PositionRun, Severity, Snippet, Source,
    SourceMap, Span,
};
pub use lower::Limits;
pub use spec::{
    compile_input, compile_spec, Checked, DeclInput, FormulaInput, Measured, Origin, Parsed, Spec,
    SpecInput,
};

#[cfg(test)]
mod tests;
