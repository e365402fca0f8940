//! Where BehaviorTree.CPP 4's SKIPPED status can arise in a tree, and where the lowering
//! (`--bt btcpp`) does not model it yet.
//!
//! SKIPPED travels as status 4 (the node IDLE afterwards) or 5 (the node RUNNING: it set
//! itself RUNNING before every child was skipped), `control.rs`. It is made by
//! `_skipIf` / `_while` (`btcpp4_conds.rs`, 4.10 `TreeNode::checkPreConditions`) and
//! RunOnce with `then_skip` (`btcpp4.rs`), and passed on or summed up by every parent
//! the lowering handles: Sequence, Fallback, SequenceWithMemory, AsyncSequence,
//! AsyncFallback, ReactiveSequence, ReactiveFallback, Parallel, ParallelAll,
//! IfThenElse, Inverter, ForceSuccess, ForceFailure, Repeat, RetryUntilSuccessful,
//! KeepRunningUntilFailure, RunOnce, SkipUnlessUpdated, WaitValueUpdate, the Loop nodes
//! and the root (SkipUnlessUpdated and a Loop with `if_empty="SKIPPED"` make it too,
//! `btcpp4_blackboard.rs`, `btcpp4_loop.rs`). The parents it does not handle yet refuse
//! a child that may answer SKIPPED, at the child.

use super::tree::{Btcpp4, Control, Kind, PortValue, ScriptNode, Tree, UpdatedNode};
use crate::model::source::{Diagnostic, SourceMap};

/// Whether node `i` may answer SKIPPED, for every node (children after their parent in
/// pre-order, so one pass from the end sees every child first).
pub(super) fn may_skip(tree: &Tree) -> Vec<bool> {
    let mut out = vec![false; tree.nodes.len()];
    for (i, n) in tree.nodes.iter().enumerate().rev() {
        let own = n
            .conds
            .iter()
            .any(|c| c.attr == "_skipIf" || c.attr == "_while");
        let kids: Vec<bool> = n.children.iter().map(|&c| out[c]).collect();
        let all = !kids.is_empty() && kids.iter().all(|k| *k);
        let any = kids.iter().any(|k| *k);
        let from_kids = match n.kind {
            Kind::Plugin(_) => false,
            Kind::Control(c) => match c {
                // Every child skipped: SKIPPED.
                Control::Sequence
                | Control::Fallback
                | Control::SequenceWithMemory
                | Control::ReactiveSequence
                | Control::ReactiveFallback
                | Control::Parallel
                | Control::Btcpp4(
                    Btcpp4::AsyncSequence | Btcpp4::AsyncFallback | Btcpp4::ParallelAll,
                ) => all,
                // The try block all skipped.
                Control::Btcpp4(Btcpp4::TryCatch) => {
                    kids.len() >= 2 && kids[..kids.len() - 1].iter().all(|k| *k)
                }
                // A skipped child (or branch) passes on.
                Control::IfThenElse
                | Control::Inverter
                | Control::ForceSuccess
                | Control::ForceFailure
                | Control::Repeat
                | Control::RetryUntilSuccessful
                | Control::BlackboardCheck(_)
                | Control::Btcpp4(
                    Btcpp4::WhileDoElse | Btcpp4::Switch(_) | Btcpp4::Timeout | Btcpp4::Delay,
                ) => any,
                // `else="SKIPPED"`, or a skipped child passed on.
                Control::Btcpp4(Btcpp4::Script(ScriptNode::Precondition)) => {
                    any || n.port("else").is_some_and(
                        |p| matches!(&p.value, PortValue::Literal(v) if v.trim() == "SKIPPED"),
                    )
                }
                // `then_skip` (true unless written false).
                Control::Btcpp4(Btcpp4::RunOnce) => {
                    any || n.port("then_skip").is_none_or(|p| match &p.value {
                        PortValue::Literal(v) => {
                            !matches!(v.trim(), "false" | "False" | "FALSE" | "0")
                        }
                        PortValue::Blackboard(_) => true,
                    })
                }
                // A skipped child answers RUNNING.
                Control::Btcpp4(Btcpp4::KeepRunningUntilFailure) => false,
                // Not updated: SKIPPED; WaitValueUpdate passes a skipped child on.
                Control::Btcpp4(Btcpp4::Updated(UpdatedNode::Skip)) => true,
                Control::Btcpp4(Btcpp4::Updated(UpdatedNode::Wait)) => any,
                // `if_empty="SKIPPED"` (a skipped child answers RUNNING).
                Control::Btcpp4(Btcpp4::Loop(_)) => n.port("if_empty").is_some_and(
                    |p| matches!(&p.value, PortValue::Literal(v) if v.trim() == "SKIPPED"),
                ),
                Control::AlwaysSuccess
                | Control::AlwaysFailure
                | Control::SetBlackboard
                | Control::Btcpp4(
                    Btcpp4::Sleep
                    | Btcpp4::Unset
                    | Btcpp4::Updated(UpdatedNode::Was)
                    | Btcpp4::Script(ScriptNode::Script | ScriptNode::Condition),
                ) => false,
            },
        };
        out[i] = own || from_kids;
    }
    out
}

/// The errors for SKIPPED reaching a parent the lowering does not model it for (under
/// BT.CPP's rules), each at the child that may answer SKIPPED.
pub(super) fn refusals(sm: &SourceMap, tree: &Tree) -> Vec<Diagnostic> {
    let skips = may_skip(tree);
    let mut out = Vec::new();
    for (i, n) in tree.nodes.iter().enumerate() {
        let Some(p) = n.parent else { continue };
        if !skips[i] {
            continue;
        }
        let parent = &tree.nodes[p];
        let why = match parent.kind {
            Kind::Control(Control::Btcpp4(
                k @ (Btcpp4::WhileDoElse
                | Btcpp4::Switch(_)
                | Btcpp4::TryCatch
                | Btcpp4::Timeout
                | Btcpp4::Delay
                | Btcpp4::Script(ScriptNode::Precondition)),
            )) => format!("SKIPPED reaching a {} is not modelled yet", super::btcpp4::node_name(k)),
            Kind::Control(Control::BlackboardCheck(_)) => {
                "SKIPPED reaching a BlackboardCheck is not modelled yet".to_string()
            }
            Kind::Control(
                Control::Sequence
                | Control::Fallback
                | Control::SequenceWithMemory
                | Control::Btcpp4(Btcpp4::AsyncSequence | Btcpp4::AsyncFallback),
            ) if stale(tree, p) => {
                "SKIPPED reaching a sequence that BehaviorTree.CPP may tick again without resetting it (the condition of a two-child IfThenElse or of a WhileDoElse, the child of a BlackboardCheck), whose count of skipped children then carries over, is not modelled yet".to_string()
            }
            _ => continue,
        };
        out.push(sm.diag(
            n.span,
            format!("this node may answer SKIPPED (BehaviorTree.CPP 4): {why}"),
        ));
    }
    out
}

/// Whether BT.CPP may tick node `i` again in a finished status, without its parent
/// resetting it: the condition of a two-child IfThenElse (`IfThenElseNode::tick` returns
/// the condition's FAILURE without `resetChildren`) or of a WhileDoElse (reset only when
/// a branch finishes), the child of a BlackboardCheck.
fn stale(tree: &Tree, i: usize) -> bool {
    let Some(p) = tree.nodes[i].parent else {
        return false;
    };
    let p = &tree.nodes[p];
    let first = p.children.first() == Some(&i);
    match p.kind {
        Kind::Control(Control::IfThenElse) => first && p.children.len() == 2,
        Kind::Control(Control::Btcpp4(Btcpp4::WhileDoElse)) => first,
        Kind::Control(Control::BlackboardCheck(_)) => true,
        _ => false,
    }
}
