//! BehaviorTree.CPP 4's pre/post conditions (`_failureIf`, `_successIf`, `_skipIf`,
//! `_while`, `_onSuccess`, `_onFailure`, `_post`, `_onHalted`) on any node, under
//! [`super::BtSemantics::Btcpp`].
//!
//! A node with conditions gets a second machine between it and its parent,
//! `<node machine>_conditions`: the parent ticks and halts it with `bt_<id>_cond_tick` /
//! `bt_<id>_cond_halt` (answered `bt_<id>_cond_response` / `..._halt_response`), and it
//! ticks and halts the node with the node's own `bt_<id>_*` events, so a leaf's ticks
//! and halts are the same messages as without conditions. Its scripts run in the
//! blackboard machine (`btcpp4_script.rs`). The rules, BT.CPP 4.10 `src/tree_node.cpp`:
//! - `TreeNode::executeTick`: `checkPreConditions` first; if one decides the answer, the
//!   node's `tick` is not called; `checkPostConditions` for a finished answer (SUCCESS or
//!   FAILURE, whoever decided it).
//! - `TreeNode::checkPreConditions`: only while the node is IDLE, `_failureIf` (true:
//!   FAILURE), `_successIf` (true: SUCCESS), `_skipIf` (true: SKIPPED), `_while` (false:
//!   SKIPPED), the node IDLE still (status 4, `control.rs`); while it is RUNNING only
//!   `_while`, whose false halts the node (`haltNode`) and answers SKIPPED. A SKIPPED
//!   the node itself answers is passed on (4 or 5), and 5 leaves the node RUNNING.
//! - `TreeNode::checkPostConditions`: `_onSuccess` or `_onFailure`, then `_post`.
//! - `TreeNode::haltNode`: the node's `halt`, then `_onHalted` (a parent halts a child
//!   only while it is RUNNING, `ControlNode::haltChild`).
//!
//! A node is IDLE at a tick unless it answered RUNNING last: every parent resets a child
//! that finished before ticking it again, except the condition of a two-child
//! IfThenElse or of a WhileDoElse (`btcpp4_skip.rs`, `stale`), which BT.CPP may tick
//! again in its finished status: there the wrapper keeps that status (`node_done`),
//! the parent halts it at every reset (`control.rs`, `Ctx::resets`), and a tick in it
//! checks no pre-condition and, for a stateful leaf, answers the status again without
//! ticking the leaf, the post-conditions run as for any finished answer. Conditions on
//! the child of a BlackboardCheck (BT.CPP 3's node, refused by BT.CPP 4) are refused.
//! The root's wrapper talks to the root machine as to a parent.

use super::blackboard::{Blackboard, MACHINE};
use super::btcpp4_script::compile;
use super::build::B;
use super::control::{Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING, SUCCESS};
use super::tree::{Tree, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

/// The wrapper machine of node `n`.
pub(super) fn machine_name(n: &TreeNode) -> String {
    format!("{}_conditions", n.machine)
}

/// The stem of the events between node `n`'s parent and its wrapper.
pub(super) fn stem(n: &TreeNode) -> String {
    format!("{}_cond", n.id)
}

/// Whether node `i` has conditions the lowering wraps it for (under BT.CPP's rules).
pub(super) fn wrapped(tree: &Tree, i: usize) -> bool {
    !tree.nodes[i].conds.is_empty()
}

/// What refuses node `i`'s conditions: under AS2FM's rules (`btcpp` false) all of them;
/// under BT.CPP's the ones not modelled yet (see the module comment).
pub(super) fn refusals(sm: &SourceMap, tree: &Tree, i: usize, btcpp: bool) -> Vec<Diagnostic> {
    let n = &tree.nodes[i];
    let mut out = Vec::new();
    for c in &n.conds {
        let why = if !btcpp {
            "AS2FM has no model of BehaviorTree.CPP's script language, so the default semantics (`--bt as2fm`) cannot lower it: use `--bt btcpp` (BehaviorTree.CPP 4's rules)"
        } else {
            // The root is ticked by the root machine as by a parent (`Tree::tickRoot`
            // resets a finished root); a node BT.CPP may tick again without a reset
            // keeps its status in the wrapper. Only a BlackboardCheck's child is left.
            if !super::btcpp4_skip::under_check(tree, i) {
                continue;
            }
            super::btcpp4_skip::BB_CHECK
        };
        out.push(sm.diag(
            c.name_span,
            format!(
                "`{}` (a BehaviorTree.CPP 4 pre/post condition) is not supported: {why}",
                c.attr
            ),
        ));
    }
    out
}

fn pre_event(id: u32) -> String {
    format!("bt_script_{id}_pre")
}
fn while_event(id: u32) -> String {
    format!("bt_script_{id}_while")
}
fn post_event(id: u32, s: u8) -> String {
    format!("bt_script_{id}_post_{s}")
}
fn halted_event(id: u32) -> String {
    format!("bt_script_{id}_halted")
}
fn done(ev: &str) -> String {
    format!("{ev}_done")
}

/// Compiles the scripts `attrs` of node `n` in order into one blackboard transition on
/// `event` that answers `done(event)` (conditions stop the chain: `stop(attr)` gives the
/// status a true condition answers, 0 when none holds). `None` when there are none or
/// after an error (`ok` false).
#[allow(clippy::too_many_arguments)]
fn chain(
    sm: &SourceMap,
    n: &TreeNode,
    b: B,
    wrapper: &str,
    event: &str,
    attrs: &[(&str, Option<u8>)],
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
    ok: &mut bool,
) -> bool {
    let present: Vec<(&super::tree::Cond, Option<u8>)> = attrs
        .iter()
        .filter_map(|(a, stop)| n.conds.iter().find(|c| c.attr == *a).map(|c| (c, *stop)))
        .collect();
    if present.is_empty() {
        return false;
    }
    let reply = done(event);
    let conditions = present.iter().any(|(_, s)| s.is_some());
    // The end of the chain.
    let mut rest: Vec<Element> = if conditions {
        vec![b.send_params(&reply, wrapper, &[("status", "0")])]
    } else {
        vec![b.send(&reply, wrapper)]
    };
    for (c, stop) in present.into_iter().rev() {
        let label = format!("`{}`", c.attr);
        let next = rest.clone();
        let reply = reply.clone();
        // `_while` decides the answer (SKIPPED) when it is false.
        let negate = c.attr == "_while";
        let then = move |v: Option<String>| match (v, stop) {
            (Some(v), Some(s)) => vec![b
                .if_chain(
                    vec![(
                        if negate { format!("!({v})") } else { v },
                        vec![b.send_params(&reply, wrapper, &[("status", &s.to_string())])],
                    )],
                    next.clone(),
                )
                .expect("one branch")],
            _ => next.clone(),
        };
        match compile(
            sm,
            n,
            &b,
            &c.code,
            c.span,
            &label,
            stop.is_some(),
            &then,
            bb,
            errs,
        ) {
            Some(body) => rest = body,
            None => {
                *ok = false;
                return true;
            }
        }
    }
    bb.scripts.push(b.tr(Some(event), None, Some("idle"), rest));
    true
}

/// How a wrapped node that BT.CPP may tick again without resetting it
/// ([`Ctx::stale`] of the wrapper's `outer` context) answers then.
#[derive(Clone, Copy, Debug)]
pub(super) struct Inner {
    /// The node is a stateful leaf (`btcpp.rs`, "Leaves"): ticked in a finished status
    /// it answers that status again without running.
    pub stateful: bool,
    /// The node's own machine keeps what a reset clears ([`Ctx::stale`]): the wrapper
    /// passes the parent's reset on.
    pub forward: bool,
}

/// The wrapper machine of node `n` (see the module comment); `outer` is the context the
/// parent sees (its `parent` and `halt_target`, and whether the parent may tick the
/// node again without resetting it, `stale`, with how the node answers then, `inner`).
/// Its scripts go to the blackboard machine. `None` after an error.
pub(super) fn wrapper(
    sm: &SourceMap,
    n: &TreeNode,
    outer: &Ctx,
    inner: Inner,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let b = B { at: n.span };
    let me = machine_name(n);
    let id = n.id;
    let mut ok = true;
    let has_pre = chain(
        sm,
        n,
        b,
        &me,
        &pre_event(id),
        &[
            ("_failureIf", Some(FAILURE)),
            ("_successIf", Some(SUCCESS)),
            ("_skipIf", Some(SKIPPED)),
            ("_while", Some(SKIPPED)),
        ],
        bb,
        errs,
        &mut ok,
    );
    // `_while` is checked again while the node is RUNNING.
    let has_while = chain(
        sm,
        n,
        b,
        &me,
        &while_event(id),
        &[("_while", Some(SKIPPED))],
        bb,
        errs,
        &mut ok,
    );
    let mut has_post = [false; 2];
    for (k, (s, on)) in [(SUCCESS, "_onSuccess"), (FAILURE, "_onFailure")]
        .into_iter()
        .enumerate()
    {
        has_post[k] = chain(
            sm,
            n,
            b,
            &me,
            &post_event(id, s),
            &[(on, None), ("_post", None)],
            bb,
            errs,
            &mut ok,
        );
    }
    let has_halted = chain(
        sm,
        n,
        b,
        &me,
        &halted_event(id),
        &[("_onHalted", None)],
        bb,
        errs,
        &mut ok,
    );
    if !ok {
        return None;
    }
    let st = stem(n);
    let (tick, halt) = (format!("bt_{st}_tick"), format!("bt_{st}_halt"));
    let respond = |expr: &str| {
        b.send_params(
            &format!("bt_{st}_response"),
            &outer.parent,
            &[("status", expr)],
        )
    };
    let halted = || b.send(&format!("bt_{st}_halt_response"), &outer.halt_target);
    let tick_inner = || b.send(&format!("bt_{id}_tick"), &n.machine);
    let (resp, halt_resp) = (
        format!("bt_{id}_response"),
        format!("bt_{id}_halt_response"),
    );
    let run = "node_running";
    // The node finished and its parent has not reset it since (its status SUCCESS or
    // FAILURE), kept only where the parent may tick it again so.
    let node_done = "node_done";
    let stale = outer.stale;
    let mut m = b.scxml(&me, "wait_for_tick");
    let mut data = vec![
        (run, "bool", "false".to_string()),
        ("result", "int8", "0".into()),
    ];
    if stale {
        data.push((node_done, "bool", "false".into()));
    }
    m.push(b.datamodel(&data));
    let mut w = b.state("wait_for_tick");
    if stale {
        // Ticked in its finished status (4.10 `TreeNode::executeTick`): no
        // pre-condition (`checkPreConditions` looks only while the node is IDLE or
        // RUNNING); a stateful leaf answers its status again without running
        // (`StatefulActionNode::tick`), any other node is ticked; the post-conditions
        // run for the finished answer.
        if inner.stateful {
            w.push(b.tr(Some(&tick), Some(node_done), Some("finished"), vec![]));
        } else {
            w.push(b.tr(
                Some(&tick),
                Some(node_done),
                Some("ticking"),
                vec![tick_inner()],
            ));
        }
        // The parent's reset of a finished node (`ControlNode::resetChildren`:
        // `resetStatus`, no `haltNode`, so no `_onHalted`): IDLE again.
        if inner.forward {
            w.push(b.tr(
                Some(&halt),
                Some(node_done),
                Some("resetting"),
                vec![
                    b.assign(node_done, "false"),
                    b.send(&format!("bt_{id}_halt"), &n.machine),
                ],
            ));
            m.push(b.state("resetting").with_child(b.tr(
                Some(&halt_resp),
                None,
                Some("wait_for_tick"),
                vec![halted()],
            )));
        } else {
            w.push(b.tr(
                Some(&halt),
                Some(node_done),
                Some("wait_for_tick"),
                vec![b.assign(node_done, "false"), halted()],
            ));
        }
    }
    if has_while {
        w.push(b.tr(
            Some(&tick),
            Some(run),
            Some("while_check"),
            vec![b.send(&while_event(id), MACHINE)],
        ));
    }
    w.push(b.tr(Some(&tick), Some(run), Some("ticking"), vec![tick_inner()]));
    if has_pre {
        w.push(b.tr(
            Some(&tick),
            None,
            Some("pre_conditions"),
            vec![b.send(&pre_event(id), MACHINE)],
        ));
    }
    w.push(b.tr(Some(&tick), None, Some("ticking"), vec![tick_inner()]));
    w.push(b.tr(
        Some(&halt),
        Some(run),
        Some("halting"),
        vec![b.send(&format!("bt_{id}_halt"), &n.machine)],
    ));
    w.push(b.tr(Some(&halt), None, Some("wait_for_tick"), vec![halted()]));
    m.push(w);
    if has_while {
        // `checkPreConditions` on a RUNNING node: `_while` false halts it (`haltNode`:
        // its `halt`, then `_onHalted`) and answers SKIPPED; the node is IDLE then.
        let ev = done(&while_event(id));
        m.push(
            b.state("while_check")
                .with_child(b.tr(
                    Some(&ev),
                    Some("_event.data.status == 0"),
                    Some("ticking"),
                    vec![tick_inner()],
                ))
                .with_child(b.tr(
                    Some(&ev),
                    None,
                    Some("while_halting"),
                    vec![b.send(&format!("bt_{id}_halt"), &n.machine)],
                )),
        );
        let skipped = respond(&SKIPPED.to_string());
        let mut h = b.state("while_halting");
        if has_halted {
            h.push(b.tr(
                Some(&halt_resp),
                None,
                Some("while_on_halted"),
                vec![b.assign(run, "false"), b.send(&halted_event(id), MACHINE)],
            ));
            m.push(h);
            m.push(b.state("while_on_halted").with_child(b.tr(
                Some(&done(&halted_event(id))),
                None,
                Some("wait_for_tick"),
                vec![skipped],
            )));
        } else {
            h.push(b.tr(
                Some(&halt_resp),
                None,
                Some("wait_for_tick"),
                vec![b.assign(run, "false"), skipped],
            ));
            m.push(h);
        }
    }
    if has_pre {
        let ev = done(&pre_event(id));
        m.push(
            b.state("pre_conditions")
                .with_child(b.tr(
                    Some(&ev),
                    Some("_event.data.status == 0"),
                    Some("ticking"),
                    vec![tick_inner()],
                ))
                // `_skipIf` true or `_while` false on an IDLE node: SKIPPED, the node
                // left IDLE, no post-condition (`isStatusCompleted` is false).
                .with_child(b.tr(
                    Some(&ev),
                    Some(&format!("_event.data.status == {SKIPPED}")),
                    Some("wait_for_tick"),
                    vec![respond(&SKIPPED.to_string())],
                ))
                .with_child(b.tr(
                    Some(&ev),
                    None,
                    Some("finished"),
                    vec![b.assign("result", "_event.data.status")],
                )),
        );
    }
    let mut on_running = vec![b.assign(run, "true")];
    let mut on_skipped = vec![b.assign(run, &format!("_event.data.status == {SKIPPED_RUNNING}"))];
    if stale {
        // RUNNING now; a SKIPPED leaves a finished status as it was unless the node
        // set itself RUNNING (code 5).
        on_running.push(b.assign(node_done, "false"));
        on_skipped.push(b.assign(
            node_done,
            &format!("{node_done} && _event.data.status == {SKIPPED}"),
        ));
    }
    on_running.push(respond(&RUNNING.to_string()));
    on_skipped.push(respond("_event.data.status"));
    m.push(
        b.state("ticking")
            .with_child(b.tr(
                Some(&resp),
                Some(&format!("_event.data.status == {RUNNING}")),
                Some("wait_for_tick"),
                on_running,
            ))
            // The node's own SKIPPED: passed on, the node RUNNING still if it set
            // itself so (code 5); no post-condition.
            .with_child(b.tr(
                Some(&resp),
                Some(IS_SKIPPED),
                Some("wait_for_tick"),
                on_skipped,
            ))
            .with_child(b.tr(
                Some(&resp),
                None,
                Some("finished"),
                vec![
                    b.assign(run, "false"),
                    b.assign("result", "_event.data.status"),
                ],
            )),
    );
    let mut f = if stale {
        b.state_entry("finished", vec![b.assign(node_done, "true")])
    } else {
        b.state("finished")
    };
    for (k, s) in [SUCCESS, FAILURE].into_iter().enumerate() {
        if has_post[k] {
            f.push(b.tr(
                None,
                Some(&format!("result == {s}")),
                Some("post_conditions"),
                vec![b.send(&post_event(id, s), MACHINE)],
            ));
        }
    }
    f.push(b.tr(None, None, Some("wait_for_tick"), vec![respond("result")]));
    m.push(f);
    if has_post.iter().any(|x| *x) {
        let mut p = b.state("post_conditions");
        for (k, s) in [SUCCESS, FAILURE].into_iter().enumerate() {
            if has_post[k] {
                p.push(b.tr(
                    Some(&done(&post_event(id, s))),
                    None,
                    Some("wait_for_tick"),
                    vec![respond("result")],
                ));
            }
        }
        m.push(p);
    }
    let mut h = b.state("halting");
    if has_halted {
        h.push(b.tr(
            Some(&halt_resp),
            None,
            Some("on_halted"),
            vec![b.assign(run, "false"), b.send(&halted_event(id), MACHINE)],
        ));
        m.push(h);
        m.push(b.state("on_halted").with_child(b.tr(
            Some(&done(&halted_event(id))),
            None,
            Some("wait_for_tick"),
            vec![halted()],
        )));
    } else {
        h.push(b.tr(
            Some(&halt_resp),
            None,
            Some("wait_for_tick"),
            vec![b.assign(run, "false"), halted()],
        ));
        m.push(h);
    }
    Some(m)
}
