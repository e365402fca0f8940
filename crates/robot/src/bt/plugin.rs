//! BT plugins: SCXML files with BT tags, read once and instantiated for every tree node
//! that uses them.
//!
//! An instance is the plugin's machine renamed `BT_plugin_<id>_<name>` with its BT tags
//! replaced by plain SCXML: `<bt_tick>` / `<bt_halt>` become transitions on
//! `bt_<id>_tick` / `bt_<id>_halt`, `<bt_return_status>` and `<bt_return_halted>` send the
//! answer to the parent, ports become the tree's constants, and blackboard entries become
//! messages to the blackboard machine. ROS tags are left as they are.

use super::blackboard::{self, Blackboard};
use super::build::B;
use super::control::{status_code, Ctx};
use super::tree::{PortValue, TreeNode};
use crate::model::source::{Diagnostic, FileId, SourceMap, Span};
use crate::model::types::{BaseType, Scalar, TypeExpr};
use crate::model::xml::{self, Element, Node};

/// A port's direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Dir {
    /// `bt_declare_port_in`.
    In,
    /// `bt_declare_port_out`.
    Out,
}

/// A port a plugin declares.
#[derive(Clone, Debug)]
pub(crate) struct DeclaredPort {
    /// The port's key.
    pub key: String,
    /// Its type as written (`int8`, `string`, ...).
    pub ty: String,
    /// In or out.
    pub dir: Dir,
    /// The declaration.
    pub span: Span,
}

/// A plugin as read from its file.
#[derive(Clone, Debug)]
pub(crate) struct Plugin {
    /// The node type the tree uses it as (the root's `name`).
    pub name: String,
    /// The root element (`<ascxml>` or `<scxml>`).
    pub root: Element,
    /// Declared ports.
    pub ports: Vec<DeclaredPort>,
    /// Whether any `<bt_halt>` appears (older models have none; their instances get a
    /// halt handler in every state).
    pub has_halt: bool,
    /// Whether it ticks children (`<bt_tick_child>`): a custom control node.
    pub ticks_children: bool,
    /// Whether it may answer RUNNING (a `<bt_return_status>` whose status is not SUCCESS
    /// or FAILURE). One that never does is a synchronous node under BT.CPP's rules (a
    /// `ConditionNode` or `SyncActionNode`: ticked again, it runs again), one that may
    /// is a `StatefulActionNode` (`btcpp.rs`, "Leaves").
    pub may_run: bool,
}

impl Plugin {
    /// The declared port `key`.
    pub(crate) fn port(&self, key: &str) -> Option<&DeclaredPort> {
        self.ports.iter().find(|p| p.key == key)
    }

    fn port_list(&self) -> String {
        if self.ports.is_empty() {
            "it declares none".into()
        } else {
            let v: Vec<&str> = self.ports.iter().map(|p| p.key.as_str()).collect();
            format!("it declares: {}", v.join(", "))
        }
    }
}

/// Whether `ty` is a type a port can have: a ROS primitive, or an array of them.
fn port_type_ok(ty: &str) -> bool {
    let t = ty.trim();
    let base = t.split('[').next().unwrap_or("").trim();
    let dims_ok = t[base.len()..].split(']').all(|d| {
        let d = d.trim().trim_start_matches('[').trim_start_matches("<=");
        d.is_empty() || d.parse::<u32>().is_ok()
    });
    // The scalar names, plus ROS's `byte` and `char` (not `wstring`).
    dims_ok && (matches!(base, "byte" | "char") || Scalar::from_exact_name(base).is_some())
}

fn contains_tag(el: &Element, tag: &str) -> bool {
    el.elements().any(|c| c.name == tag || contains_tag(c, tag))
}

/// Whether a `<bt_return_status>` under `el` may answer RUNNING (its status is not
/// SUCCESS or FAILURE).
fn may_answer_running(el: &Element) -> bool {
    el.elements().any(|c| {
        (c.name == "bt_return_status"
            && !matches!(
                c.attr_value("status").map(str::trim),
                Some("SUCCESS" | "FAILURE")
            ))
            || may_answer_running(c)
    })
}

/// Reads the plugin file `file`.
pub(crate) fn read(sm: &SourceMap, file: FileId) -> Result<Plugin, Vec<Diagnostic>> {
    let root = xml::parse(sm, file).map_err(|d| vec![d])?;
    let mut errs = Vec::new();
    if root.name != "ascxml" && root.name != "scxml" {
        errs.push(sm.diag(
            root.span,
            format!(
                "a BT plugin must be an <ascxml> or <scxml> file, found <{}>",
                root.name
            ),
        ));
    }
    let name = match root.attr("name") {
        Some(a) if !a.value.trim().is_empty() => a.value.trim().to_string(),
        _ => {
            errs.push(sm.diag(
                root.span,
                "a BT plugin needs a `name`: the node type the tree uses",
            ));
            String::new()
        }
    };
    let mut ports: Vec<DeclaredPort> = Vec::new();
    for c in root.elements() {
        let dir = match c.name.as_str() {
            "bt_declare_port_in" => Dir::In,
            "bt_declare_port_out" => Dir::Out,
            _ => continue,
        };
        c.check_attrs(sm, &["key", "type"], &mut errs);
        let (key, ty) = match (c.required(sm, "key"), c.required(sm, "type")) {
            (Ok(k), Ok(t)) => (k, t),
            (k, t) => {
                errs.extend(k.err().into_iter().chain(t.err()));
                continue;
            }
        };
        if !port_type_ok(&ty.value) {
            errs.push(sm.diag(
                ty.value_span,
                format!(
                    "port `{}` has type `{}`; a port is bool, intN, uintN, float32, float64 or string (or an array of them)",
                    key.value, ty.value
                ),
            ));
        }
        if let Some(p) = ports.iter().find(|p| p.key == key.value.trim()) {
            let at = sm.diag(p.span, "");
            errs.push(sm.diag(
                key.value_span,
                format!(
                    "port `{}` is declared twice (also at line {})",
                    key.value, at.line
                ),
            ));
            continue;
        }
        ports.push(DeclaredPort {
            key: key.value.trim().to_string(),
            ty: ty.value.trim().to_string(),
            dir,
            span: c.span,
        });
    }
    if !errs.is_empty() {
        return Err(errs);
    }
    Ok(Plugin {
        name,
        has_halt: contains_tag(&root, "bt_halt"),
        ticks_children: contains_tag(&root, "bt_tick_child"),
        may_run: may_answer_running(&root),
        root,
        ports,
    })
}

/// Checks the port values the tree gives `node` against `plugin`'s declarations and
/// records blackboard entries with their types.
pub(crate) fn check_ports(
    sm: &SourceMap,
    plugin: &Plugin,
    node: &TreeNode,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) {
    for p in &node.ports {
        let Some(decl) = plugin.port(&p.key) else {
            errs.push(sm.diag(
                p.span,
                format!(
                    "plugin `{}` has no port `{}` ({})",
                    plugin.name,
                    p.key,
                    plugin.port_list()
                ),
            ));
            continue;
        };
        match &p.value {
            PortValue::Literal(v) => {
                if decl.dir == Dir::Out {
                    errs.push(sm.diag(
                        p.span,
                        format!(
                            "`{}` is an output port of `{}`: give it a blackboard entry such as `{{{}}}`, not a constant",
                            p.key, plugin.name, p.key
                        ),
                    ));
                } else if let Err(m) = check_literal(v, &decl.ty) {
                    errs.push(sm.diag(
                        p.span,
                        format!("port `{}` of `{}`: {m}", p.key, plugin.name),
                    ));
                }
            }
            PortValue::Blackboard(name) => {
                if !bb.declared.contains(name) {
                    bb.declared.push(name.clone());
                }
                if decl.dir == Dir::Out && !bb.port_outputs.contains(name) {
                    bb.port_outputs.push(name.clone());
                }
                let why = format!("port `{}` of plugin `{}`", p.key, plugin.name);
                blackboard::register(sm, bb, name, &decl.ty, p.span, &why, errs)
            }
        }
    }
}

/// A type written in a comparable form (`int32` and `int32 ` alike).
pub(crate) fn normalize(ty: &str) -> String {
    match TypeExpr::parse(ty) {
        Ok(t) => format!("{t:?}"),
        Err(_) => ty.trim().to_string(),
    }
}

/// A constant that does not fit its port's or entry's type: the constant as written and
/// the type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct BadLiteral {
    value: String,
    ty: String,
}

impl std::fmt::Display for BadLiteral {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` is not a valid {}", self.value, self.ty)
    }
}

impl std::error::Error for BadLiteral {}

/// Whether constant `v` fits type `ty`.
pub(crate) fn check_literal(v: &str, ty: &str) -> Result<(), BadLiteral> {
    let t = v.trim();
    let base = match TypeExpr::parse(ty) {
        Ok(TypeExpr::Base(b)) => b,
        _ => return Ok(()),
    };
    let ok = match base {
        BaseType::Int => {
            let parsed = t.parse::<i64>();
            let unsigned = ty.trim().starts_with('u');
            matches!(parsed, Ok(n) if !unsigned || n >= 0) && int_fits(ty.trim(), t)
        }
        BaseType::Float => t.parse::<f64>().is_ok_and(|f| f.is_finite()),
        BaseType::Bool => matches!(t, "true" | "false" | "True" | "False" | "1" | "0"),
        _ => true,
    };
    if ok {
        Ok(())
    } else {
        Err(BadLiteral {
            value: v.to_string(),
            ty: ty.trim().to_string(),
        })
    }
}

fn int_fits(ty: &str, v: &str) -> bool {
    let Ok(n) = v.parse::<i128>() else {
        return false;
    };
    // Any other type holds what the simulator's integers hold.
    let (lo, hi) = Scalar::from_exact_name(ty)
        .and_then(Scalar::int_range)
        .unwrap_or((i64::MIN.into(), i64::MAX.into()));
    (lo..=hi).contains(&n)
}

/// A constant written as an expression of type `ty`.
pub(crate) fn literal_expr(v: &str, ty: &str) -> String {
    let t = v.trim();
    match TypeExpr::parse(ty) {
        Ok(TypeExpr::Base(BaseType::Bool)) => match t {
            "True" | "true" | "1" => "true".into(),
            _ => "false".into(),
        },
        // `01`, `+1`: the number, written as the model's expressions read it.
        Ok(TypeExpr::Base(BaseType::Int)) => {
            t.parse::<i64>().map_or(t.to_string(), |n| n.to_string())
        }
        Ok(TypeExpr::Base(BaseType::Float)) => t.to_string(),
        _ if ty.trim() == "string" => format!("'{}'", v.replace('\\', "\\\\").replace('\'', "\\'")),
        _ => t.to_string(),
    }
}

/// Lowers one instance of `plugin` for tree node `node`.
pub(crate) fn instance(
    sm: &SourceMap,
    plugin: &Plugin,
    node: &TreeNode,
    ctx: &Ctx,
    bb: &mut Blackboard,
    errs: &mut Vec<Diagnostic>,
) -> Element {
    let mut root = plugin.root.clone();
    root.name = "scxml".into();
    let span = root.attr("name").map(|a| a.value_span).unwrap_or(root.span);
    root.set_attr_at("name", ctx.machine.clone(), span);
    root.children.retain(|c| {
        !matches!(c, Node::Element(e) if e.name == "bt_declare_port_in" || e.name == "bt_declare_port_out")
    });
    if !node.children.is_empty() && !plugin.ticks_children {
        errs.push(sm.diag(
            node.span,
            format!(
                "`{}` is a leaf plugin (it has no <bt_tick_child>) but has {} children here",
                plugin.name,
                node.children.len()
            ),
        ));
    }
    let mut l = Lower {
        sm,
        plugin,
        node,
        ctx,
        bb,
        errs,
        pending_states: Vec::new(),
    };
    l.block(&mut root);
    // Each state made to wait for the blackboard comes right after the state it was split
    // from, as in AS2FM (`ScxmlState._generate_variable_config_retrieval`,
    // scxml_converter/scxml_entries/scxml_state.py, returns `[state, *new states]`).
    let mut pending = std::mem::take(&mut l.pending_states);
    let mut children = Vec::with_capacity(root.children.len() + pending.len());
    for n in std::mem::take(&mut root.children) {
        let from = match &n {
            Node::Element(e) if e.name == "state" => e.attr_value("id").map(String::from),
            _ => None,
        };
        children.push(n);
        if let Some(id) = from {
            let (mine, rest): (Vec<_>, Vec<_>) = pending.into_iter().partition(|(p, _)| *p == id);
            children.extend(mine.into_iter().map(|(_, s)| Node::Element(s)));
            pending = rest;
        }
    }
    children.extend(pending.into_iter().map(|(_, s)| Node::Element(s)));
    root.children = children;
    if !plugin.has_halt {
        let b = B { at: root.span };
        for s in root.elements_mut() {
            if s.name == "state" {
                s.push(b.tr(Some(&ctx.halt_ev()), None, None, vec![ctx.respond_halted()]));
            }
        }
    }
    root
}

struct Lower<'a> {
    sm: &'a SourceMap,
    plugin: &'a Plugin,
    node: &'a TreeNode,
    ctx: &'a Ctx,
    bb: &'a mut Blackboard,
    errs: &'a mut Vec<Diagnostic>,
    /// States made by splitting transitions, added at the end of the machine.
    /// States split off to wait for the blackboard, with the id of the state they come from.
    pending_states: Vec<(String, Element)>,
}

/// Executable content and transitions that may read the blackboard by being split.
fn splittable(name: &str) -> bool {
    name == "transition" || (name.starts_with("ros_") && name != "ros_time_rate")
}

impl Lower<'_> {
    fn err(&mut self, span: Span, msg: impl Into<String>) {
        self.errs.push(self.sm.diag(span, msg));
    }

    /// The value of port `key` read at `span`: as an expression (`expr`) or as raw text;
    /// `Some((text, true, _))` for a blackboard read. The span is where the text was
    /// written: the tree's port value for raw text (a service or topic name, say, so
    /// that an error about it points at the tree), else `span`.
    fn get_input(&mut self, key: &str, span: Span, expr: bool) -> Option<(String, bool, Span)> {
        let Some(decl) = self.plugin.port(key) else {
            self.err(
                span,
                format!(
                    "port `{key}` is not declared (add <bt_declare_port_in key=\"{key}\" type=\"...\"/>; {})",
                    self.plugin.port_list()
                ),
            );
            return None;
        };
        let Some(p) = self.node.port(key) else {
            let at = self.sm.diag(span, "");
            self.err(
                self.node.span,
                format!(
                    "node needs port `{key}`: plugin `{}` reads it at {}:{}:{}",
                    self.plugin.name, at.file, at.line, at.col
                ),
            );
            return None;
        };
        match &p.value {
            PortValue::Literal(v) => Some(if expr {
                (literal_expr(v, &decl.ty), false, span)
            } else {
                (v.trim().to_string(), false, p.span)
            }),
            PortValue::Blackboard(name) => {
                if expr {
                    Some((format!("_event.data.{name}"), true, span))
                } else {
                    self.err(
                        span,
                        format!(
                            "port `{key}` is the blackboard entry `{{{name}}}` but is read here as a fixed text (only an <expr> can read the blackboard)"
                        ),
                    );
                    None
                }
            }
        }
    }

    /// The `id` attribute of a child tag: a child index of this node, or an expression
    /// whose value is one.
    fn child_ref(&mut self, el: &Element) -> Option<ChildRef> {
        let a = match el.required(self.sm, "id") {
            Ok(a) => a,
            Err(d) => {
                self.errs.push(d);
                return None;
            }
        };
        let n = self.ctx.children.len();
        if n == 0 {
            self.err(a.value_span, "this node has no children in the tree");
            return None;
        }
        match a.value.trim().parse::<usize>() {
            Ok(i) if i < n => Some(ChildRef::Index(i)),
            Ok(_) => {
                self.err(
                    a.value_span,
                    format!(
                        "`{}` is not a child index of this node (it has {n} children)",
                        a.value
                    ),
                );
                None
            }
            Err(_) => Some(ChildRef::Expr(a.value.trim().to_string())),
        }
    }

    /// Children `id` may name: `(index, condition that it is that child)`.
    fn children_of(&self, r: &ChildRef) -> Vec<(usize, Option<String>)> {
        match r {
            ChildRef::Index(i) => vec![(*i, None)],
            ChildRef::Expr(e) => (0..self.ctx.children.len())
                .map(|i| (i, Some(format!("({e}) == {i}"))))
                .collect(),
        }
    }

    /// Lowers the children of `el` in place; true when a blackboard read inside is still
    /// to be handled by splitting an enclosing transition.
    fn block(&mut self, el: &mut Element) -> bool {
        let mut reads = false;
        let mut split: Vec<(usize, String)> = Vec::new();
        let children = std::mem::take(&mut el.children);
        let mut out: Vec<Node> = Vec::with_capacity(children.len());
        for node in children {
            let Node::Element(mut c) = node else {
                out.push(node);
                continue;
            };
            // `<expr><bt_get_input key/></expr>` is the attribute `expr` of `el`.
            let kids: Vec<&Element> = c.elements().collect();
            if kids.len() == 1 && kids[0].name == "bt_get_input" {
                let gi = kids[0].clone();
                gi.check_attrs(self.sm, &["key"], self.errs);
                match gi.required(self.sm, "key") {
                    Ok(k) => {
                        let key = k.value.trim().to_string();
                        let expr = matches!(c.name.as_str(), "expr" | "cond");
                        if let Some((v, bb, at)) = self.get_input(&key, gi.span, expr) {
                            if bb && c.name != "expr" {
                                self.err(
                                    gi.span,
                                    format!("port `{key}` is a blackboard entry: a condition cannot read the blackboard (assign it to a variable first)"),
                                );
                            } else {
                                el.set_attr_at(&c.name, v, at);
                                reads |= bb;
                            }
                        }
                    }
                    Err(d) => self.errs.push(d),
                }
                continue;
            }
            let b = B { at: c.span };
            let tag = c.name.clone();
            match tag.as_str() {
                "bt_tick" | "bt_halt" => {
                    c.check_attrs(self.sm, &["target", "cond"], self.errs);
                    let ev = if tag == "bt_tick" {
                        self.ctx.tick_ev()
                    } else {
                        self.ctx.halt_ev()
                    };
                    c.name = "transition".into();
                    let at = c.span;
                    c.set_attr_at("event", ev, at);
                    if self.block(&mut c) {
                        reads = true;
                        split.push((out.len(), tag.clone()));
                    }
                    out.push(Node::Element(c));
                }
                "bt_child_status" | "bt_child_halted" => {
                    let allowed: &[&str] = if tag == "bt_child_status" {
                        &["id", "target", "cond"]
                    } else {
                        &["id", "target"]
                    };
                    c.check_attrs(self.sm, allowed, self.errs);
                    let Some(r) = self.child_ref(&c) else {
                        continue;
                    };
                    c.remove_attr("id");
                    c.name = "transition".into();
                    let cond = c.remove_attr("cond");
                    for (i, which) in self.children_of(&r) {
                        let mut t = c.clone();
                        let at = t.span;
                        let ev = if tag == "bt_child_status" {
                            self.ctx.child_resp(i)
                        } else {
                            self.ctx.child_halt_resp(i)
                        };
                        t.set_attr_at("event", ev, at);
                        let user = cond.as_ref().map(|a| (status_cond(&a.value), a.value_span));
                        match (which, user) {
                            (None, Some((u, span))) => t.set_attr_at("cond", u, span),
                            (Some(w), None) => t.set_attr_at("cond", w, at),
                            (Some(w), Some((u, span))) => {
                                t.set_attr_at("cond", format!("{w} && ({u})"), span)
                            }
                            (None, None) => {}
                        }
                        if self.block(&mut t) {
                            reads = true;
                            split.push((out.len(), tag.clone()));
                        }
                        out.push(Node::Element(t));
                    }
                }
                "bt_return_status" => {
                    c.check_attrs(self.sm, &["status"], self.errs);
                    match c.required(self.sm, "status") {
                        Ok(a) => match status_code(&a.value) {
                            Some(s) => {
                                let ctx = Ctx { b, ..self.ctx.clone() };
                                out.push(Node::Element(ctx.respond(s)));
                            }
                            None => self.err(
                                a.value_span,
                                format!(
                                    "unknown status `{}` (expected SUCCESS, FAILURE or RUNNING)",
                                    a.value
                                ),
                            ),
                        },
                        Err(d) => self.errs.push(d),
                    }
                }
                "bt_return_halted" => {
                    c.check_attrs(self.sm, &[], self.errs);
                    let ctx = Ctx { b, ..self.ctx.clone() };
                    out.push(Node::Element(ctx.respond_halted()));
                }
                "bt_tick_child" | "bt_halt_child" => {
                    c.check_attrs(self.sm, &["id"], self.errs);
                    if let Some(r) = self.child_ref(&c) {
                        let ctx = Ctx { b, ..self.ctx.clone() };
                        let send = |i: usize| {
                            if tag == "bt_tick_child" {
                                ctx.tick_child(i)
                            } else {
                                ctx.halt_child(i)
                            }
                        };
                        let branches: Vec<(String, Vec<Element>)> = self
                            .children_of(&r)
                            .into_iter()
                            .map(|(i, w)| (w.unwrap_or_default(), vec![send(i)]))
                            .collect();
                        let el = match r {
                            ChildRef::Index(_) => branches.into_iter().next().and_then(|b| b.1.into_iter().next()),
                            ChildRef::Expr(_) => ctx.b.if_chain(branches, Vec::new()),
                        };
                        if let Some(el) = el {
                            out.push(Node::Element(el));
                        }
                    }
                }
                "bt_set_output" => {
                    c.check_attrs(self.sm, &["key", "expr"], self.errs);
                    if let Some(s) = self.set_output(&c) {
                        out.push(Node::Element(s));
                    }
                }
                "bt_get_input" => self.err(
                    c.span,
                    "<bt_get_input> must be the only content of an attribute element such as <expr>",
                ),
                "bt_declare_port_in" | "bt_declare_port_out" => self.err(
                    c.span,
                    format!("<{tag}> must be a direct child of the plugin's root"),
                ),
                t if t.starts_with("bt_") => self.err(
                    c.span,
                    format!(
                        "unknown BT tag <{t}> (known: bt_tick, bt_halt, bt_return_status, bt_return_halted, bt_get_input, bt_set_output, bt_declare_port_in, bt_declare_port_out, bt_tick_child, bt_halt_child, bt_child_status, bt_child_halted)"
                    ),
                ),
                _ => {
                    if self.block(&mut c) {
                        if el.name == "state" && splittable(&c.name) {
                            split.push((out.len(), tag.clone()));
                        } else if el.name == "state" || el.name == "scxml" || el.name == "ascxml" {
                            self.err(
                                c.span,
                                format!("a blackboard entry is read inside <{tag}>: only transitions can read the blackboard"),
                            );
                        } else {
                            reads = true;
                        }
                    }
                    out.push(Node::Element(c));
                }
            }
        }
        el.children = out;
        if el.name == "state" {
            if !split.is_empty() {
                self.split(el, &split);
            }
            return false;
        }
        if el.name == "scxml" || el.name == "ascxml" {
            return false;
        }
        reads
    }

    /// `<bt_set_output key expr>`: a write to the blackboard entry the port names.
    fn set_output(&mut self, c: &Element) -> Option<Element> {
        let key = match c.required(self.sm, "key") {
            Ok(k) => k.clone(),
            Err(d) => {
                self.errs.push(d);
                return None;
            }
        };
        let expr = match c.required(self.sm, "expr") {
            Ok(e) => e.clone(),
            Err(d) => {
                self.errs.push(d);
                return None;
            }
        };
        let k = key.value.trim();
        if self.plugin.port(k).is_none() {
            self.err(
                key.value_span,
                format!(
                    "port `{k}` is not declared (add <bt_declare_port_out key=\"{k}\" type=\"...\"/>; {})",
                    self.plugin.port_list()
                ),
            );
            return None;
        }
        let entry = match self.node.port(k).map(|p| &p.value) {
            Some(PortValue::Blackboard(name)) => name.clone(),
            Some(PortValue::Literal(v)) => {
                let span = self.node.port(k).map(|p| p.span).unwrap_or(self.node.span);
                self.err(
                    span,
                    format!(
                        "plugin `{}` writes port `{k}`, so the tree must give it a blackboard entry such as `{{{k}}}`, not `{v}`",
                        self.plugin.name
                    ),
                );
                return None;
            }
            None => {
                let at = self.sm.diag(c.span, "");
                self.err(
                    self.node.span,
                    format!(
                        "node needs port `{k}`: plugin `{}` writes it at {}:{}:{}",
                        self.plugin.name, at.file, at.line, at.col
                    ),
                );
                return None;
            }
        };
        let b = B { at: c.span };
        let mut s = b.send(&blackboard::set_event(&entry), blackboard::MACHINE);
        let mut p = b.el("param", &[("name", "value")]);
        p.set_attr_at("expr", expr.value.clone(), expr.value_span);
        s.push(p);
        Some(s)
    }

    /// Splits the transitions at `at` (indices into `state`'s children) that read the
    /// blackboard: each now asks the blackboard and waits in a new state for the answer,
    /// where the original content runs.
    fn split(&mut self, state: &mut Element, at: &[(usize, String)]) {
        let sid = state.attr_value("id").unwrap_or("state").to_string();
        self.bb.add_reader(&self.ctx.machine);
        let mut new_states = Vec::new();
        for (k, (i, tag)) in at.iter().enumerate() {
            let Some(Node::Element(t)) = state.children.get_mut(*i) else {
                continue;
            };
            let b = B { at: t.span };
            let wait_id = format!("{sid}_{tag}_{}", k + 1);
            let body = std::mem::take(&mut t.children);
            let has_targets = body
                .iter()
                .any(|n| matches!(n, Node::Element(e) if e.name == "target"));
            let target = t.remove_attr("target");
            t.set_attr("target", wait_id.clone());
            t.push(b.send(blackboard::REQ, blackboard::MACHINE));
            let mut get = b.tr(Some(blackboard::GET), None, None, vec![]);
            match target {
                Some(a) => get.set_attr_at("target", a.value, a.value_span),
                None if !has_targets => get.set_attr("target", sid.clone()),
                None => {}
            }
            get.children = body;
            new_states.push((sid.clone(), b.state(&wait_id).with_child(get)));
        }
        self.pending_states.append(&mut new_states);
    }
}

/// Which child a `bt_*_child` tag means.
enum ChildRef {
    /// A constant index.
    Index(usize),
    /// An expression over the plugin's data.
    Expr(String),
}

/// A condition on a child's answer: `_bt.status` is the answer, status names are codes.
fn status_cond(cond: &str) -> String {
    let mut out = String::with_capacity(cond.len());
    let mut word = String::new();
    let flush = |w: &mut String, out: &mut String| {
        match w.as_str() {
            "SUCCESS" => out.push('1'),
            "FAILURE" => out.push('2'),
            "RUNNING" => out.push('3'),
            _ => out.push_str(w),
        }
        w.clear();
    };
    for ch in cond.chars() {
        if ch.is_ascii_alphanumeric() || ch == '_' || ch == '.' {
            word.push(ch);
        } else {
            flush(&mut word, &mut out);
            out.push(ch);
        }
    }
    flush(&mut word, &mut out);
    out.replace("_bt.status", "_event.data.status")
}
