//! Shared helpers for hindsight's workspace-level tests.
//!
//! - [`oracle`]: the reference Past-MTL evaluator, straight from the semantics.
//! - [`gen`]: seeded random formulas and traces for differential tests.
//! - [`trace`]: the corpus's declaration and trace-point syntax, and event/state valuation.
//! - [`checked`]: codegen's checked AST as an oracle formula, with a tree-walking atom evaluator.
//! - [`bt`]: BehaviorTree.CPP's semantics: an independent tree reader and reference executor.
//! - [`engines`]: compiled specs run through the interpreter and postcard tables.

pub mod bt;
pub mod checked;
pub mod engines;
pub mod gen;
pub mod oracle;
pub mod trace;
