//! Reads a BehaviorTree.cpp XML tree (`BTCPP_format` 3 or 4) into a flat list of nodes,
//! inlining SubTrees.
//!
//! The two formats differ in names (3's `SequenceStar` and `SubTreePlus`, 4's
//! `SequenceWithMemory`) and in how a `<SubTree>` remaps: in format 3 a plain
//! `<SubTree inner="outer"/>` names the caller's entry `outer` (BT.CPP 3.8's
//! `gtest_subtree.cpp`, `SubTree.SiblingPorts_Issue_72`), in format 4 `outer` is a
//! constant and `{outer}` the entry.
//!
//! Nodes are numbered in depth-first pre-order from 1000, as AS2FM numbers them, so the
//! root is always node 1000 and its events are `bt_1000_tick` / `bt_1000_response`.

use super::plugin::Plugin;
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::xml::Element;
use std::collections::HashMap;

mod names;
mod subtree;

use names::{format_name_error, node_type, SUPPORTED, UNSUPPORTED};
use subtree::Scope;

/// The id of the tree's root node.
pub(crate) const FIRST_ID: u32 = 1000;

/// Deepest SubTree nesting accepted (a SubTree that includes itself would never end).
const MAX_SUBTREE_DEPTH: usize = 32;

/// The control and built-in leaf nodes lowered without a plugin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Control {
    Sequence,
    ReactiveSequence,
    SequenceWithMemory,
    Fallback,
    ReactiveFallback,
    Parallel,
    IfThenElse,
    Inverter,
    ForceSuccess,
    ForceFailure,
    Repeat,
    RetryUntilSuccessful,
    AlwaysSuccess,
    AlwaysFailure,
    /// BlackboardCheckInt / Double / String / Bool (BT.CPP 3.8's
    /// `BlackboardPreconditionNode<T>`, AS2FM's `blackboard_check_int.ascxml`).
    BlackboardCheck(CheckType),
    SetBlackboard,
    /// BehaviorTree.CPP 4's nodes AS2FM has no model of, lowered under `--bt btcpp`
    /// only (`btcpp4.rs`): AsyncSequence, AsyncFallback, ParallelAll, WhileDoElse,
    /// KeepRunningUntilFailure, RunOnce, and Switch2 ... Switch6 (the number of cases).
    Btcpp4(Btcpp4),
}

/// The built-in nodes of BehaviorTree.CPP 4 that only `--bt btcpp` lowers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Btcpp4 {
    AsyncSequence,
    AsyncFallback,
    ParallelAll,
    WhileDoElse,
    KeepRunningUntilFailure,
    RunOnce,
    /// `Switch<n>`, n in 2..=6.
    Switch(u8),
    /// `Timeout` (`msec`), `Delay` (`delay_msec`), `Sleep` (`msec`): timers in model time
    /// (`btcpp4_time.rs`).
    Timeout,
    Delay,
    Sleep,
    /// `TryCatch` (BT.CPP 4.10; `catch_on_halt`).
    TryCatch,
    /// `Script`, `ScriptCondition`, `Precondition`: BT.CPP 4's script language
    /// (`btcpp4_script.rs`).
    Script(ScriptNode),
    /// `UnsetBlackboard` (`key`): an entry only scripts use loses its value
    /// (`btcpp4_blackboard.rs`).
    Unset,
    /// `WasEntryUpdated`, `SkipUnlessUpdated`, `WaitValueUpdate` (`entry`): the entry's
    /// update counter (`btcpp4_loop.rs`).
    Updated(UpdatedNode),
    /// `LoopInt`, `LoopBool`, `LoopDouble`, `LoopString` over a queue written in the tree
    /// (`btcpp4_loop.rs`).
    Loop(LoopType),
    /// A `<SubTree>` node with pre/post conditions (BT.CPP 4 `SubTreeNode`, a decorator
    /// over the inlined body; `btcpp4_subtree.rs`). A SubTree without them is inlined.
    SubTree,
}

/// The nodes that look at an entry's update counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum UpdatedNode {
    /// `WasEntryUpdated`: SUCCESS if updated, else FAILURE.
    Was,
    /// `SkipUnlessUpdated`: ticks its child if updated, else SKIPPED.
    Skip,
    /// `WaitValueUpdate`: ticks its child if updated, else RUNNING.
    Wait,
}

/// The item type of a `Loop<T>` node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum LoopType {
    Int,
    Bool,
    Double,
    String,
}

/// The nodes that run a script.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ScriptNode {
    /// `Script`: runs `code`, SUCCESS.
    Script,
    /// `ScriptCondition`: SUCCESS if `code` is true, else FAILURE.
    Condition,
    /// `Precondition`: ticks its child if `if` is true, else answers `else`.
    Precondition,
}

/// The ports of `Switch6`; `Switch<n>` takes the first `n + 1`.
const SWITCH_PORTS: [&str; 7] = [
    "variable", "case_1", "case_2", "case_3", "case_4", "case_5", "case_6",
];

/// The value type a BlackboardCheck node compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CheckType {
    /// `BlackboardCheckInt`: `int32`, the type of AS2FM's model's `value_A`/`value_B` ports.
    Int,
    /// `BlackboardCheckDouble`: `float64`, equal within `f32::EPSILON` (BT.CPP 3.8,
    /// `blackboard_precondition.h`, `IsSame(const double&, const double&)`).
    Double,
    /// `BlackboardCheckString`: `string`.
    String,
    /// `BlackboardCheckBool`: `bool`.
    Bool,
}

impl CheckType {
    /// The node's name.
    pub(crate) fn node_name(self) -> &'static str {
        match self {
            CheckType::Int => "BlackboardCheckInt",
            CheckType::Double => "BlackboardCheckDouble",
            CheckType::String => "BlackboardCheckString",
            CheckType::Bool => "BlackboardCheckBool",
        }
    }
    /// The port type of `value_A` and `value_B`.
    pub(crate) fn port_type(self) -> &'static str {
        match self {
            CheckType::Int => "int32",
            CheckType::Double => "float64",
            CheckType::String => "string",
            CheckType::Bool => "bool",
        }
    }
}

/// The `BTCPP_format` of the tree file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) enum Format {
    /// `BTCPP_format="3"`: BehaviorTree.CPP 3.8.
    V3,
    /// `BTCPP_format="4"`: BehaviorTree.CPP 4.
    V4,
    /// No `BTCPP_format`: read as 4 (BT.CPP 4 does), except where 3 and 4 would read
    /// the same text differently, which is then an error.
    #[default]
    Unspecified,
}

impl Control {
    /// The built-in node called `name` in a tree (both formats' names; see
    /// [`format_name_error`] for the ones one format does not have).
    fn from_name(name: &str) -> Option<Control> {
        Some(match name {
            "Sequence" => Control::Sequence,
            "ReactiveSequence" => Control::ReactiveSequence,
            "SequenceWithMemory" | "SequenceStar" => Control::SequenceWithMemory,
            "Fallback" => Control::Fallback,
            "ReactiveFallback" => Control::ReactiveFallback,
            "Parallel" => Control::Parallel,
            "IfThenElse" => Control::IfThenElse,
            "Inverter" => Control::Inverter,
            "ForceSuccess" => Control::ForceSuccess,
            "ForceFailure" => Control::ForceFailure,
            "Repeat" => Control::Repeat,
            "RetryUntilSuccessful" | "RetryUntilSuccesful" => Control::RetryUntilSuccessful,
            "AlwaysSuccess" => Control::AlwaysSuccess,
            "AlwaysFailure" => Control::AlwaysFailure,
            "BlackboardCheckInt" => Control::BlackboardCheck(CheckType::Int),
            "BlackboardCheckDouble" => Control::BlackboardCheck(CheckType::Double),
            "BlackboardCheckString" => Control::BlackboardCheck(CheckType::String),
            "BlackboardCheckBool" => Control::BlackboardCheck(CheckType::Bool),
            "SetBlackboard" => Control::SetBlackboard,
            "AsyncSequence" => Control::Btcpp4(Btcpp4::AsyncSequence),
            "AsyncFallback" => Control::Btcpp4(Btcpp4::AsyncFallback),
            "ParallelAll" => Control::Btcpp4(Btcpp4::ParallelAll),
            "WhileDoElse" => Control::Btcpp4(Btcpp4::WhileDoElse),
            "KeepRunningUntilFailure" => Control::Btcpp4(Btcpp4::KeepRunningUntilFailure),
            "RunOnce" => Control::Btcpp4(Btcpp4::RunOnce),
            "Switch2" => Control::Btcpp4(Btcpp4::Switch(2)),
            "Switch3" => Control::Btcpp4(Btcpp4::Switch(3)),
            "Switch4" => Control::Btcpp4(Btcpp4::Switch(4)),
            "Switch5" => Control::Btcpp4(Btcpp4::Switch(5)),
            "Switch6" => Control::Btcpp4(Btcpp4::Switch(6)),
            "Timeout" => Control::Btcpp4(Btcpp4::Timeout),
            "Delay" => Control::Btcpp4(Btcpp4::Delay),
            "Sleep" => Control::Btcpp4(Btcpp4::Sleep),
            "TryCatch" => Control::Btcpp4(Btcpp4::TryCatch),
            "Script" => Control::Btcpp4(Btcpp4::Script(ScriptNode::Script)),
            "ScriptCondition" => Control::Btcpp4(Btcpp4::Script(ScriptNode::Condition)),
            "Precondition" => Control::Btcpp4(Btcpp4::Script(ScriptNode::Precondition)),
            "UnsetBlackboard" => Control::Btcpp4(Btcpp4::Unset),
            "WasEntryUpdated" => Control::Btcpp4(Btcpp4::Updated(UpdatedNode::Was)),
            "SkipUnlessUpdated" => Control::Btcpp4(Btcpp4::Updated(UpdatedNode::Skip)),
            "WaitValueUpdate" => Control::Btcpp4(Btcpp4::Updated(UpdatedNode::Wait)),
            "LoopInt" => Control::Btcpp4(Btcpp4::Loop(LoopType::Int)),
            "LoopBool" => Control::Btcpp4(Btcpp4::Loop(LoopType::Bool)),
            "LoopDouble" => Control::Btcpp4(Btcpp4::Loop(LoopType::Double)),
            "LoopString" => Control::Btcpp4(Btcpp4::Loop(LoopType::String)),
            _ => return None,
        })
    }

    /// Allowed number of children: `(min, max)`.
    fn arity(self) -> (usize, usize) {
        use Control::*;
        match self {
            Sequence | ReactiveSequence | SequenceWithMemory | Fallback | ReactiveFallback
            | Parallel => (1, usize::MAX),
            IfThenElse => (2, 3),
            Inverter | ForceSuccess | ForceFailure | Repeat | RetryUntilSuccessful
            | BlackboardCheck(_) => (1, 1),
            AlwaysSuccess | AlwaysFailure | SetBlackboard => (0, 0),
            Btcpp4(b) => match b {
                self::Btcpp4::AsyncSequence
                | self::Btcpp4::AsyncFallback
                | self::Btcpp4::ParallelAll => (1, usize::MAX),
                self::Btcpp4::WhileDoElse => (2, 3),
                self::Btcpp4::KeepRunningUntilFailure
                | self::Btcpp4::RunOnce
                | self::Btcpp4::Timeout
                | self::Btcpp4::Delay
                | self::Btcpp4::Loop(_)
                | self::Btcpp4::SubTree
                | self::Btcpp4::Updated(UpdatedNode::Skip | UpdatedNode::Wait) => (1, 1),
                self::Btcpp4::Sleep
                | self::Btcpp4::Unset
                | self::Btcpp4::Updated(UpdatedNode::Was) => (0, 0),
                // The try block and the catch child (`TryCatchNode::tick`: at least 2).
                self::Btcpp4::TryCatch => (2, usize::MAX),
                // The cases and the default (BT.CPP 4.10 `switch_node.h`,
                // `SwitchNode::tick`: `NUM_CASES + 1` children).
                self::Btcpp4::Switch(n) => (n as usize + 1, n as usize + 1),
                self::Btcpp4::Script(ScriptNode::Precondition) => (1, 1),
                self::Btcpp4::Script(_) => (0, 0),
            },
        }
    }

    /// Attributes the node takes besides `name` and `ID`.
    fn params(self) -> &'static [&'static str] {
        use Control::*;
        match self {
            Parallel => &[
                "success_count",
                "failure_count",
                "success_threshold",
                "failure_threshold",
            ],
            Repeat => &["num_cycles"],
            RetryUntilSuccessful => &["num_attempts"],
            BlackboardCheck(_) => &["value_A", "value_B", "return_on_mismatch"],
            SetBlackboard => &["value", "output_key"],
            Btcpp4(self::Btcpp4::ParallelAll) => &["max_failures"],
            Btcpp4(self::Btcpp4::RunOnce) => &["then_skip"],
            Btcpp4(self::Btcpp4::Switch(n)) => &SWITCH_PORTS[..=n as usize],
            Btcpp4(self::Btcpp4::Timeout | self::Btcpp4::Sleep) => &["msec"],
            Btcpp4(self::Btcpp4::Delay) => &["delay_msec"],
            Btcpp4(self::Btcpp4::TryCatch) => &["catch_on_halt"],
            Btcpp4(self::Btcpp4::Script(ScriptNode::Precondition)) => &["if", "else"],
            Btcpp4(self::Btcpp4::Script(_)) => &["code"],
            Btcpp4(self::Btcpp4::Unset) => &["key"],
            Btcpp4(self::Btcpp4::Updated(_)) => &["entry"],
            Btcpp4(self::Btcpp4::Loop(_)) => &["queue", "value", "if_empty"],
            _ => &[],
        }
    }
}

/// What a node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A built-in node.
    Control(Control),
    /// A leaf (or custom control node) given as a plugin: index into the plugin list.
    Plugin(usize),
}

/// The value a tree gives a port.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum PortValue {
    /// A constant, as written.
    Literal(String),
    /// A blackboard entry `{name}`.
    Blackboard(String),
}

/// A port assignment on a tree node: `key="value"`.
#[derive(Clone, Debug)]
pub(crate) struct Port {
    /// The port's key.
    pub key: String,
    /// The value after SubTree remapping.
    pub value: PortValue,
    /// Where the value is written.
    pub span: Span,
}

/// One node of the flattened tree.
#[derive(Clone, Debug)]
pub(crate) struct TreeNode {
    /// `1000 + pre-order index`.
    pub id: u32,
    /// Built-in or plugin.
    pub kind: Kind,
    /// The machine generated for the node: `BT_plugin_<id>_<name>`.
    pub machine: String,
    /// The node's element in the tree (for its span and attributes).
    pub span: Span,
    /// Port assignments (every attribute but `ID`, `name` and `_description`).
    pub ports: Vec<Port>,
    /// Indices of the children in [`Tree::nodes`].
    pub children: Vec<usize>,
    /// Index of the parent; `None` for the root.
    pub parent: Option<usize>,
    /// For a node that runs a script: each entry name its script uses, and what it is in
    /// the whole tree's terms (a SubTree remaps or prefixes its names).
    pub script_names: Vec<(String, PortValue)>,
    /// Its pre/post conditions (`_failureIf`, ... `_post`), syntax checked, in the order
    /// written (`btcpp4_conds.rs`).
    pub conds: Vec<Cond>,
    /// The root of a SubTree's inlined body, which BT.CPP's SubTree node resets once it
    /// finished (`btcpp4_subtree.rs`).
    pub subtree_body: bool,
}

/// A pre/post-condition attribute of a node.
#[derive(Clone, Debug)]
pub(crate) struct Cond {
    /// `_failureIf`, `_successIf`, `_skipIf`, `_while`, `_onHalted`, `_onFailure`,
    /// `_onSuccess` or `_post`.
    pub attr: String,
    /// The script.
    pub code: String,
    /// Where the attribute's name is.
    pub name_span: Span,
    /// Where its value is.
    pub span: Span,
}

impl TreeNode {
    /// Node `id` of `kind` written at `span` under `parent`, its machine named after
    /// `label`: no ports, children, script names or conditions yet.
    fn new(id: u32, kind: Kind, label: &str, span: Span, parent: Option<usize>) -> TreeNode {
        TreeNode {
            id,
            kind,
            machine: format!("BT_plugin_{id}_{label}"),
            span,
            ports: Vec::new(),
            children: Vec::new(),
            parent,
            script_names: Vec::new(),
            conds: Vec::new(),
            subtree_body: false,
        }
    }

    /// The port called `key`, if the tree sets it.
    pub(crate) fn port(&self, key: &str) -> Option<&Port> {
        self.ports.iter().find(|p| p.key == key)
    }
}

/// A flattened tree: `nodes[0]` is the root.
#[derive(Clone, Debug, Default)]
pub(crate) struct Tree {
    /// Nodes in pre-order.
    pub nodes: Vec<TreeNode>,
}

struct Reader<'a> {
    sm: &'a SourceMap,
    plugins: &'a [Plugin],
    trees: HashMap<String, &'a Element>,
    errs: Vec<Diagnostic>,
    nodes: Vec<TreeNode>,
    scopes: Vec<Scope>,
    subtree_count: usize,
    format: Format,
}

/// Reads the tree document `root` (already parsed) into a flat tree.
pub(crate) fn read(
    sm: &SourceMap,
    root: &Element,
    plugins: &[Plugin],
) -> Result<Tree, Vec<Diagnostic>> {
    let mut r = Reader {
        sm,
        plugins,
        trees: HashMap::new(),
        errs: Vec::new(),
        nodes: Vec::new(),
        scopes: Vec::new(),
        subtree_count: 0,
        format: Format::Unspecified,
    };
    if root.name != "root" {
        return Err(vec![sm.diag(
            root.span,
            format!(
                "expected a BehaviorTree.cpp <root> element, found <{}>",
                root.name
            ),
        )]);
    }
    root.check_attrs(sm, &["BTCPP_format", "main_tree_to_execute"], &mut r.errs);
    if let Some(f) = root.attr("BTCPP_format") {
        match f.value.trim() {
            "3" => r.format = Format::V3,
            "4" => r.format = Format::V4,
            other => {
                r.err(
                    f.value_span,
                    format!("unsupported BTCPP_format `{other}` (hindsight reads 3 and 4)"),
                );
                return Err(r.errs);
            }
        }
    }
    let mut order: Vec<&Element> = Vec::new();
    for el in root.elements() {
        match el.name.as_str() {
            "BehaviorTree" => {
                let id = el.attr_value("ID").unwrap_or("").to_string();
                if let Some(prev) = r.trees.insert(id.clone(), el) {
                    let at = sm.diag(prev.span, "");
                    r.err(
                        el.span,
                        format!(
                            "BehaviorTree `{id}` is defined twice (also at {}:{})",
                            at.line, at.col
                        ),
                    );
                }
                order.push(el);
            }
            "TreeNodesModel" => {}
            "include" => r.err(
                el.span,
                "<include> is not supported: put every tree in one file",
            ),
            other => r.err(
                el.span,
                format!("unexpected <{other}> in <root> (expected <BehaviorTree>)"),
            ),
        }
    }
    let main = match root.attr("main_tree_to_execute") {
        Some(a) => match r.trees.get(a.value.trim()) {
            Some(t) => Some(*t),
            None => {
                r.err(
                    a.value_span,
                    format!("no BehaviorTree with ID `{}` in this file", a.value.trim()),
                );
                None
            }
        },
        None => match order.as_slice() {
            [] => {
                r.err(root.span, "the file defines no <BehaviorTree>");
                None
            }
            [one] => Some(*one),
            many => match r.trees.get("MainTree") {
                Some(t) => Some(*t),
                None => {
                    r.err(
                        many[1].span,
                        "several BehaviorTrees and no `main_tree_to_execute` on <root>",
                    );
                    None
                }
            },
        },
    };
    if let Some(main) = main {
        r.tree_body(main, None, 0);
    }
    if r.errs.is_empty() {
        Ok(Tree { nodes: r.nodes })
    } else {
        Err(r.errs)
    }
}

/// `{name}` as a blackboard entry name.
pub(crate) fn blackboard_name(value: &str) -> Option<&str> {
    let v = value.trim();
    let inner = v.strip_prefix('{')?.strip_suffix('}')?.trim();
    Some(inner)
}

/// A name usable inside a machine name: letters, digits and `_`.
fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

fn is_ident(s: &str) -> bool {
    let mut cs = s.chars();
    matches!(cs.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && cs.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The model variable of the main tree's entry `name`: the entry's own name, but for a
/// word the model's expressions reserve (`var`, `NaN`, ...: `hindsight_expr::is_reserved`),
/// which BehaviorTree.CPP takes as an entry name (4.10's `gtest_subtree.cpp`
/// `SubtreeIssue592` writes `var`) and which becomes `bb__` and the word. A SubTree's own
/// entries carry its prefix, so they are never reserved.
pub(crate) fn root_entry(name: &str) -> String {
    if hindsight_expr::is_reserved(name) {
        format!("bb__{name}")
    } else {
        name.to_string()
    }
}

/// A port value as text (an entry as `{entry}`).
fn lit(v: &PortValue) -> String {
    match v {
        PortValue::Literal(s) => s.clone(),
        PortValue::Blackboard(b) => format!("{{{b}}}"),
    }
}

impl Reader<'_> {
    /// Pushes `n` (numbered for the next index) as the last child of its parent.
    fn push_node(&mut self, n: TreeNode) {
        let idx = self.nodes.len();
        debug_assert_eq!(n.id, FIRST_ID + idx as u32);
        if let Some(p) = n.parent {
            self.nodes[p].children.push(idx);
        }
        self.nodes.push(n);
    }

    fn err(&mut self, span: Span, msg: impl Into<String>) {
        self.errs.push(self.sm.diag(span, msg));
    }

    /// Inlines the single child of `<BehaviorTree>` `t` as a child of `parent`.
    fn tree_body(&mut self, t: &Element, parent: Option<usize>, depth: usize) {
        t.check_attrs(self.sm, &["ID", "_description"], &mut self.errs);
        let kids: Vec<&Element> = t.elements().collect();
        match kids.as_slice() {
            [one] => {
                self.node(one, parent, depth);
            }
            [] => self.err(
                t.span,
                "a <BehaviorTree> needs exactly one root node, found none",
            ),
            [_, second, ..] => self.err(
                second.span,
                "a <BehaviorTree> needs exactly one root node, found more",
            ),
        }
    }

    /// Resolves the value `raw` of port `key` written in the innermost scope: `{name}`
    /// is an entry, `{=}` (format 3: `=`) the entry called as the port is.
    fn resolve(&self, key: &str, raw: &str) -> PortValue {
        let same = match self.format {
            Format::V3 => raw.trim() == "=" || raw.trim() == "{=}",
            _ => raw.trim() == "{=}",
        };
        if same {
            return self.resolve_bb(key, self.scopes.len());
        }
        match blackboard_name(raw) {
            Some(name) => self.resolve_bb(name, self.scopes.len()),
            None => PortValue::Literal(raw.to_string()),
        }
    }

    fn resolve_bb(&self, name: &str, depth: usize) -> PortValue {
        if depth == 0 {
            return PortValue::Blackboard(root_entry(name));
        }
        let s = &self.scopes[depth - 1];
        if let Some(v) = s.map.get(name) {
            return v.clone();
        }
        if s.autoremap {
            self.resolve_bb(name, depth - 1)
        } else {
            PortValue::Blackboard(format!("{}{}", s.prefix, name))
        }
    }

    fn node(&mut self, el: &Element, parent: Option<usize>, depth: usize) {
        if el.name == "SubTree" || el.name == "SubTreePlus" {
            self.subtree(el, parent, depth);
            return;
        }
        let Some((type_name, type_span)) = node_type(el) else {
            self.err(
                el.span,
                format!("<{}> needs an `ID` naming the node type", el.name),
            );
            return;
        };
        if let Some(m) = format_name_error(&type_name, self.format) {
            self.err(type_span, m);
            return;
        }
        let kind = match self.plugins.iter().position(|p| p.name == type_name) {
            Some(i) => Kind::Plugin(i),
            None => match Control::from_name(&type_name) {
                Some(c) => Kind::Control(c),
                None if UNSUPPORTED.iter().any(|(n, _)| *n == type_name) => {
                    for a in &el.attrs {
                        if let Some(m) = super::script::port_error(&type_name, &a.name, &a.value) {
                            self.err(a.value_span, m);
                        }
                    }
                    let why = UNSUPPORTED
                        .iter()
                        .find(|(n, _)| *n == type_name)
                        .map_or("", |(_, w)| *w);
                    self.err(
                        type_span,
                        format!(
                            "the BehaviorTree.CPP built-in node `{type_name}` is not supported by hindsight: {why} (supported: {})",
                            SUPPORTED.join(", ")
                        ),
                    );
                    return;
                }
                None => {
                    self.unknown_node(&type_name, type_span);
                    // The nodes below it are not read, but a tree written for another
                    // executor (Nav2's RecoveryNode, PipelineSequence, RateController)
                    // lacks many: name them all at once.
                    self.unknown_below(el);
                    return;
                }
            },
        };
        let idx = self.nodes.len();
        let id = FIRST_ID + idx as u32;
        let label = match el.attr_value("name") {
            Some(n) if !n.trim().is_empty() => sanitize(n.trim()),
            _ => sanitize(&type_name),
        };
        let mut ports = Vec::new();
        let mut conds: Vec<Cond> = Vec::new();
        for a in &el.attrs {
            if a.name == "name"
                || a.name == "_description"
                || (a.name == "ID" && el.name != type_name)
            {
                continue;
            }
            if a.name.starts_with('_') {
                if !self.condition(a, &mut conds) {
                    self.err(
                        a.name_span,
                        format!(
                            "`{}` (a BehaviorTree.cpp script attribute) is not supported",
                            a.name
                        ),
                    );
                }
                continue;
            }
            if let Kind::Control(c) = kind {
                if !c.params().contains(&a.name.as_str()) {
                    let allowed = c.params();
                    self.err(
                        a.name_span,
                        format!(
                            "unknown attribute `{}` on {type_name} (expected {})",
                            a.name,
                            if allowed.is_empty() {
                                "only `name`".to_string()
                            } else {
                                format!("`name` or one of: {}", allowed.join(", "))
                            }
                        ),
                    );
                    continue;
                }
            }
            let mut value = self.resolve(&a.name, &a.value);
            // SetBlackboard's `output_key` names an entry without braces in BT.CPP
            // (`SetBlackboard::tick` reads it as a string), with braces in AS2FM's model (an
            // output port): either way an entry, private to the SubTree it is in.
            if kind == Kind::Control(Control::SetBlackboard) && a.name == "output_key" {
                let raw = a.value.trim();
                let name = blackboard_name(raw).unwrap_or(raw);
                if !is_ident(name) {
                    self.err(
                        a.value_span,
                        format!("`{raw}` is not a blackboard entry name"),
                    );
                    continue;
                }
                value = self.resolve_bb(name, self.scopes.len());
                if let PortValue::Literal(c) = &value {
                    self.err(
                        a.value_span,
                        format!("SetBlackboard writes `{name}`, which the SubTree it is in sets to the constant `{c}`: map it to an entry (`{{...}}`) to write it"),
                    );
                    continue;
                }
            }
            if let PortValue::Blackboard(b) = &value {
                if !is_ident(b) {
                    self.err(
                        a.value_span,
                        format!("blackboard entry `{{{b}}}` is not a valid name"),
                    );
                    continue;
                }
            }
            ports.push(Port {
                key: a.name.clone(),
                value,
                span: a.value_span,
            });
        }
        let mut script_names: Vec<(String, PortValue)> = Vec::new();
        for c in &conds {
            for name in super::script::names(&c.code) {
                if !script_names.iter().any(|(n, _)| *n == name) {
                    let v = self.resolve_bb(&name, self.scopes.len());
                    script_names.push((name, v));
                }
            }
        }
        // UnsetBlackboard's `key` names an entry (`blackboard->unset(key)`), resolved as a
        // script's names are; inside a SubTree `Blackboard::unset` erases the SubTree's
        // own entry only, which a remapped key may or may not be: not modelled.
        if let Kind::Control(Control::Btcpp4(Btcpp4::Unset)) = kind {
            if let Some(p) = ports.iter().find(|p| p.key == "key") {
                if let PortValue::Literal(k) = &p.value {
                    let k = k.trim().to_string();
                    if self.scopes.is_empty() && is_ident(&k) {
                        if !script_names.iter().any(|(n, _)| *n == k) {
                            let v = self.resolve_bb(&k, 0);
                            script_names.push((k, v));
                        }
                    } else if !self.scopes.is_empty() {
                        self.err(p.span, "UnsetBlackboard inside a SubTree is not modelled (BehaviorTree.CPP erases the SubTree's own entry only, which a remapped key may or may not be)".to_string());
                    } else {
                        self.err(p.span, format!("`{k}` is not a blackboard entry name"));
                    }
                }
            }
        }
        // The entry-updated nodes' `entry` names an entry with or without braces (4.10
        // `EntryUpdatedAction` / `EntryUpdatedDecorator` constructors strip them), which
        // `Blackboard::getEntry` looks up through a SubTree's remapping.
        if let Kind::Control(Control::Btcpp4(Btcpp4::Updated(_))) = kind {
            if let Some(p) = ports.iter_mut().find(|p| p.key == "entry") {
                if let PortValue::Literal(k) = &p.value {
                    let k = k.trim().to_string();
                    if is_ident(&k) {
                        p.value = self.resolve_bb(&k, self.scopes.len());
                    }
                }
            }
        }
        if let Kind::Control(Control::Btcpp4(Btcpp4::Script(_))) = kind {
            for p in &ports {
                if let Some(m) = super::script::port_error(&type_name, &p.key, &lit(&p.value)) {
                    self.err(p.span, m);
                }
                if let (PortValue::Literal(code), "code" | "if") = (&p.value, p.key.as_str()) {
                    for name in super::script::names(code) {
                        if !script_names.iter().any(|(n, _)| *n == name) {
                            let v = self.resolve_bb(&name, self.scopes.len());
                            script_names.push((name, v));
                        }
                    }
                }
            }
        }
        self.push_node(TreeNode {
            ports,
            script_names,
            conds,
            ..TreeNode::new(id, kind, &label, el.span, parent)
        });
        let kids: Vec<&Element> = el.elements().collect();
        for k in &kids {
            self.node(k, Some(idx), depth);
        }
        // Children that failed to read still count, so one error is not reported twice.
        let n = kids.len();
        let (lo, hi) = match kind {
            Kind::Control(c) => c.arity(),
            Kind::Plugin(_) => (0, usize::MAX),
        };
        if n < lo || n > hi {
            let want = if lo == hi {
                format!("{lo}")
            } else if hi == usize::MAX {
                format!("at least {lo}")
            } else {
                format!("{lo} to {hi}")
            };
            self.err(
                el.span,
                format!("{type_name} needs {want} children, found {n}"),
            );
        }
    }
}
