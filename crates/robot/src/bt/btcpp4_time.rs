//! BehaviorTree.CPP 4's timed nodes, Timeout, Delay and Sleep, with their timers in model
//! time, and TryCatch (4.10), lowered under [`super::BtSemantics::Btcpp`] only.
//!
//! # The timers in model time
//! In BT.CPP each of these nodes owns a `TimerQueue` (`utils/timer_queue.h`): `add(ms,
//! callback)` runs the callback on the queue's own thread once `ms` of wall-clock time
//! have passed, `cancel`/`cancelAll` run it with `aborted` instead. The callbacks
//! (`TimeoutNode::tick`, `DelayNode::tick`, `SleepNode::onStart`) set a flag the next tick
//! reads, Timeout's also halts its RUNNING child there and then, and each emits the
//! wake-up signal (`TreeNode::emitWakeUpSignal`).
//!
//! The model's executor ticks the root once per period of the tree's timer
//! (`bt_tick_rate`), `tickOnce` or `tickExactlyOnce`, and never sleeps until a wake-up
//! (it is a ROS timer callback, not `tickWhileRunning`). So a timer started by a tick at
//! time `t` with duration `d` fires at model time `t + d` exactly, between executor ticks:
//! its flag and its halt happen then, and the wake-up it emits stays pending until the
//! next executor tick, whose `Tree::tickRoot` takes it (under `tickOnce`) to tick the
//! root again if that tick answers RUNNING. A timer due at the very instant of an
//! executor tick fires before that tick (in the library the two race; docs/SEMANTICS.md
//! section 5, "Timers of the tree").
//!
//! The root machine keeps the time (`add_clock`): it gets one more ROS timer,
//! `<stem>_timers`, whose period divides the tick period and every duration, declared
//! before the tick timer so that at an instant its event comes first; it counts those
//! events in `bt_now`. A node starts its timer with `bt_<id>_timer_start` (the root sets
//! `bt_<id>_due = bt_now + d`) and cancels it with `bt_<id>_timer_cancel`. Between
//! executor ticks (in `idle` or `done`) the root fires the due timers one at a time in
//! node order: `bt_<id>_timer` to the node, which reacts (Timeout halts its child) and
//! answers `bt_<id>_timer_done` before the next one fires and before the next tick. A
//! timer that falls due while a tick is still running (a leaf waiting on a ROS action
//! across time) fires when that tick ends, as Timeout's callback waits on
//! `timeout_mutex_` while its child is being ticked.

use super::btcpp::WAKE_UP;
use super::build::B;
use super::control::{
    init_state, n_children, Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED_RUNNING, SKIP_COUNT, SUCCESS,
};
use super::tree::{Btcpp4, Kind, PortValue, Tree, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::{Element, Node};

/// Clock events one tick period may hold at most (a finer clock is refused: every event
/// is a step of every run).
const MAX_EVENTS_PER_PERIOD: u64 = 1000;

/// Whether `k` is lowered here.
pub(super) fn handles(k: Btcpp4) -> bool {
    matches!(
        k,
        Btcpp4::Timeout | Btcpp4::Delay | Btcpp4::Sleep | Btcpp4::TryCatch
    )
}

/// The tree's clock: its period and the timed nodes' durations in its events.
pub(super) struct Clock {
    /// The clock's rate in hertz, written so that its period is exact.
    rate: String,
    /// `(node id, node machine, duration in clock events)`, in node order.
    timers: Vec<(u32, String, u64)>,
}

impl Clock {
    /// The duration of node `id`'s timer in clock events, if it has one.
    fn units(&self, id: u32) -> Option<u64> {
        self.timers.iter().find(|t| t.0 == id).map(|t| t.2)
    }
}

/// The duration port of a timed node, in milliseconds (an `unsigned` in BT.CPP:
/// `InputPort<unsigned>`), or an error at the port.
fn msec(sm: &SourceMap, n: &TreeNode, k: Btcpp4, errs: &mut Vec<Diagnostic>) -> Option<u64> {
    let key = if k == Btcpp4::Delay {
        "delay_msec"
    } else {
        "msec"
    };
    let Some(p) = n.port(key) else {
        // `getInput` fails: "Missing parameter [msec] in TimeoutNode" at the first tick.
        errs.push(sm.diag(
            n.span,
            format!(
                "this node needs `{key}` (BehaviorTree.CPP throws at its first tick without it)"
            ),
        ));
        return None;
    };
    match &p.value {
        PortValue::Literal(v) => match v.trim().parse::<u64>() {
            Ok(x) if x <= u32::MAX as u64 => Some(x),
            _ => {
                errs.push(sm.diag(
                    p.span,
                    format!("`{key}` must be a whole number of milliseconds (0 to 4294967295), not `{v}`"),
                ));
                None
            }
        },
        PortValue::Blackboard(b) => {
            errs.push(sm.diag(
                p.span,
                format!("`{key}` must be a constant; a blackboard entry (`{{{b}}}`) is not supported here"),
            ));
            None
        }
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The rate in hertz whose period is exactly `ns` nanoseconds, written as a decimal
/// (`crate::rate::period` reads it back exactly), if there is one.
fn exact_rate(ns: u64) -> Option<String> {
    (0..=18u32).find_map(|k| {
        let num = 1_000_000_000u128 * 10u128.pow(k);
        if num % ns as u128 != 0 {
            return None;
        }
        let m = (num / ns as u128).to_string();
        let k = k as usize;
        let text = if k == 0 {
            m
        } else if m.len() > k {
            format!("{}.{}", &m[..m.len() - k], &m[m.len() - k..])
        } else {
            format!("0.{}{m}", "0".repeat(k - m.len()))
        };
        let p = crate::rate::period(&text).ok()?;
        (p.exact && p.period_ns == ns).then_some(text)
    })
}

/// The tree's clock, when some node has a timer (a Timeout or Sleep of 0 ms has none,
/// a Delay of 0 ms has one due at once): its period is the greatest common divisor of the
/// tick period (`rate_text`, as the root machine's timer writes it) and every duration.
/// Errors (at the node) when that period has no exact rate or is too fine.
pub(super) fn clock(
    sm: &SourceMap,
    tree: &Tree,
    rate_text: &str,
    errs: &mut Vec<Diagnostic>,
) -> Option<Clock> {
    let mut timed = Vec::new();
    for n in &tree.nodes {
        let Kind::Control(super::tree::Control::Btcpp4(k)) = n.kind else {
            continue;
        };
        if !matches!(k, Btcpp4::Timeout | Btcpp4::Delay | Btcpp4::Sleep) {
            continue;
        }
        let Some(ms) = msec(sm, n, k, errs) else {
            continue;
        };
        // `TimeoutNode::tick` adds no timer for 0 ms; `SleepNode::onStart` answers
        // SUCCESS at once.
        if ms == 0 && k != Btcpp4::Delay {
            continue;
        }
        timed.push((n, ms * 1_000_000));
    }
    let first = timed.first()?.0;
    let period = crate::rate::period(rate_text).ok()?.period_ns;
    let q = timed
        .iter()
        .fold(period, |g, (_, d)| if *d == 0 { g } else { gcd(g, *d) });
    let Some(rate) = exact_rate(q).filter(|_| period / q <= MAX_EVENTS_PER_PERIOD) else {
        errs.push(sm.diag(
            first.span,
            format!(
                "hindsight times the tree's timers with one clock whose period divides the tick period ({period} ns) and every duration: {q} ns, {}",
                if period / q > MAX_EVENTS_PER_PERIOD {
                    format!("more than {MAX_EVENTS_PER_PERIOD} events per tick period: choose durations that share a coarser divisor with the tick period")
                } else {
                    "a period no rate in hertz has exactly".to_string()
                }
            ),
        ));
        return None;
    };
    Some(Clock {
        rate,
        timers: timed
            .iter()
            .map(|(n, d)| (n.id, n.machine.clone(), d / q))
            .collect(),
    })
}

/// Checks node `n`'s ports and builds its machine; `root` is the root machine (the
/// timers' keeper), `clock` the tree's clock.
pub(super) fn lower(
    sm: &SourceMap,
    k: Btcpp4,
    n: &TreeNode,
    ctx: &Ctx,
    root: &str,
    clock: Option<&Clock>,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    if k == Btcpp4::TryCatch {
        // `catch_on_halt` is read with `getInput<bool>` (`convertFromString<bool>`).
        let on_halt = match n.port("catch_on_halt").map(|p| (&p.value, p.span)) {
            None => false,
            Some((PortValue::Literal(v), span)) => match v.trim() {
                "true" | "True" | "TRUE" | "1" => true,
                "false" | "False" | "FALSE" | "0" => false,
                other => {
                    errs.push(sm.diag(
                        span,
                        format!("`catch_on_halt` must be true or false, not `{other}`"),
                    ));
                    return None;
                }
            },
            Some((PortValue::Blackboard(b), span)) => {
                errs.push(sm.diag(
                    span,
                    format!("`catch_on_halt` must be a constant; a blackboard entry (`{{{b}}}`) is not supported here"),
                ));
                return None;
            }
        };
        return Some(try_catch(ctx, on_halt));
    }
    // The duration was checked (and any error reported) by `clock`.
    let ms = msec(sm, n, k, &mut Vec::new())?;
    // Without a clock the duration was refused (`clock` said why), or the node has no
    // timer (0 ms).
    if clock.is_none_or(|c| c.units(n.id).is_none()) && (ms > 0 || k == Btcpp4::Delay) {
        return None;
    }
    let t = Timer { ctx, root };
    Some(match k {
        Btcpp4::Timeout => timeout(&t, ms > 0),
        Btcpp4::Delay => delay(&t),
        _ => sleep(&t, ms > 0),
    })
}

/// A timed node's side of the timer protocol.
struct Timer<'a> {
    ctx: &'a Ctx,
    root: &'a str,
}

impl Timer<'_> {
    fn send(&self, what: &str) -> Element {
        self.ctx
            .b
            .send(&format!("bt_{}_{what}", self.ctx.id), self.root)
    }
    /// `TimerQueue::add`.
    fn start(&self) -> Element {
        self.send("timer_start")
    }
    /// `TimerQueue::cancel` / `cancelAll`.
    fn cancel(&self) -> Element {
        self.send("timer_cancel")
    }
    /// The event of the timer firing.
    fn fired(&self) -> String {
        format!("bt_{}_timer", self.ctx.id)
    }
    /// The callback is over: the wake-up signal (when someone listens), then the
    /// answer to the root.
    fn done(&self, wake: bool) -> Vec<Element> {
        let mut v: Vec<Element> = if wake {
            self.ctx
                .wake
                .iter()
                .map(|r| self.ctx.b.send(WAKE_UP, r))
                .collect()
        } else {
            Vec::new()
        };
        v.push(self.send("timer_done"));
        v
    }
}

/// Datamodel: `vars` (ints or bools) then the children's RUNNING flags.
fn datamodel(ctx: &Ctx, vars: &[(&str, &str)]) -> Element {
    let mut d: Vec<(String, &str, String)> = vars
        .iter()
        .map(|(v, e)| {
            let t = if *e == "true" || *e == "false" {
                "bool"
            } else {
                "int8"
            };
            (v.to_string(), t, e.to_string())
        })
        .collect();
    d.extend(ctx.running_data());
    let d: Vec<(&str, &str, String)> = d
        .iter()
        .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
        .collect();
    ctx.b.datamodel(&d)
}

/// The halt of a one-child decorator: `also`, then the child halted if RUNNING
/// (`DecoratorNode::halt` → `resetChild`), then the answer.
fn decorator_halt(ctx: &Ctx, w: &mut Element, m: &mut Element, also: Vec<Element>) {
    let b = &ctx.b;
    let r = super::btcpp::running(ctx, 0);
    let mut at_once = also.clone();
    at_once.push(ctx.respond_halted());
    w.push(b.tr(
        Some(&ctx.halt_ev()),
        Some(&format!("!{r}")),
        Some("wait_for_tick"),
        at_once,
    ));
    w.push(b.tr(Some(&ctx.halt_ev()), None, Some("halting_child"), also));
    m.push(ctx.halting_child_state());
}

/// `tick_child`: the child's answer; a finished one runs `finish` (the node's own
/// bookkeeping; the child needs no reset, it is not RUNNING) and is the answer.
fn tick_child_state(ctx: &Ctx, finish: Vec<Element>) -> Element {
    let b = &ctx.b;
    let r = super::btcpp::running(ctx, 0);
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE] {
        let mut body = vec![b.assign(&r, "false")];
        body.extend(finish.iter().cloned());
        body.push(ctx.respond(s));
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            body,
        ));
    }
    t.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(&format!("_event.data.status == {RUNNING}")),
        Some("wait_for_tick"),
        vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
    ));
    // A skipped child is not a finished one (`isStatusCompleted`): its SKIPPED is the
    // answer, nothing reset, the timer left running; the node set itself RUNNING when it
    // started (`TimeoutNode::tick`, `DelayNode::tick`), so 5. Timeout's timer then
    // halts the child only if it stays RUNNING (code 5).
    let mut skipped: Vec<Element> = ctx.mark_skipped(0).into_iter().collect();
    skipped.push(ctx.respond(SKIPPED_RUNNING));
    t.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("wait_for_tick"),
        skipped,
    ));
    t
}

/// Timeout as BT.CPP 4.10 runs it (`decorators/timeout_node.cpp`):
/// - `TimeoutNode::tick`: the first tick (`!timeout_started_`) starts the timer (none for
///   0 ms) and clears `child_halted_`; with `child_halted_` set the tick answers FAILURE
///   (and the next one starts again); otherwise it ticks the child, and a finished answer
///   ends the timeout, cancels the timer and resets the child (not RUNNING: no halt).
/// - the timer's callback: if the child is RUNNING, `child_halted_`, `haltChild()`, and
///   the wake-up signal; otherwise nothing.
/// - `TimeoutNode::halt`: not started, `cancelAll`, `DecoratorNode::halt`.
fn timeout(t: &Timer, timed: bool) -> Element {
    let ctx = t.ctx;
    let b = &ctx.b;
    let r = super::btcpp::running(ctx, 0);
    let mut m = b.scxml(&ctx.machine, "init");
    m.push(datamodel(
        ctx,
        &[
            ("children_count", n_children(ctx).as_str()),
            ("started", "false"),
            ("child_halted", "false"),
        ],
    ));
    m.push(init_state(ctx, "children_count != 1"));
    let mut start = vec![
        b.assign("started", "true"),
        b.assign("child_halted", "false"),
    ];
    if timed {
        start.push(t.start());
    }
    let mut w = b
        .state("wait_for_tick")
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some("!started"),
            Some("tick_child"),
            start,
        ))
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some("child_halted"),
            Some("wait_for_tick"),
            vec![b.assign("started", "false"), ctx.respond(FAILURE)],
        ))
        .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_child"), vec![]));
    let cancel = || {
        if timed {
            vec![b.if_then("started", vec![t.cancel()])]
        } else {
            Vec::new()
        }
    };
    let mut also = cancel();
    also.push(b.assign("started", "false"));
    if timed {
        w.push(b.tr(
            Some(&t.fired()),
            Some(&r),
            Some("expiring"),
            vec![b.assign("child_halted", "true")],
        ));
        w.push(b.tr(Some(&t.fired()), None, Some("wait_for_tick"), t.done(false)));
    }
    decorator_halt(ctx, &mut w, &mut m, also);
    m.push(w);
    if timed {
        m.push(
            b.state_entry("expiring", ctx.halt_child_body(0))
                .with_child(b.tr(
                    Some(&ctx.child_halt_resp(0)),
                    None,
                    Some("wait_for_tick"),
                    t.done(true),
                )),
        );
    }
    let mut finish = cancel();
    finish.push(b.assign("started", "false"));
    m.push(tick_child_state(ctx, finish));
    m.push(b.state("error"));
    m
}

/// Delay as BT.CPP 4.10 runs it (`decorators/delay_node.cpp`):
/// - `DelayNode::tick`: the first tick (`!delay_started_`) clears `delay_complete_` and
///   starts the timer; until the timer fired the tick answers RUNNING without ticking the
///   child; after, it ticks the child, and a finished answer ends the delay and resets
///   the child (not RUNNING: no halt). (`delay_aborted_` is never set: dead branch.)
/// - the timer's callback: `delay_complete_` and the wake-up signal.
/// - `DelayNode::halt`: not started, `cancelAll`, `DecoratorNode::halt`.
fn delay(t: &Timer) -> Element {
    let ctx = t.ctx;
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    m.push(datamodel(
        ctx,
        &[
            ("children_count", n_children(ctx).as_str()),
            ("started", "false"),
            ("complete", "false"),
        ],
    ));
    m.push(init_state(ctx, "children_count != 1"));
    let mut w = b
        .state("wait_for_tick")
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some("!started"),
            Some("wait_for_tick"),
            vec![
                b.assign("started", "true"),
                b.assign("complete", "false"),
                t.start(),
                ctx.respond(RUNNING),
            ],
        ))
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some("!complete"),
            Some("wait_for_tick"),
            vec![ctx.respond(RUNNING)],
        ))
        .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_child"), vec![]));
    let mut done = vec![b.assign("complete", "true")];
    done.extend(t.done(true));
    w.push(b.tr(Some(&t.fired()), None, Some("wait_for_tick"), done));
    let also = vec![
        b.if_then("started && !complete", vec![t.cancel()]),
        b.assign("started", "false"),
    ];
    decorator_halt(ctx, &mut w, &mut m, also);
    m.push(w);
    m.push(tick_child_state(ctx, vec![b.assign("started", "false")]));
    m.push(b.state("error"));
    m
}

/// Sleep as BT.CPP 4.10 runs it (`actions/sleep_node.cpp`), a `StatefulActionNode`:
/// `onStart` answers SUCCESS for 0 ms, else starts the timer (`timer_waiting_`) and
/// answers RUNNING; `onRunning` answers RUNNING while the timer waits, then SUCCESS;
/// the callback clears `timer_waiting_` and emits the wake-up signal; `onHalted` clears
/// it and cancels the timer. (A finished Sleep ticked again before its parent reset it
/// answers its status without running: its parent handles that, as for a leaf plugin,
/// `btcpp.rs`.)
fn sleep(t: &Timer, timed: bool) -> Element {
    let ctx = t.ctx;
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    m.push(b.datamodel(&[
        ("running", "bool", "false".into()),
        ("waiting", "bool", "false".into()),
    ]));
    let mut w = b.state("wait_for_tick");
    if timed {
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            Some("!running"),
            Some("wait_for_tick"),
            vec![
                b.assign("running", "true"),
                b.assign("waiting", "true"),
                t.start(),
                ctx.respond(RUNNING),
            ],
        ));
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            Some("waiting"),
            Some("wait_for_tick"),
            vec![ctx.respond(RUNNING)],
        ));
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            None,
            Some("wait_for_tick"),
            vec![b.assign("running", "false"), ctx.respond(SUCCESS)],
        ));
        let mut done = vec![b.assign("waiting", "false")];
        done.extend(t.done(true));
        w.push(b.tr(Some(&t.fired()), None, Some("wait_for_tick"), done));
    } else {
        w.push(b.tr(
            Some(&ctx.tick_ev()),
            None,
            Some("wait_for_tick"),
            vec![ctx.respond(SUCCESS)],
        ));
    }
    let mut halt = Vec::new();
    if timed {
        halt.push(b.if_then("running && waiting", vec![t.cancel()]));
    }
    halt.extend([
        b.assign("running", "false"),
        b.assign("waiting", "false"),
        ctx.respond_halted(),
    ]);
    w.push(b.tr(Some(&ctx.halt_ev()), None, Some("wait_for_tick"), halt));
    m.push(w);
    m
}

/// A state `name` that halts, in child order from `var` up to (not including) `bound`,
/// every child that last answered RUNNING and resets the others' flags
/// (`ControlNode::haltChild` for each), then goes to `target` doing `finish`. Whoever
/// enters it sets `var` first.
pub(super) fn halting(
    ctx: &Ctx,
    name: &str,
    bound: &str,
    target: &str,
    finish: Vec<Element>,
) -> Element {
    let b = &ctx.b;
    let var = "halt_idx";
    let mut entry = ctx.skip_idle(var, None);
    entry.push(b.if_then(&format!("{var} < {bound}"), vec![ctx.dispatch(var, true)]));
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
        Some(&format!("{var} >= {bound}")),
        Some(target),
        finish,
    ));
    s
}

/// TryCatch as BT.CPP 4.10 runs it (`controls/try_catch_node.cpp`):
/// - `TryCatchNode::tick`: the children but the last (the try block) run as a Sequence,
///   resuming at `current_child_idx_`; RUNNING is the answer; all SUCCESS resets the
///   children and the index and answers SUCCESS; a FAILURE resets the children
///   (`resetChildren`: halts the RUNNING ones) and the index, enters the catch
///   (`in_catch_`) and ticks the last child in the same tick (`return tick()`). In the
///   catch the last child is ticked: RUNNING is the answer, a finished answer (either)
///   resets the children, leaves the catch and answers FAILURE.
/// - `TryCatchNode::halt`: with `catch_on_halt` and not in the catch, it halts the try
///   children (`haltChild`, each only if RUNNING), ticks the catch child once and halts
///   it if it answered RUNNING; then the index back to 0, out of the catch, and
///   `ControlNode::halt` resets the children. (Halted only while RUNNING, as every node
///   under BT.CPP's rules, so `isStatusActive(status())` holds.)
fn try_catch(ctx: &Ctx, catch_on_halt: bool) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let last = ctx.children.len() - 1;
    let r_last = super::btcpp::running(ctx, last);
    let mut m = b.scxml(&ctx.machine, "init");
    // Where BT.CPP may tick the node again without a reset (`Ctx::stale`) its parent
    // halts it at every reset, running or not; `TryCatchNode::halt` runs only for a
    // RUNNING node (`ControlNode::haltChild`), so the catch on halt needs `active`.
    let n = n_children(ctx);
    let mut vars = vec![
        ("children_count", n.as_str()),
        (idx, "0"),
        ("halt_idx", "0"),
        ("in_catch", "false"),
        (SKIP_COUNT, "0"),
    ];
    let active = "active";
    if ctx.stale {
        vars.push((active, "false"));
    }
    m.push(datamodel(ctx, &vars));
    m.push(init_state(ctx, "children_count < 2"));
    let set_active = || {
        if ctx.stale {
            vec![b.assign(active, "true")]
        } else {
            Vec::new()
        }
    };
    let mut w = b
        .state("wait_for_tick")
        .with_child(b.tr(
            Some(&ctx.tick_ev()),
            Some("in_catch"),
            Some("tick_catch"),
            set_active(),
        ))
        .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_try"), set_active()));
    if catch_on_halt {
        w.push(b.tr(
            Some(&ctx.halt_ev()),
            Some(if ctx.stale {
                "!in_catch && active"
            } else {
                "!in_catch"
            }),
            Some("halting_try"),
            vec![b.assign("halt_idx", "0")],
        ));
    }
    w.push(b.tr(
        Some(&ctx.halt_ev()),
        None,
        Some("halting_on_halt"),
        vec![b.assign("halt_idx", "0")],
    ));
    m.push(w);
    // The try block.
    let mut t = b.state_entry(
        "tick_try",
        vec![b.if_then(
            &format!("{idx} < children_count - 1"),
            vec![ctx.dispatch(idx, false)],
        )],
    );
    for i in 0..last {
        let r = super::btcpp::running(ctx, i);
        let is = |s: u8| format!("_event.data.status == {s} && {idx} == {i}");
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&is(SUCCESS)),
            Some("tick_try"),
            vec![b.assign(&r, "false"), b.assign(idx, &format!("{idx} + 1"))],
        ));
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&is(FAILURE)),
            Some("halting_to_catch"),
            vec![b.assign(&r, "false"), b.assign("halt_idx", "0")],
        ));
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&is(RUNNING)),
            Some("wait_for_tick"),
            vec![b.assign(&r, "true"), ctx.respond(RUNNING)],
        ));
        // `case NodeStatus::SKIPPED`: on to the next try child, counted
        // (`skipped_count_`); the child RUNNING still if it answered 5.
        let mut skipped: Vec<Element> = ctx.mark_skipped(i).into_iter().collect();
        skipped.push(b.assign(idx, &format!("{idx} + 1")));
        skipped.push(b.assign(SKIP_COUNT, &format!("{SKIP_COUNT} + 1")));
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("{IS_SKIPPED} && {idx} == {i}")),
            Some("tick_try"),
            skipped,
        ));
    }
    t.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count - 1")),
        Some("halting_on_success"),
        vec![b.assign("halt_idx", "0")],
    ));
    m.push(t);
    // The whole try block skipped answers SKIPPED (`all_skipped`), the node RUNNING as
    // it set itself (5); the count restarts either way (`skipped_count_ = 0`).
    let answer = b
        .if_chain(
            vec![(
                format!("{SKIP_COUNT} == children_count - 1"),
                vec![ctx.respond(SKIPPED_RUNNING)],
            )],
            vec![ctx.respond(SUCCESS)],
        )
        .expect("one branch");
    let mut on_success = vec![b.assign(idx, "0")];
    if ctx.stale {
        on_success.push(b.assign(active, &format!("{SKIP_COUNT} == children_count - 1")));
    }
    on_success.extend([answer, b.assign(SKIP_COUNT, "0")]);
    m.push(halting(
        ctx,
        "halting_on_success",
        "children_count",
        "wait_for_tick",
        on_success,
    ));
    // A FAILURE leaves `skipped_count_` as it is, but the node then finishes FAILURE and
    // its parent resets it before the next tick (`!isStatusActive(status())` restarts
    // the count), so the count restarts here; where BT.CPP may tick it again without a
    // reset (`Ctx::stale`) it carries over, and the parent's reset (a halt) clears it.
    let mut to_catch = vec![b.assign(idx, "0"), b.assign("in_catch", "true")];
    if !ctx.stale {
        to_catch.push(b.assign(SKIP_COUNT, "0"));
    }
    m.push(halting(
        ctx,
        "halting_to_catch",
        "children_count",
        "tick_catch",
        to_catch,
    ));
    // The catch.
    let mut c = b.state_entry("tick_catch", vec![ctx.tick_child(last)]);
    c.push(b.tr(
        Some(&ctx.child_resp(last)),
        Some(&format!("_event.data.status == {RUNNING}")),
        Some("wait_for_tick"),
        vec![b.assign(&r_last, "true"), ctx.respond(RUNNING)],
    ));
    // Any other answer, SKIPPED too, ends the catch (`catch_status != RUNNING`); a
    // catch child that answered 5 is RUNNING still, so `resetChildren` halts it.
    c.push(b.tr(
        Some(&ctx.child_resp(last)),
        None,
        Some("halting_after_catch"),
        vec![
            b.assign(&r_last, &format!("_event.data.status == {SKIPPED_RUNNING}")),
            b.assign("halt_idx", "0"),
        ],
    ));
    m.push(c);
    m.push(halting(
        ctx,
        "halting_after_catch",
        "children_count",
        "wait_for_tick",
        [
            vec![b.assign(idx, "0"), b.assign("in_catch", "false")],
            if ctx.stale {
                vec![b.assign(active, "false")]
            } else {
                Vec::new()
            },
            vec![ctx.respond(FAILURE)],
        ]
        .concat(),
    ));
    m.push(halting(
        ctx,
        "halting_on_halt",
        "children_count",
        "wait_for_tick",
        [
            vec![
                b.assign(idx, "0"),
                b.assign("in_catch", "false"),
                b.assign(SKIP_COUNT, "0"),
            ],
            if ctx.stale {
                vec![b.assign(active, "false")]
            } else {
                Vec::new()
            },
            vec![ctx.respond_halted()],
        ]
        .concat(),
    ));
    if catch_on_halt {
        m.push(halting(
            ctx,
            "halting_try",
            "children_count - 1",
            "catch_on_halt",
            Vec::new(),
        ));
        let mut c = b.state_entry("catch_on_halt", vec![ctx.tick_child(last)]);
        c.push(b.tr(
            Some(&ctx.child_resp(last)),
            Some(&format!("_event.data.status == {RUNNING}")),
            Some("halting_catch"),
            vec![b.assign(&r_last, "true")],
        ));
        // Not RUNNING (SKIPPED included): not halted here, but a 5 is RUNNING still,
        // and `ControlNode::halt`'s `resetChildren` halts it.
        c.push(b.tr(
            Some(&ctx.child_resp(last)),
            None,
            Some("halting_on_halt"),
            vec![
                b.assign(&r_last, &format!("_event.data.status == {SKIPPED_RUNNING}")),
                b.assign("halt_idx", "0"),
            ],
        ));
        m.push(c);
        m.push(
            b.state_entry("halting_catch", ctx.halt_child_body(last))
                .with_child(b.tr(
                    Some(&ctx.child_halt_resp(last)),
                    None,
                    Some("halting_on_halt"),
                    vec![b.assign("halt_idx", "0")],
                )),
        );
    }
    m.push(b.state("error"));
    m
}

/// Makes the root machine `root` the keeper of the tree's timers (module doc): the
/// clock timer (declared before the tick timer `tick_timer`), `bt_now`, each timer's
/// due time, start and cancel taken in every state, and the due timers fired one at a
/// time, in node order, from `idle` and `done` before anything else happens there.
pub(super) fn add_clock(
    b: B,
    root: &mut Element,
    clock: &Clock,
    clock_timer: &str,
    tick_timer: &str,
) {
    let due = |id: u32| format!("bt_{id}_due");
    let due_cond = |id: u32| format!("{} != -1 && {} <= bt_now", due(id), due(id));
    let any_due = clock
        .timers
        .iter()
        .map(|t| format!("({})", due_cond(t.0)))
        .collect::<Vec<_>>()
        .join(" || ");
    // Data.
    let mut vars: Vec<(String, &str, String)> = vec![
        ("bt_now".into(), "int32", "0".into()),
        ("bt_tick_due".into(), "bool", "false".into()),
    ];
    vars.extend(
        clock
            .timers
            .iter()
            .map(|t| (due(t.0), "int32", "-1".to_string())),
    );
    let data: Vec<Element> = vars
        .iter()
        .map(|(v, t, e)| b.el("data", &[("id", v), ("type", t), ("expr", e)]))
        .collect();
    if !root.elements().any(|e| e.name == "datamodel") {
        root.children
            .insert(0, Node::Element(b.el("datamodel", &[])));
    }
    if let Some(dm) = root.elements_mut().find(|e| e.name == "datamodel") {
        data.into_iter().for_each(|d| dm.push(d));
    }
    // The clock timer, before the tick timer.
    let at = root
        .children
        .iter()
        .position(|c| matches!(c, Node::Element(e) if e.name == "ros_time_rate"))
        .unwrap_or(root.children.len());
    root.children.insert(
        at,
        Node::Element(b.el(
            "ros_time_rate",
            &[("name", clock_timer), ("rate_hz", &clock.rate)],
        )),
    );
    // What the idle state does on a tick event, and its wake-up transition (tickOnce).
    let idle_tick = root
        .elements()
        .find(|e| e.name == "state" && e.attr_value("id") == Some("idle"))
        .and_then(|s| {
            s.elements()
                .find(|c| c.name == "ros_rate_callback" && c.attr_value("name") == Some(tick_timer))
                .cloned()
        });
    let wake = root
        .elements()
        .find(|e| e.name == "state" && e.attr_value("id") == Some("idle"))
        .and_then(|s| {
            s.elements()
                .find(|c| c.name == "transition" && c.attr_value("event") == Some(WAKE_UP))
                .cloned()
        });
    let start_cancel = || {
        let mut v = Vec::new();
        for (id, _, units) in &clock.timers {
            v.push(b.tr(
                Some(&format!("bt_{id}_timer_start")),
                None,
                None,
                vec![b.assign(&due(*id), &format!("bt_now + {units}"))],
            ));
            v.push(b.tr(
                Some(&format!("bt_{id}_timer_cancel")),
                None,
                None,
                vec![b.assign(&due(*id), "-1")],
            ));
        }
        v
    };
    let count = |target: Option<&str>| {
        let mut attrs = vec![("name", clock_timer)];
        if let Some(t) = target {
            attrs.push(("target", t));
        }
        let mut cb = b.el("ros_rate_callback", &attrs);
        cb.push(b.assign("bt_now", "bt_now + 1"));
        cb
    };
    let mut added = Vec::new();
    for st in root.elements_mut().filter(|e| e.name == "state") {
        let id = st.attr_value("id").unwrap_or_default().to_string();
        for t in start_cancel() {
            st.push(t);
        }
        match id.as_str() {
            "idle" | "done" => {
                // Re-entering runs the check below.
                st.push(count(Some(&id)));
                st.push(b.tr(None, Some(&any_due), Some(&format!("{id}_timers")), vec![]));
                if id == "idle" {
                    if let Some(cb) = &idle_tick {
                        // A tick event taken while a timer fired (`bt_tick_due`).
                        let mut t = b.tr(
                            None,
                            Some("bt_tick_due"),
                            cb.attr_value("target"),
                            vec![b.assign("bt_tick_due", "false")],
                        );
                        for c in cb.elements() {
                            t.push(c.clone());
                        }
                        st.push(t);
                    }
                }
                added.push(id);
            }
            _ => st.push(count(None)),
        }
    }
    for rest in added {
        // `<rest>_timers`: fire the first due timer, in node order, or go back.
        let mut check = b.state(&format!("{rest}_timers"));
        for (id, machine, _) in &clock.timers {
            check.push(b.tr(
                None,
                Some(&due_cond(*id)),
                Some(&format!("{rest}_timer_{id}")),
                vec![
                    b.assign(&due(*id), "-1"),
                    b.send(&format!("bt_{id}_timer"), machine),
                ],
            ));
        }
        check.push(b.tr(None, None, Some(&rest), vec![]));
        root.push(check);
        for (id, _, _) in &clock.timers {
            let mut w = b.state(&format!("{rest}_timer_{id}"));
            w.push(b.tr(
                Some(&format!("bt_{id}_timer_done")),
                None,
                Some(&format!("{rest}_timers")),
                vec![],
            ));
            for t in start_cancel() {
                w.push(t);
            }
            w.push(count(None));
            if let Some(wk) = &wake {
                w.push(wk.clone());
            }
            if rest == "idle" && idle_tick.is_some() {
                let mut cb = b.el("ros_rate_callback", &[("name", tick_timer)]);
                cb.push(b.assign("bt_tick_due", "true"));
                w.push(cb);
            }
            root.push(w);
        }
    }
}
