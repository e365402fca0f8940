//! The machines of the nodes whose BehaviorTree.CPP 4 rules differ from AS2FM's models
//! ([`super::BtSemantics::Btcpp`]): SequenceWithMemory, Parallel, Repeat and
//! RetryUntilSuccessful; the root machine under `tickOnce` is `control.rs`'s
//! `root_machine` with the wake-up signal.
//!
//! The other built-in nodes keep AS2FM's machines, with every child's halt conditional on
//! the child having last answered RUNNING (`child_<i>_running`, the `WhenRunning` rule
//! of `control.rs`): that is BT.CPP's `ControlNode::haltChild` /
//! `DecoratorNode::resetChild` (BT.CPP 4.10 `src/control_node.cpp`,
//! `src/decorator_node.cpp`: halt only a RUNNING child, then reset its status), and the
//! rest of those nodes' rules agree with AS2FM's.
//!
//! # Wake-up yields
//! A tree created from XML gives every node the wake-up signal (`requiresWakeUp()` is
//! true), so SequenceWithMemory, Repeat and RetryUntilSuccessful answer RUNNING after a
//! child that was IDLE when ticked finishes while more work remains, emitting the signal
//! (`TreeNode::emitWakeUpSignal`). A child's status at the start of its tick is IDLE or
//! RUNNING for these three nodes (they reset every child that finished before ticking it
//! again), so "was IDLE" is `!child_<i>_running` before the answer is recorded. Under
//! `tickOnce` the node sends `bt_wake_up` to the root machine, which ticks the root again
//! at once if it answers RUNNING (BT.CPP 4 `bt_factory.cpp`, `Tree::tickRoot`: `while
//! (opt != EXACTLY_ONCE && status == RUNNING && wake_up_->waitFor(0))`); a signal
//! emitted in a tick whose root finished stays pending (`waitFor` is not called then) and
//! is taken by the next tick that answers RUNNING.
//!
//! # Leaves
//! A leaf plugin that may answer RUNNING stands for a stateful action (BT.CPP 4
//! `action_node.cpp`, `StatefulActionNode::tick`: ticked in a finished status that its
//! parent did not reset, it answers that status again without running); one that never
//! does for a synchronous node (a `ConditionNode` or `SyncActionNode`, whose every tick
//! runs it; `plugin.rs`, `Plugin::may_run`). The parents that tick a child they did not
//! reset are a two-child IfThenElse whose condition failed (`parallel.rs`,
//! `if_then_else`) and WhileDoElse, whose condition is ticked while a branch runs
//! (`btcpp4_skip.rs`, `stale`).

use super::control::{
    index_out_of_range, init_state, n_children, on_child_skipped, skip_to_next, Ctx, FAILURE,
    IS_SKIPPED, RUNNING, SKIPPED_RUNNING, SKIP_COUNT, SUCCESS,
};
use crate::model::xml::Element;

/// The event a node sends the root machine when it emits the wake-up signal.
pub(crate) const WAKE_UP: &str = "bt_wake_up";

/// The root machine's flag: a wake-up signal is pending.
pub(super) const WAKE_PENDING: &str = "wake_pending";

/// The variable naming child `i`'s RUNNING flag (every child has one under BT.CPP's
/// rules).
pub(super) fn running(ctx: &Ctx, i: usize) -> String {
    ctx.running_var(i)
        .expect("under BT.CPP's rules every child is WhenRunning")
}

/// Answers RUNNING after emitting the wake-up signal (sent only when someone listens).
pub(super) fn yield_running(ctx: &Ctx) -> Vec<Element> {
    let mut v: Vec<Element> = ctx
        .wake
        .iter()
        .map(|root| ctx.b.send(WAKE_UP, root))
        .collect();
    v.push(ctx.respond(RUNNING));
    v
}

/// A state `name` that halts, in child order from the value of `var` on, every child
/// that last answered RUNNING and resets the others' flags (BT.CPP 4.10
/// `control_node.cpp`, `ControlNode::haltChildren(first)` / `haltChild`), then goes to
/// `wait_for_tick` doing `finish`. Whoever enters it sets `var` first.
pub(super) fn halting_state(ctx: &Ctx, name: &str, var: &str, finish: Vec<Element>) -> Element {
    let b = &ctx.b;
    let mut entry = ctx.skip_idle(var, None);
    entry.push(b.if_then(
        &format!("{var} < children_count"),
        vec![ctx.dispatch(var, true)],
    ));
    let mut s = b.state_entry(name, entry);
    for i in 0..ctx.children.len() {
        s.push(b.tr(
            Some(&ctx.child_halt_resp(i)),
            Some(&format!("{var} == {i}")),
            Some(name),
            vec![b.assign(var, &format!("{var} + 1"))],
        ));
    }
    s.push(b.tr(
        None,
        Some(&format!("{var} >= children_count")),
        Some("wait_for_tick"),
        finish,
    ));
    s
}

/// SequenceWithMemory as BT.CPP 4.10 runs it (`sequence_with_memory_node.cpp`):
/// - `SequenceWithMemory::tick`: a SUCCESS moves to the next child; if that child was
///   IDLE when ticked and children remain, the node yields (wake-up, RUNNING); RUNNING
///   answers RUNNING; FAILURE halts the children from the failed one on
///   (`haltChild(i)` for `i >= current_child_idx_`) and answers FAILURE keeping the
///   index; all children done resets them (`resetChildren`) and the index.
/// - `SequenceWithMemory::halt` keeps the index and resets the children.
pub(super) fn sequence_with_memory(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let (idx, h) = ("current_child_idx", "halt_idx");
    let mut m = b.scxml(&ctx.machine, "init");
    let flags = ctx.running_data();
    let mut data = vec![
        (idx, "int8", "0".to_string()),
        (h, "int8", "0".to_string()),
        ("children_count", "int8", n_children(ctx)),
        (SKIP_COUNT, "int8", "0".to_string()),
    ];
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 1"));
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_children"), vec![]))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("halting_on_halt"),
                vec![b.assign(h, "0")],
            )),
    );
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, false)],
    );
    let mut t = b.state_entry("tick_children", vec![guard]);
    // 4.10 `SequenceWithMemory::tick`, `case NodeStatus::SKIPPED`: on to the next child,
    // counted in `skipped_count_` (cleared when the node starts IDLE: after it finished,
    // was halted, or failed and was reset by its parent).
    skip_to_next(ctx, &mut t, idx, "tick_children");
    for i in 0..ctx.children.len() {
        let r = running(ctx, i);
        let resp = ctx.child_resp(i);
        let is = |s: u8| format!("_event.data.status == {s} && {idx} == {i}");
        // Started IDLE, more children left: yield.
        let mut body = vec![b.assign(&r, "false"), b.assign(idx, &format!("{idx} + 1"))];
        body.extend(yield_running(ctx));
        t.push(b.tr(
            Some(&resp),
            Some(&format!(
                "{} && !{r} && {idx} + 1 < children_count",
                is(SUCCESS)
            )),
            Some("wait_for_tick"),
            body,
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(SUCCESS)),
            Some("tick_children"),
            vec![b.assign(&r, "false"), b.assign(idx, &format!("{idx} + 1"))],
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(FAILURE)),
            Some("halting_on_failure"),
            vec![b.assign(&r, "false"), b.assign(h, idx)],
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(RUNNING)),
            Some("wait_for_tick"),
            vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
        ));
    }
    t.push(b.tr(
        None,
        Some(&format!("{idx} == children_count")),
        Some("halting_on_success"),
        vec![b.assign(h, "0")],
    ));
    t.push(index_out_of_range(ctx, idx));
    m.push(t);
    // Every child skipped: SKIPPED (the node set itself RUNNING first).
    let all_skipped = b
        .if_chain(
            vec![(
                format!("{SKIP_COUNT} == children_count"),
                vec![ctx.respond(SKIPPED_RUNNING)],
            )],
            vec![ctx.respond(SUCCESS)],
        )
        .expect("one branch");
    m.push(halting_state(
        ctx,
        "halting_on_success",
        h,
        vec![b.assign(idx, "0"), all_skipped, b.assign(SKIP_COUNT, "0")],
    ));
    // The count is left as it is (a parent resets the node before ticking it again,
    // which restarts it), except where BT.CPP may tick it again without a reset
    // (`Ctx::stale`): there it carries over (`!isStatusActive(status())` is false).
    let mut on_failure = vec![ctx.respond(FAILURE)];
    if !ctx.stale {
        on_failure.push(b.assign(SKIP_COUNT, "0"));
    }
    m.push(halting_state(ctx, "halting_on_failure", h, on_failure));
    m.push(halting_state(
        ctx,
        "halting_on_halt",
        h,
        vec![ctx.respond_halted(), b.assign(SKIP_COUNT, "0")],
    ));
    m.push(b.state("error"));
    m
}

/// Repeat (`retry` false) or RetryUntilSuccessful (`retry`) as BT.CPP 4.10 runs them
/// (`decorators/repeat_node.cpp`, `RepeatNode::tick`; `decorators/retry_node.cpp`,
/// `RetryNode::tick`): while attempts are left the child is ticked; the status that
/// repeats (SUCCESS for Repeat, FAILURE for Retry) counts an attempt and resets the
/// child (`resetChild`: no halt, it is not RUNNING), then yields (wake-up, RUNNING) if
/// the child was IDLE when ticked and attempts remain, else ticks it again at once; the
/// other status resets the count and is the answer; RUNNING is the answer. No attempt
/// left answers the repeating status (Repeat SUCCESS, Retry FAILURE) and resets the
/// count. `halt` resets the count and halts the child if RUNNING (`RepeatNode::halt`,
/// `RetryNode::halt`). `n == -1` never runs out.
pub(super) fn repeat(ctx: &Ctx, n: i64, retry: bool) -> Element {
    let b = &ctx.b;
    let (count, limit) = if retry {
        ("try_count", "max_attempts")
    } else {
        ("cycle_count", "n_cycles")
    };
    let (again, stop) = if retry {
        (FAILURE, SUCCESS)
    } else {
        (SUCCESS, FAILURE)
    };
    let r = running(ctx, 0);
    let mut m = super::decorators::repeat_head(ctx, count, limit, n, "start_tick");
    // `do_loop = count < limit || limit == -1`, checked before every attempt.
    m.push(
        b.state("start_tick")
            .with_child(b.tr(
                None,
                Some(&format!("{limit} == -1 || {count} < {limit}")),
                Some("tick_child"),
                vec![],
            ))
            .with_child(b.tr(
                None,
                None,
                Some("wait_for_tick"),
                vec![b.assign(count, "0"), ctx.respond(again)],
            )),
    );
    let resp = ctx.child_resp(0);
    let is = |s: u8| format!("_event.data.status == {s}");
    let mut yielding = vec![
        b.assign(&r, "false"),
        b.assign(count, &format!("{count} + 1")),
    ];
    yielding.extend(yield_running(ctx));
    m.push(
        b.state_entry("tick_child", vec![ctx.tick_child(0)])
            .with_child(b.tr(
                Some(&resp),
                Some(&format!(
                    "{} && !{r} && ({limit} == -1 || {count} + 1 < {limit})",
                    is(again)
                )),
                Some("wait_for_tick"),
                yielding,
            ))
            .with_child(b.tr(
                Some(&resp),
                Some(&is(again)),
                Some("start_tick"),
                vec![
                    b.assign(&r, "false"),
                    b.assign(count, &format!("{count} + 1")),
                ],
            ))
            .with_child(b.tr(
                Some(&resp),
                Some(&is(stop)),
                Some("wait_for_tick"),
                vec![
                    b.assign(&r, "false"),
                    b.assign(count, "0"),
                    ctx.respond(stop),
                ],
            ))
            .with_child(b.tr(
                Some(&resp),
                Some(&is(RUNNING)),
                Some("wait_for_tick"),
                vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
            ))
            // 4.10 `RepeatNode::tick` / `RetryNode::tick`, `case NodeStatus::SKIPPED`:
            // `resetChild()` (a halt only if it still runs, code 5) and SKIPPED, the
            // count kept.
            .with_child(b.tr(
                Some(&resp),
                Some(&format!("_event.data.status == {SKIPPED_RUNNING}")),
                Some("halting_skipped"),
                ctx.halt_child_body(0),
            ))
            .with_child(b.tr(
                Some(&resp),
                Some(IS_SKIPPED),
                Some("wait_for_tick"),
                vec![b.assign(&r, "false"), ctx.respond(SKIPPED_RUNNING)],
            )),
    );
    m.push(b.state("halting_skipped").with_child(b.tr(
        Some(&ctx.child_halt_resp(0)),
        None,
        Some("wait_for_tick"),
        vec![ctx.respond(SKIPPED_RUNNING)],
    )));
    m.push(b.state("error"));
    m
}

/// Parallel as BT.CPP 4.10 runs it (`controls/parallel_node.cpp`, `ParallelNode::tick`):
/// each tick goes over the children in order, ticking only those not yet finished
/// (`completed_list_`), the counts adding up across ticks; after each child it answers
/// SUCCESS when `success` children succeeded, FAILURE when success is out of reach
/// (`children_count - failure_count < success`) or `failure` children failed, in both
/// cases clearing what it remembers and resetting the children (`clear`,
/// `resetChildren`); RUNNING after the last child. `ParallelNode::halt` clears and
/// resets the children. The thresholds are already resolved (`-1`: all children).
///
/// SKIPPED (4.10 `ParallelNode::tick`): a skipped child is not finished; the children
/// skipped in this tick count towards a success threshold written negative
/// (`success_neg`), and every child skipped answers SKIPPED (the node set itself
/// RUNNING first).
pub(super) fn parallel(ctx: &Ctx, success: i64, failure: i64, success_neg: bool) -> Element {
    let b = &ctx.b;
    let (idx, h) = ("current_child_idx", "halt_idx");
    let n = ctx.children.len();
    let done = |i: usize| format!("child_{i}_done");
    let mut m = b.scxml(&ctx.machine, "init");
    let mut data: Vec<(String, &str, String)> = vec![
        ("children_count".into(), "int8", n_children(ctx)),
        ("success_threshold".into(), "int8", success.to_string()),
        ("failure_threshold".into(), "int8", failure.to_string()),
        (idx.into(), "int8", "0".into()),
        (h.into(), "int8", "0".into()),
        ("success_count".into(), "int8", "0".into()),
        ("failure_count".into(), "int8", "0".into()),
        (SKIP_COUNT.into(), "int8", "0".into()),
    ];
    data.extend((0..n).map(|i| (done(i), "bool", "false".to_string())));
    data.extend(ctx.running_data());
    let data: Vec<(&str, &str, String)> = data
        .iter()
        .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
        .collect();
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 1"));
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("tick_current_child"),
                vec![b.assign(idx, "0"), b.assign(SKIP_COUNT, "0")],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("halting_on_halt"),
                vec![b.assign(h, "0")],
            )),
    );
    // Tick the current child unless it finished in an earlier tick.
    let tick = b
        .if_chain(
            (0..n)
                .map(|i| {
                    (
                        format!("{idx} == {i} && !{}", done(i)),
                        vec![ctx.tick_child(i)],
                    )
                })
                .collect(),
            Vec::new(),
        )
        .expect("Parallel has children");
    let mut t = b.state_entry("tick_current_child", vec![tick]);
    t.push(b.tr(
        None,
        Some(&format!(
            "{idx} >= children_count && {SKIP_COUNT} == children_count"
        )),
        Some("wait_for_tick"),
        vec![ctx.respond(SKIPPED_RUNNING)],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("wait_for_tick"),
        vec![ctx.respond(RUNNING)],
    ));
    on_child_skipped(ctx, &mut t, idx, "eval_after_child", || {
        vec![b.assign(SKIP_COUNT, &format!("{SKIP_COUNT} + 1"))]
    });
    for i in 0..n {
        t.push(b.tr(
            None,
            Some(&format!("{idx} == {i} && {}", done(i))),
            Some("eval_after_child"),
            vec![],
        ));
    }
    for i in 0..n {
        let r = running(ctx, i);
        for (status, body) in [
            (
                SUCCESS,
                vec![
                    b.assign(&r, "false"),
                    b.assign(&done(i), "true"),
                    b.assign("success_count", "success_count + 1"),
                ],
            ),
            (
                FAILURE,
                vec![
                    b.assign(&r, "false"),
                    b.assign(&done(i), "true"),
                    b.assign("failure_count", "failure_count + 1"),
                ],
            ),
            (RUNNING, vec![b.assign(&r, "true")]),
        ] {
            t.push(b.tr(
                Some(&ctx.child_resp(i)),
                Some(&format!("_event.data.status == {status} && {idx} == {i}")),
                Some("eval_after_child"),
                body,
            ));
        }
    }
    m.push(t);
    m.push(
        b.state("eval_after_child")
            .with_child(b.tr(
                None,
                Some(&if success_neg {
                    format!("success_count + {SKIP_COUNT} >= success_threshold")
                } else {
                    "success_count >= success_threshold".to_string()
                }),
                Some("halting_after_success"),
                vec![b.assign(h, "0")],
            ))
            .with_child(b.tr(
                None,
                Some(
                    "children_count - failure_count < success_threshold \
                     || failure_count == failure_threshold",
                ),
                Some("halting_after_failure"),
                vec![b.assign(h, "0")],
            ))
            .with_child(b.tr(
                None,
                None,
                Some("tick_current_child"),
                vec![b.assign(idx, &format!("{idx} + 1"))],
            )),
    );
    // `ParallelNode::clear`.
    let clear = || {
        let mut v = vec![
            b.assign("success_count", "0"),
            b.assign("failure_count", "0"),
        ];
        v.extend((0..n).map(|i| b.assign(&done(i), "false")));
        v
    };
    for (state, answer) in [
        ("halting_after_success", ctx.respond(SUCCESS)),
        ("halting_after_failure", ctx.respond(FAILURE)),
        ("halting_on_halt", ctx.respond_halted()),
    ] {
        let mut finish = clear();
        finish.push(answer);
        m.push(halting_state(ctx, state, h, finish));
    }
    m.push(b.state("error"));
    m
}
