//! BehaviorTree.CPP 4's Switch2 ... Switch6 (`--bt btcpp`): how the node picks its child
//! (a constant `variable`, or a string entry compared to each case on every tick) and
//! its machine.

use super::blackboard::Blackboard;
use super::btcpp::{halting_state, running};
use super::btcpp4::{node_name, push_child_done, push_data};
use super::btcpp4_skip::SELF_RUNNING;
use super::control::{init_state, n_children, Ctx, IS_SKIPPED, RUNNING};
use super::tree::{Btcpp4, PortValue, TreeNode};
use crate::model::source::{Diagnostic, SourceMap};
use crate::model::xml::Element;

/// How Switch node `n` (of `cases` cases) picks its child, or errors.
pub(super) fn pick(
    sm: &SourceMap,
    k: Btcpp4,
    cases: usize,
    n: &TreeNode,
    bb: &Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Option<SwitchPick> {
    let name = node_name(k);
    let before = errs.len();
    let mut given: Vec<(usize, String)> = Vec::new();
    for i in 1..=cases {
        let key = format!("case_{i}");
        // A case not given never matches (`getInput` fails and the loop goes on).
        let Some(p) = n.port(&key) else { continue };
        match &p.value {
            PortValue::Literal(v) => given.push((i - 1, v.clone())),
            PortValue::Blackboard(b) => errs.push(sm.diag(
                p.span,
                format!("`{key}` of {name} must be a constant; a blackboard entry (`{{{b}}}`) is not supported here"),
            )),
        }
    }
    let pick = match n.port("variable").map(|p| (&p.value, p.span)) {
        // No variable: the default child (`getInput("variable")` fails).
        None => SwitchPick::Fixed(cases),
        Some((PortValue::Literal(v), _)) => SwitchPick::Fixed(
            given
                .iter()
                .find(|(_, c)| same_text(v, c))
                .map_or(cases, |(i, _)| *i),
        ),
        Some((PortValue::Blackboard(entry), span)) => {
            match bb.entry(entry) {
                Some(e) if e.ty.trim() == "string" => {}
                // `type_entries` reported a conflict or the missing type.
                Some(_) | None => {
                    if errs.len() == before && bb.entry(entry).is_none() {
                        errs.push(sm.diag(span, format!("blackboard entry `{{{entry}}}` has no type: nothing writes it a constant and no port reads it")));
                    }
                    return None;
                }
            }
            // BT.CPP compares the texts as numbers too (`CheckStringEquality`): a string
            // entry holding `1.0` matches a case `1`. hindsight compares strings as
            // text only, so a case that reads as a number is refused.
            for (i, c) in &given {
                if numeric_text(c) {
                    let span = n
                        .port(&format!("case_{}", i + 1))
                        .map_or(n.span, |p| p.span);
                    errs.push(sm.diag(
                        span,
                        format!("`case_{}` of {name} is the number `{c}`: BehaviorTree.CPP would also match the entry's text as a number (`1.0` matches `1`), which hindsight does not model for the string entry `{{{entry}}}`", i + 1),
                    ));
                }
            }
            SwitchPick::Entry(
                entry.clone(),
                given
                    .iter()
                    .map(|(i, c)| (*i, super::plugin::literal_expr(c, "string")))
                    .collect(),
            )
        }
    };
    (errs.len() == before).then_some(pick)
}

/// How a Switch picks its child on a tick.
pub(super) enum SwitchPick {
    /// The `variable` port is a constant: the child is known when lowering.
    Fixed(usize),
    /// The `variable` port is a string entry: `(case index, value as an expression)` for
    /// each case port given, compared in order to the entry read on every tick.
    Entry(String, Vec<(usize, String)>),
}

/// Switch2 ... Switch6 as BT.CPP 4.10 runs them (`controls/switch_node.h`,
/// `SwitchNode::tick`): the first case equal to `variable` picks its child, none (or no
/// `variable`) the last, the default; a child that answered RUNNING on an earlier tick
/// and is not the one picked is halted first (`haltChild(running_child_)`); RUNNING
/// remembers the child, a finished answer resets every child and forgets it.
/// `SwitchNode::halt` forgets it and resets the children.
pub(super) fn switch(ctx: &Ctx, pick: &SwitchPick) -> Element {
    let b = &ctx.b;
    let h = "halt_idx";
    let mut m = b.scxml(&ctx.machine, "init");
    push_data(
        ctx,
        &mut m,
        &[
            ("children_count", "int8", n_children(ctx)),
            (h, "int8", "0".into()),
            ("running_child", "int8", "-1".into()),
            ("match_index", "int8", "0".into()),
            ("result", "int8", "0".into()),
            (SELF_RUNNING, "bool", "false".into()),
        ],
    );
    m.push(init_state(ctx, "children_count < 1"));
    let default = ctx.children.len() - 1;
    let mut w = b.state("wait_for_tick");
    match pick {
        SwitchPick::Fixed(i) => w.push(b.tr(
            Some(&ctx.tick_ev()),
            None,
            Some("choose_child"),
            vec![b.assign("match_index", &i.to_string())],
        )),
        SwitchPick::Entry(entry, cases) => {
            w.push(b.tr(
                Some(&ctx.tick_ev()),
                None,
                Some("read_blackboard"),
                vec![b.send(super::blackboard::REQ, super::blackboard::MACHINE)],
            ));
            let var = format!("_event.data.{entry}");
            let chain = b.if_chain(
                cases
                    .iter()
                    .map(|(i, v)| {
                        (
                            format!("{var} == {v}"),
                            vec![b.assign("match_index", &i.to_string())],
                        )
                    })
                    .collect(),
                vec![b.assign("match_index", &default.to_string())],
            );
            let body = chain.map_or_else(
                || vec![b.assign("match_index", &default.to_string())],
                |c| vec![c],
            );
            m.push(b.state("read_blackboard").with_child(b.tr(
                Some(super::blackboard::GET),
                None,
                Some("choose_child"),
                body,
            )));
        }
    }
    w.push(b.tr(
        Some(&ctx.halt_ev()),
        None,
        Some("halting_on_halt"),
        vec![b.assign(h, "0")],
    ));
    m.push(w);
    m.push(
        b.state("choose_child")
            .with_child(b.tr(
                None,
                Some("running_child != -1 && running_child != match_index"),
                Some("halting_previous"),
                vec![],
            ))
            .with_child(b.tr(None, None, Some("tick_child"), vec![])),
    );
    let mut hp = b.state_entry(
        "halting_previous",
        vec![ctx.dispatch("running_child", true)],
    );
    for i in 0..ctx.children.len() {
        hp.push(b.tr(
            Some(&ctx.child_halt_resp(i)),
            Some(&format!("running_child == {i}")),
            Some("tick_child"),
            vec![b.assign("running_child", "-1")],
        ));
    }
    m.push(hp);
    let mut t = b.state_entry("tick_child", vec![ctx.dispatch("match_index", false)]);
    for i in 0..ctx.children.len() {
        let r = running(ctx, i);
        push_child_done(ctx, &mut t, "match_index", i, h);
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!(
                "_event.data.status == {RUNNING} && match_index == {i}"
            )),
            Some("wait_for_tick"),
            vec![
                b.assign(&r, "true"),
                b.assign("running_child", "match_index"),
                b.assign(SELF_RUNNING, "true"),
                ctx.respond(RUNNING),
            ],
        ));
        // 4.10 `SwitchNode::tick`: a skipped child makes `running_child_ = -1` and is the
        // answer, nothing reset (a child that answered 5 stays RUNNING until a
        // `resetChildren`). The node never sets its own status, so it is RUNNING (5)
        // only if it answered RUNNING last (`executeTick` does not store SKIPPED).
        let mut skipped: Vec<Element> = ctx.mark_skipped(i).into_iter().collect();
        skipped.push(b.assign("running_child", "-1"));
        skipped.push(super::btcpp4_skip::skipped_keeping_status(ctx));
        t.push(b.tr(
            Some(&ctx.child_resp(i)),
            Some(&format!("{IS_SKIPPED} && match_index == {i}")),
            Some("wait_for_tick"),
            skipped,
        ));
    }
    m.push(t);
    m.push(halting_state(
        ctx,
        "halting_when_done",
        h,
        vec![
            b.assign("running_child", "-1"),
            b.assign(SELF_RUNNING, "false"),
            ctx.respond_expr("result"),
        ],
    ));
    m.push(halting_state(
        ctx,
        "halting_on_halt",
        h,
        vec![
            b.assign("running_child", "-1"),
            b.assign(SELF_RUNNING, "false"),
            ctx.respond_halted(),
        ],
    ));
    m.push(b.state("error"));
    m
}

/// BT.CPP 4.10 `controls/switch_node.cpp`, `details::CheckStringEquality` without
/// scripting enums: equal as text, else both whole numbers (`std::from_chars` into
/// `int`, the whole text) and equal, else both real numbers and equal.
pub(super) fn same_text(a: &str, b: &str) -> bool {
    // `from_chars` takes no leading `+` (Rust's `parse` does).
    let num = |s: &str| !s.starts_with('+');
    a == b
        || (num(a)
            && num(b)
            && (matches!((a.parse::<i32>(), b.parse::<i32>()), (Ok(x), Ok(y)) if x == y)
                || matches!((a.parse::<f64>(), b.parse::<f64>()), (Ok(x), Ok(y)) if x == y)))
}

/// Whether the text could compare equal to another as a number in
/// [`same_text`] (so comparing it to a string entry as text alone could be wrong).
pub(super) fn numeric_text(s: &str) -> bool {
    !s.starts_with('+') && (s.parse::<i32>().is_ok() || s.parse::<f64>().is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switch_compares_text_then_integers_then_reals() {
        assert!(same_text("a", "a"));
        assert!(!same_text("a", "b"));
        assert!(same_text("1", "01"));
        assert!(same_text("1.5", "1.50"));
        assert!(same_text("2", "2.0"));
        assert!(!same_text("+2", "2"));
        assert!(numeric_text("3") && numeric_text("-0.5") && !numeric_text("a"));
    }
}
