//! The node names a tree may use and the ones it may not: BehaviorTree.CPP's built-ins
//! hindsight lowers or refuses, each format's own names, Nav2's inner nodes, and the
//! errors at nodes of no known type.

use super::{Control, Format, Reader};
use crate::model::source::Span;
use crate::model::xml::Element;

/// The built-in nodes, as listed in errors.
pub(super) const SUPPORTED: &[&str] = &[
    "Sequence",
    "ReactiveSequence",
    "SequenceWithMemory (format 3: SequenceStar)",
    "Fallback",
    "ReactiveFallback",
    "Parallel",
    "IfThenElse",
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "AlwaysSuccess",
    "AlwaysFailure",
    "SetBlackboard",
    "BlackboardCheckInt",
    "BlackboardCheckDouble",
    "BlackboardCheckString",
    "BlackboardCheckBool",
    "SubTree",
    "SubTreePlus (format 3)",
    "AsyncSequence, AsyncFallback, ParallelAll, WhileDoElse, KeepRunningUntilFailure, RunOnce, Switch2 ... Switch6, Timeout, Delay, Sleep, TryCatch, Script, ScriptCondition, Precondition, UnsetBlackboard, WasEntryUpdated, SkipUnlessUpdated, WaitValueUpdate, LoopInt, LoopBool, LoopDouble, LoopString (with `--bt btcpp`)",
];

/// Nav2's control and decorator nodes (the `<Control>` and `<Decorator>` entries of
/// `nav2_behavior_tree/nav2_tree_nodes.xml`), which a tree written for Nav2's navigator
/// uses: named as such when no plugin is called so.
const NAV2_INNER: &[&str] = &[
    "PipelineSequence",
    "RecoveryNode",
    "RoundRobin",
    "NonblockingSequence",
    "PersistentSequence",
    "PauseResumeController",
    "RateController",
    "DistanceController",
    "SpeedController",
    "GoalUpdater",
    "PathLongerOnApproach",
    "SingleTrigger",
    "GoalUpdatedController",
];

/// BehaviorTree.CPP's other built-in nodes (the ones its `BehaviorTreeFactory`
/// registers in 4.10 or 3.8, and the queue nodes its headers ship), each with why
/// hindsight refuses it. README lists the same.
pub(crate) const UNSUPPORTED: &[(&str, &str)] = &[
    (
        "ManualSelector",
        "it asks a person at a terminal which child to run",
    ),
    ("ConsumeQueue", "BehaviorTree.CPP 4 does not register it: a C++ program registers it for its own queue type"),
    ("PopFromQueue", "BehaviorTree.CPP 4 does not register it: a C++ program registers it for its own queue type"),
    ("QueueSize", "BehaviorTree.CPP 4 does not register it: a C++ program registers it for its own queue type"),
];

/// Why `name` cannot be used in a tree of format `format` although hindsight knows it:
/// each format has names the other has not (BT.CPP 4 registers `SequenceStar` only
/// under `USE_BTCPP3_OLD_NAMES`, and has no `SubTreePlus`).
pub(super) fn format_name_error(name: &str, format: Format) -> Option<String> {
    match (name, format) {
        ("SequenceStar", Format::V4) => Some(
            "`SequenceStar` is BehaviorTree.CPP 3's name: in BTCPP_format 4 it is `SequenceWithMemory` (or set BTCPP_format=\"3\")".into(),
        ),
        ("SubTreePlus", Format::V4) => Some(
            "`SubTreePlus` is BehaviorTree.CPP 3's node: in BTCPP_format 4 `SubTree` remaps the same way (or set BTCPP_format=\"3\")".into(),
        ),
        _ => None,
    }
}

/// The type a node element names and where: its tag (`<Sequence>`), or the `ID` of an
/// `<Action>`, `<Condition>`, `<Control>` or `<Decorator>` (`None`: that `ID` is missing).
pub(super) fn node_type(el: &Element) -> Option<(String, Span)> {
    if matches!(
        el.name.as_str(),
        "Action" | "Condition" | "Control" | "Decorator"
    ) {
        el.attr("ID")
            .map(|a| (a.value.trim().to_string(), a.value_span))
    } else {
        Some((el.name.clone(), el.span))
    }
}

impl Reader<'_> {
    pub(super) fn unknown_node(&mut self, type_name: &str, at: Span) {
        if NAV2_INNER.contains(&type_name) {
            self.err(
                at,
                format!(
                    "`{type_name}` is a control or decorator node of Nav2 (nav2_behavior_tree), \
                     not of BehaviorTree.CPP: hindsight lowers BT.CPP's built-in nodes, and \
                     plugins model leaves only, so a tree with Nav2's inner nodes cannot be \
                     modelled yet"
                ),
            );
            return;
        }
        let mut known: Vec<&str> = self.plugins.iter().map(|p| p.name.as_str()).collect();
        known.sort_unstable();
        self.err(
            at,
            format!(
                "unknown node `{type_name}`: not a built-in node and no plugin is called so \
                 (plugins: {})",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            ),
        );
    }

    /// Reports every node of an unknown type below `el` (whose own type is unknown), as
    /// [`Reader::node`] would have if it could read `el`.
    pub(super) fn unknown_below(&mut self, el: &Element) {
        for c in el.elements() {
            if matches!(c.name.as_str(), "SubTree" | "SubTreePlus") {
                continue;
            }
            // A node without its `ID` is said once its parent is known.
            let (type_name, at) = node_type(c).unwrap_or_default();
            let known = type_name.is_empty()
                || self.plugins.iter().any(|p| p.name == type_name)
                || Control::from_name(&type_name).is_some()
                || UNSUPPORTED.iter().any(|(n, _)| *n == type_name)
                || format_name_error(&type_name, self.format).is_some();
            if !known {
                self.unknown_node(&type_name, at);
            }
            self.unknown_below(c);
        }
    }
}
