//! BehaviorTree.CPP semantics for tests: an independent reader and reference executor
//! ([`oracle`]), random trees and scripts ([`gen`]), and the lowering harness's model
//! writer ([`model`]).

pub mod gen;
pub mod model;
pub mod oracle;
pub mod tree;
