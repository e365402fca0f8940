//! BehaviorTree.CPP's SubTree node under `--bt btcpp`: a `<SubTree>` with pre/post
//! conditions (BT.CPP 4), and the reset of an inlined body once it finished.
//!
//! A SubTree is inlined, except one that carries `_failureIf` ... `_onHalted`: that one
//! is a node of its own ([`super::tree`], `subtree_node`), a decorator over the inlined
//! body whose conditions' machine (`btcpp4_conds.rs`) wraps it as it wraps any node.
//! The rules, read in BT.CPP 4.10 and measured in 4.8.2 (README, "Scripts under
//! `--bt btcpp`"):
//! - the conditions run in the caller's blackboard (`xml_parsing.cpp`,
//!   `XMLParser::PImpl::createNodeFromXML` creates the SubTree node with the blackboard
//!   of the tree it is written in, and takes its `_skipIf` ... attributes as conditions,
//!   never as ports `recursivelyCreateSubtree` remaps), so their names are the caller's;
//! - `SubTreeNode::tick` (`decorators/subtree_node.cpp`) sets the node RUNNING when it
//!   is IDLE, ticks the body, resets the body once it finished and passes its answer on:
//!   the one-child decorator with every status mapped to itself. A body answering
//!   SKIPPED leaves the node RUNNING, so SKIPPED travels as 5: the parent halts the
//!   node at its reset (`DecoratorNode::halt`, then the node's `_onHalted`), and until
//!   then the node's `_failureIf`, `_successIf`, `_skipIf` are not checked
//!   (`TreeNode::checkPreConditions`).

use super::control::{Ctx, FAILURE, RUNNING, SUCCESS};
use super::tree::Tree;
use crate::model::xml::Element;

/// The SubTree node's machine: the body's SUCCESS, FAILURE, RUNNING answered as they
/// are, its SKIPPED answered 5 (the node RUNNING, `SubTreeNode::tick`).
pub(super) fn machine(ctx: &Ctx) -> Element {
    super::decorators::decorator(ctx, [SUCCESS, FAILURE, RUNNING])
}

/// Whether node `i` is the root of a SubTree's body, which BT.CPP resets once it
/// finished: 4.10 `SubTreeNode::tick` calls `resetChild` when the body's answer is
/// completed (3.8 `SubtreeNode::tick` when it is not RUNNING), so where BT.CPP ticks the
/// SubTree again without resetting it (the condition of a two-child IfThenElse or of a
/// WhileDoElse, `btcpp4_skip.rs`, `stale`) the body starts afresh, where an inlined
/// body would keep its finished status: a leaf runs again, its pre-conditions are
/// checked again (4.8.2 measured, `tests/bt/btcpp4/subtree.toml`).
pub(super) fn body_reset(tree: &Tree, i: usize) -> bool {
    tree.nodes[i].subtree_body
}
