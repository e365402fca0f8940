//! Reads a BehaviorTree.cpp (v4) XML tree into a flat list of nodes, inlining SubTrees.
//!
//! Nodes are numbered in depth-first pre-order from 1000, as AS2FM numbers them, so the
//! root is always node 1000 and its events are `bt_1000_tick` / `bt_1000_response`.

use super::plugin::Plugin;
use crate::model::source::{Diagnostic, SourceMap, Span};
use crate::model::xml::Element;
use std::collections::HashMap;

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
    BlackboardCheckInt,
    SetBlackboard,
}

impl Control {
    /// The built-in node called `name` in a tree.
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
            "BlackboardCheckInt" => Control::BlackboardCheckInt,
            "SetBlackboard" => Control::SetBlackboard,
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
            | BlackboardCheckInt => (1, 1),
            AlwaysSuccess | AlwaysFailure | SetBlackboard => (0, 0),
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
            BlackboardCheckInt => &["value_A", "value_B", "return_on_mismatch"],
            SetBlackboard => &["value", "output_key"],
            _ => &[],
        }
    }
}

/// The built-in nodes, as listed in errors.
const SUPPORTED: &[&str] = &[
    "Sequence",
    "ReactiveSequence",
    "SequenceWithMemory",
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
    "BlackboardCheckInt",
    "SetBlackboard",
    "SubTree",
];

/// BehaviorTree.cpp's other built-in nodes: named in a clear error.
const UNSUPPORTED: &[&str] = &[
    "FallbackWithMemory",
    "ParallelAll",
    "WhileDoElse",
    "Switch2",
    "Switch3",
    "Switch4",
    "Switch5",
    "Switch6",
    "ManualSelector",
    "KeepRunningUntilFailure",
    "Delay",
    "Timeout",
    "RunOnce",
    "Precondition",
    "LoopInt",
    "LoopDouble",
    "LoopString",
    "LoopBool",
    "BlackboardCheckDouble",
    "BlackboardCheckString",
    "UnsetBlackboard",
    "Script",
    "ScriptCondition",
    "Sleep",
    "WasEntryUpdated",
    "SkipUnlessUpdated",
    "WaitValueUpdate",
    "EntryUpdated",
];

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
}

impl TreeNode {
    /// The port called `key`, if the tree sets it.
    pub fn port(&self, key: &str) -> Option<&Port> {
        self.ports.iter().find(|p| p.key == key)
    }
}

/// A flattened tree: `nodes[0]` is the root.
#[derive(Clone, Debug, Default)]
pub(crate) struct Tree {
    /// Nodes in pre-order.
    pub nodes: Vec<TreeNode>,
}

/// One SubTree instance being inlined: how its blackboard names map to the caller's.
struct Scope {
    /// Explicit remapping `inner -> value in the caller`.
    map: HashMap<String, PortValue>,
    /// `_autoremap="true"`: unmapped names are the caller's names.
    autoremap: bool,
    /// Prefix that makes unmapped names private to this instance.
    prefix: String,
}

struct Reader<'a> {
    sm: &'a SourceMap,
    plugins: &'a [Plugin],
    trees: HashMap<String, &'a Element>,
    errs: Vec<Diagnostic>,
    nodes: Vec<TreeNode>,
    scopes: Vec<Scope>,
    subtree_count: usize,
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
        if !matches!(f.value.trim(), "3" | "4") {
            r.err(
                f.value_span,
                format!("unsupported BTCPP_format `{}` (expected 4)", f.value),
            );
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
                            at.line, at.column
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

impl Reader<'_> {
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

    /// Resolves the value `raw` written in the innermost scope.
    fn resolve(&self, raw: &str) -> PortValue {
        match blackboard_name(raw) {
            Some(name) => self.resolve_bb(name, self.scopes.len()),
            None => PortValue::Literal(raw.to_string()),
        }
    }

    fn resolve_bb(&self, name: &str, depth: usize) -> PortValue {
        if depth == 0 {
            return PortValue::Blackboard(name.to_string());
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
        let (type_name, type_span) = if matches!(
            el.name.as_str(),
            "Action" | "Condition" | "Control" | "Decorator"
        ) {
            match el.attr("ID") {
                Some(a) => (a.value.trim().to_string(), a.value_span),
                None => {
                    self.err(
                        el.span,
                        format!("<{}> needs an `ID` naming the node type", el.name),
                    );
                    return;
                }
            }
        } else {
            (el.name.clone(), el.span)
        };
        let kind = match self.plugins.iter().position(|p| p.name == type_name) {
            Some(i) => Kind::Plugin(i),
            None => match Control::from_name(&type_name) {
                Some(c) => Kind::Control(c),
                None if UNSUPPORTED.contains(&type_name.as_str()) => {
                    self.err(
                        type_span,
                        format!(
                            "the BehaviorTree.cpp node `{type_name}` is not supported (supported: {})",
                            SUPPORTED.join(", ")
                        ),
                    );
                    return;
                }
                None => {
                    let mut known: Vec<&str> =
                        self.plugins.iter().map(|p| p.name.as_str()).collect();
                    known.sort_unstable();
                    self.err(
                        type_span,
                        format!(
                            "unknown node `{type_name}`: not a built-in node and no plugin is called so (plugins: {})",
                            if known.is_empty() { "none".to_string() } else { known.join(", ") }
                        ),
                    );
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
        for a in &el.attrs {
            if a.name == "name"
                || a.name == "_description"
                || (a.name == "ID" && el.name != type_name)
            {
                continue;
            }
            if a.name.starts_with('_') {
                self.err(
                    a.name_span,
                    format!(
                        "`{}` (a BehaviorTree.cpp script attribute) is not supported",
                        a.name
                    ),
                );
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
            // SetBlackboard's `output_key` names an entry even without braces, and a
            // SubTree's remapping applies to it (BT.CPP's `SetBlackboardNode::tick` looks
            // it up with `getEntry` in the node's own, remapped, blackboard).
            let value = match blackboard_name(&a.value) {
                None if a.name == "output_key"
                    && matches!(kind, Kind::Control(Control::SetBlackboard)) =>
                {
                    self.resolve_bb(a.value.trim(), self.scopes.len())
                }
                _ => self.resolve(&a.value),
            };
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
        self.nodes.push(TreeNode {
            id,
            kind,
            machine: format!("BT_plugin_{id}_{label}"),
            span: el.span,
            ports,
            children: Vec::new(),
            parent,
        });
        if let Some(p) = parent {
            self.nodes[p].children.push(idx);
        }
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

    fn subtree(&mut self, el: &Element, parent: Option<usize>, depth: usize) {
        let Some(id) = el.attr("ID") else {
            self.err(el.span, "<SubTree> needs an `ID` naming a BehaviorTree");
            return;
        };
        let Some(t) = self.trees.get(id.value.trim()).copied() else {
            let mut known: Vec<&str> = self.trees.keys().map(|s| s.as_str()).collect();
            known.sort_unstable();
            self.err(
                id.value_span,
                format!(
                    "no BehaviorTree with ID `{}` (trees: {})",
                    id.value.trim(),
                    known.join(", ")
                ),
            );
            return;
        };
        if depth >= MAX_SUBTREE_DEPTH {
            self.err(
                el.span,
                format!("SubTrees nested more than {MAX_SUBTREE_DEPTH} deep (does `{}` include itself?)", id.value.trim()),
            );
            return;
        }
        if el.elements().next().is_some() {
            self.err(el.span, "a <SubTree> has no children");
        }
        let mut scope = Scope {
            map: HashMap::new(),
            autoremap: false,
            prefix: String::new(),
        };
        for a in &el.attrs {
            match a.name.as_str() {
                "ID" | "name" | "_description" => {}
                "_autoremap" | "__shared_blackboard" => match a.value.trim() {
                    "true" | "1" => scope.autoremap = true,
                    "false" | "0" => {}
                    v => self.err(
                        a.value_span,
                        format!("`{}` must be true or false, not `{v}`", a.name),
                    ),
                },
                n if n.starts_with('_') => self.err(
                    a.name_span,
                    format!("`{n}` (a BehaviorTree.cpp script attribute) is not supported"),
                ),
                n => {
                    let v = self.resolve(&a.value);
                    scope.map.insert(n.to_string(), v);
                }
            }
        }
        self.subtree_count += 1;
        scope.prefix = format!("{}_{}_", sanitize(id.value.trim()), self.subtree_count);
        self.scopes.push(scope);
        self.tree_body(t, parent, depth + 1);
        self.scopes.pop();
    }
}
