//! The machines of Parallel (every child each tick, answers by counting) and IfThenElse
//! (a condition child chooses the branch child).

use super::control::{
    answer_by_flags, init_state, n_children, on_child_skipped, on_child_status, reset_children,
    Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED_RUNNING, SUCCESS,
};
use crate::model::xml::Element;

/// Parallel: ticks every child in order each tick; SUCCESS when `success` children
/// succeeded, FAILURE when `failure` failed (halting all children first), else RUNNING.
pub(super) fn parallel(ctx: &Ctx, success: i64, failure: i64) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let n = ctx.children.len();
    let flags = ctx.running_data();
    let mut m = b.scxml(&ctx.machine, "init");
    m.push(
        b.datamodel(
            &[
                ("children_count", "uint8", n_children(ctx)),
                ("success_threshold", "uint8", success.to_string()),
                ("failure_threshold", "uint8", failure.to_string()),
                (idx, "uint8", "0".into()),
                ("success_count", "uint8", "0".into()),
                ("failure_count", "uint8", "0".into()),
            ]
            .into_iter()
            .chain(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())))
            .collect::<Vec<_>>(),
        ),
    );
    m.push(
        b.state("init")
            .with_child(b.tr(None, Some("children_count <= 0"), Some("error"), vec![]))
            .with_child(b.tr(
                None,
                Some("success_threshold < 1 || success_threshold > children_count"),
                Some("error"),
                vec![],
            ))
            .with_child(b.tr(
                None,
                Some("failure_threshold < 1 || failure_threshold > children_count"),
                Some("error"),
                vec![],
            ))
            .with_child(b.tr(None, None, Some("wait_for_tick"), vec![])),
    );
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("tick_children_init"),
                vec![],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("halting_on_parent_halt"),
                vec![b.assign(idx, "0")],
            )),
    );
    m.push(
        b.state_entry(
            "tick_children_init",
            vec![
                b.assign(idx, "0"),
                b.assign("success_count", "0"),
                b.assign("failure_count", "0"),
            ],
        )
        .with_child(b.tr(None, None, Some("tick_current_child"), vec![])),
    );
    let mut t = b.state_entry("tick_current_child", vec![ctx.dispatch(idx, false)]);
    t.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("wait_for_tick"),
        vec![ctx.respond(RUNNING)],
    ));
    for (status, counter) in [
        (SUCCESS, Some("success_count")),
        (FAILURE, Some("failure_count")),
        (RUNNING, None),
    ] {
        for i in 0..n {
            let body = match counter {
                Some(c) => vec![b.assign(c, &format!("{c} + 1"))],
                None => vec![],
            };
            t.push(b.tr(
                Some(&ctx.child_resp(i)),
                Some(&format!("_event.data.status == {status} && {idx} == {i}")),
                Some("eval_after_child"),
                ctx.marked(i, status, body),
            ));
        }
    }
    m.push(t);
    m.push(
        b.state("eval_after_child")
            .with_child(b.tr(
                None,
                Some("success_count >= success_threshold"),
                Some("halting_after_success"),
                vec![b.assign(idx, "0")],
            ))
            .with_child(b.tr(
                None,
                Some("failure_count >= failure_threshold"),
                Some("halting_after_failure"),
                vec![b.assign(idx, "0")],
            ))
            .with_child(b.tr(
                None,
                None,
                Some("tick_current_child"),
                vec![b.assign(idx, &format!("{idx} + 1"))],
            )),
    );
    for (state, done) in [
        ("halting_after_success", ctx.respond(SUCCESS)),
        ("halting_after_failure", ctx.respond(FAILURE)),
        ("halting_on_parent_halt", ctx.respond_halted()),
    ] {
        let mut entry = ctx.skip_idle(idx, None);
        entry.push(ctx.dispatch(idx, true));
        let mut h = b.state_entry(state, entry);
        h.push(b.tr(
            None,
            Some(&format!("{idx} >= children_count")),
            Some("wait_for_tick"),
            vec![done],
        ));
        for i in 0..n {
            h.push(b.tr(
                Some(&ctx.child_halt_resp(i)),
                Some(&format!("{idx} == {i}")),
                Some(state),
                vec![b.assign(idx, &format!("{idx} + 1"))],
            ));
        }
        m.push(h);
    }
    m.push(b.state("error"));
    m
}

/// IfThenElse: ticks the condition (child 0) while no branch runs; SUCCESS runs child 1,
/// FAILURE child 2 (or answers FAILURE with two children); the branch's answer is the
/// node's, and a finished branch halts every child first.
///
/// With `stale_condition` (BT.CPP's rules, a condition that is a leaf plugin and two
/// children), a failed condition is not reset (`IfThenElseNode::tick` returns its
/// FAILURE without `resetChildren`), and a stateful leaf ticked again in a finished
/// status answers that status without running (BT.CPP 4 `action_node.cpp`,
/// `StatefulActionNode::tick`): from then on the node answers FAILURE without ticking it.
pub(super) fn if_then_else(ctx: &Ctx, stale_condition: bool) -> Element {
    let b = &ctx.b;
    let idx = "child_idx";
    let mut m = b.scxml(&ctx.machine, "init");
    let flags = ctx.running_data();
    let mut data = vec![
        (idx, "int8", "0".to_string()),
        ("ret_failure", "bool", "false".into()),
        ("ret_success", "bool", "false".into()),
        ("children_count", "int8", n_children(ctx)),
    ];
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    if stale_condition {
        data.push(("condition_failed", "bool", "false".into()));
    }
    if ctx.btcpp {
        data.push(("ret_skipped", "bool", "false".into()));
    }
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 2 || children_count > 3"));
    let mut w = b.state("wait_for_tick");
    if stale_condition {
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            Some(&format!("{idx} == 0 && condition_failed")),
            Some("wait_for_tick"),
            vec![ctx.respond(FAILURE)],
        ));
    }
    m.push(
        w.with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some(&format!("{idx} == 0")),
            Some("tick_condition_child"),
            vec![],
        ))
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some(&format!("{idx} > 0")),
            Some("tick_exec_child"),
            vec![],
        ))
        .with_child(b.tr(
            Some(&ctx.halt_ev()),
            None,
            Some("reset_children"),
            vec![b.assign(idx, "0")],
        )),
    );
    let mut finish = answer_by_flags(ctx, idx, "ret_failure", "ret_success");
    if ctx.btcpp {
        // 4.10 `IfThenElseNode::tick`: a skipped branch is not RUNNING, so the children
        // are reset and its SKIPPED is the answer (the node set itself RUNNING first).
        finish = vec![b
            .if_chain(
                vec![(
                    "ret_skipped".into(),
                    vec![
                        ctx.respond(SKIPPED_RUNNING),
                        b.assign("ret_skipped", "false"),
                        b.assign(idx, "0"),
                    ],
                )],
                answer_by_flags(ctx, idx, "ret_failure", "ret_success"),
            )
            .expect("one branch")];
    }
    m.push(reset_children(ctx, idx, finish));
    let cond_resp = ctx.child_resp(0);
    let mut cond = b.state_entry("tick_condition_child", vec![ctx.tick_child(0)]);
    if ctx.btcpp {
        // 4.10 `IfThenElseNode::tick`: a skipped condition leaves `child_idx_` 0 and
        // reaches `throw std::logic_error("Something unexpected happened in
        // IfThenElseNode")`; where BT.CPP throws the tree stops (README).
        cond.push(b.tr(Some(&cond_resp), Some(IS_SKIPPED), Some("error"), vec![]));
    }
    m.push(
        cond.with_child(b.tr(None, Some(&format!("{idx} != 0")), Some("error"), vec![]))
            .with_child(b.tr(
                Some(&cond_resp),
                Some(&format!("_event.data.status == {SUCCESS}")),
                Some("tick_exec_child"),
                ctx.marked(0, SUCCESS, vec![b.assign(idx, "1")]),
            ))
            .with_child(b.tr(
                Some(&cond_resp),
                Some(&format!(
                    "_event.data.status == {FAILURE} && children_count == 3"
                )),
                Some("tick_exec_child"),
                ctx.marked(0, FAILURE, vec![b.assign(idx, "2")]),
            ))
            .with_child(b.tr(
                Some(&cond_resp),
                Some(&format!(
                    "_event.data.status == {FAILURE} && children_count < 3"
                )),
                Some("wait_for_tick"),
                ctx.marked(0, FAILURE, {
                    let mut v = vec![ctx.respond(FAILURE)];
                    if stale_condition {
                        v.push(b.assign("condition_failed", "true"));
                    }
                    v
                }),
            ))
            .with_child(b.tr(
                Some(&cond_resp),
                Some(&format!("_event.data.status == {RUNNING}")),
                Some("wait_for_tick"),
                ctx.marked(0, RUNNING, vec![ctx.respond(RUNNING)]),
            )),
    );
    let mut t = b.state_entry("tick_exec_child", vec![ctx.dispatch(idx, false)]);
    t.push(b.tr(
        None,
        Some(&format!("{idx} != 1 && {idx} != 2")),
        Some("error"),
        vec![],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("error"),
        vec![],
    ));
    for (status, flag) in [(SUCCESS, "ret_success"), (FAILURE, "ret_failure")] {
        on_child_status(ctx, &mut t, idx, status, "reset_children", || {
            vec![b.assign(idx, "0"), b.assign(flag, "true")]
        });
    }
    on_child_status(ctx, &mut t, idx, RUNNING, "wait_for_tick", || {
        vec![ctx.respond(RUNNING)]
    });
    if ctx.btcpp {
        on_child_skipped(ctx, &mut t, idx, "reset_children", || {
            vec![b.assign(idx, "0"), b.assign("ret_skipped", "true")]
        });
    }
    m.push(t);
    m.push(b.state("error"));
    m
}
