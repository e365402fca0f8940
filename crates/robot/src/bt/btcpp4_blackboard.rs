//! BehaviorTree.CPP 4's UnsetBlackboard and the entry-updated nodes (WasEntryUpdated,
//! SkipUnlessUpdated, WaitValueUpdate) lowered under [`super::BtSemantics::Btcpp`]
//! (docs/SEMANTICS.md, "Entries that may be unset, update counters, and queues").
//!
//! UnsetBlackboard clears the entry's "has value" flag in the blackboard machine
//! (`btcpp4_script.rs`, `has`), so that a script reading the entry afterwards throws, as
//! in BT.CPP. Only an entry that scripts (and Loop nodes, `btcpp4_loop.rs`) alone use can
//! be unset here: an entry a plugin's port, a BlackboardCheck or a Switch types, or a
//! SetBlackboard writes, holds a value in the model at all times, and is refused at the
//! `key` port. (An entry UnsetBlackboard names is a script's: a Loop writes numbers
//! there.)
//!
//! # Update counters
//! BT.CPP 4 keeps a counter per entry (`Blackboard::Entry::sequence_id`, one more at
//! every write, 0 for an entry created anew). For every entry an entry-updated node looks
//! at ([`Blackboard::watched`]), the blackboard machine keeps `bt_seq__<entry>`: one more
//! at every `bt_blackboard_set_<entry>` (SetBlackboard, a plugin's output, a Loop's
//! `value`) and every script assignment (`btcpp4_script.rs`, `compile`), 0 again where
//! UnsetBlackboard erases the entry. Each node keeps the counter it saw last,
//! `bt_seen__<id>`, in the blackboard machine too, so that looking and remembering is one
//! transition no write can come between: the node sends `bt_updated_<id>_run` and gets
//! `bt_updated_<id>_done` with `value` true when the entry exists (its "has value" flag,
//! for an entry that has one; any other entry holds a value from the start, with counter
//! 0, which answers as a missing one would) and its counter differs from the one seen,
//! which it then keeps (BT.CPP 4.10 `src/actions/updated_action.cpp`,
//! `EntryUpdatedAction::tick`; `src/decorators/updated_decorator.cpp`,
//! `EntryUpdatedDecorator::tick`). A counter of 64 bits grows by one per write, at most
//! one per model step: no run the simulator can make overflows it.

use super::blackboard::{Blackboard, Entry, MACHINE};
use super::btcpp4_script::asking_machine;
use super::control::{Ctx, FAILURE, IS_SKIPPED, RUNNING, SKIPPED, SKIPPED_RUNNING, SUCCESS};
use super::tree::{Btcpp4, Control, Kind, PortValue, Tree, TreeNode, UpdatedNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

/// The blackboard machine's update counter of entry `e`.
pub(crate) fn seq(e: &str) -> String {
    format!("bt_seq__{e}")
}

/// The blackboard machine's copy of the counter node `id` saw last.
fn seen(id: u32) -> String {
    format!("bt_seen__{id}")
}

/// The event asking the blackboard machine whether node `id`'s entry was updated.
fn updated_run(id: u32) -> String {
    format!("bt_updated_{id}_run")
}

/// The blackboard machine's answer to node `id` (`value`: updated).
fn updated_done(id: u32) -> String {
    format!("bt_updated_{id}_done")
}

/// The node's name in a tree.
pub(super) fn updated_name(u: UpdatedNode) -> &'static str {
    match u {
        UpdatedNode::Was => "WasEntryUpdated",
        UpdatedNode::Skip => "SkipUnlessUpdated",
        UpdatedNode::Wait => "WaitValueUpdate",
    }
}

/// Before any node is lowered (so that every script knows which writes to count): the
/// entries the entry-updated nodes look at, and the entries the Loop nodes write
/// (`btcpp4_loop.rs`).
pub(super) fn prepare(
    sm: &SourceMap,
    tree: &Tree,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) {
    super::btcpp4_script::float_entries(tree, bb);
    for (i, n) in tree.nodes.iter().enumerate() {
        match n.kind {
            Kind::Control(Control::Btcpp4(Btcpp4::Updated(_))) => {
                if let Some(PortValue::Blackboard(g)) = n.port("entry").map(|p| &p.value) {
                    if !bb.watched.contains(g) {
                        bb.watched.push(g.clone());
                    }
                }
            }
            Kind::Control(Control::Btcpp4(Btcpp4::Loop(t))) => {
                super::btcpp4_loop::prepare(sm, tree, i, t, bb, errs)
            }
            _ => {}
        }
    }
    // The entries a port created that an UnsetBlackboard erases (`Blackboard::gone`).
    for n in &tree.nodes {
        if n.kind != Kind::Control(Control::Btcpp4(Btcpp4::Unset)) {
            continue;
        }
        if let Some(g) = unset_key(n) {
            if bb.declared.contains(&g) && !bb.gone.contains(&g) {
                bb.gone.push(g);
            }
        }
    }
}

/// The entry UnsetBlackboard node `n` erases, as the tree reader resolved its `key`
/// (`script_names`); `None` where it did not (it reported why) or `key` is not a name.
fn unset_key(n: &TreeNode) -> Option<String> {
    let PortValue::Literal(k) = &n.port("key")?.value else {
        return None;
    };
    match n.script_names.iter().find(|(name, _)| name == k.trim()) {
        Some((_, PortValue::Blackboard(g))) => Some(g.clone()),
        _ => None,
    }
}

/// The counters' variables: one per watched entry, one per entry-updated node.
pub(super) fn counter_data(bb: &Blackboard) -> Vec<(String, &'static str)> {
    let mut v: Vec<(String, &'static str)> = bb.watched.iter().map(|e| (seq(e), "int64")).collect();
    v.extend(bb.updated.iter().map(|(id, _, _)| (seen(*id), "int64")));
    v
}

/// The count of a write of entry `e`, if its counter is kept.
pub(super) fn count_write(bb: &Blackboard, b: super::build::B, e: &str) -> Option<Element> {
    bb.watched
        .iter()
        .any(|w| w == e)
        .then(|| b.assign(&seq(e), &format!("{} + 1", seq(e))))
}

/// The blackboard machine's transitions that answer the entry-updated nodes.
pub(super) fn updated_transitions(bb: &Blackboard, b: super::build::B) -> Vec<Element> {
    bb.updated
        .iter()
        .map(|(id, e, machine)| {
            let (c, s) = (seq(e), seen(*id));
            // `getEntry` finds no entry: not updated, the counter seen kept.
            let exists = if bb.script_entries.contains(e) {
                format!("{} && ", super::btcpp4_script::has(e))
            } else {
                String::new()
            };
            let done = updated_done(*id);
            let body = b
                .if_chain(
                    vec![(
                        format!("{exists}{c} != {s}"),
                        vec![
                            b.assign(&s, &c),
                            b.send_params(&done, machine, &[("value", "true")]),
                        ],
                    )],
                    vec![b.send_params(&done, machine, &[("value", "false")])],
                )
                .expect("one branch");
            b.tr(Some(&updated_run(*id)), None, Some("idle"), vec![body])
        })
        .collect()
}

/// Checks entry-updated node `n` and builds its machine; its look at the counter goes
/// into the blackboard machine ([`Blackboard::updated`]).
pub(super) fn updated(
    sm: &SourceMap,
    u: UpdatedNode,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    let name = updated_name(u);
    // The constructors throw "Missing port 'entry'" without it, or with it empty.
    let Some(p) = n.port("entry") else {
        errs.push(sm.diag(
            n.span,
            format!("{name} needs `entry` (BehaviorTree.CPP throws \"Missing port 'entry'\")"),
        ));
        return None;
    };
    let g = match &p.value {
        PortValue::Blackboard(g) => g.clone(),
        // The tree reader resolved a name through the SubTrees (`getEntry` follows their
        // remapping): a literal left is no name, or a SubTree's constant.
        PortValue::Literal(v) => {
            errs.push(sm.diag(
                p.span,
                format!("`entry` of {name} must name a blackboard entry (`x` or `{{x}}`); `{}` is not a name, or is a constant its SubTree sets, whose counter is not modelled", v.trim()),
            ));
            return None;
        }
    };
    bb.updated.push((n.id, g, ctx.machine.clone()));
    Some(match u {
        UpdatedNode::Was => was_updated(ctx),
        UpdatedNode::Skip => updated_decorator(ctx, SKIPPED),
        UpdatedNode::Wait => updated_decorator(ctx, RUNNING),
    })
}

/// WasEntryUpdated (`EntryUpdatedAction::tick`): SUCCESS if updated, else FAILURE; never
/// RUNNING, so a halt answers at once.
fn was_updated(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let mut m = asking_machine(ctx, "asking", &updated_run(ctx.id));
    let done = updated_done(ctx.id);
    m.push(
        b.state("asking")
            .with_child(b.tr(
                Some(&done),
                Some("_event.data.value"),
                Some("wait_for_tick"),
                vec![ctx.respond(SUCCESS)],
            ))
            .with_child(b.tr(
                Some(&done),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond(FAILURE)],
            )),
    );
    m
}

/// SkipUnlessUpdated (`otherwise` SKIPPED) and WaitValueUpdate (RUNNING) as
/// `EntryUpdatedDecorator::tick` runs them: a child still RUNNING
/// (`still_executing_child_`) is ticked without looking at the entry; otherwise not
/// updated answers `otherwise` and updated ticks the child, whose answer is the node's.
/// The node never sets its own status (SKIPPED leaves it as it was: code 5 while it is
/// RUNNING, `control.rs`), and a finished child is reset after the tick
/// (`DecoratorNode::executeTick`): not RUNNING, so nothing to halt.
///
/// A halt forgets the running child and does not halt it: BT.CPP 4.8.2, the library the
/// tests run, leaves it RUNNING, and the decorator's next tick that finds the entry
/// updated goes on with it (docs/SEMANTICS.md; 4.10's `EntryUpdatedDecorator::halt`
/// calls `DecoratorNode::halt`, which would halt it).
fn updated_decorator(ctx: &Ctx, otherwise: u8) -> Element {
    let b = &ctx.b;
    let (still, me) = ("still_executing_child", "self_running");
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    m.push(b.datamodel(&[
        (still, "bool", "false".into()),
        (me, "bool", "false".into()),
    ]));
    // SKIPPED, the node's own status as it was (RUNNING or not).
    let skipped = || {
        b.if_chain(
            vec![(me.to_string(), vec![ctx.respond(SKIPPED_RUNNING)])],
            vec![ctx.respond(SKIPPED)],
        )
        .expect("one branch")
    };
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                Some(still),
                Some("tick_child"),
                vec![],
            ))
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("asking"),
                vec![b.send(&updated_run(ctx.id), MACHINE)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("wait_for_tick"),
                vec![
                    b.assign(still, "false"),
                    b.assign(me, "false"),
                    ctx.respond_halted(),
                ],
            )),
    );
    let not_updated = if otherwise == RUNNING {
        vec![b.assign(me, "true"), ctx.respond(RUNNING)]
    } else {
        vec![skipped()]
    };
    let done = updated_done(ctx.id);
    m.push(
        b.state("asking")
            .with_child(b.tr(
                Some(&done),
                Some("_event.data.value"),
                Some("tick_child"),
                vec![],
            ))
            .with_child(b.tr(Some(&done), None, Some("wait_for_tick"), not_updated)),
    );
    let mut t = b.state_entry("tick_child", vec![ctx.tick_child(0)]);
    for s in [SUCCESS, FAILURE, RUNNING] {
        let r = if s == RUNNING { "true" } else { "false" };
        t.push(b.tr(
            Some(&ctx.child_resp(0)),
            Some(&format!("_event.data.status == {s}")),
            Some("wait_for_tick"),
            vec![b.assign(still, r), b.assign(me, r), ctx.respond(s)],
        ));
    }
    t.push(b.tr(
        Some(&ctx.child_resp(0)),
        Some(IS_SKIPPED),
        Some("wait_for_tick"),
        vec![b.assign(still, "false"), skipped()],
    ));
    m.push(t);
    m
}

/// The event asking the blackboard machine to unset node `id`'s entry.
fn run_event(id: u32) -> String {
    format!("bt_unset_{id}_run")
}

/// The blackboard machine's answer to node `id`.
fn done_event(id: u32) -> String {
    format!("bt_unset_{id}_done")
}

/// Checks UnsetBlackboard node `n` and builds its machine; its transition goes into the
/// blackboard machine (`bb.scripts`).
pub(super) fn unset(
    sm: &SourceMap,
    n: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<Element> {
    // `UnsetBlackboardNode::tick` (4.10 `actions/unset_blackboard_node.h`): without
    // `key` it throws "missing input port [key]".
    let Some(p) = n.port("key") else {
        errs.push(sm.diag(
            n.span,
            "UnsetBlackboard needs `key` (BehaviorTree.CPP throws \"missing input port [key]\")",
        ));
        return None;
    };
    let g = match &p.value {
        // The tree reader resolved the key's entry (`script_names`): a SubTree's key was
        // refused there, and an unresolved one reported.
        PortValue::Literal(_) => unset_key(n)?,
        PortValue::Blackboard(e) => {
            errs.push(sm.diag(
                p.span,
                format!("`key` of UnsetBlackboard is the entry's name; `{{{e}}}` would make BehaviorTree.CPP read the entry's value as the name to erase, which is not modelled: write key=\"{e}\""),
            ));
            return None;
        }
    };
    if bb.texts.contains(&g) {
        errs.push(sm.diag(
            p.span,
            format!("UnsetBlackboard erases `{g}`, which a SetBlackboard writes: only entries that scripts alone use may be unset in the model"),
        ));
        return None;
    }
    match bb.entry(&g) {
        Some(e) if e.why != "a script" => {
            let at = sm.diag(e.span, "");
            errs.push(sm.diag(
                p.span,
                format!("UnsetBlackboard erases `{g}`, which is {} at {}:{}:{} ({}): only entries that scripts alone use may be unset in the model", e.ty, at.file, at.line, at.col, e.why),
            ));
            return None;
        }
        Some(_) => {}
        None => bb.entries.push(Entry {
            name: g.clone(),
            ty: super::btcpp4_script::entry_type(bb, &g).into(),
            span: p.span,
            why: "a script".into(),
        }),
    }
    if !bb.script_entries.contains(&g) {
        bb.script_entries.push(g.clone());
    }
    // `blackboard->unset(key)`: the entry no longer holds a value (also when it held
    // none), and one created again counts its writes from 0; then SUCCESS.
    let b = &ctx.b;
    let mut body = vec![b.assign(&super::btcpp4_script::has(&g), "false")];
    if bb.gone.contains(&g) {
        body.push(b.assign(&super::btcpp4_script::gone(&g), "true"));
    }
    if bb.watched.contains(&g) {
        body.push(b.assign(&seq(&g), "0"));
    }
    body.push(b.send(&done_event(n.id), &ctx.machine));
    bb.scripts
        .push(b.tr(Some(&run_event(n.id)), None, Some("idle"), body));
    Some(machine(ctx))
}

/// The node's machine: a tick asks the blackboard machine to unset the entry and answers
/// SUCCESS once it has; never RUNNING, so a halt answers at once.
fn machine(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let mut m = asking_machine(ctx, "unsetting", &run_event(ctx.id));
    m.push(b.state("unsetting").with_child(b.tr(
        Some(&done_event(ctx.id)),
        None,
        Some("wait_for_tick"),
        vec![ctx.respond(SUCCESS)],
    )));
    m
}
