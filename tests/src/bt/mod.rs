//! BehaviorTree.CPP semantics for tests: an independent reader and reference executor
//! ([`oracle`]), random trees and scripts ([`gen`]), the lowering harness's model writer
//! ([`model`]), and the real library run through its Python bindings ([`real`]).

pub mod gen;
pub mod model;
pub mod oracle;
pub mod real;
pub mod script;
pub mod subtree_cond;
pub mod tree;
