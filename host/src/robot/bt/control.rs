//! The machines of the built-in nodes, the root machine that ticks the tree, and the
//! blackboard machine: the same states, variables and events as AS2FM's translation.
//!
//! Statuses travel as the `status` parameter of `bt_<id>_response`: 1 SUCCESS,
//! 2 FAILURE, 3 RUNNING. A parent halts a child with `bt_<id>_halt` and waits for
//! `bt_<id>_halt_response`; Sequence-like nodes halt every child when they finish.

use super::build::B;
use super::tree::Control;
use crate::model::xml::Element;

/// Status code of SUCCESS.
pub(crate) const SUCCESS: u8 = 1;
/// Status code of FAILURE.
pub(crate) const FAILURE: u8 = 2;
/// Status code of RUNNING.
pub(crate) const RUNNING: u8 = 3;

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
    /// The children: id and machine.
    pub children: Vec<(u32, String)>,
    /// `None`: halt every child as AS2FM does. `Some`: the [`HaltEffect`] of each child;
    /// a child is halted only if that can change something.
    pub effects: Option<Vec<HaltEffect>>,
}

impl Ctx {
    /// `bt_<id>_tick`.
    pub fn tick_ev(&self) -> String {
        format!("bt_{}_tick", self.id)
    }
    /// `bt_<id>_halt`.
    pub fn halt_ev(&self) -> String {
        format!("bt_{}_halt", self.id)
    }
    /// Sends `bt_<id>_response` with `status`.
    pub fn respond(&self, status: u8) -> Element {
        self.b.send_params(
            &format!("bt_{}_response", self.id),
            &self.parent,
            &[("status", &status.to_string())],
        )
    }
    /// Sends `bt_<id>_halt_response`.
    pub fn respond_halted(&self) -> Element {
        self.b
            .send(&format!("bt_{}_halt_response", self.id), &self.halt_target)
    }
    /// Sends `bt_<child>_tick` to child `i`.
    pub fn tick_child(&self, i: usize) -> Element {
        let (id, m) = &self.children[i];
        self.b.send(&format!("bt_{id}_tick"), m)
    }
    /// Sends `bt_<child>_halt` to child `i`.
    pub fn halt_child(&self, i: usize) -> Element {
        let (id, m) = &self.children[i];
        self.b.send(&format!("bt_{id}_halt"), m)
    }
    /// What halting child `i` may change: always `Always` when every child is halted.
    pub fn effect(&self, i: usize) -> HaltEffect {
        self.effects.as_ref().map_or(HaltEffect::Always, |e| e[i])
    }
    /// The variable that says child `i` last answered RUNNING (kept for children whose
    /// halt matters only while they run).
    fn running_var(&self, i: usize) -> Option<String> {
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
    pub fn mark(&self, i: usize, status: u8) -> Option<Element> {
        let v = self.running_var(i)?;
        Some(
            self.b
                .assign(&v, if status == RUNNING { "true" } else { "false" }),
        )
    }
    /// Halts child `i`, forgetting that it ran.
    pub fn halt_child_body(&self, i: usize) -> Vec<Element> {
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
    pub fn halt_single(&self, halting: &str, also: Vec<Element>) -> Vec<Element> {
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
    /// `body` followed by the record that child `i` answered `status`.
    pub(crate) fn marked(&self, i: usize, status: u8, mut body: Vec<Element>) -> Vec<Element> {
        body.extend(self.mark(i, status));
        body
    }
    /// The condition under which halting child `i` is skipped: `None` never skips it.
    pub(crate) fn skip_cond(&self, i: usize) -> Option<String> {
        match self.effect(i) {
            HaltEffect::Never => Some("true".into()),
            HaltEffect::WhenRunning => self.running_var(i).map(|v| format!("!{v}")),
            HaltEffect::Always => None,
        }
    }
    /// In `reset_children`-like states: moves `idx` past the children that need no
    /// halt (and past `also`, a child index variable that is never halted here); empty
    /// when every child is halted.
    fn skip_idle(&self, idx: &str, also: Option<&str>) -> Vec<Element> {
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
    pub fn child_resp(&self, i: usize) -> String {
        format!("bt_{}_response", self.children[i].0)
    }
    /// `bt_<child>_halt_response` of child `i`.
    pub fn child_halt_resp(&self, i: usize) -> String {
        format!("bt_{}_halt_response", self.children[i].0)
    }
    /// `if var == 0: send to child 0, elseif var == 1: ...`, ticking or halting.
    fn dispatch(&self, var: &str, halt: bool) -> Element {
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
        Control::IfThenElse => if_then_else(ctx),
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
    }
}

/// One transition per child, as AS2FM writes them: the child's response with `status`
/// while `idx` points at it goes to `target` doing `body()`.
fn on_child_status(
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
fn sequence_head(ctx: &Ctx, idx: &str, flags: &[&str]) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "init");
    let mut data = vec![(idx, "int8", "0".to_string())];
    data.extend(flags.iter().map(|f| (*f, "bool", "false".to_string())));
    data.push(("children_count", "int8", n_children(ctx)));
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

fn n_children(ctx: &Ctx) -> String {
    ctx.children.len().to_string()
}

/// The `reset_children` state shared by the sequence-like nodes: halts every child in
/// order, then answers the parent according to `finish`.
fn reset_children(ctx: &Ctx, idx: &str, finish: Vec<Element>) -> Element {
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

fn init_state(ctx: &Ctx, bad: &str) -> Element {
    let b = &ctx.b;
    b.state("init")
        .with_child(b.tr(None, Some(bad), Some("error"), vec![]))
        .with_child(b.tr(None, None, Some("wait_for_tick"), vec![]))
}

/// Sequence (`cont` = SUCCESS) or Fallback (`cont` = FAILURE): a child answering `cont`
/// moves on to the next; `stop` halts every child and answers `stop`; RUNNING answers
/// RUNNING and the next tick resumes at the same child.
fn sequence(ctx: &Ctx, cont: u8, stop: u8) -> Element {
    let b = &ctx.b;
    let idx = "current_child_idx";
    let mut m = sequence_head(ctx, idx, &["seq_failure", "seq_success"]);
    let finish = vec![
        b.if_chain(
            vec![
                ("seq_failure".into(), vec![ctx.respond(FAILURE)]),
                ("seq_success".into(), vec![ctx.respond(SUCCESS)]),
            ],
            vec![ctx.respond_halted()],
        )
        .expect("two branches"),
        b.assign(idx, "0"),
        b.assign("seq_failure", "false"),
        b.assign("seq_success", "false"),
    ];
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
    on_child_status(ctx, &mut t, idx, cont, "tick_children", || {
        vec![b.assign(idx, &format!("{idx} + 1"))]
    });
    on_child_status(ctx, &mut t, idx, stop, "reset_children", || {
        vec![b.assign(idx, "0"), b.assign(flag(stop), "true")]
    });
    on_child_status(ctx, &mut t, idx, RUNNING, "wait_for_tick", || {
        vec![ctx.respond(RUNNING)]
    });
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
fn sequence_with_memory(ctx: &Ctx) -> Element {
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
fn reactive(ctx: &Ctx, seq: bool) -> Element {
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
                vec![b.assign(idx, "0"), b.assign(stop_child, "-1")],
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
    on_child_status(ctx, &mut t, idx, cont, "tick_children", || {
        vec![
            b.assign(count, &format!("{count} + 1")),
            b.assign(idx, &format!("{idx} + 1")),
        ]
    });
    on_child_status(ctx, &mut t, idx, stop, "reset_children", || {
        vec![b.assign(stop_child, idx), b.assign(idx, "0")]
    });
    on_child_status(ctx, &mut t, idx, RUNNING, "reset_other_children", || {
        vec![b.assign("running_child", idx), b.assign(idx, "0")]
    });
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

/// Parallel: ticks every child in order each tick; SUCCESS when `success` children
/// succeeded, FAILURE when `failure` failed (halting all children first), else RUNNING.
fn parallel(ctx: &Ctx, success: i64, failure: i64) -> Element {
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
fn if_then_else(ctx: &Ctx) -> Element {
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
    m.push(b.datamodel(&data));
    m.push(init_state(ctx, "children_count < 2 || children_count > 3"));
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
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
    let finish = vec![
        b.if_chain(
            vec![
                ("ret_failure".into(), vec![ctx.respond(FAILURE)]),
                ("ret_success".into(), vec![ctx.respond(SUCCESS)]),
            ],
            vec![ctx.respond_halted()],
        )
        .expect("two branches"),
        b.assign(idx, "0"),
        b.assign("ret_failure", "false"),
        b.assign("ret_success", "false"),
    ];
    m.push(reset_children(ctx, idx, finish));
    let cond_resp = ctx.child_resp(0);
    m.push(
        b.state_entry("tick_condition_child", vec![ctx.tick_child(0)])
            .with_child(b.tr(None, Some(&format!("{idx} != 0")), Some("error"), vec![]))
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
                ctx.marked(0, FAILURE, vec![ctx.respond(FAILURE)]),
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
    m.push(t);
    m.push(b.state("error"));
    m
}

/// A one-child decorator mapping the child's SUCCESS, FAILURE, RUNNING to `map`.
fn decorator(ctx: &Ctx, map: [u8; 3]) -> Element {
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
    m.push(
        b.state_entry("halting_child", ctx.halt_child_body(0))
            .with_child(b.tr(
                Some(&ctx.child_halt_resp(0)),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond_halted()],
            )),
    );
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for (from, to) in [SUCCESS, FAILURE, RUNNING].into_iter().zip(map) {
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {from}")),
            Some("wait_for_tick"),
            ctx.marked(0, from, vec![ctx.respond(to)]),
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
fn repeat(ctx: &Ctx, n: i64, retry: bool) -> Element {
    if retry {
        return retry_node(ctx, n);
    }
    let b = &ctx.b;
    let (count, limit) = ("cycle_count", "n_cycles");
    let (again, stop) = (SUCCESS, FAILURE);
    let more = format!("{limit} == -1 || {count} < {limit}");
    let mut m = repeat_head(ctx, count, limit, n, "start_tick");
    // Out of cycles: Repeat succeeded.
    m.push(
        b.state("start_tick")
            .with_child(b.tr(None, Some(&more), Some("tick_child"), vec![]))
            .with_child(b.tr(
                None,
                None,
                Some("wait_for_tick"),
                vec![ctx.respond(again), b.assign(count, "0")],
            )),
    );
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
    m.push(
        b.state("handle_tick")
            .with_child(b.tr(None, Some(&more), Some("tick_child"), vec![]))
            .with_child(b.tr(
                None,
                None,
                Some("wait_for_tick"),
                vec![ctx.respond(FAILURE), b.assign(count, "0")],
            )),
    );
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
/// Repeat and RetryUntilSuccessful.
fn repeat_head(ctx: &Ctx, count: &str, limit: &str, n: i64, start: &str) -> Element {
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
fn constant(ctx: &Ctx, status: u8) -> Element {
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

/// The machine that ticks the root node `root` (`machine`) at every `<stem>_tick` timer
/// event. With `tick_if_not_running` false it stops after the first answer that is not
/// RUNNING, as AS2FM's does.
pub(crate) fn root_machine(
    b: B,
    name: &str,
    timer: &str,
    rate_hz: f64,
    root: (u32, &str),
    tick_if_not_running: bool,
) -> Element {
    let (id, machine) = root;
    let resp = format!("bt_{id}_response");
    let mut m = b.scxml(name, "idle");
    m.push(b.el(
        "ros_time_rate",
        &[("name", timer), ("rate_hz", &format_rate(rate_hz))],
    ));
    let mut cb = b.el(
        "ros_rate_callback",
        &[("name", timer), ("target", "wait_tick_res")],
    );
    cb.push(b.send(&format!("bt_{id}_tick"), machine));
    m.push(b.state("idle").with_child(cb).with_child(b.tr(
        Some(&resp),
        None,
        Some("error"),
        vec![],
    )));
    let mut w = b.state("wait_tick_res");
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
    m.push(b.state("done"));
    m.push(b.state("error"));
    m
}

/// A rate as written in an attribute: `1.0`, `0.5`, `10.0`.
fn format_rate(r: f64) -> String {
    if r.fract() == 0.0 && r.abs() < 1e15 {
        format!("{r:.1}")
    } else {
        format!("{r}")
    }
}
