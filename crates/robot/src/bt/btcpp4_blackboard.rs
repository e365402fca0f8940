//! BehaviorTree.CPP 4's UnsetBlackboard lowered under [`super::BtSemantics::Btcpp`]: the
//! entry's "has value" flag in the blackboard machine (`btcpp4_script.rs`, `has`) is
//! cleared, so that a script reading the entry afterwards throws, as in BT.CPP
//! (docs/SEMANTICS.md, "Entries that may be unset, update counters, and queues").
//!
//! Only an entry that scripts alone use can be unset here: an entry a plugin's port, a
//! BlackboardCheck or a Switch types, or a SetBlackboard writes, holds a value in the
//! model at all times, and is refused at the `key` port. The entry-updated nodes and the
//! Loop nodes are not lowered yet (README, "BehaviorTree.CPP built-ins hindsight
//! refuses"); the test oracle models them.

use super::blackboard::{Blackboard, Entry, MACHINE};
use super::control::{Ctx, SUCCESS};
use super::tree::{PortValue, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

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
    // The tree reader resolved the key's entry (`script_names`): a SubTree's key was
    // refused there.
    let resolved = |k: &str| {
        n.script_names
            .iter()
            .find(|(name, _)| name == k.trim())
            .map(|(_, v)| v)
    };
    let g = match &p.value {
        // Unresolved: the tree reader reported why.
        PortValue::Literal(k) => match resolved(k) {
            Some(PortValue::Blackboard(g)) => g.clone(),
            _ => return None,
        },
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
            ty: "int64".into(),
            span: p.span,
            why: "a script".into(),
        }),
    }
    if !bb.script_entries.contains(&g) {
        bb.script_entries.push(g.clone());
    }
    // `blackboard->unset(key)`: the entry no longer holds a value (also when it held
    // none); then SUCCESS.
    let b = &ctx.b;
    bb.scripts.push(b.tr(
        Some(&run_event(n.id)),
        None,
        Some("idle"),
        vec![
            b.assign(&super::btcpp4_script::has(&g), "false"),
            b.send(&done_event(n.id), &ctx.machine),
        ],
    ));
    Some(machine(ctx))
}

/// The node's machine: a tick asks the blackboard machine to unset the entry and answers
/// SUCCESS once it has; never RUNNING, so a halt answers at once.
fn machine(ctx: &Ctx) -> Element {
    let b = &ctx.b;
    let mut m = b.scxml(&ctx.machine, "wait_for_tick");
    m.push(
        b.state("wait_for_tick")
            .with_child(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("unsetting"),
                vec![b.send(&run_event(ctx.id), MACHINE)],
            ))
            .with_child(b.tr(
                Some(&ctx.halt_ev()),
                None,
                Some("wait_for_tick"),
                vec![ctx.respond_halted()],
            )),
    );
    m.push(b.state("unsetting").with_child(b.tr(
        Some(&done_event(ctx.id)),
        None,
        Some("wait_for_tick"),
        vec![ctx.respond(SUCCESS)],
    )));
    m
}
