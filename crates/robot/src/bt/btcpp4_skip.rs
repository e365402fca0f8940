//! Where BehaviorTree.CPP 4's SKIPPED status can arise in a tree, where the lowering
//! (`--bt btcpp`) does not model it yet, and the parts of the machines of the nodes that
//! keep their own status when they pass a SKIPPED on (Switch, Precondition).
//!
//! SKIPPED travels as status 4 (the node IDLE afterwards) or 5 (the node RUNNING: it set
//! itself RUNNING before every child was skipped), `control.rs`. It is made by
//! `_skipIf` / `_while` (`btcpp4_conds.rs`, 4.10 `TreeNode::checkPreConditions`) and
//! RunOnce with `then_skip` (`btcpp4.rs`), and passed on or summed up by every parent
//! the lowering handles: Sequence, Fallback, SequenceWithMemory, AsyncSequence,
//! AsyncFallback, ReactiveSequence, ReactiveFallback, Parallel, ParallelAll,
//! IfThenElse, WhileDoElse, Switch2-6, TryCatch, Inverter, ForceSuccess, ForceFailure,
//! Repeat, RetryUntilSuccessful, KeepRunningUntilFailure, RunOnce, Timeout, Delay,
//! Precondition, SkipUnlessUpdated, WaitValueUpdate, the Loop nodes and the root
//! (SkipUnlessUpdated and a Loop with `if_empty="SKIPPED"` make it too,
//! `btcpp4_blackboard.rs`, `btcpp4_loop.rs`). A sequence (or TryCatch) BT.CPP may tick
//! again without resetting it keeps its count of skipped children ([`stale`]): its
//! parent halts it at every reset (`control.rs`, `Ctx::resets`). The one parent that
//! refuses a child that may answer SKIPPED, at the child, is a BlackboardCheck
//! (BT.CPP 3's, [`BB_CHECK`]).

use super::control::{Ctx, IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING};
use super::tree::{Btcpp4, Control, Kind, PortValue, ScriptNode, Tree, UpdatedNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

/// Whether a node that does not set its own status before ticking its child (Switch,
/// Precondition) answered RUNNING last (its status as BT.CPP keeps it): then a SKIPPED
/// it passes on leaves it RUNNING (5), else IDLE (4).
pub(super) const SELF_RUNNING: &str = "self_running";

/// SKIPPED answered by a node that keeps its own status (see [`SELF_RUNNING`]).
pub(super) fn skipped_keeping_status(ctx: &Ctx) -> Element {
    ctx.respond_expr(&format!("{SELF_RUNNING} ? {SKIPPED_RUNNING} : {SKIPPED}"))
}

/// Precondition's `else` answer (`PreconditionNode::tick`, 4.10
/// `decorators/script_precondition.h`, `return else_return`): stored as the node's
/// status by `executeTick` unless it is SKIPPED, which leaves the status as it was.
pub(super) fn else_answer(ctx: &Ctx, otherwise: u8) -> Vec<Element> {
    if otherwise == SKIPPED {
        return vec![skipped_keeping_status(ctx)];
    }
    let running = if otherwise == RUNNING {
        "true"
    } else {
        "false"
    };
    vec![ctx.b.assign(SELF_RUNNING, running), ctx.respond(otherwise)]
}

/// Precondition's child answering SKIPPED (`PreconditionNode::tick`): not a finished
/// status (`isStatusCompleted`), so the child is not reset and `_children_running`
/// stays set (the next tick ticks the child without the `if` script); the SKIPPED is
/// the answer, the node's own status kept (it never sets it itself).
pub(super) fn precondition_child_skipped(ctx: &Ctx) -> Element {
    let mut body: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
    body.push(skipped_keeping_status(ctx));
    ctx.b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("wait_for_tick"),
        body,
    )
}

/// Precondition's `halting_child` state: the child halted (only while RUNNING), the
/// node's own status reset (`haltNode`), `_children_running` kept (the node has no
/// `halt` of its own: `DecoratorNode::halt`).
pub(super) fn precondition_halting(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    b.state_entry("halting_child", ctx.halt_child_body(0))
        .with_child(b.tr(
            Some(&ctx.child_halt_resp(0)),
            None,
            Some("wait_for_tick"),
            vec![b.assign(SELF_RUNNING, "false"), ctx.respond_halted()],
        ))
}

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
                    Btcpp4::WhileDoElse
                    | Btcpp4::Switch(_)
                    | Btcpp4::Timeout
                    | Btcpp4::Delay
                    | Btcpp4::SubTree,
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

/// The errors for SKIPPED reaching a parent the lowering does not model it for, each at
/// the child that may answer SKIPPED: a BlackboardCheck. BlackboardCheckInt/Double/String
/// are BT.CPP 3's nodes: BT.CPP 4's factory does not register them (4.8.2 refuses the
/// tree at load, "Node not recognized"), and BT.CPP 3 has no SKIPPED status, so no
/// BehaviorTree.CPP runs such a tree.
pub(super) fn refusals(sm: &SourceMap, tree: &Tree) -> Vec<Diagnostic> {
    let skips = may_skip(tree);
    let mut out = Vec::new();
    for (i, n) in tree.nodes.iter().enumerate() {
        let Some(p) = n.parent else { continue };
        // A sequence there with a child that may answer SKIPPED may answer it too: BT.CPP
        // 3's BlackboardCheck does not reset its child, so its count of skipped
        // children carries over a finished tick.
        let sequence = matches!(
            n.kind,
            Kind::Control(
                Control::Sequence
                    | Control::Fallback
                    | Control::SequenceWithMemory
                    | Control::Btcpp4(
                        Btcpp4::AsyncSequence | Btcpp4::AsyncFallback | Btcpp4::TryCatch
                    ),
            )
        ) && n.children.iter().any(|&c| skips[c]);
        if (skips[i] || sequence)
            && matches!(
                tree.nodes[p].kind,
                Kind::Control(Control::BlackboardCheck(_))
            )
        {
            out.push(sm.diag(
                n.span,
                format!("this node may answer SKIPPED (BehaviorTree.CPP 4): {BB_CHECK}"),
            ));
        }
    }
    out
}

/// Why a BT.CPP 4 construction under a BlackboardCheck is refused.
pub(super) const BB_CHECK: &str = "its parent, a BlackboardCheck, is a BehaviorTree.CPP 3 node (BehaviorTree.CPP 4 does not register it and refuses the tree when it loads it, \"Node not recognized\"), and BehaviorTree.CPP 3 has neither SKIPPED, pre/post conditions nor Loop nodes: no BehaviorTree.CPP runs this tree";

/// Whether node `i` is the child of a BlackboardCheck.
pub(super) fn under_check(tree: &Tree, i: usize) -> bool {
    tree.nodes[i].parent.is_some_and(|p| {
        matches!(
            tree.nodes[p].kind,
            Kind::Control(Control::BlackboardCheck(_))
        )
    })
}

/// Whether BT.CPP 4 may tick node `i` again in a finished status, without its parent
/// resetting it: the condition of a two-child IfThenElse (4.10 `IfThenElseNode::tick`
/// returns the condition's FAILURE without `resetChildren`) or of a WhileDoElse
/// (`WhileDoElseNode::tick` ticks it at every tick and resets the children only when a
/// branch finishes). Such a node keeps its finished status: `TreeNode::checkPreConditions`
/// then checks none of `_failureIf`, `_successIf`, `_skipIf`, `_while` (only while IDLE,
/// `_while` also while RUNNING); `SequenceNode::tick`, `FallbackNode::tick`,
/// `SequenceWithMemory::tick`, `TryCatchNode::tick` keep `skipped_count_` (reset only
/// when `!isStatusActive(status())`); `LoopNode<T>::tick` goes on with its queue (a copy
/// is taken only when IDLE); a stateful leaf answers its status again without running
/// (`StatefulActionNode::tick`).
pub(super) fn stale(tree: &Tree, i: usize) -> bool {
    let Some(p) = tree.nodes[i].parent else {
        return false;
    };
    // A SubTree's body is reset by the SubTree node once it finished
    // (`btcpp4_subtree.rs`, `body_reset`).
    if super::btcpp4_subtree::body_reset(tree, i) {
        return false;
    }
    let p = &tree.nodes[p];
    let first = p.children.first() == Some(&i);
    match p.kind {
        Kind::Control(Control::IfThenElse) => first && p.children.len() == 2,
        Kind::Control(Control::Btcpp4(Btcpp4::WhileDoElse)) => first,
        _ => false,
    }
}

/// Whether node `i`'s own machine needs to know when its parent resets it, in a place
/// where BT.CPP may tick it again without a reset ([`stale`]): a sequence (Sequence,
/// Fallback, SequenceWithMemory, AsyncSequence, AsyncFallback, TryCatch) with a child
/// that may answer SKIPPED (its `skipped_count_`), or a Loop node (its queue).
pub(super) fn resets_matter(tree: &Tree, skips: &[bool], i: usize) -> bool {
    if !stale(tree, i) {
        return false;
    }
    let n = &tree.nodes[i];
    match n.kind {
        Kind::Control(
            Control::Sequence
            | Control::Fallback
            | Control::SequenceWithMemory
            | Control::Btcpp4(Btcpp4::AsyncSequence | Btcpp4::AsyncFallback | Btcpp4::TryCatch),
        ) => n.children.iter().any(|&c| skips[c]),
        Kind::Control(Control::Btcpp4(Btcpp4::Loop(_))) => true,
        _ => false,
    }
}
