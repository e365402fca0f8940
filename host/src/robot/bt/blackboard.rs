//! The blackboard: one machine holding every `{entry}` the tree names, and the built-in
//! nodes that use it (SetBlackboard, BlackboardCheckInt).
//!
//! As in AS2FM's translation, a write is `bt_blackboard_set_<entry>` with a `value`
//! parameter; a read is `bt_blackboard_req`, answered by `bt_blackboard_get` carrying
//! every entry as a parameter of the same name, sent to every machine that reads.

use super::build::B;
use super::control::{status_code, Ctx, FAILURE, RUNNING, SUCCESS};
use crate::model::source::Span;
use crate::model::xml::Element;

/// The blackboard machine's name.
pub(crate) const MACHINE: &str = "bt_blackboard_fsm";
/// The read request event.
pub(crate) const REQ: &str = "bt_blackboard_req";
/// The read answer event.
pub(crate) const GET: &str = "bt_blackboard_get";

/// The write event of entry `name`.
pub(crate) fn set_event(name: &str) -> String {
    format!("bt_blackboard_set_{name}")
}

/// One blackboard entry.
#[derive(Clone, Debug)]
pub(crate) struct Entry {
    /// The entry's name (without braces).
    pub name: String,
    /// Its type (a port type such as `int32` or `string`).
    pub ty: String,
    /// Where the type was first given.
    pub span: Span,
}

/// The entries and readers collected while lowering the tree.
#[derive(Clone, Debug, Default)]
pub(crate) struct Blackboard {
    /// Entries in the order first seen.
    pub entries: Vec<Entry>,
    /// Machines that read (receive `bt_blackboard_get`), in the order first seen.
    pub readers: Vec<String>,
}

impl Blackboard {
    /// The entry called `name`.
    pub fn entry(&self, name: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.name == name)
    }

    /// Records that `machine` reads the blackboard.
    pub fn add_reader(&mut self, machine: &str) {
        if !self.readers.iter().any(|r| r == machine) {
            self.readers.push(machine.to_string());
        }
    }

    /// The blackboard machine, or `None` when the tree uses no entry.
    pub fn machine(&self, b: B) -> Option<Element> {
        if self.entries.is_empty() {
            return None;
        }
        let mut m = b.scxml(MACHINE, "idle");
        let vars: Vec<(&str, &str, String)> = self
            .entries
            .iter()
            .map(|e| (e.name.as_str(), e.ty.as_str(), default_value(&e.ty)))
            .collect();
        m.push(b.datamodel(&vars));
        let mut idle = b.state("idle");
        for e in &self.entries {
            idle.push(b.tr(
                Some(&set_event(&e.name)),
                None,
                Some("idle"),
                vec![b.assign(&e.name, "_event.data.value")],
            ));
        }
        if !self.readers.is_empty() {
            let params: Vec<(&str, &str)> = self
                .entries
                .iter()
                .map(|e| (e.name.as_str(), e.name.as_str()))
                .collect();
            let sends = self
                .readers
                .iter()
                .map(|r| b.send_params(GET, r, &params))
                .collect();
            idle.push(b.tr(Some(REQ), None, Some("idle"), sends));
        }
        m.push(idle);
        Some(m)
    }
}

/// The value an entry of type `ty` has before anything writes it.
pub(crate) fn default_value(ty: &str) -> String {
    let t = ty.trim();
    if t.ends_with(']') {
        "[]".into()
    } else if t == "bool" || t == "boolean" {
        "false".into()
    } else if t == "string" {
        "''".into()
    } else if t.starts_with("float") || t == "double" {
        "0.0".into()
    } else {
        "0".into()
    }
}

/// SetBlackboard: on every tick writes `value` (an expression) to `entry`, answers
/// SUCCESS.
pub(crate) fn set_blackboard(ctx: &Ctx, entry: &str, value: &str) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "idle");
    m.push(
        b.state("idle")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("idle"),
                vec![
                    b.send_params(&set_event(entry), MACHINE, &[("value", value)]),
                    ctx.respond(SUCCESS),
                ],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("idle"),
                vec![ctx.respond_halted()],
            )),
    );
    m
}

/// BlackboardCheckInt: compares `a` and `b` (expressions over `_event.data` when
/// `reads` is true, after a blackboard read); equal ticks the child and answers as it
/// does, different answers `mismatch` (SUCCESS, FAILURE or RUNNING; FAILURE by default).
/// On a mismatch the child is halted before the answer, as AS2FM's
/// `blackboard_check_int.ascxml` does (its `value_mismatch` state) and BT.CPP's
/// `BlackboardPreconditionNode::tick` (`haltChild` when the child is RUNNING); with
/// `Halts::WhenNeeded` only if that can change something.
fn mismatch_halts(ctx: &Ctx, event: Option<&str>, mismatch: u8) -> Vec<Element> {
    let b = &ctx.b;
    let at_once = |cond: Option<&str>| b.tr(event, cond, Some("idle"), vec![ctx.respond(mismatch)]);
    let go = b.tr(event, None, Some("value_mismatch"), vec![]);
    match ctx.skip_cond(0) {
        None => vec![go],
        Some(c) if c == "true" => vec![at_once(None)],
        Some(c) => vec![at_once(Some(&c)), go],
    }
}

pub(crate) fn check_int(ctx: &Ctx, a: &str, b_expr: &str, reads: bool, mismatch: &str) -> Element {
    let b = &ctx.b;
    let mismatch = status_code(mismatch).unwrap_or(FAILURE);
    let mut m = b.scxml(&ctx.machine, "idle");
    let flags = ctx.running_data();
    if !flags.is_empty() {
        let data: Vec<(&str, &str, String)> = flags
            .iter()
            .map(|(v, t, e)| (v.as_str(), *t, e.clone()))
            .collect();
        m.push(b.datamodel(&data));
    }
    let compare = |event: Option<&str>| {
        vec![b.tr(
            event,
            Some(&format!("({a}) == ({b_expr})")),
            Some("tick_child"),
            vec![],
        )]
        .into_iter()
        .chain(mismatch_halts(ctx, event, mismatch))
        .collect::<Vec<_>>()
    };
    let mut idle = b.state("idle");
    if reads {
        idle.push(b.tr(
            Some(&ctx.tick_ev()),
            None,
            Some("read_blackboard"),
            vec![b.send(REQ, MACHINE)],
        ));
    } else {
        idle.push(b.tr(Some(&ctx.tick_ev()), None, Some("compare"), vec![]));
    }
    for t in ctx.halt_single("halting_child", Vec::new()) {
        // The idle state here is `idle`, not `wait_for_tick`.
        idle.push(retarget(t, "wait_for_tick", "idle"));
    }
    m.push(idle);
    if reads {
        let mut r = b.state("read_blackboard");
        for t in compare(Some(GET)) {
            r.push(t);
        }
        m.push(r);
    } else {
        let mut c = b.state("compare");
        for t in compare(None) {
            c.push(t);
        }
        m.push(c);
    }
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE, RUNNING] {
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("idle"),
            ctx.marked(0, s, vec![ctx.respond(s)]),
        ));
    }
    m.push(t);
    m.push(
        b.state_entry("value_mismatch", ctx.halt_child_body(0))
            .with_child(b.tr(
                Some(&ctx.child_halt_resp(0)),
                None,
                Some("idle"),
                vec![ctx.respond(mismatch)],
            )),
    );
    m.push(
        b.state_entry("halting_child", ctx.halt_child_body(0))
            .with_child(b.tr(
                Some(&ctx.child_halt_resp(0)),
                None,
                Some("idle"),
                vec![ctx.respond_halted()],
            )),
    );
    m
}

/// `t` with target `from` changed to `to`.
fn retarget(mut t: Element, from: &str, to: &str) -> Element {
    if t.attr_value("target") == Some(from) {
        t.set_attr("target", to);
    }
    t
}
