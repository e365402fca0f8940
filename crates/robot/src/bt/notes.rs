//! Where a tree's runs under AS2FM's node models and under BehaviorTree.CPP 4 are known to
//! differ ([`super::BtSemantics`]): one note per construction, at its node, for
//! `hindsight validate` to warn about.

use super::plugin::Plugin;
use super::tree::{Control, Kind, Tree};
use crate::model::source::{Diagnostic, SourceMap, Span};

/// The notes of `tree`, in node order, each once per place in the files (a SubTree used
/// twice is one place).
pub(super) fn notes(sm: &SourceMap, tree: &Tree, plugins: &[Plugin]) -> Vec<Diagnostic> {
    let mut out: Vec<(Span, String)> = Vec::new();
    let mut add = |span: Span, msg: String| {
        if !out.iter().any(|(s, m)| *s == span && *m == msg) {
            out.push((span, msg));
        }
    };
    let control = |i: usize| match tree.nodes[i].kind {
        Kind::Control(c) => Some(c),
        Kind::Plugin(_) => None,
    };
    for n in &tree.nodes {
        let Kind::Control(c) = n.kind else { continue };
        let kids = n.children.len();
        match c {
            Control::SequenceWithMemory if kids >= 2 => {
                add(
                    n.span,
                    "SequenceWithMemory: under BehaviorTree.CPP 4 it answers RUNNING after a \
                     child that finishes on the tick that started it (a wake-up yield; \
                     `SequenceWithMemory::tick`), where AS2FM's model goes on to the next \
                     child in the same tick"
                        .into(),
                );
                // A running SWM is halted only by an ancestor that halts a running child
                // while itself going on (or finishing).
                let mut p = n.parent;
                while let Some(a) = p {
                    if let Some(
                        h @ (Control::ReactiveSequence
                        | Control::ReactiveFallback
                        | Control::Parallel
                        | Control::BlackboardCheck(_)),
                    ) = control(a)
                    {
                        let at = sm.diag(tree.nodes[a].span, "");
                        add(
                            n.span,
                            format!(
                                "SequenceWithMemory under a {h:?} (at {}:{}): halted while \
                                 running, it starts again from its first child in AS2FM's \
                                 model but resumes where it was in BehaviorTree.CPP 4 \
                                 (`SequenceWithMemory::halt` keeps its index)",
                                at.line, at.col
                            ),
                        );
                        break;
                    }
                    p = tree.nodes[a].parent;
                }
            }
            Control::Repeat | Control::RetryUntilSuccessful => {
                let key = if c == Control::Repeat {
                    "num_cycles"
                } else {
                    "num_attempts"
                };
                let count = n
                    .port(key)
                    .and_then(|p| match &p.value {
                        super::tree::PortValue::Literal(v) => v.trim().parse::<i64>().ok(),
                        _ => None,
                    })
                    .unwrap_or(0);
                if count == -1 || count > 1 {
                    add(
                        n.span,
                        format!(
                            "{c:?}: under BehaviorTree.CPP 4 it answers RUNNING between \
                             attempts whose child finishes on the tick that started it (a \
                             wake-up yield; `{}::tick`), where AS2FM's model starts the next \
                             attempt in the same tick",
                            if c == Control::Repeat {
                                "RepeatNode"
                            } else {
                                "RetryNode"
                            }
                        ),
                    );
                }
                if c == Control::Repeat
                    && n.children.first().and_then(|&k| control(k))
                        == Some(Control::SequenceWithMemory)
                {
                    add(
                        n.span,
                        "Repeat over a SequenceWithMemory: AS2FM's Repeat halts its child \
                         after every attempt (a failed SequenceWithMemory starts again from \
                         its first child), BehaviorTree.CPP 4 halts only a RUNNING child (it \
                         resumes at the child that failed)"
                            .into(),
                    );
                }
            }
            Control::Parallel if kids >= 2 => add(
                n.span,
                "Parallel: BehaviorTree.CPP 4 does not tick again a child that finished, \
                 counts across ticks and fails as soon as the success threshold is out of \
                 reach (`ParallelNode::tick`); AS2FM's model ticks every child on every tick \
                 and counts from zero"
                    .into(),
            ),
            Control::IfThenElse if kids == 2 => {
                // Only a condition that may answer RUNNING (a stateful action) keeps its
                // status; a synchronous one runs again, as AS2FM's model ticks it.
                if let Kind::Plugin(p) = tree.nodes[n.children[0]].kind {
                    if !plugins[p].ticks_children && plugins[p].may_run {
                        add(
                            n.span,
                            "IfThenElse with two children: once its condition fails, \
                             BehaviorTree.CPP 4 does not reset it (`IfThenElseNode::tick`), \
                             and a stateful action (the condition's plugin may answer \
                             RUNNING) in a finished status answers it again without \
                             running: the node answers FAILURE from then on, where AS2FM's \
                             model ticks the condition again"
                                .into(),
                        );
                    }
                }
            }
            _ => {}
        }
    }
    out.into_iter().map(|(s, m)| sm.diag(s, m)).collect()
}
