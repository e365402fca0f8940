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
//! IfThenElse or of a WhileDoElse and the child of a BlackboardCheck, which BT.CPP may
//! tick again in its finished status (skipping its pre-conditions); conditions there are
//! refused. The root's wrapper talks to the root machine as to a parent.

use super::blackboard::{Blackboard, MACHINE};
use super::btcpp4_script::compile;
use super::build::B;
use super::control::{Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING, SUCCESS};
use super::tree::{Btcpp4, Control, Kind, Tree, TreeNode};
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
            let Some(p) = n.parent else {
                // The root: the root machine ticks it as a parent would. `Tree::tickRoot`
                // resets a finished root (`resetStatus`), so it is IDLE at every tick
                // unless it answered RUNNING (or SKIPPED with its status RUNNING).
                continue;
            };
            let p = &tree.nodes[p];
            let first = p.children.first() == Some(&i);
            let stale = match p.kind {
                Kind::Control(Control::IfThenElse) => first && p.children.len() == 2,
                Kind::Control(Control::Btcpp4(Btcpp4::WhileDoElse)) => first,
                Kind::Control(Control::BlackboardCheck(_)) => true,
                _ => false,
            };
            if !stale {
                continue;
            }
            "BehaviorTree.CPP may tick this node again without resetting it (the condition of a two-child IfThenElse or of a WhileDoElse, the child of a BlackboardCheck), skipping its pre-conditions: not modelled yet"
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

/// The wrapper machine of node `n` (see the module comment); `outer` is the context the
/// parent sees (its `parent` and `halt_target`). Its scripts go to the blackboard
/// machine. `None` after an error.
pub(super) fn wrapper(
    sm: &SourceMap,
    n: &TreeNode,
    outer: &Ctx,
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
    let mut m = b.scxml(&me, "wait_for_tick");
    m.push(b.datamodel(&[
        (run, "bool", "false".into()),
        ("result", "int8", "0".into()),
    ]));
    let mut w = b.state("wait_for_tick");
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
    m.push(
        b.state("ticking")
            .with_child(b.tr(
                Some(&resp),
                Some(&format!("_event.data.status == {RUNNING}")),
                Some("wait_for_tick"),
                vec![b.assign(run, "true"), respond(&RUNNING.to_string())],
            ))
            // The node's own SKIPPED: passed on, the node RUNNING still if it set
            // itself so (code 5); no post-condition.
            .with_child(b.tr(
                Some(&resp),
                Some(IS_SKIPPED),
                Some("wait_for_tick"),
                vec![
                    b.assign(run, &format!("_event.data.status == {SKIPPED_RUNNING}")),
                    respond("_event.data.status"),
                ],
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
    let mut f = b.state("finished");
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
