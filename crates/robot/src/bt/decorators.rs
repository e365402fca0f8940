//! The machines of the one-child decorators (Inverter, ForceSuccess, ForceFailure, Repeat,
//! RetryUntilSuccessful) and of the leaves AlwaysSuccess / AlwaysFailure.

use super::control::{
    init_state, n_children, Ctx, HaltEffect, FAILURE, IS_SKIPPED, RUNNING, SKIPPED_RUNNING, SUCCESS,
};
use crate::model::xml::Element;

/// A one-child decorator mapping the child's SUCCESS, FAILURE, RUNNING to `map`; under
/// BT.CPP's rules a SKIPPED child answers SKIPPED, the node RUNNING (4.10
/// `InverterNode::tick`, `ForceSuccessNode::tick`, `ForceFailureNode::tick`: the child's
/// SKIPPED is returned after `setStatus(RUNNING)`, the child not reset).
pub(super) fn decorator(ctx: &Ctx, map: [u8; 3]) -> Element {
    decorator_skipping(ctx, map, SKIPPED_RUNNING)
}

/// [`decorator`] answering `skipped` when the child is SKIPPED (under BT.CPP's rules).
pub(super) fn decorator_skipping(ctx: &Ctx, map: [u8; 3], skipped: u8) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    let mut data = vec![("children_count".to_string(), "int8", n_children(ctx))];
    data.extend(ctx.running_data());
    let data: Vec<(&str, &str, String)> = data
        .iter()
        .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
        .collect();
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count != 1"));
    let mut w = b.state("wait_for_tick").with_child(b.tr(
        Some(&ctx.tick_ev()),
        None,
        Some("tick_child"),
        vec![],
    ));
    for t in ctx.halt_single("halting_child", Vec::new()) {
        w.push(t);
    }
    m.push(w);
    m.push(ctx.halting_child_state());
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for (from, to) in [SUCCESS, FAILURE, RUNNING].into_iter().zip(map) {
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {from}")),
            Some("wait_for_tick"),
            ctx.marked(0, from, vec![ctx.respond(to)]),
        ));
    }
    if ctx.btcpp {
        let mut body: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
        body.push(ctx.respond(skipped));
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(IS_SKIPPED),
            Some("wait_for_tick"),
            body,
        ));
    }
    m.push(t);
    m.push(b.state("error"));
    m
}

/// Repeat (`retry` false: SUCCESS ticks the child again, up to `n` times, FAILURE stops)
/// or RetryUntilSuccessful (`retry`: FAILURE ticks again up to `n` attempts, SUCCESS
/// stops), within one tick; `n == -1` never stops.
///
/// Who halts the child after a finished attempt differs, and we follow AS2FM:
/// `repeat_node.ascxml` halts it after every attempt (`bt_halt_child` in its `tick_child`
/// state), `retry_node.ascxml` never does: it ticks again, so a SequenceWithMemory that
/// failed resumes at the failed child on the next attempt. BT.CPP (`RetryNode::tick`,
/// `RepeatNode::tick`) calls `DecoratorNode::resetChild`, which halts only a RUNNING
/// child, i.e. never after a finished attempt: for Repeat AS2FM's reading differs (a
/// SequenceWithMemory that failed under a Repeat starts again from its first child);
/// see README, "BT semantics".
pub(super) fn repeat(ctx: &Ctx, n: i64, retry: bool) -> Element {
    if retry {
        return retry_node(ctx, n);
    }
    let b = &ctx.b;
    let (count, limit) = ("cycle_count", "n_cycles");
    let (again, stop) = (SUCCESS, FAILURE);
    let more = format!("{limit} == -1 || {count} < {limit}");
    let mut m = repeat_head(ctx, count, limit, n, "start_tick");
    // Out of cycles: Repeat succeeded.
    m.push(attempt_or_answer(ctx, "start_tick", &more, count, again));
    m.push(
        b.state("handle_tick_loop")
            .with_child(b.tr(
                Some(&ctx.child_halt_resp(0)),
                Some(&more),
                Some("tick_child"),
                vec![],
            ))
            .with_child(b.tr(
                Some(&ctx.child_halt_resp(0)),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond(again), b.assign(count, "0")],
            )),
    );
    m.push(b.state("handle_failure").with_child(b.tr(
        Some(&ctx.child_halt_resp(0)),
        None,
        Some("wait_for_tick"),
        vec![ctx.respond(stop)],
    )));
    // A child that finished an attempt is idle: halted only if that does more.
    let halts = ctx.effect(0) == HaltEffect::Always;
    let (again_to, again_body, stop_to, stop_body) = if halts {
        (
            "handle_tick_loop",
            vec![b.assign(count, &format!("{count} + 1")), ctx.halt_child(0)],
            "handle_failure",
            vec![b.assign(count, "0"), ctx.halt_child(0)],
        )
    } else {
        (
            "start_tick",
            vec![b.assign(count, &format!("{count} + 1"))],
            "wait_for_tick",
            vec![b.assign(count, "0"), ctx.respond(stop)],
        )
    };
    m.push(repeat_tick_child(
        ctx, again, again_to, again_body, stop, stop_to, stop_body,
    ));
    m.push(b.state("error"));
    m
}

/// RetryUntilSuccessful as AS2FM's `retry_node.ascxml`: `handle_tick` ticks the child
/// while attempts are left (else FAILURE); a FAILURE counts an attempt and goes back to
/// `handle_tick` with no halt; SUCCESS answers at once.
fn retry_node(ctx: &Ctx, n: i64) -> Element {
    let b = &ctx.b;
    let (count, limit) = ("try_count", "max_attempts");
    let more = format!("{limit} == -1 || {count} < {limit}");
    let mut m = repeat_head(ctx, count, limit, n, "handle_tick");
    m.push(attempt_or_answer(ctx, "handle_tick", &more, count, FAILURE));
    m.push(repeat_tick_child(
        ctx,
        FAILURE,
        "handle_tick",
        vec![b.assign(count, &format!("{count} + 1"))],
        SUCCESS,
        "wait_for_tick",
        vec![ctx.respond(SUCCESS), b.assign(count, "0")],
    ));
    m.push(b.state("error"));
    m
}

/// The datamodel, init, `wait_for_tick` (a tick goes to `start`) and `halting_child` of
/// Repeat and RetryUntilSuccessful, AS2FM's and BT.CPP's alike.
pub(super) fn repeat_head(ctx: &Ctx, count: &str, limit: &str, n: i64, start: &str) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    let flags = ctx.running_data();
    let mut data = vec![
        ("children_count", "int8", n_children(ctx)),
        (count, "int8", "0".into()),
        (limit, "int8", n.to_string()),
    ];
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count != 1"));
    let mut w =
        b.state("wait_for_tick")
            .with_child(b.tr(Some(&ctx.tick_ev()), None, Some(start), vec![]));
    for t in ctx.halt_single("halting_child", vec![b.assign(count, "0")]) {
        w.push(t);
    }
    m.push(w);
    let mut halting = ctx.halt_child_body(0);
    halting.push(b.assign(count, "0"));
    m.push(b.state_entry("halting_child", halting).with_child(b.tr(
        Some(&ctx.child_halt_resp(0)),
        None,
        Some("wait_for_tick"),
        vec![ctx.respond_halted()],
    )));
    m
}

/// State `name` of Repeat / RetryUntilSuccessful: ticks the child while `more` holds, else
/// answers `status` and resets `count`.
fn attempt_or_answer(ctx: &Ctx, name: &str, more: &str, count: &str, status: u8) -> Element {
    let b = &ctx.b;
    b.state(name)
        .with_child(b.tr(None, Some(more), Some("tick_child"), vec![]))
        .with_child(b.tr(
            None,
            None,
            Some("wait_for_tick"),
            vec![ctx.respond(status), b.assign(count, "0")],
        ))
}

/// `tick_child` of Repeat / RetryUntilSuccessful: `again` goes to `again_to` doing
/// `again_body`, `stop` to `stop_to` doing `stop_body`, RUNNING answers RUNNING.
#[allow(clippy::too_many_arguments)]
fn repeat_tick_child(
    ctx: &Ctx,
    again: u8,
    again_to: &str,
    again_body: Vec<Element>,
    stop: u8,
    stop_to: &str,
    stop_body: Vec<Element>,
) -> Element {
    let b = &ctx.b;
    b.state_entry("tick_child", vec![ctx.tick_child(0)])
        .with_child(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {again}")),
            Some(again_to),
            ctx.marked(0, again, again_body),
        ))
        .with_child(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {stop}")),
            Some(stop_to),
            ctx.marked(0, stop, stop_body),
        ))
        .with_child(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {RUNNING}")),
            Some("wait_for_tick"),
            ctx.marked(0, RUNNING, vec![ctx.respond(RUNNING)]),
        ))
}

/// AlwaysSuccess / AlwaysFailure.
pub(super) fn constant(ctx: &Ctx, status: u8) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    m.push(b.datamodel(&[("children_count", "int8", "0".into())]));
    m.push(
        b.state("init")
            .with_child(b.tr(None, Some("children_count != 0"), Some("error"), vec![]))
            .with_child(b.tr(None, None, Some("idle"), vec![])),
    );
    m.push(
        b.state("idle")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("idle"),
                vec![ctx.respond(status)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("idle"),
                vec![ctx.respond_halted()],
            )),
    );
    m.push(b.state("error"));
    m
}
