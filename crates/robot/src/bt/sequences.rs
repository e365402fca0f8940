//! The machines of Sequence, Fallback, SequenceWithMemory, ReactiveSequence and
//! ReactiveFallback: the nodes that tick their children one after another.

use super::control::{
    answer_by_flags, index_out_of_range, init_state, n_children, on_child_status, reset_children,
    sequence_head, skip_to_next, Ctx, HaltEffect, FAILURE, IS_SKIPPED, RUNNING, SKIPPED_RUNNING,
    SKIP_COUNT, SUCCESS,
};
use crate::model::xml::Element;

/// Sequence (`cont` = SUCCESS) or Fallback (`cont` = FAILURE): a child answering `cont`
/// moves on to the next; `stop` halts every child and answers `stop`; RUNNING answers
/// RUNNING and the next tick resumes at the same child.
pub(super) fn sequence(ctx: &Ctx, cont: u8, stop: u8) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let mut m = sequence_head(ctx, idx, &["seq_failure", "seq_success"]);
    let flag = |s: u8| {
        if s == SUCCESS {
            "seq_success"
        } else {
            "seq_failure"
        }
    };
    let finish = if ctx.btcpp {
        // BT.CPP 4.10 `SequenceNode::tick` / `FallbackNode::tick`: every child skipped
        // answers SKIPPED (the node set itself RUNNING first); `halt` and a finished
        // loop clear `skipped_count_`. `stop` leaves it: the count restarts at the next
        // tick only if the node was reset in between (`!isStatusActive(status())`),
        // which every parent does, except where BT.CPP may tick the node again without
        // a reset (`Ctx::stale`: the parent halts it at every reset instead).
        let reset_count = if ctx.stale {
            b.if_then(&format!("!{}", flag(stop)), vec![b.assign(SKIP_COUNT, "0")])
        } else {
            b.assign(SKIP_COUNT, "0")
        };
        vec![
            b.if_chain(
                vec![
                    (flag(stop).into(), vec![ctx.respond(stop)]),
                    (
                        format!("{} && {SKIP_COUNT} == children_count", flag(cont)),
                        vec![ctx.respond(SKIPPED_RUNNING)],
                    ),
                    (flag(cont).into(), vec![ctx.respond(cont)]),
                ],
                vec![ctx.respond_halted()],
            )
            .expect("three branches"),
            b.assign(idx, "0"),
            reset_count,
            b.assign("seq_failure", "false"),
            b.assign("seq_success", "false"),
        ]
    } else {
        answer_by_flags(ctx, idx, "seq_failure", "seq_success")
    };
    m.push(reset_children(ctx, idx, finish));
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, false)],
    );
    let mut t = b.state_entry("tick_children", vec![guard]);
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
    // `case NodeStatus::SKIPPED`: on to the next child, counted.
    if ctx.btcpp {
        skip_to_next(ctx, &mut t, idx, "tick_children");
    }
    t.push(b.tr(
        None,
        Some(&format!("{idx} == children_count")),
        Some("reset_children"),
        vec![b.assign(idx, "0"), b.assign(flag(cont), "true")],
    ));
    t.push(index_out_of_range(ctx, idx));
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
    t.push(index_out_of_range(ctx, idx));
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
    // BT.CPP 4.10 `ReactiveSequence::tick` / `ReactiveFallback::tick`: the children
    // skipped in this tick (`all_skipped`).
    if ctx.btcpp {
        data.push((SKIP_COUNT, "int8", "0".into()));
    }
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 1"));
    let mut start = vec![
        b.assign(count, "0"),
        b.assign(idx, "0"),
        b.assign(stop_child, "-1"),
    ];
    if ctx.btcpp {
        start.push(b.assign(SKIP_COUNT, "0"));
    }
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_children"), start))
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
    let mut answers = vec![
        (
            format!("{count} == children_count"),
            vec![ctx.respond(cont)],
        ),
        (format!("{stop_child} >= 0"), vec![ctx.respond(stop)]),
    ];
    if ctx.btcpp {
        // Every child skipped: SKIPPED (the node set itself RUNNING first); some
        // skipped, the others `cont`: `cont`.
        answers.insert(
            0,
            (
                format!("{SKIP_COUNT} == children_count"),
                vec![ctx.respond(SKIPPED_RUNNING)],
            ),
        );
        answers[1].0 = format!("{count} + {SKIP_COUNT} == children_count");
    }
    let mut finish = vec![
        b.if_chain(answers, vec![ctx.respond_halted()])
            .expect("two branches"),
        b.assign(idx, "0"),
        b.assign(count, "0"),
        b.assign("running_child", "-1"),
        b.assign(stop_child, "-1"),
    ];
    if ctx.btcpp {
        finish.push(b.assign(SKIP_COUNT, "0"));
    }
    m.push(reset_children(ctx, idx, finish));
    let guard_var = if ctx.btcpp {
        idx
    } else if seq {
        count
    } else {
        idx
    };
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
    if ctx.btcpp {
        // `case NodeStatus::SKIPPED`: `haltChild(index)` (a halt only if it still runs,
        // code 5), then on to the next child.
        let next = || {
            vec![
                b.assign(SKIP_COUNT, &format!("{SKIP_COUNT} + 1")),
                b.assign(idx, &format!("{idx} + 1")),
            ]
        };
        let mut hs = b.state("halting_skipped");
        for i in 0..n {
            t.push(b.tr(
                Some(&ctx.child_resp(i)),
                Some(&format!(
                    "_event.data.status == {SKIPPED_RUNNING} && {idx} == {i}"
                )),
                Some("halting_skipped"),
                ctx.halt_child_body(i),
            ));
            t.push(b.tr(
                Some(&ctx.child_resp(i)),
                Some(&format!("{IS_SKIPPED} && {idx} == {i}")),
                Some("tick_children"),
                next(),
            ));
            hs.push(b.tr(
                Some(&ctx.child_halt_resp(i)),
                Some(&format!("{idx} == {i}")),
                Some("tick_children"),
                next(),
            ));
        }
        m.push(hs);
    }
    let done = if ctx.btcpp {
        format!("{count} + {SKIP_COUNT} == children_count")
    } else {
        format!("{count} == children_count")
    };
    t.push(b.tr(
        None,
        Some(&done),
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
