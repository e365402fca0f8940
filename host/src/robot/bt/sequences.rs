//! The machines of Sequence, Fallback, SequenceWithMemory, ReactiveSequence and
//! ReactiveFallback: the nodes that tick their children one after another.

use super::control::{
    answer_by_flags, init_state, n_children, on_child_status, reset_children, sequence_head, Ctx,
    HaltEffect, FAILURE, RUNNING, SUCCESS,
};
use crate::model::xml::Element;

/// Sequence (`cont` = SUCCESS) or Fallback (`cont` = FAILURE): a child answering `cont`
/// moves on to the next; `stop` halts every child and answers `stop`; RUNNING answers
/// RUNNING and the next tick resumes at the same child.
pub(super) fn sequence(ctx: &Ctx, cont: u8, stop: u8) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let mut m = sequence_head(ctx, idx, &["seq_failure", "seq_success"]);
    let finish = answer_by_flags(ctx, idx, "seq_failure", "seq_success");
    m.push(reset_children(ctx, idx, finish));
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, false)],
    );
    let mut t = b.state_entry("tick_children", vec![guard]);
    let flag = |s: u8| {
        if s == SUCCESS {
            "seq_success"
        } else {
            "seq_failure"
        }
    };
    // The child's answers in each model's order, state `tick_children`: AS2FM's
    // sequence.ascxml SUCCESS, FAILURE, RUNNING; fallback.ascxml RUNNING, SUCCESS,
    // FAILURE (one status each, so the order changes no run, only the text).
    let order = if cont == SUCCESS {
        [cont, stop, RUNNING]
    } else {
        [RUNNING, stop, cont]
    };
    for s in order {
        if s == cont {
            on_child_status(ctx, &mut t, idx, cont, "tick_children", || {
                vec![b.assign(idx, &format!("{idx} + 1"))]
            });
        } else if s == stop {
            on_child_status(ctx, &mut t, idx, stop, "reset_children", || {
                vec![b.assign(idx, "0"), b.assign(flag(stop), "true")]
            });
        } else {
            on_child_status(ctx, &mut t, idx, RUNNING, "wait_for_tick", || {
                vec![ctx.respond(RUNNING)]
            });
        }
    }
    t.push(b.tr(
        None,
        Some(&format!("{idx} == children_count")),
        Some("reset_children"),
        vec![b.assign(idx, "0"), b.assign(flag(cont), "true")],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} < 0 || {idx} > children_count")),
        Some("error"),
        vec![],
    ));
    m.push(t);
    m.push(b.state("error"));
    m
}

/// SequenceWithMemory: like Sequence, but a failing child is the only one halted and the
/// next tick starts again at that child.
pub(super) fn sequence_with_memory(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let mut m = sequence_head(ctx, idx, &["seq_success"]);
    let finish = vec![
        b.if_chain(
            vec![("seq_success".into(), vec![ctx.respond(SUCCESS)])],
            vec![ctx.respond_halted()],
        )
        .expect("one branch"),
        b.assign(idx, "0"),
        b.assign("seq_success", "false"),
    ];
    m.push(reset_children(ctx, idx, finish));
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, false)],
    );
    let mut t = b.state_entry("tick_children", vec![guard]);
    let n = ctx.children.len();
    on_child_status(ctx, &mut t, idx, SUCCESS, "tick_children", || {
        vec![b.assign(idx, &format!("{idx} + 1"))]
    });
    // A failing child is idle: it needs a halt only if halting does more than that.
    for i in 0..n {
        let (target, body) = if ctx.effect(i) == HaltEffect::Always {
            ("halt_current_child", vec![])
        } else {
            ("wait_for_tick", vec![ctx.respond(FAILURE)])
        };
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("_event.data.status == {FAILURE} && {idx} == {i}")),
            Some(target),
            ctx.marked(i, FAILURE, body),
        ));
    }
    on_child_status(ctx, &mut t, idx, RUNNING, "wait_for_tick", || {
        vec![ctx.respond(RUNNING)]
    });
    t.push(b.tr(
        None,
        Some(&format!("{idx} == children_count")),
        Some("reset_children"),
        vec![b.assign(idx, "0"), b.assign("seq_success", "true")],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} < 0 || {idx} > children_count")),
        Some("error"),
        vec![],
    ));
    m.push(t);
    let mut h = b.state_entry("halt_current_child", vec![ctx.dispatch(idx, true)]);
    for i in 0..n {
        h.push(b.tr(
            Some(&ctx.child_halt_resp(i)),
            Some(&format!("{idx} == {i}")),
            Some("wait_for_tick"),
            vec![ctx.respond(FAILURE)],
        ));
    }
    m.push(h);
    m.push(b.state("error"));
    m
}

/// ReactiveSequence (`seq`) or ReactiveFallback: every tick starts at the first child; a
/// RUNNING child halts all the others and answers RUNNING; the stopping status halts all
/// children and answers it; all children answering the continuing status answers that.
pub(super) fn reactive(ctx: &Ctx, seq: bool) -> Element {
    let b = &ctx.b;
    let (count, stop_child, cont, stop) = if seq {
        ("success_count", "failed_child", SUCCESS, FAILURE)
    } else {
        ("failure_count", "success_child", FAILURE, SUCCESS)
    };
    let idx = "child_idx";
    let mut m = b.scxml(&ctx.machine, "init");
    let flags = ctx.running_data();
    let mut data = vec![
        (count, "int8", "0".to_string()),
        ("running_child", "int8", "-1".into()),
        (stop_child, "int8", "-1".into()),
        (idx, "int8", "0".into()),
        ("children_count", "int8", n_children(ctx)),
    ];
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 1"));
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("tick_children"),
                vec![
                    b.assign(count, "0"),
                    b.assign(idx, "0"),
                    b.assign(stop_child, "-1"),
                ],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("reset_children"),
                // The variable a halt resets is each model's, state `wait_for_tick`:
                // AS2FM's reactive_sequence.ascxml `failed_child`,
                // reactive_fallback.ascxml `running_child`. Either is already -1 or
                // unread until set again, so no run changes.
                vec![
                    b.assign(idx, "0"),
                    b.assign(if seq { stop_child } else { "running_child" }, "-1"),
                ],
            )),
    );
    let finish = vec![
        b.if_chain(
            vec![
                (
                    format!("{count} == children_count"),
                    vec![ctx.respond(cont)],
                ),
                (format!("{stop_child} >= 0"), vec![ctx.respond(stop)]),
            ],
            vec![ctx.respond_halted()],
        )
        .expect("two branches"),
        b.assign(idx, "0"),
        b.assign(count, "0"),
        b.assign("running_child", "-1"),
        b.assign(stop_child, "-1"),
    ];
    m.push(reset_children(ctx, idx, finish));
    let guard_var = if seq { count } else { idx };
    let guard = b.if_then(
        &format!("{guard_var} < children_count"),
        vec![ctx.dispatch(idx, false)],
    );
    let mut t = b.state_entry("tick_children", vec![guard]);
    let n = ctx.children.len();
    // The child's answers in each model's order, state `tick_children`: AS2FM's
    // reactive_sequence.ascxml SUCCESS, FAILURE, RUNNING; reactive_fallback.ascxml
    // RUNNING, FAILURE, SUCCESS.
    let order = if seq {
        [cont, stop, RUNNING]
    } else {
        [RUNNING, cont, stop]
    };
    for s in order {
        if s == cont {
            on_child_status(ctx, &mut t, idx, cont, "tick_children", || {
                vec![
                    b.assign(count, &format!("{count} + 1")),
                    b.assign(idx, &format!("{idx} + 1")),
                ]
            });
        } else if s == stop {
            on_child_status(ctx, &mut t, idx, stop, "reset_children", || {
                vec![b.assign(stop_child, idx), b.assign(idx, "0")]
            });
        } else {
            on_child_status(ctx, &mut t, idx, RUNNING, "reset_other_children", || {
                vec![b.assign("running_child", idx), b.assign(idx, "0")]
            });
        }
    }
    t.push(b.tr(
        None,
        Some(&format!("{count} == children_count")),
        Some("reset_children"),
        vec![b.assign(idx, "0")],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} < 0 || {idx} >= children_count")),
        Some("error"),
        vec![],
    ));
    m.push(t);
    let skip = b.if_then(
        &format!("{idx} == running_child"),
        vec![b.assign(idx, &format!("{idx} + 1"))],
    );
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, true)],
    );
    let mut entry = if ctx.effects.is_some() {
        ctx.skip_idle(idx, Some("running_child"))
    } else {
        vec![skip]
    };
    entry.push(guard);
    let mut r = b.state_entry("reset_other_children", entry);
    for i in 0..n {
        r.push(b.tr(
            Some(&ctx.child_halt_resp(i)),
            Some(&format!("{idx} == {i}")),
            Some("reset_other_children"),
            vec![b.assign(idx, &format!("{idx} + 1"))],
        ));
    }
    r.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("wait_for_tick"),
        vec![ctx.respond(RUNNING)],
    ));
    m.push(r);
    m.push(b.state("error"));
    m
}
