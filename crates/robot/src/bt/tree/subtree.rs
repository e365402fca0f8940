//! Reading a `<SubTree>`: inlining its BehaviorTree in a new blackboard scope (remapped
//! ports, `_autoremap`, private entries), and the node a format-4 SubTree with pre/post
//! conditions becomes; the pre/post condition attributes of any node.

use std::collections::HashMap;

use super::{
    blackboard_name, format_name_error, is_ident, sanitize, Btcpp4, Cond, Control, Format, Kind,
    PortValue, Reader, TreeNode, FIRST_ID, MAX_SUBTREE_DEPTH,
};
use crate::model::xml::{Attr, Element};

/// One SubTree instance being inlined: how its blackboard names map to the caller's.
pub(super) struct Scope {
    /// Explicit remapping `inner -> value in the caller`.
    pub(super) map: HashMap<String, PortValue>,
    /// `_autoremap="true"`: unmapped names are the caller's names.
    pub(super) autoremap: bool,
    /// Prefix that makes unmapped names private to this instance.
    pub(super) prefix: String,
}

impl Reader<'_> {
    /// Inlines the BehaviorTree the `<SubTree>` `el` names, under `parent` (its index), in
    /// a new blackboard scope: its remapped ports, `_autoremap`, or entries private to
    /// this instance; `depth` is the number of SubTrees around it.
    pub(super) fn subtree(&mut self, el: &Element, parent: Option<usize>, depth: usize) {
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
        // Which SubTree this is decides the spelling of its "share every entry" flag and
        // how a plain value reads (BT.CPP 3.8 `subtree_node.h`: `SubtreeNode` has
        // `__shared_blackboard` and remaps names, `SubtreePlusNode` has `__autoremap` and
        // reads `{}` as BT.CPP 4's `SubTree` does with `_autoremap`).
        let v3_plain = el.name == "SubTree" && self.format == Format::V3;
        if el.name == "SubTreePlus" && self.format == Format::V4 {
            if let Some(m) = format_name_error("SubTreePlus", self.format) {
                self.err(el.span, m);
            }
            return;
        }
        let flags: &[&str] = match (el.name.as_str(), self.format) {
            ("SubTreePlus", _) => &["__autoremap"],
            (_, Format::V3) => &["__shared_blackboard"],
            (_, Format::V4) => &["_autoremap"],
            (_, Format::Unspecified) => &["_autoremap", "__shared_blackboard"],
        };
        for a in &el.attrs {
            match a.name.as_str() {
                "ID" | "name" | "_description" => {}
                n if flags.contains(&n) => match a.value.trim() {
                    "true" | "1" => scope.autoremap = true,
                    "false" | "0" => {}
                    v => self.err(
                        a.value_span,
                        format!("`{}` must be true or false, not `{v}`", a.name),
                    ),
                },
                n @ ("_autoremap" | "__autoremap" | "__shared_blackboard") => self.err(
                    a.name_span,
                    format!(
                        "`{n}` is not an attribute of <{}> in this tree's format ({}): use {}",
                        el.name,
                        match self.format {
                            Format::V3 => "BTCPP_format 3",
                            Format::V4 => "BTCPP_format 4",
                            Format::Unspecified => "no BTCPP_format, read as 4",
                        },
                        flags
                            .iter()
                            .map(|f| format!("`{f}`"))
                            .collect::<Vec<_>>()
                            .join(" or ")
                    ),
                ),
                // Pre/post conditions (format 4): the SubTree node's own
                // (`btcpp4_subtree.rs`, `subtree_node`), read below.
                n if self.format != Format::V3
                    && super::super::script::condition_error(n, "").is_some() => {}
                n if n.starts_with('_') => self.err(
                    a.name_span,
                    format!("`{n}` (a BehaviorTree.cpp script attribute) is not supported on a <SubTree>{}", if self.format == Format::V3 { " in BTCPP_format 3 (BehaviorTree.CPP 3 has no pre/post conditions)" } else { "" }),
                ),
                n if v3_plain => {
                    // `inner="outer"`: the caller's entry `outer` (braces tolerated).
                    let raw = a.value.trim();
                    let name = match raw {
                        "=" | "{=}" => n,
                        _ => blackboard_name(raw).unwrap_or(raw),
                    };
                    if !is_ident(name) {
                        self.err(
                            a.value_span,
                            format!("`{raw}` is not a blackboard entry name (in BTCPP_format 3 a <SubTree> maps `{n}` to an entry of the caller)"),
                        );
                        continue;
                    }
                    let v = self.resolve_bb(name, self.scopes.len());
                    scope.map.insert(n.to_string(), v);
                }
                n => {
                    let raw = a.value.trim();
                    if self.format == Format::Unspecified
                        && el.name == "SubTree"
                        && blackboard_name(raw).is_none()
                    {
                        self.err(
                            a.value_span,
                            format!(
                                "`{n}=\"{raw}\"` reads differently in BehaviorTree.CPP 3 (the caller's entry `{raw}`) and 4 (the constant \"{raw}\"): set BTCPP_format on <root>, or write `{{{raw}}}` for the entry"
                            ),
                        );
                        continue;
                    }
                    let v = self.resolve(n, &a.value);
                    scope.map.insert(n.to_string(), v);
                }
            }
        }
        self.subtree_count += 1;
        scope.prefix = format!("{}_{}_", sanitize(id.value.trim()), self.subtree_count);
        // With pre/post conditions, a node of its own between the caller and the body.
        let parent = self.subtree_node(el, parent).or(parent);
        self.scopes.push(scope);
        let at = self.nodes.len();
        self.tree_body(t, parent, depth + 1);
        if let Some(b) = self.nodes.get_mut(at) {
            b.subtree_body = true;
        }
        self.scopes.pop();
    }

    /// `a` as a pre/post condition (`_skipIf` ... `_onHalted`): pushed on `conds` when
    /// its script parses, an error at its value when not; `false` when `a` names no
    /// condition.
    pub(super) fn condition(&mut self, a: &Attr, conds: &mut Vec<Cond>) -> bool {
        match super::super::script::condition_error(&a.name, &a.value) {
            Some(Ok(_)) => conds.push(Cond {
                attr: a.name.clone(),
                code: a.value.clone(),
                name_span: a.name_span,
                span: a.value_span,
            }),
            Some(Err(e)) => self.err(a.value_span, format!("`{}`: {e}", a.name)),
            None => return false,
        }
        true
    }

    /// The node a format-4 `<SubTree>` with pre/post conditions becomes, pushed under
    /// `parent` (its index), or `None` when it has none (the body is inlined). BT.CPP 4
    /// `xml_parsing.cpp`, `XMLParser::PImpl::createNodeFromXML`: the SubTree node is
    /// created with the caller's blackboard and takes `_skipIf` ... `_onHalted` as its
    /// conditions (not as remapped ports), so their names are resolved in the caller's
    /// scope, whatever the SubTree remaps (`btcpp4_subtree.rs`).
    pub(super) fn subtree_node(&mut self, el: &Element, parent: Option<usize>) -> Option<usize> {
        if self.format == Format::V3 {
            return None;
        }
        let mut conds = Vec::new();
        for a in &el.attrs {
            self.condition(a, &mut conds);
        }
        if conds.is_empty() {
            return None;
        }
        let mut script_names: Vec<(String, PortValue)> = Vec::new();
        for c in &conds {
            for name in super::super::script::names(&c.code) {
                if !script_names.iter().any(|(n, _)| *n == name) {
                    let v = self.resolve_bb(&name, self.scopes.len());
                    script_names.push((name, v));
                }
            }
        }
        let idx = self.nodes.len();
        let id = FIRST_ID + idx as u32;
        let label = match el.attr_value("name") {
            Some(n) if !n.trim().is_empty() => sanitize(n.trim()),
            _ => format!(
                "SubTree_{}",
                sanitize(el.attr_value("ID").unwrap_or("").trim())
            ),
        };
        let kind = Kind::Control(Control::Btcpp4(Btcpp4::SubTree));
        self.push_node(TreeNode {
            script_names,
            conds,
            ..TreeNode::new(id, kind, &label, el.span, parent)
        });
        Some(idx)
    }
}
