//! The machines of BehaviorTree.CPP 4's built-in nodes that AS2FM has no model of,
//! lowered under [`super::BtSemantics::Btcpp`] only: AsyncSequence, AsyncFallback,
//! ParallelAll, WhileDoElse, KeepRunningUntilFailure, RunOnce and Switch2 ... Switch6 (the
//! last in `btcpp4_switch.rs`).
//!
//! They follow the same conventions as `btcpp.rs`: every child has its RUNNING flag
//! (`child_<i>_running`) and is halted only while it is set (BT.CPP 4.10
//! `control_node.cpp`, `ControlNode::haltChild`; `decorator_node.cpp`,
//! `DecoratorNode::resetChild`), yields emit the wake-up signal to the root machine
//! under `tickOnce`, and a leaf plugin is a stateful action that answers its last
//! finished status again, without running, when ticked before its parent reset it
//! (WhileDoElse's condition is the one such child here). Every rule is cited from the
//! BT.CPP 4.10 source beside the code; `tests/tests/bt_btcpp_lowering.rs` holds the
//! machines to the oracle's BT.CPP 4 reading, which `tests/tests/bt_real.rs` holds to the
//! real library.

use super::blackboard::Blackboard;
use super::btcpp::{halting_state, running, yield_running};
use super::control::{
    index_out_of_range, init_state, n_children, on_child_skipped, skip_to_next, Ctx, FAILURE,
    IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING, SKIP_COUNT, SUCCESS,
};
use super::tree::{Btcpp4, PortValue, ScriptNode, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

/// The node's name in a tree.
pub(super) fn node_name(k: Btcpp4) -> String {
    match k {
        Btcpp4::AsyncSequence => "AsyncSequence".into(),
        Btcpp4::AsyncFallback => "AsyncFallback".into(),
        Btcpp4::ParallelAll => "ParallelAll".into(),
        Btcpp4::WhileDoElse => "WhileDoElse".into(),
        Btcpp4::KeepRunningUntilFailure => "KeepRunningUntilFailure".into(),
        Btcpp4::RunOnce => "RunOnce".into(),
        Btcpp4::Switch(n) => format!("Switch{n}"),
        Btcpp4::Timeout => "Timeout".into(),
        Btcpp4::Delay => "Delay".into(),
        Btcpp4::Sleep => "Sleep".into(),
        Btcpp4::TryCatch => "TryCatch".into(),
        Btcpp4::Unset => "UnsetBlackboard".into(),
        Btcpp4::Updated(u) => super::btcpp4_blackboard::updated_name(u).into(),
        Btcpp4::Loop(t) => super::btcpp4_loop::loop_name(t).into(),
        Btcpp4::SubTree => "SubTree (with pre/post conditions)".into(),
        Btcpp4::Script(s) => match s {
            ScriptNode::Script => "Script".into(),
            ScriptNode::Condition => "ScriptCondition".into(),
            ScriptNode::Precondition => "Precondition".into(),
        },
    }
}

/// The error for node `n` under AS2FM's rules (`--bt as2fm`, the default).
pub(super) fn as2fm_refusal(k: Btcpp4) -> String {
    format!(
        "`{}` is a BehaviorTree.CPP 4 node that AS2FM has no model of, so the default semantics (`--bt as2fm`) cannot lower it: use `--bt btcpp` (BehaviorTree.CPP 4's rules)",
        node_name(k)
    )
}

/// Checks node `n`'s ports and builds its machine (under BT.CPP's rules only).
pub(super) fn lower(
    sm: &SourceMap,
    k: Btcpp4,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    match k {
        Btcpp4::AsyncSequence => Some(async_sequence(ctx, SUCCESS, FAILURE)),
        Btcpp4::AsyncFallback => Some(async_sequence(ctx, FAILURE, SUCCESS)),
        Btcpp4::WhileDoElse => Some(while_do_else(ctx)),
        // `KeepRunningUntilFailureNode::tick` (4.10 `decorators/
        // keep_running_until_failure_node.h`): a finished child is reset
        // (`resetChild`), its SUCCESS answered RUNNING (no wake-up), its FAILURE
        // FAILURE, RUNNING RUNNING: the one-child decorator's machine. A SKIPPED child
        // is not reset and the node answers `status()`, the RUNNING it set itself.
        Btcpp4::KeepRunningUntilFailure => Some(super::decorators::decorator_skipping(
            ctx,
            [RUNNING, FAILURE, RUNNING],
            RUNNING,
        )),
        Btcpp4::ParallelAll => {
            // `max_failures` defaults to 1 (`ParallelAllNode::providedPorts`).
            let before = errs.len();
            let (f, span) = super::int_param(sm, n, &["max_failures"], errs).unwrap_or((1, n.span));
            let count = ctx.children.len() as i64;
            // `setFailureThreshold`.
            let th = if f < 0 { (count + f + 1).max(0) } else { f };
            if th > count {
                errs.push(sm.diag(
                    span,
                    format!("`max_failures` {f} is more than the {count} children: BehaviorTree.CPP throws at the first tick (\"Number of children is less than threshold\")"),
                ));
                return None;
            }
            (errs.len() == before).then(|| parallel_all(ctx, th))
        }
        Btcpp4::RunOnce => {
            // `then_skip` defaults to true (`RunOnceNode::providedPorts`); read with
            // `convertFromString<bool>`.
            let skip = match n.port("then_skip").map(|p| (&p.value, p.span)) {
                None => None,
                Some((PortValue::Literal(v), span)) => match v.trim() {
                    "false" | "False" | "FALSE" | "0" => Some((false, span)),
                    "true" | "True" | "TRUE" | "1" => Some((true, span)),
                    other => {
                        errs.push(sm.diag(
                            span,
                            format!("`then_skip` must be true or false, not `{other}`"),
                        ));
                        return None;
                    }
                },
                Some((PortValue::Blackboard(b), span)) => {
                    errs.push(sm.diag(
                        span,
                        format!("`then_skip` must be a constant; a blackboard entry (`{{{b}}}`) is not supported here"),
                    ));
                    return None;
                }
            };
            Some(run_once(ctx, skip.is_none_or(|(s, _)| s)))
        }
        // `mod.rs` lowers them with `btcpp4_time.rs`, which needs the tree's clock.
        Btcpp4::Timeout | Btcpp4::Delay | Btcpp4::Sleep | Btcpp4::TryCatch => None,
        Btcpp4::Script(s) => super::btcpp4_script::lower(sm, s, n, ctx, bb, errs),
        Btcpp4::Unset => super::btcpp4_blackboard::unset(sm, n, ctx, bb, errs),
        Btcpp4::Updated(u) => super::btcpp4_blackboard::updated(sm, u, n, ctx, bb, errs),
        Btcpp4::Loop(t) => super::btcpp4_loop::lower(sm, t, n, ctx, bb, errs),
        Btcpp4::SubTree => Some(super::btcpp4_subtree::machine(ctx)),
        Btcpp4::Switch(cases) => {
            let pick = super::btcpp4_switch::pick(sm, k, cases as usize, n, bb, errs)?;
            if matches!(pick, super::btcpp4_switch::SwitchPick::Entry(..)) {
                bb.add_reader(&ctx.machine);
            }
            Some(super::btcpp4_switch::switch(ctx, &pick))
        }
    }
}

/// The datamodel entries: `vars` then the children's RUNNING flags.
fn data(ctx: &Ctx, vars: &[(&str, &str, String)]) -> Vec<(String, &'static str, String)> {
    let mut out: Vec<(String, &'static str, String)> = vars
        .iter()
        .map(|(v, t, e)| {
            let t: &'static str = match *t {
                "bool" => "bool",
                _ => "int8",
            };
            (v.to_string(), t, e.clone())
        })
        .collect();
    out.extend(ctx.running_data());
    out
}

pub(super) fn push_data(ctx: &Ctx, m: &mut Element, vars: &[(&str, &str, String)]) {
    let d = data(ctx, vars);
    let d: Vec<(&str, &str, String)> = d
        .iter()
        .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
        .collect();
    m.push(ctx.b.datamodel(&d));
}

/// AsyncSequence (`cont` SUCCESS, `stop` FAILURE) or AsyncFallback (`cont` FAILURE,
/// `stop` SUCCESS) as BT.CPP 4.10 runs them: `SequenceNode::tick` /
/// `FallbackNode::tick` (`controls/sequence_node.cpp`, `controls/fallback_node.cpp`)
/// registered with `make_async` true. A child answering `cont` moves to the next; if it
/// was IDLE when ticked and children remain, the node yields (wake-up, RUNNING); `stop`
/// resets every child (`resetChildren`: halts the RUNNING ones) and the index and answers
/// `stop`; RUNNING answers RUNNING, the next tick resuming at that child; all children
/// done resets them and the index and answers `cont`. `SequenceNode::halt` /
/// `FallbackNode::halt` set the index back to 0 and reset the children.
pub(super) fn async_sequence(ctx: &Ctx, cont: u8, stop: u8) -> Element {
    let b = &ctx.b;
    let (idx, h) = ("current_child_idx", "halt_idx");
    let mut m = b.scxml(&ctx.machine, "init");
    push_data(
        ctx,
        &mut m,
        &[
            (idx, "int8", "0".into()),
            (h, "int8", "0".into()),
            ("children_count", "int8", n_children(ctx)),
            (SKIP_COUNT, "int8", "0".into()),
        ],
    );
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
    for i in 0..ctx.children.len() {
        let r = running(ctx, i);
        let resp = ctx.child_resp(i);
        let is = |s: u8| format!("_event.data.status == {s} && {idx} == {i}");
        // `asynch_ && requiresWakeUp() && prev_status == IDLE && current_child_idx_ <
        // children_count`: a child that started idle finished with children left.
        let mut body = vec![b.assign(&r, "false"), b.assign(idx, &format!("{idx} + 1"))];
        body.extend(yield_running(ctx));
        t.push(b.tr(
            Some(&resp),
            Some(&format!(
                "{} && !{r} && {idx} + 1 < children_count",
                is(cont)
            )),
            Some("wait_for_tick"),
            body,
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(cont)),
            Some("tick_children"),
            vec![b.assign(&r, "false"), b.assign(idx, &format!("{idx} + 1"))],
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(stop)),
            Some("halting_on_stop"),
            vec![b.assign(&r, "false"), b.assign(h, "0")],
        ));
        t.push(b.tr(
            Some(&resp),
            Some(&is(RUNNING)),
            Some("wait_for_tick"),
            vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
        ));
    }
    // `case NodeStatus::SKIPPED`: on to the next child, counted (`skipped_count_`).
    skip_to_next(ctx, &mut t, idx, "tick_children");
    t.push(b.tr(
        None,
        Some(&format!("{idx} == children_count")),
        Some("halting_on_cont"),
        vec![b.assign(h, "0")],
    ));
    t.push(index_out_of_range(ctx, idx));
    m.push(t);
    // Every child skipped answers SKIPPED (the node set itself RUNNING first).
    let on_cont = b
        .if_chain(
            vec![(
                format!("{SKIP_COUNT} == children_count"),
                vec![ctx.respond(SKIPPED_RUNNING)],
            )],
            vec![ctx.respond(cont)],
        )
        .expect("one branch");
    for (state, answer) in [
        ("halting_on_cont", on_cont),
        ("halting_on_stop", ctx.respond(stop)),
        ("halting_on_halt", ctx.respond_halted()),
    ] {
        let mut finish = vec![b.assign(idx, "0"), answer];
        // `stop` leaves `skipped_count_`: it carries over where BT.CPP may tick the
        // node again without a reset (`Ctx::stale`).
        if !(ctx.stale && state == "halting_on_stop") {
            finish.push(b.assign(SKIP_COUNT, "0"));
        }
        m.push(halting_state(ctx, state, h, finish));
    }
    m.push(b.state("error"));
    m
}

/// ParallelAll as BT.CPP 4.10 runs it (`controls/parallel_all_node.cpp`,
/// `ParallelAllNode::tick`): every tick ticks, in order, each child that has not
/// finished since the node last finished (`completed_list_`), counting failures across
/// ticks; when every child has finished it resets the children (`haltChildren`: none is
/// RUNNING then), forgets what it counted and answers FAILURE if at least `threshold`
/// children failed, else SUCCESS; otherwise RUNNING. `ParallelAllNode::halt` forgets and
/// resets the children. `threshold` is already resolved (`setFailureThreshold`: a
/// negative `max_failures` counts from the number of children, at least 0).
pub(super) fn parallel_all(ctx: &Ctx, threshold: i64) -> Element {
    let b = &ctx.b;
    let (idx, h) = ("current_child_idx", "halt_idx");
    let n = ctx.children.len();
    let done = |i: usize| format!("child_{i}_done");
    let mut m = b.scxml(&ctx.machine, "init");
    let mut vars: Vec<(String, &str, String)> = vec![
        ("children_count".into(), "int8", n_children(ctx)),
        ("failure_threshold".into(), "int8", threshold.to_string()),
        (idx.into(), "int8", "0".into()),
        (h.into(), "int8", "0".into()),
        ("done_count".into(), "int8", "0".into()),
        ("failure_count".into(), "int8", "0".into()),
        (SKIP_COUNT.into(), "int8", "0".into()),
    ];
    vars.extend((0..n).map(|i| (done(i), "bool", "false".to_string())));
    let vars: Vec<(&str, &str, String)> = vars
        .iter()
        .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
        .collect();
    push_data(ctx, &mut m, &vars);
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
        .expect("ParallelAll has children");
    let mut t = b.state_entry("tick_current_child", vec![tick]);
    // 4.10 `ParallelAllNode::tick`: a skipped child counts as finished for this tick only
    // (`skipped_count`); every child skipped answers SKIPPED (the node set itself
    // RUNNING first), nothing cleared.
    t.push(b.tr(
        None,
        Some(&format!(
            "{idx} >= children_count && {SKIP_COUNT} == children_count"
        )),
        Some("wait_for_tick"),
        vec![ctx.respond(SKIPPED_RUNNING)],
    ));
    on_child_skipped(ctx, &mut t, idx, "tick_current_child", || {
        vec![
            b.assign(SKIP_COUNT, &format!("{SKIP_COUNT} + 1")),
            b.assign(idx, &format!("{idx} + 1")),
        ]
    });
    t.push(b.tr(
        None,
        Some(&format!(
            "{idx} >= children_count && done_count + {SKIP_COUNT} >= children_count"
        )),
        Some("halting_when_done"),
        vec![b.assign(h, "0")],
    ));
    t.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("wait_for_tick"),
        vec![ctx.respond(RUNNING)],
    ));
    let next = || b.assign(idx, &format!("{idx} + 1"));
    for i in 0..n {
        // Already completed: `continue`.
        t.push(b.tr(
            None,
            Some(&format!("{idx} == {i} && {}", done(i))),
            Some("tick_current_child"),
            vec![next()],
        ));
    }
    for i in 0..n {
        let r = running(ctx, i);
        for (status, mut body) in [
            (
                SUCCESS,
                vec![b.assign(&r, "false"), b.assign(&done(i), "true")],
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
            if status != RUNNING {
                body.push(b.assign("done_count", "done_count + 1"));
            }
            body.push(next());
            t.push(b.tr(
                Some(&ctx.child_resp(i)),
                Some(&format!("_event.data.status == {status} && {idx} == {i}")),
                Some("tick_current_child"),
                body,
            ));
        }
    }
    m.push(t);
    let clear = || {
        let mut v = vec![b.assign("done_count", "0"), b.assign("failure_count", "0")];
        v.extend((0..n).map(|i| b.assign(&done(i), "false")));
        v
    };
    let mut finish = vec![b
        .if_chain(
            vec![(
                "failure_count >= failure_threshold".into(),
                vec![ctx.respond(FAILURE)],
            )],
            vec![ctx.respond(SUCCESS)],
        )
        .expect("one branch")];
    finish.extend(clear());
    m.push(halting_state(ctx, "halting_when_done", h, finish));
    let mut on_halt = clear();
    on_halt.push(ctx.respond_halted());
    m.push(halting_state(ctx, "halting_on_halt", h, on_halt));
    m.push(b.state("error"));
    m
}

/// WhileDoElse as BT.CPP 4.10 runs it (`controls/while_do_else_node.cpp`,
/// `WhileDoElseNode::tick`): the condition (child 0) is ticked on every tick; RUNNING is
/// the answer; SUCCESS halts the else branch (`haltChild(2)`, only if RUNNING) and ticks
/// the do branch (child 1); FAILURE halts the do branch and ticks the else branch (child
/// 2), or with two children is the answer. A RUNNING branch is the answer; a finished
/// answer resets every child (`resetChildren`). So while a branch runs the condition is
/// not reset: a leaf condition (a stateful action, `btcpp.rs`) then answers its last
/// status again without running (`cond_done`). `WhileDoElseNode::halt` resets the
/// children.
pub(super) fn while_do_else(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let h = "halt_idx";
    let stale = ctx.stateful.first() == Some(&true);
    let mut m = b.scxml(&ctx.machine, "init");
    let mut vars = vec![
        ("children_count", "int8", n_children(ctx)),
        (h, "int8", "0".into()),
        ("cond_status", "int8", "0".into()),
        ("branch", "int8", "0".into()),
        ("result", "int8", "0".into()),
    ];
    if stale {
        vars.push(("cond_done", "int8", "0".into()));
    }
    push_data(ctx, &mut m, &vars);
    m.push(init_state(ctx, "children_count < 2 || children_count > 3"));
    let mut w = b.state("wait_for_tick");
    if stale {
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            Some("cond_done > 0"),
            Some("choose_branch"),
            vec![b.assign("cond_status", "cond_done")],
        ));
    }
    m.push(
        w.with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_condition"), vec![]))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("halting_on_halt"),
                vec![b.assign(h, "0")],
            )),
    );
    let r0 = running(ctx, 0);
    let mut c = b.state_entry("tick_condition", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE] {
        let mut body = vec![
            b.assign(&r0, "false"),
            b.assign("cond_status", &s.to_string()),
        ];
        if stale {
            body.push(b.assign("cond_done", &s.to_string()));
        }
        c.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("choose_branch"),
            body,
        ));
    }
    c.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(&format!("_event.data.status == {RUNNING}")),
        Some("wait_for_tick"),
        vec![b.assign(&r0, "true"), ctx.respond(RUNNING)],
    ));
    // 4.10 `WhileDoElseNode::tick`: a skipped condition is neither SUCCESS nor FAILURE,
    // so no branch runs and `status` stays IDLE: `resetChildren()` (halting the RUNNING
    // children, the condition too if it answered 5), then `return status`, whose
    // `setStatus(NodeStatus::IDLE)` in `TreeNode::executeTick` throws. Where BT.CPP
    // throws the tree stops (`error`).
    let mut skipped: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
    skipped.push(b.assign(h, "0"));
    c.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("halting_to_error"),
        skipped,
    ));
    m.push(c);
    m.push(super::btcpp4_time::halting(
        ctx,
        "halting_to_error",
        "children_count",
        "error",
        Vec::new(),
    ));
    // The branch to tick and the one to halt first (only while it runs).
    let three = ctx.children.len() == 3;
    let mut choose = b.state("choose_branch");
    if three {
        let (r1, r2) = (running(ctx, 1), running(ctx, 2));
        choose.push(b.tr(
            None,
            Some(&format!("cond_status == {SUCCESS} && {r2}")),
            Some("halting_other"),
            vec![b.assign("branch", "1")],
        ));
        choose.push(b.tr(
            None,
            Some(&format!("cond_status == {SUCCESS}")),
            Some("tick_branch"),
            vec![b.assign("branch", "1")],
        ));
        choose.push(b.tr(
            None,
            Some(&format!("cond_status == {FAILURE} && {r1}")),
            Some("halting_other"),
            vec![b.assign("branch", "2")],
        ));
        choose.push(b.tr(
            None,
            None,
            Some("tick_branch"),
            vec![b.assign("branch", "2")],
        ));
        // `haltChild(2)` before the do branch, `haltChild(1)` before the else branch.
        let mut halting = b.state_entry(
            "halting_other",
            vec![b
                .if_chain(
                    vec![
                        ("branch == 1".into(), ctx.halt_child_body(2)),
                        ("branch == 2".into(), ctx.halt_child_body(1)),
                    ],
                    Vec::new(),
                )
                .expect("two branches")],
        );
        for (other, branch) in [(2, 1), (1, 2)] {
            halting.push(b.tr(
                Some(&ctx.child_halt_resp(other)),
                Some(&format!("branch == {branch}")),
                Some("tick_branch"),
                vec![],
            ));
        }
        m.push(choose);
        m.push(halting);
    } else {
        choose.push(b.tr(
            None,
            Some(&format!("cond_status == {SUCCESS}")),
            Some("tick_branch"),
            vec![b.assign("branch", "1")],
        ));
        choose.push(b.tr(
            None,
            None,
            Some("halting_when_done"),
            vec![b.assign("result", &FAILURE.to_string()), b.assign(h, "0")],
        ));
        m.push(choose);
    }
    let mut t = b.state_entry("tick_branch", vec![ctx.dispatch("branch", false)]);
    for i in 1..ctx.children.len() {
        let r = running(ctx, i);
        push_child_done(ctx, &mut t, "branch", i, h);
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("_event.data.status == {RUNNING} && branch == {i}")),
            Some("wait_for_tick"),
            vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
        ));
        // A skipped branch is not RUNNING: `resetChildren()` (a branch that answered 5
        // is halted) and its SKIPPED is the answer, the node RUNNING as it set itself.
        let mut skipped: Vec<Element> = ctx.mark_skipped(i).into_iter().collect();
        skipped.push(b.assign("result", &SKIPPED_RUNNING.to_string()));
        skipped.push(b.assign(h, "0"));
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("{IS_SKIPPED} && branch == {i}")),
            Some("halting_when_done"),
            skipped,
        ));
    }
    m.push(t);
    let forget = || {
        if stale {
            vec![b.assign("cond_done", "0")]
        } else {
            Vec::new()
        }
    };
    let mut finish = forget();
    finish.push(ctx.respond_expr("result"));
    m.push(halting_state(ctx, "halting_when_done", h, finish));
    let mut on_halt = forget();
    on_halt.push(ctx.respond_halted());
    m.push(halting_state(ctx, "halting_on_halt", h, on_halt));
    m.push(b.state("error"));
    m
}

/// RunOnce as BT.CPP 4.10 runs it (`decorators/run_once_node.h`, `RunOnceNode::tick`):
/// until the child has finished once the node ticks it and answers as it does (a
/// SKIPPED child is not finished: SKIPPED, the node RUNNING as it set itself); its first
/// finished status is kept (`returned_status_`), the child reset, and every later tick
/// answers, without ticking the child, SKIPPED with `then_skip` (`skip`, the default;
/// the node's own status untouched, so IDLE: code 4), else that status. A halt
/// (`DecoratorNode::halt`) resets the child (halting it if RUNNING) and keeps what it
/// remembers.
pub(super) fn run_once(ctx: &Ctx, skip: bool) -> Element {
    let b = &ctx.b;
    let once = "returned_status";
    let mut m = b.scxml(&ctx.machine, "init");
    push_data(
        ctx,
        &mut m,
        &[
            ("children_count", "int8", n_children(ctx)),
            (once, "int8", "0".into()),
        ],
    );
    m.push(init_state(ctx, "children_count != 1"));
    let mut w = b
        .state("wait_for_tick")
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some(&format!("{once} > 0")),
            Some("wait_for_tick"),
            vec![if skip {
                ctx.respond(SKIPPED)
            } else {
                ctx.respond_expr(once)
            }],
        ))
        .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_child"), vec![]));
    for t in ctx.halt_single("halting_child", Vec::new()) {
        w.push(t);
    }
    m.push(w);
    m.push(ctx.halting_child_state());
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE, RUNNING] {
        let mut body = Vec::new();
        if s != RUNNING {
            body.push(b.assign(once, &s.to_string()));
        }
        body.push(ctx.respond(s));
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            ctx.marked(0, s, body),
        ));
    }
    let mut body: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
    body.push(ctx.respond(SKIPPED_RUNNING));
    t.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("wait_for_tick"),
        body,
    ));
    m.push(t);
    m.push(b.state("error"));
    m
}

/// Into state `t` of a node that ticks the one child `chosen` names: the transitions on
/// child `i`'s SUCCESS and FAILURE, each the node's result, the child no longer running,
/// then `halting_when_done` with halt index `h` from 0 (`WhileDoElseNode::tick`,
/// `SwitchNode::tick`: a finished branch is the answer, the other children halted).
pub(super) fn push_child_done(ctx: &Ctx, t: &mut Element, chosen: &str, i: usize, h: &str) {
    let b = &ctx.b;
    let r = running(ctx, i);
    for s in [SUCCESS, FAILURE] {
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("_event.data.status == {s} && {chosen} == {i}")),
            Some("halting_when_done"),
            vec![
                b.assign(&r, "false"),
                b.assign("result", &s.to_string()),
                b.assign(h, "0"),
            ],
        ));
    }
}
