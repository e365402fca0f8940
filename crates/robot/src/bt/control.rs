//! The machines of the built-in nodes (dispatch here; the machines themselves in
//! `sequences.rs`, `parallel.rs`, `decorators.rs`), the shared [`Ctx`] and state helpers,
//! and the root machine that ticks the tree: the same states, variables and events as
//! AS2FM's translation.
//!
//! Statuses travel as the `status` parameter of `bt_<id>_response`: 1 SUCCESS,
//! 2 FAILURE, 3 RUNNING. A parent halts a child with `bt_<id>_halt` and waits for
//! `bt_<id>_halt_response`; Sequence-like nodes halt every child when they finish.

use super::btcpp::{WAKE_PENDING, WAKE_UP};
use super::build::B;
use super::decorators::{constant, decorator, repeat};
use super::parallel::{if_then_else, parallel};
use super::sequences::{reactive, sequence, sequence_with_memory};
use super::tree::Control;
use crate::model::xml::Element;

/// Status code of SUCCESS.
pub(crate) const SUCCESS: u8 = 1;
/// Status code of FAILURE.
pub(crate) const FAILURE: u8 = 2;
/// Status code of RUNNING.
pub(crate) const RUNNING: u8 = 3;
/// Status code of SKIPPED from a node that is IDLE afterwards (BT.CPP 4 only: a
/// pre-condition skipped it, or it answers SKIPPED without setting its own status;
/// `TreeNode::executeTick` does not store SKIPPED, 4.10 `tree_node.cpp`).
pub(crate) const SKIPPED: u8 = 4;
/// Status code of SKIPPED from a node that set itself RUNNING before every child was
/// skipped (`setStatus(NodeStatus::RUNNING)` at the top of most controls' and
/// decorators' `tick`): its parent sees a RUNNING child, and halts it when it resets it
/// (`ControlNode::haltChild`). Every parent reads 4 and 5 alike otherwise.
pub(crate) const SKIPPED_RUNNING: u8 = 5;
/// The guard of a SKIPPED answer (4 or 5).
pub(crate) const IS_SKIPPED: &str = "_event.data.status >= 4";

/// The code of a status name (`SUCCESS`, `FAILURE`, `RUNNING`).
pub(crate) fn status_code(name: &str) -> Option<u8> {
    match name.trim() {
        "SUCCESS" => Some(SUCCESS),
        "FAILURE" => Some(FAILURE),
        "RUNNING" => Some(RUNNING),
        _ => None,
    }
}

/// What halting a node in the idle state does, as far as anyone else can tell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum HaltEffect {
    /// Nothing, in any state: a leaf plugin without `<bt_halt>` (it answers at once and
    /// stays where it is), AlwaysSuccess, AlwaysFailure, SetBlackboard, and decorators
    /// without variables over such a child.
    Never,
    /// Nothing once it answered SUCCESS or FAILURE (or was halted, or never ticked): a
    /// built-in control node over children that are `Never` or `WhenRunning`. Its
    /// variables are then already reset, and its children idle.
    WhenRunning,
    /// Possibly something: user code runs (`<bt_halt>` in a plugin, a custom control
    /// plugin), or the node keeps memory across answers (SequenceWithMemory).
    Always,
}

/// Everything a node's machine needs to know about its place in the tree.
#[derive(Clone, Debug)]
pub(crate) struct Ctx {
    /// Builder carrying the tree node's span.
    pub b: B,
    /// The node's id.
    pub id: u32,
    /// The node's machine.
    pub machine: String,
    /// Who gets `bt_<id>_response`: the parent's machine, or the root machine.
    pub parent: String,
    /// Who gets `bt_<id>_halt_response`: the parent's machine, or `NONE` for the root.
    pub halt_target: String,
    /// The children: the stem of their events (`bt_<stem>_tick`: the id, or
    /// `<id>_cond` for a node with pre/post conditions, `btcpp4_conds.rs`) and machine.
    pub children: Vec<(String, String)>,
    /// `None`: halt every child as AS2FM does. `Some`: the [`HaltEffect`] of each child;
    /// a child is halted only if that can change something.
    pub effects: Option<Vec<HaltEffect>>,
    /// The node follows BT.CPP 4's rules ([`super::BtSemantics::Btcpp`]): every child is
    /// `WhenRunning` in `effects` (halted only while RUNNING, BT.CPP 4.10
    /// `control_node.cpp`, `ControlNode::haltChild`), and the nodes whose rules differ
    /// from AS2FM's get the machines of `btcpp.rs`.
    pub btcpp: bool,
    /// Where a node sends the wake-up signal (`bt_wake_up`, BT.CPP 4.10 `tree_node.cpp`,
    /// `TreeNode::emitWakeUpSignal`): the root machine under `tickOnce`, `None` when no
    /// one listens (AS2FM's rules, or `tickExactlyOnce`).
    pub wake: Option<String>,
    /// Under BT.CPP's rules, whether each child is a leaf plugin, a stateful action
    /// (`btcpp.rs`, "Leaves"); empty under AS2FM's.
    pub stateful: Vec<bool>,
    /// Under BT.CPP's rules, whether the parent may tick this node again in a finished
    /// status without resetting it (the condition of a two-child IfThenElse or of a
    /// WhileDoElse, `btcpp4_skip.rs`, `stale`) and this node's rules depend on that
    /// status (a sequence's `skipped_count_`, a Loop's queue): then the parent halts
    /// it at every reset, and a halt while it is not running is BT.CPP's
    /// `resetStatus` (the node IDLE again, nothing else).
    pub stale: bool,
    /// Per child: the child is [`Ctx::stale`] (or its conditions' machine is), so it is
    /// halted at every reset, running or not; empty under AS2FM's rules.
    pub resets: Vec<bool>,
}

impl Ctx {
    /// `bt_<id>_tick`.
    pub(crate) fn tick_ev(&self) -> String {
        format!("bt_{}_tick", self.id)
    }
    /// `bt_<id>_halt`.
    pub(crate) fn halt_ev(&self) -> String {
        format!("bt_{}_halt", self.id)
    }
    /// Sends `bt_<id>_response` with `status`.
    pub(crate) fn respond(&self, status: u8) -> Element {
        self.b.send_params(
            &format!("bt_{}_response", self.id),
            &self.parent,
            &[("status", &status.to_string())],
        )
    }
    /// Sends `bt_<id>_response` with the status `expr` evaluates to.
    pub(crate) fn respond_expr(&self, expr: &str) -> Element {
        self.b.send_params(
            &format!("bt_{}_response", self.id),
            &self.parent,
            &[("status", expr)],
        )
    }
    /// Sends `bt_<id>_halt_response`.
    pub(crate) fn respond_halted(&self) -> Element {
        self.b
            .send(&format!("bt_{}_halt_response", self.id), &self.halt_target)
    }
    /// Sends `bt_<child>_tick` to child `i`.
    pub(crate) fn tick_child(&self, i: usize) -> Element {
        let (id, m) = &self.children[i];
        self.b.send(&format!("bt_{id}_tick"), m)
    }
    /// Sends `bt_<child>_halt` to child `i`.
    pub(crate) fn halt_child(&self, i: usize) -> Element {
        let (id, m) = &self.children[i];
        self.b.send(&format!("bt_{id}_halt"), m)
    }
    /// What halting child `i` may change: always `Always` when every child is halted.
    pub(crate) fn effect(&self, i: usize) -> HaltEffect {
        self.effects.as_ref().map_or(HaltEffect::Always, |e| e[i])
    }
    /// The variable that says child `i` last answered RUNNING (kept for children whose
    /// halt matters only while they run).
    pub(super) fn running_var(&self, i: usize) -> Option<String> {
        (self.effect(i) == HaltEffect::WhenRunning).then(|| format!("child_{i}_running"))
    }
    /// The datamodel entries of the running flags.
    pub(crate) fn running_data(&self) -> Vec<(String, &'static str, String)> {
        (0..self.children.len())
            .filter_map(|i| self.running_var(i))
            .map(|v| (v, "bool", "false".to_string()))
            .collect()
    }
    /// Records that child `i` answered `status` (for children whose flag is kept).
    pub(crate) fn mark(&self, i: usize, status: u8) -> Option<Element> {
        let v = self.running_var(i)?;
        Some(
            self.b
                .assign(&v, if status == RUNNING { "true" } else { "false" }),
        )
    }
    /// The `halting_child` state of a one-child node: halts child 0 (only if it runs),
    /// and when the child has answered, answers the parent's halt and goes back to
    /// `wait_for_tick`.
    pub(crate) fn halting_child_state(&self) -> Element {
        let b = &self.b;
        b.state_entry("halting_child", self.halt_child_body(0))
            .with_child(b.tr(
                Some(&self.child_halt_resp(0)),
                None,
                Some("wait_for_tick"),
                vec![self.respond_halted()],
            ))
    }
    /// Halts child `i`, forgetting that it ran.
    pub(crate) fn halt_child_body(&self, i: usize) -> Vec<Element> {
        let mut v: Vec<Element> = self
            .running_var(i)
            .map(|r| self.b.assign(&r, "false"))
            .into_iter()
            .collect();
        v.push(self.halt_child(i));
        v
    }
    /// The transitions on the node's own halt in the idle state of a one-child node:
    /// to `halting` (which halts the child and answers), or, when the child needs no
    /// halt, `also` and the answer at once.
    pub(crate) fn halt_single(&self, halting: &str, also: Vec<Element>) -> Vec<Element> {
        let b = &self.b;
        let at_once = |cond: Option<&str>| {
            let mut body = also.clone();
            body.push(self.respond_halted());
            b.tr(Some(&self.halt_ev()), cond, Some("wait_for_tick"), body)
        };
        let go = b.tr(Some(&self.halt_ev()), None, Some(halting), vec![]);
        match self.skip_cond(0) {
            None => vec![go],
            Some(c) if c == "true" => vec![at_once(None)],
            Some(c) => vec![at_once(Some(&c)), go],
        }
    }
    /// Records that child `i` answered SKIPPED: RUNNING still when the code is 5.
    pub(crate) fn mark_skipped(&self, i: usize) -> Option<Element> {
        let v = self.running_var(i)?;
        Some(
            self.b
                .assign(&v, &format!("_event.data.status == {SKIPPED_RUNNING}")),
        )
    }
    /// `body` followed by the record that child `i` answered `status`.
    pub(crate) fn marked(&self, i: usize, status: u8, mut body: Vec<Element>) -> Vec<Element> {
        body.extend(self.mark(i, status));
        body
    }
    /// The condition under which halting child `i` is skipped: `None` never skips it.
    pub(crate) fn skip_cond(&self, i: usize) -> Option<String> {
        if self.resets.get(i) == Some(&true) {
            return None;
        }
        match self.effect(i) {
            HaltEffect::Never => Some("true".into()),
            HaltEffect::WhenRunning => self.running_var(i).map(|v| format!("!{v}")),
            HaltEffect::Always => None,
        }
    }
    /// In `reset_children`-like states: moves `idx` past the children that need no
    /// halt (and past `also`, a child index variable that is never halted here); empty
    /// when every child is halted.
    pub(super) fn skip_idle(&self, idx: &str, also: Option<&str>) -> Vec<Element> {
        if self.effects.is_none() {
            return Vec::new();
        }
        (0..self.children.len())
            .filter_map(|i| {
                let skip = match (self.skip_cond(i), also) {
                    (Some(c), Some(a)) if c != "true" => format!("{idx} == {a} || {c}"),
                    (Some(c), _) => c,
                    (None, Some(a)) => format!("{idx} == {a}"),
                    (None, None) => return None,
                };
                let cond = if skip == "true" {
                    format!("{idx} == {i}")
                } else {
                    format!("{idx} == {i} && ({skip})")
                };
                Some(
                    self.b
                        .if_then(&cond, vec![self.b.assign(idx, &format!("{idx} + 1"))]),
                )
            })
            .collect()
    }
    /// `bt_<child>_response` of child `i`.
    pub(crate) fn child_resp(&self, i: usize) -> String {
        format!("bt_{}_response", self.children[i].0)
    }
    /// `bt_<child>_halt_response` of child `i`.
    pub(crate) fn child_halt_resp(&self, i: usize) -> String {
        format!("bt_{}_halt_response", self.children[i].0)
    }
    /// `if var == 0: send to child 0, elseif var == 1: ...`, ticking or halting.
    pub(super) fn dispatch(&self, var: &str, halt: bool) -> Element {
        let branches = (0..self.children.len())
            .map(|i| {
                let body = if halt {
                    self.halt_child_body(i)
                } else {
                    vec![self.tick_child(i)]
                };
                (format!("{var} == {i}"), body)
            })
            .collect();
        self.b
            .if_chain(branches, Vec::new())
            .expect("control nodes have children")
    }
}

/// The machine of built-in node `c`; `params` are its attribute values already checked
/// (`(success threshold, failure threshold)` for Parallel, the count for Repeat/Retry).
pub(crate) fn machine(c: Control, ctx: &Ctx, num: &[i64]) -> Element {
    match c {
        Control::Sequence => sequence(ctx, SUCCESS, FAILURE),
        Control::Fallback => sequence(ctx, FAILURE, SUCCESS),
        Control::SequenceWithMemory => sequence_with_memory(ctx),
        Control::ReactiveSequence => reactive(ctx, true),
        Control::ReactiveFallback => reactive(ctx, false),
        Control::Parallel => parallel(ctx, num[0], num[1]),
        Control::IfThenElse => if_then_else(ctx, false),
        Control::Inverter => decorator(ctx, [FAILURE, SUCCESS, RUNNING]),
        Control::ForceSuccess => decorator(ctx, [SUCCESS, SUCCESS, RUNNING]),
        Control::ForceFailure => decorator(ctx, [FAILURE, FAILURE, RUNNING]),
        Control::Repeat => repeat(ctx, num[0], false),
        Control::RetryUntilSuccessful => repeat(ctx, num[0], true),
        Control::AlwaysSuccess => constant(ctx, SUCCESS),
        Control::AlwaysFailure => constant(ctx, FAILURE),
        Control::BlackboardCheck(_) | Control::SetBlackboard => {
            unreachable!("blackboard nodes are built in blackboard.rs")
        }
        Control::Btcpp4(_) => unreachable!("BT.CPP 4's own nodes are built in btcpp4.rs"),
    }
}

/// The count of children skipped since the node last finished (`skipped_count_`).
pub(super) const SKIP_COUNT: &str = "skipped_count";

/// Under BT.CPP's rules, one transition per child: its SKIPPED answer while `idx` points
/// at it goes to `target`, recording whether it still runs, doing `body()`.
pub(super) fn on_child_skipped(
    ctx: &Ctx,
    t: &mut Element,
    idx: &str,
    target: &str,
    body: impl Fn() -> Vec<Element>,
) {
    for i in 0..ctx.children.len() {
        let mut v: Vec<Element> = ctx.mark_skipped(i).into_iter().collect();
        v.extend(body());
        t.push(ctx.b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("{IS_SKIPPED} && {idx} == {i}")),
            Some(target),
            v,
        ));
    }
}

/// [`on_child_skipped`] of a sequence or fallback under BT.CPP 4 (`case
/// NodeStatus::SKIPPED`): on to the next child, the skip counted in [`SKIP_COUNT`]
/// (`skipped_count_`), back to `target`.
pub(super) fn skip_to_next(ctx: &Ctx, t: &mut Element, idx: &str, target: &str) {
    on_child_skipped(ctx, t, idx, target, || {
        vec![
            ctx.b.assign(idx, &format!("{idx} + 1")),
            ctx.b.assign(SKIP_COUNT, &format!("{SKIP_COUNT} + 1")),
        ]
    });
}

/// The transition of a node whose child index `idx` left its range: to `error`.
pub(super) fn index_out_of_range(ctx: &Ctx, idx: &str) -> Element {
    ctx.b.tr(
        None,
        Some(&format!("{idx} < 0 || {idx} > children_count")),
        Some("error"),
        vec![],
    )
}

/// One transition per child, as AS2FM writes them: the child's response with `status`
/// while `idx` points at it goes to `target` doing `body()`.
pub(super) fn on_child_status(
    ctx: &Ctx,
    t: &mut Element,
    idx: &str,
    status: u8,
    target: &str,
    body: impl Fn() -> Vec<Element>,
) {
    for i in 0..ctx.children.len() {
        t.push(ctx.b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("_event.data.status == {status} && {idx} == {i}")),
            Some(target),
            ctx.marked(i, status, body()),
        ));
    }
}

/// The start of Sequence, Fallback and SequenceWithMemory: the child index, the result
/// `flags`, the init check, and `wait_for_tick` (a tick ticks the children, a halt resets
/// them).
pub(super) fn sequence_head(ctx: &Ctx, idx: &str, flags: &[&str]) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    let mut data = vec![(idx, "int8", "0".to_string())];
    data.extend(flags.iter().map(|f| (*f, "bool", "false".to_string())));
    data.push(("children_count", "int8", n_children(ctx)));
    // BT.CPP 4.10 `SequenceNode` / `FallbackNode`: `skipped_count_`.
    if ctx.btcpp {
        data.push((SKIP_COUNT, "int8", "0".to_string()));
    }
    let flags = ctx.running_data();
    data.extend(flags.iter().map(|(v, t, e)| (v.as_str(), *t, e.clone())));
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 1"));
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(Some(&ctx.tick_ev()), None, Some("tick_children"), vec![]))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("reset_children"),
                vec![b.assign(idx, "0")],
            )),
    );
    m
}

pub(super) fn n_children(ctx: &Ctx) -> String {
    ctx.children.len().to_string()
}

/// The `finish` of [`reset_children`] for a node that keeps why it halts its children in
/// two flags: answers FAILURE if `failure` is set, else SUCCESS if `success` is, else
/// halted; then clears `idx` and both flags.
pub(super) fn answer_by_flags(ctx: &Ctx, idx: &str, failure: &str, success: &str) -> Vec<Element> {
    let b = &ctx.b;
    vec![
        b.if_chain(
            vec![
                (failure.into(), vec![ctx.respond(FAILURE)]),
                (success.into(), vec![ctx.respond(SUCCESS)]),
            ],
            vec![ctx.respond_halted()],
        )
        .expect("two branches"),
        b.assign(idx, "0"),
        b.assign(failure, "false"),
        b.assign(success, "false"),
    ]
}

/// The `reset_children` state shared by the sequence-like nodes: halts every child in
/// order, then answers the parent according to `finish`.
pub(super) fn reset_children(ctx: &Ctx, idx: &str, finish: Vec<Element>) -> Element {
    let b = &ctx.b;
    let guard = b.if_then(
        &format!("{idx} < children_count"),
        vec![ctx.dispatch(idx, true)],
    );
    let mut entry = ctx.skip_idle(idx, None);
    entry.push(guard);
    let mut s = b.state_entry("reset_children", entry);
    for i in 0..ctx.children.len() {
        s.push(b.tr(
            Some(&ctx.child_halt_resp(i)),
            Some(&format!("{idx} == {i}")),
            Some("reset_children"),
            vec![b.assign(idx, &format!("{idx} + 1"))],
        ));
    }
    s.push(b.tr(
        None,
        Some(&format!("{idx} >= children_count")),
        Some("wait_for_tick"),
        finish,
    ));
    s
}

pub(super) fn init_state(ctx: &Ctx, bad: &str) -> Element {
    let b = &ctx.b;
    b.state("init")
        .with_child(b.tr(None, Some(bad), Some("error"), vec![]))
        .with_child(b.tr(None, None, Some("wait_for_tick"), vec![]))
}

/// The machine that ticks the root node `root` (the stem of its events, `bt_<stem>_tick`,
/// and its machine: `<id>_cond` and its conditions' machine for a root with pre/post
/// conditions, `btcpp4_conds.rs`) at every `<stem>_tick` timer event. With
/// `tick_if_not_running` false it stops after the first answer that is not RUNNING, as
/// AS2FM's does.
///
/// With `wake_up` (BT.CPP's `tickOnce`) it also keeps the wake-up signal: `bt_wake_up`
/// sets `wake_pending` in any state; a RUNNING answer while it is set clears it and
/// ticks the root again at once (BT.CPP 4 `bt_factory.cpp`, `Tree::tickRoot`, the inner
/// `while` over `wake_up_->waitFor(0)`, which clears the signal it takes). A finished
/// answer leaves the signal pending: `waitFor` is only called after a RUNNING one.
pub(crate) fn root_machine(
    b: B,
    name: &str,
    timer: &str,
    rate_hz: f64,
    root: (&str, &str),
    tick_if_not_running: bool,
    wake_up: bool,
) -> Element {
    let (id, machine) = root;
    let resp = format!("bt_{id}_response");
    let tick = || b.send(&format!("bt_{id}_tick"), machine);
    // A state that takes the wake-up signal whenever it comes.
    let waking = |s: Element| {
        if wake_up {
            s.with_child(b.tr(
                Some(WAKE_UP),
                None,
                None,
                vec![b.assign(WAKE_PENDING, "true")],
            ))
        } else {
            s
        }
    };
    let mut m = b.scxml(name, "idle");
    if wake_up {
        m.push(b.datamodel(&[(WAKE_PENDING, "bool", "false".into())]));
    }
    m.push(b.el(
        "ros_time_rate",
        &[("name", timer), ("rate_hz", &format_rate(rate_hz))],
    ));
    let mut cb = b.el(
        "ros_rate_callback",
        &[("name", timer), ("target", "wait_tick_res")],
    );
    cb.push(tick());
    m.push(waking(b.state("idle").with_child(cb)).with_child(b.tr(
        Some(&resp),
        None,
        Some("error"),
        vec![],
    )));
    let mut w = waking(b.state("wait_tick_res"));
    if wake_up {
        w.push(b.tr(
            Some(&resp),
            Some(&format!(
                "_event.data.status == {RUNNING} && {WAKE_PENDING}"
            )),
            Some("wait_tick_res"),
            vec![b.assign(WAKE_PENDING, "false"), tick()],
        ));
    }
    if tick_if_not_running {
        w.push(b.tr(Some(&resp), None, Some("idle"), vec![]));
    } else {
        w.push(b.tr(
            Some(&resp),
            Some(&format!("_event.data.status == {RUNNING}")),
            Some("idle"),
            vec![],
        ));
        w.push(b.tr(Some(&resp), None, Some("done"), vec![]));
    }
    m.push(w);
    m.push(waking(b.state("done")));
    m.push(b.state("error"));
    m
}

/// A rate as written in an attribute: `1.0`, `0.5`, `10.0`.
pub(super) fn format_rate(r: f64) -> String {
    if r.fract() == 0.0 && r.abs() < 1e15 {
        format!("{r:.1}")
    } else {
        format!("{r}")
    }
}
