//! Pass 2: one node model (or action thread) with ROS tags becomes one plain `<scxml>` tree.

use super::expr::{rewrite, Scope};
use super::{find, Cx, DECLARATIONS};
use crate::model::source::{unescaped_offset, Span};
use crate::model::xml::{Element, Node};
use crate::types::FlatField;

/// Every ROS tag the lowering knows: declarations and the tags inside states.
const KNOWN_TAGS: &[&str] = &[
    "ros_time_rate",
    "ros_topic_publisher",
    "ros_topic_subscriber",
    "ros_service_server",
    "ros_service_client",
    "ros_action_server",
    "ros_action_client",
    "ros_action_thread",
    "ros_rate_callback",
    "ros_topic_publish",
    "ros_topic_callback",
    "ros_service_send_request",
    "ros_service_handle_request",
    "ros_service_send_response",
    "ros_service_handle_response",
    "ros_action_send_goal",
    "ros_action_handle_goal",
    "ros_action_accept_goal",
    "ros_action_reject_goal",
    "ros_action_handle_goal_response",
    "ros_action_start_thread",
    "ros_action_handle_thread_start",
    "ros_action_thread_free",
    "ros_action_handle_thread_free",
    "ros_action_feedback",
    "ros_action_handle_feedback",
    "ros_action_succeed",
    "ros_action_aborted",
    "ros_action_canceled",
    "ros_action_handle_success_result",
    "ros_action_handle_aborted_result",
    "ros_action_handle_canceled_result",
];

/// What the machine being lowered is.
struct UnitCx {
    name: String,
    machine: usize,
    /// `(action key, thread index)` for a thread instance.
    thread: Option<(String, u32)>,
}

/// Attributes that hold expressions (rewritten with the callback's scope).
const EXPR_ATTRS: [&str; 6] = [
    "expr",
    "cond",
    "location",
    "goal_id",
    "thread_id",
    "delayexpr",
];

impl Cx<'_> {
    pub(super) fn lower_unit(&mut self, machines: &[Element], ui: usize) -> Element {
        let u = self.units[ui].clone();
        let src = Self::unit_root(machines, &u);
        let ucx = UnitCx {
            name: u.name.clone(),
            machine: u.machine,
            thread: u.thread.as_ref().map(|(k, t, _)| (k.clone(), *t)),
        };
        let mut root = Element::new("scxml", src.span);
        root.set_attr("name", u.name.clone());
        if let Some(a) = machines[u.machine].attr("name") {
            root.attrs[0].value_span = a.value_span;
            root.attrs[0].name_span = a.name_span;
        }
        for a in &src.attrs {
            match a.name.as_str() {
                "initial" | "version" | "model_src" | "binding" => root.attrs.push(a.clone()),
                // AS2FM drops it; ecmascript is the only data model anyway.
                "datamodel" => {}
                n if n.starts_with("xmlns") => {}
                // `<ros_action_thread name n_threads>` and unknown attributes of the root.
                "name" | "n_threads" => {}
                other => {
                    let msg = format!("unknown attribute `{other}` on <{}>", src.name);
                    self.err(a.name_span, msg);
                }
            }
        }
        root.set_attr("xmlns", "http://www.w3.org/2005/07/scxml");
        let scope = Scope::default();
        self.rand_used = false;
        for node in &src.children {
            match node {
                Node::Element(el) if DECLARATIONS.contains(&el.name.as_str()) => {}
                Node::Element(el) if el.name == "state" || el.name == "final" => {
                    let s = self.lower_state(el, &ucx);
                    root.push(s);
                }
                Node::Element(el) => {
                    for n in self.lower_el(el, &ucx, &scope) {
                        root.children.push(n);
                    }
                }
                other => root.children.push(other.clone()),
            }
        }
        // AS2FM writes a datamodel only when it has entries (`ScxmlRoot.as_xml`,
        // scxml_converter/scxml_entries/scxml_root.py).
        root.children
            .retain(|n| !matches!(n, Node::Element(e) if e.name == "datamodel" && e.elements().next().is_none()));
        if self.rand_used {
            let data = Element::new("data", src.span)
                .with_attr("id", "__RAND__")
                .with_attr("type", "float64")
                .with_attr("expr", "0.0");
            if root.elements().any(|e| e.name == "datamodel") {
                if let Some(dm) = root.elements_mut().find(|e| e.name == "datamodel") {
                    dm.push(data);
                }
            } else {
                let dm = Element::new("datamodel", src.span).with_child(data);
                root.children.insert(0, Node::Element(dm));
            }
        }
        root
    }

    fn lower_state(&mut self, el: &Element, u: &UnitCx) -> Element {
        let scope = Scope::default();
        let mut s = Element::new(el.name.clone(), el.span);
        s.attrs = el.attrs.clone();
        for node in &el.children {
            match node {
                Node::Element(c) => s.children.extend(self.lower_el(c, u, &scope)),
                other => s.children.push(other.clone()),
            }
        }
        self.probabilistic(&mut s);
        // As AS2FM writes states (`ScxmlState.as_xml`, scxml_converter/scxml_entries/
        // scxml_state.py): `onentry`, `onexit`, then the transitions.
        s.children.sort_by_key(|n| match n {
            Node::Element(e) if e.name == "onentry" => 0,
            Node::Element(e) if e.name == "onexit" => 1,
            _ => 2,
        });
        s
    }

    /// Expands transitions whose children are `<target id prob>` (see the module docs).
    ///
    /// As `export_plain_scxml_models` (jani_generator/scxml_helpers/top_level_interpreter.py)
    /// does: one transition per target, in order, guarded by the transition's condition and
    /// `lo < __RAND__ && __RAND__ <= hi`; `__RAND__` is added at the end of the datamodel and
    /// drawn at the end of the state's `onentry`. (A target without `prob` gets no interval
    /// there; here it shares what the others leave, so that the shares add up to one.)
    fn probabilistic(&mut self, s: &mut Element) {
        let mut uses_rand = false;
        let mut out = Vec::new();
        for node in std::mem::take(&mut s.children) {
            let Node::Element(t) = node else {
                out.push(node);
                continue;
            };
            if t.name != "transition" || !t.elements().any(|c| c.name == "target") {
                out.push(Node::Element(t));
                continue;
            }
            uses_rand = true;
            // Targets without `prob` share what the others leave, and the last one ends at 1.
            let mut given = 0.0f64;
            let mut unset = 0usize;
            for c in t.elements().filter(|c| c.name == "target") {
                match c.attr("prob") {
                    Some(a) => given += a.value.trim().parse::<f64>().unwrap_or(0.0),
                    None => unset += 1,
                }
            }
            let rest = if unset > 0 {
                ((1.0 - given) / unset as f64).max(0.0)
            } else {
                0.0
            };
            let count = t.elements().filter(|c| c.name == "target").count();
            let mut lo = 0.0f64;
            for (k, c) in t.elements().enumerate() {
                if c.name != "target" {
                    self.err(
                        c.span,
                        format!(
                            "<{}> next to probabilistic <target>s: put it inside each <target>",
                            c.name
                        ),
                    );
                    continue;
                }
                let Some((id, id_span)) = self.attr_or_err(c, "id") else {
                    continue;
                };
                let (p, p_span) = match c.attr("prob") {
                    Some(a) => match a.value.trim().parse::<f64>() {
                        Ok(v) if (0.0..=1.0).contains(&v) => (v, a.value_span),
                        _ => {
                            let msg =
                                format!("`prob` must be a number in [0, 1], not `{}`", a.value);
                            self.err(a.value_span, msg);
                            continue;
                        }
                    },
                    None => (rest, c.span),
                };
                let last = k + 1 == t.elements().count() && count > 0;
                let hi = if last && unset > 0 { 1.0 } else { lo + p };
                let range = format!("{lo:?} < __RAND__ && __RAND__ <= {hi:?}");
                lo = hi;
                let mut n = Element::new("transition", c.span);
                for a in &t.attrs {
                    if a.name != "target" && a.name != "cond" {
                        n.attrs.push(a.clone());
                    }
                }
                let cond = match t.attr("cond") {
                    Some(a) => format!("({}) && {range}", a.value),
                    None => range,
                };
                let cspan = t.attr("cond").map(|a| a.value_span).unwrap_or(p_span);
                n.set_attr_at("cond", cond, cspan);
                n.set_attr_at("target", id, id_span);
                n.children = c.children.clone();
                out.push(Node::Element(n));
            }
            if lo > 1.0 + 1e-9 {
                self.err(
                    t.span,
                    format!("the probabilities of these targets add up to {lo} > 1"),
                );
            }
        }
        s.children = out;
        if uses_rand {
            let draw = Element::new("assign", s.span)
                .with_attr("location", "__RAND__")
                .with_attr("expr", "Math.random()");
            if s.elements().any(|e| e.name == "onentry") {
                if let Some(on) = s.elements_mut().find(|e| e.name == "onentry") {
                    on.push(draw);
                }
            } else {
                let on = Element::new("onentry", s.span).with_child(draw);
                s.children.insert(0, Node::Element(on));
            }
            self.rand_used = true;
        }
    }

    /// Rewrites the expression attributes of `el` with `scope`.
    fn rewrite_attrs(&mut self, el: &Element, scope: &Scope) -> Element {
        let mut n = Element::new(el.name.clone(), el.span);
        for a in &el.attrs {
            let mut a = a.clone();
            if EXPR_ATTRS.contains(&a.name.as_str()) {
                match rewrite(&a.value, scope) {
                    Ok(v) => a.value = v,
                    Err((k, m)) => {
                        let at = unescaped_offset(self.sm, a.value_span, k as u32);
                        self.err(at, m.to_string());
                    }
                }
            }
            n.attrs.push(a);
        }
        n
    }

    fn rewrite_value(&mut self, el: &Element, name: &str, scope: &Scope) -> Option<(String, Span)> {
        let (v, span) = self.attr_or_err(el, name)?;
        match rewrite(&v, scope) {
            Ok(v) => Some((v, span)),
            Err((k, m)) => {
                let at = unescaped_offset(self.sm, span, k as u32);
                self.err(at, m.to_string());
                None
            }
        }
    }

    /// Lowers one element (and its subtree) to the nodes that replace it.
    fn lower_el(&mut self, el: &Element, u: &UnitCx, scope: &Scope) -> Vec<Node> {
        if el.name.starts_with("ros_") {
            return self.lower_ros(el, u, scope);
        }
        if el.name == "datamodel" || el.name == "data" {
            return vec![Node::Element(el.clone())];
        }
        let mut n = self.rewrite_attrs(el, scope);
        if n.name == "send" && n.attr("target").is_none() && n.attr("targetexpr").is_none() {
            // AS2FM sends a targetless event to every machine that handles it (see `route`).
            n.set_attr("target", super::AUTO_TARGET);
        }
        for node in &el.children {
            match node {
                Node::Element(c) => n.children.extend(self.lower_el(c, u, scope)),
                other => n.children.push(other.clone()),
            }
        }
        vec![Node::Element(n)]
    }

    fn body(&mut self, el: &Element, u: &UnitCx, scope: &Scope, into: &mut Element) {
        for node in &el.children {
            match node {
                Node::Element(c) if c.name == "field" => {
                    self.err(c.span, format!("<field> is not allowed in <{}>", el.name));
                }
                Node::Element(c) => into.children.extend(self.lower_el(c, u, scope)),
                other => into.children.push(other.clone()),
            }
        }
    }

    /// A transition on `event` from callback `el`, with an extra guard.
    fn callback(
        &mut self,
        el: &Element,
        u: &UnitCx,
        scope: &Scope,
        event: &str,
        guard: Option<String>,
    ) -> Vec<Node> {
        let mut t = Element::new("transition", el.span);
        t.set_attr("event", event);
        let user = match el.attr("cond") {
            Some(_) => self.rewrite_value(el, "cond", scope),
            None => None,
        };
        match (guard, user) {
            (Some(g), Some((c, span))) => t.set_attr_at("cond", format!("{g} && ({c})"), span),
            (Some(g), None) => t.set_attr("cond", g),
            (None, Some((c, span))) => t.set_attr_at("cond", c, span),
            (None, None) => {}
        }
        if let Some(a) = el.attr("target") {
            t.attrs.push(a.clone());
        }
        self.body(el, u, scope, &mut t);
        vec![Node::Element(t)]
    }

    /// `<param>`s for the `<field>` children of `el`, then defaults for the fields not given.
    fn params(
        &mut self,
        el: &Element,
        fields: &[FlatField],
        what: &str,
        scope: &Scope,
    ) -> Vec<Element> {
        let mut given: Vec<(usize, Element)> = Vec::new();
        for c in el.elements() {
            if c.name != "field" {
                self.err(
                    c.span,
                    format!("unexpected <{}> in <{}> (only <field>)", c.name, el.name),
                );
                continue;
            }
            let Some((name, nspan)) = self.attr_or_err(c, "name") else {
                continue;
            };
            let Some(fi) = fields.iter().position(|f| f.dotted() == name.trim()) else {
                let known: Vec<String> = fields.iter().map(|f| f.dotted()).collect();
                self.err(
                    nspan,
                    format!(
                        "`{}` is not a field of {what} (fields: {})",
                        name.trim(),
                        if known.is_empty() {
                            "none".into()
                        } else {
                            known.join(", ")
                        }
                    ),
                );
                continue;
            };
            if given.iter().any(|(i, _)| *i == fi) {
                self.err(nspan, format!("field `{}` is given twice", name.trim()));
                continue;
            }
            let Some((expr, espan)) = self.rewrite_value(c, "expr", scope) else {
                continue;
            };
            let mut p = Element::new("param", c.span);
            p.set_attr_at("name", fields[fi].param_name(), nspan);
            p.set_attr_at("expr", expr, espan);
            typed_if_array(&mut p, &fields[fi]);
            given.push((fi, p));
        }
        let mut out: Vec<Element> = given.iter().map(|(_, p)| p.clone()).collect();
        for (i, f) in fields.iter().enumerate() {
            if !given.iter().any(|(g, _)| *g == i) {
                let mut p = Element::new("param", el.span)
                    .with_attr("name", f.param_name())
                    .with_attr("expr", f.default.clone());
                typed_if_array(&mut p, f);
                out.push(p);
            }
        }
        out
    }

    fn send(&self, span: Span, event: &str, target: &str, params: Vec<Element>) -> Element {
        let mut s = Element::new("send", span)
            .with_attr("event", event)
            .with_attr("target", target);
        for p in params {
            s.push(p);
        }
        s
    }

    fn param(span: Span, name: &str, expr: impl Into<String>) -> Element {
        Element::new("param", span)
            .with_attr("name", name)
            .with_attr("expr", expr)
    }

    fn unknown_alias(&mut self, el: &Element, what: &str) -> Vec<Node> {
        let name = el.attr_value("name").unwrap_or("").to_string();
        let span = el.attr("name").map(|a| a.value_span).unwrap_or(el.span);
        self.err(
            span,
            format!(
                "<{}> names `{name}`, which is not {what} declared in this machine",
                el.name
            ),
        );
        Vec::new()
    }

    /// The service `alias` names among `aliases` (a machine's service clients or servers,
    /// `role` saying which); `None` when it names none (reported) or the service's type was
    /// not found (reported where it is declared).
    fn service_named(
        &mut self,
        el: &Element,
        aliases: &[super::Alias],
        alias: &str,
        role: &str,
    ) -> Option<super::Service> {
        let Some(key) = find(aliases, alias) else {
            self.unknown_alias(el, role);
            return None;
        };
        self.services.iter().find(|s| s.key == key).cloned()
    }

    /// A request `el` to the `what` (service, action) that client `alias` names,
    /// which nothing serves: reported where the name is written (in a behavior
    /// tree, when a BT plugin read it from a port), naming the request.
    fn no_server(&mut self, el: &Element, what: &str, clients: &[super::Alias], alias: &str) {
        // The client was found before this is called; without it, the request's place.
        let (name, span) = match clients.iter().find(|a| a.alias == alias.trim()) {
            Some(a) => a.name.clone(),
            None => (alias.trim().to_string(), el.span),
        };
        let at = self.sm.diag(el.span, "");
        self.err(
            span,
            format!(
                "{what} `{name}` has no server (no node model declares a \
                 <ros_{what}_server> for it; requested by <{}> at {}:{}:{})",
                el.name, at.file, at.line, at.col
            ),
        );
    }

    /// One ROS tag inside a state or executable content.
    fn lower_ros(&mut self, el: &Element, u: &UnitCx, scope: &Scope) -> Vec<Node> {
        if !KNOWN_TAGS.contains(&el.name.as_str()) {
            self.err(
                el.span,
                format!(
                    "unsupported ROS tag <{}> (AS2FM's translation has no equivalent either, \
                     or it is not implemented yet)",
                    el.name
                ),
            );
            return Vec::new();
        }
        let Some((alias, _)) = self.attr_or_err(el, "name") else {
            return Vec::new();
        };
        let alias = alias.trim().to_string();
        let d = self.machines[u.machine].1.clone();
        let one = |e: Element| vec![Node::Element(e)];
        match el.name.as_str() {
            "ros_rate_callback" => {
                if !d.timers.iter().any(|t| t.0 == alias) {
                    return self.unknown_alias(el, "a timer (<ros_time_rate>)");
                }
                self.callback(el, u, scope, &format!("ros_time_rate.{alias}"), None)
            }
            "ros_topic_publish" => {
                let Some(a) = d.publishers.iter().find(|a| a.alias == alias) else {
                    return self.unknown_alias(el, "a topic publisher");
                };
                let key = a.key.clone();
                let Some((ty, fields)) = &a.msg else {
                    return Vec::new();
                };
                let what = format!("topic `{key}` ({ty})");
                let params = self.params(el, fields, &what, scope);
                // A targetless send, as `RosTopicPublish.as_plain_scxml`
                // (scxml_converter/ascxml_extensions/ros_entries/scxml_ros_topic.py) makes:
                // `super::route` gives it to every subscriber with a callback.
                let event = format!("topic_{key}_msg");
                one(self.send(el.span, &event, super::AUTO_TARGET, params))
            }
            "ros_topic_callback" => {
                let Some(a) = d.subscribers.iter().find(|a| a.alias == alias) else {
                    return self.unknown_alias(el, "a topic subscriber");
                };
                let key = a.key.clone();
                let Some((ty, fields)) = &a.msg else {
                    return Vec::new();
                };
                // `_msg` has the fields of the type this subscriber declared.
                let what = format!("topic `{key}` ({ty})");
                let sc = Scope {
                    fields: vec![("_msg", fields, what)],
                    ..Scope::default()
                };
                self.callback(el, u, &sc, &format!("topic_{key}_msg"), None)
            }
            "ros_service_send_request" => {
                let Some(s) = self.service_named(el, &d.srv_clients, &alias, "a service client")
                else {
                    return Vec::new();
                };
                let key = s.key.clone();
                if s.server.is_none() {
                    self.no_server(el, "service", &d.srv_clients, &alias);
                }
                let params = self.params(
                    el,
                    &s.fields.request,
                    &format!("the request of `{}`", s.ty),
                    scope,
                );
                one(self.send(
                    el.span,
                    &format!("srv_{key}_req_client_{}", u.name),
                    &format!("srv_handler_{key}"),
                    params,
                ))
            }
            "ros_service_handle_response" | "ros_service_handle_request" => {
                // A client's callback on its response, or the server's on a request.
                let response = el.name == "ros_service_handle_response";
                let (aliases, role) = if response {
                    (&d.srv_clients, "a service client")
                } else {
                    (&d.srv_servers, "a service server")
                };
                let Some(s) = self.service_named(el, aliases, &alias, role) else {
                    return Vec::new();
                };
                let key = &s.key;
                let (var, part, fields, event) = if response {
                    let event = format!("srv_{key}_response_client_{}", u.name);
                    ("_res", "response", &s.fields.response, event)
                } else {
                    (
                        "_req",
                        "request",
                        &s.fields.request,
                        format!("srv_{key}_request"),
                    )
                };
                let what = format!("the {part} of `{}`", s.ty);
                let sc = Scope {
                    fields: vec![(var, fields, what)],
                    ..Scope::default()
                };
                self.callback(el, u, &sc, &event, None)
            }
            "ros_service_send_response" => {
                let Some(s) = self.service_named(el, &d.srv_servers, &alias, "a service server")
                else {
                    return Vec::new();
                };
                let key = s.key.clone();
                let params = self.params(
                    el,
                    &s.fields.response,
                    &format!("the response of `{}`", s.ty),
                    scope,
                );
                one(self.send(
                    el.span,
                    &format!("srv_{key}_response"),
                    &format!("srv_handler_{key}"),
                    params,
                ))
            }
            _ => self.lower_action(el, u, scope, &alias, &d),
        }
    }

    fn lower_action(
        &mut self,
        el: &Element,
        u: &UnitCx,
        scope: &Scope,
        alias: &str,
        d: &super::Decls,
    ) -> Vec<Node> {
        let one = |e: Element| vec![Node::Element(e)];
        let client = matches!(
            el.name.as_str(),
            "ros_action_send_goal"
                | "ros_action_handle_goal_response"
                | "ros_action_handle_feedback"
                | "ros_action_handle_success_result"
                | "ros_action_handle_aborted_result"
                | "ros_action_handle_canceled_result"
        );
        let server = matches!(
            el.name.as_str(),
            "ros_action_handle_goal"
                | "ros_action_accept_goal"
                | "ros_action_reject_goal"
                | "ros_action_start_thread"
                | "ros_action_handle_thread_free"
                | "ros_action_thread_free"
                | "ros_action_handle_thread_start"
                | "ros_action_feedback"
                | "ros_action_succeed"
                | "ros_action_aborted"
                | "ros_action_canceled"
        );
        if !client && !server {
            self.err(
                el.span,
                format!("unsupported ROS tag <{}> (AS2FM's translation has no equivalent either, or it is not implemented yet)", el.name),
            );
            return Vec::new();
        }
        let key = if client {
            find(&d.act_clients, alias)
        } else {
            find(&d.act_servers, alias)
        };
        let Some(key) = key.map(String::from) else {
            return self.unknown_alias(
                el,
                if client {
                    "an action client"
                } else {
                    "an action server"
                },
            );
        };
        let Some(a) = self.actions.iter().find(|a| a.key == key).cloned() else {
            return Vec::new();
        };
        let handler = format!("action_handler_{key}");
        let server_name = a.server.clone().unwrap_or_else(|| "NONE".into());
        let goal_what = format!("the goal of `{}`", a.ty);
        let fb_what = format!("the feedback of `{}`", a.ty);
        let res_what = format!("the result of `{}`", a.ty);
        let ev = |s: &str| format!("action_{key}_{s}");
        let cl = |s: &str| format!("action_{key}_{s}_client_{}", u.name);
        let goal_id = |this: &mut Self| -> Option<(String, Span)> {
            this.rewrite_value(el, "goal_id", scope)
        };
        match el.name.as_str() {
            "ros_action_send_goal" => {
                if a.server.is_none() {
                    self.no_server(el, "action", &d.act_clients, alias);
                }
                let params = self.params(el, &a.fields.goal, &goal_what, scope);
                one(self.send(el.span, &cl("goal_req"), &handler, params))
            }
            "ros_action_handle_goal_response" => {
                let mut out = Vec::new();
                for (attr, what) in [("accept", "goal_accept"), ("reject", "goal_reject")] {
                    let Some((target, tspan)) = self.attr_or_err(el, attr) else {
                        continue;
                    };
                    let mut t = Element::new("transition", el.span).with_attr("event", cl(what));
                    t.set_attr_at("target", target, tspan);
                    out.push(Node::Element(t));
                }
                out
            }
            "ros_action_handle_feedback" => {
                let sc = Scope {
                    fields: vec![("_feedback", &a.fields.feedback, fb_what)],
                    ..Scope::default()
                };
                self.callback(el, u, &sc, &cl("feedback_handle"), None)
            }
            "ros_action_handle_success_result"
            | "ros_action_handle_aborted_result"
            | "ros_action_handle_canceled_result" => {
                let code = match el.name.as_str() {
                    "ros_action_handle_success_result" => 4,
                    "ros_action_handle_canceled_result" => 5,
                    _ => 6,
                };
                let sc = Scope {
                    result: Some((&a.fields.result, res_what)),
                    ..Scope::default()
                };
                self.callback(
                    el,
                    u,
                    &sc,
                    &cl("result_handle"),
                    Some(format!("_event.data.code == {code}")),
                )
            }
            "ros_action_handle_goal" => {
                let sc = Scope {
                    fields: vec![("_goal", &a.fields.goal, goal_what)],
                    action: true,
                    ..Scope::default()
                };
                self.callback(el, u, &sc, &ev("goal_handle"), None)
            }
            "ros_action_handle_thread_start" => {
                let Some((_, tid)) = u.thread.clone().filter(|(k, _)| *k == key) else {
                    self.err(el.span, "<ros_action_handle_thread_start> must be inside the action's <ros_action_thread>");
                    return Vec::new();
                };
                let sc = Scope {
                    fields: vec![("_goal", &a.fields.goal, goal_what)],
                    action: true,
                    ..Scope::default()
                };
                self.callback(
                    el,
                    u,
                    &sc,
                    &ev("thread_start"),
                    Some(format!("_event.data.thread_id == {tid}")),
                )
            }
            "ros_action_handle_thread_free" => {
                self.callback(el, u, scope, &ev("thread_free"), None)
            }
            "ros_action_thread_free" => {
                let Some((_, tid)) = u.thread.clone().filter(|(k, _)| *k == key) else {
                    self.err(
                        el.span,
                        "<ros_action_thread_free> must be inside the action's <ros_action_thread>",
                    );
                    return Vec::new();
                };
                one(self.send(
                    el.span,
                    &ev("thread_free"),
                    &server_name,
                    vec![Self::param(el.span, "thread_id", tid.to_string())],
                ))
            }
            "ros_action_accept_goal" | "ros_action_reject_goal" => {
                let Some((g, gspan)) = goal_id(self) else {
                    return Vec::new();
                };
                let what = if el.name == "ros_action_accept_goal" {
                    "goal_accepted"
                } else {
                    "goal_rejected"
                };
                let mut p = Element::new("param", el.span).with_attr("name", "goal_id");
                p.set_attr_at("expr", g, gspan);
                one(self.send(el.span, &ev(what), &handler, vec![p]))
            }
            "ros_action_start_thread" => {
                let Some((g, _)) = goal_id(self) else {
                    return Vec::new();
                };
                let Some((tid, _)) = self.rewrite_value(el, "thread_id", scope) else {
                    return Vec::new();
                };
                let fields = self.params(el, &a.fields.goal, &goal_what, scope);
                if a.threads.is_empty() {
                    self.err(
                        el.span,
                        format!("action `{key}` has no <ros_action_thread> to start"),
                    );
                }
                // AS2FM sends `thread_start` without a target and gives it to every thread
                // from a `set` (see `super::route`), so no order is its rule; the threads
                // from last to first is the order of the corpus translations, whose runs
                // `robot_ros.rs` compares with ours seed by seed.
                a.threads
                    .iter()
                    .rev()
                    .map(|t| {
                        let mut ps = fields.clone();
                        ps.push(Self::param(el.span, "goal_id", g.clone()));
                        ps.push(Self::param(el.span, "thread_id", tid.clone()));
                        Node::Element(self.send(el.span, &ev("thread_start"), t, ps))
                    })
                    .collect()
            }
            "ros_action_feedback" => {
                let Some((g, _)) = goal_id(self) else {
                    return Vec::new();
                };
                let mut ps = self.params(el, &a.fields.feedback, &fb_what, scope);
                ps.push(Self::param(el.span, "goal_id", g));
                one(self.send(el.span, &ev("feedback"), &handler, ps))
            }
            _ => {
                // ros_action_succeed / ros_action_aborted / ros_action_canceled
                let code = match el.name.as_str() {
                    "ros_action_succeed" => 4,
                    "ros_action_canceled" => 5,
                    _ => 6,
                };
                let Some((g, _)) = goal_id(self) else {
                    return Vec::new();
                };
                let mut ps = self.params(el, &a.fields.result, &res_what, scope);
                ps.push(Self::param(el.span, "goal_id", g));
                ps.push(Self::param(el.span, "code", code.to_string()));
                one(self.send(el.span, &ev("result"), &handler, ps))
            }
        }
    }
}

/// Gives an array field's `<param>` the interface's type: an array's element type need
/// not follow from its value (`[]`).
fn typed_if_array(param: &mut Element, field: &FlatField) {
    if field.scxml_type.ends_with(']') {
        param.set_attr("type", field.scxml_type.clone());
    }
}
