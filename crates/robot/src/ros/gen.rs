//! The machines the translation adds: service handlers, action handlers and the global timer.
//!
//! Each follows the function of AS2FM's converter that generates it (cited beside the code);
//! like AS2FM's, their sends carry no target until `super::route` gives every send of an
//! event to the machines with a transition on it (`NONE` when there is none).

use super::{gcd, Cx, AUTO_TARGET};
use crate::model::source::Span;
use crate::model::xml::Element;
use crate::types::FlatField;

fn data(span: Span, id: &str, ty: &str, expr: &str) -> Element {
    Element::new("data", span)
        .with_attr("id", id)
        .with_attr("type", ty)
        .with_attr("expr", expr)
}

fn assign(span: Span, location: &str, expr: &str) -> Element {
    Element::new("assign", span)
        .with_attr("location", location)
        .with_attr("expr", expr)
}

fn send(span: Span, event: &str, target: &str) -> Element {
    Element::new("send", span)
        .with_attr("event", event)
        .with_attr("target", target)
}

fn param(span: Span, name: &str, expr: &str) -> Element {
    Element::new("param", span)
        .with_attr("name", name)
        .with_attr("expr", expr)
}

fn transition(span: Span, event: &str, target: &str) -> Element {
    Element::new("transition", span)
        .with_attr("event", event)
        .with_attr("target", target)
}

fn machine(span: Span, name: &str, initial: &str) -> Element {
    Element::new("scxml", span)
        .with_attr("name", name)
        .with_attr("version", "1.0")
        .with_attr("model_src", "")
        .with_attr("initial", initial)
        .with_attr("xmlns", "http://www.w3.org/2005/07/scxml")
}

/// Copies every field of the event into the handler's variables.
fn take_fields(t: &mut Element, span: Span, fields: &[FlatField]) {
    for f in fields {
        let p = f.param_name();
        t.push(assign(span, &p, &format!("_event.data.{p}")));
    }
}

/// Passes the handler's copies of `fields` on as parameters.
fn forward(s: &mut Element, span: Span, fields: &[FlatField]) {
    for f in fields {
        let p = f.param_name();
        s.push(param(span, &p, &p));
    }
}

/// A datamodel with one variable per distinct field, then `extra`.
///
/// AS2FM joins the groups with Python's dict union (`req_params | res_params` in
/// `RosServiceHandler.to_scxml`, `goal | feedback | result` in `RosActionHandler.to_scxml`):
/// a field in two groups keeps the place of its first and the type of its last.
fn datamodel(span: Span, groups: &[&[FlatField]], extra: &[(&str, &str, &str)]) -> Element {
    let mut dm = Element::new("datamodel", span);
    let mut vars: Vec<(String, &FlatField)> = Vec::new();
    for f in groups.iter().flat_map(|g| g.iter()) {
        let p = f.param_name();
        match vars.iter_mut().find(|(n, _)| *n == p) {
            Some(v) => v.1 = f,
            None => vars.push((p, f)),
        }
    }
    for (p, f) in &vars {
        dm.push(data(span, p, &f.scxml_type, &f.default));
    }
    for (id, ty, expr) in extra {
        dm.push(data(span, id, ty, expr));
    }
    dm
}

/// `if goal_id == 0 {..} elseif goal_id == 1 {..}` over the clients.
fn per_client(
    span: Span,
    clients: &[String],
    mut body: impl FnMut(&str) -> Vec<Element>,
) -> Option<Element> {
    let mut iff: Option<Element> = None;
    for (i, c) in clients.iter().enumerate() {
        let cond = format!("goal_id == {i}");
        match &mut iff {
            None => iff = Some(Element::new("if", span).with_attr("cond", cond)),
            Some(e) => e.push(Element::new("elseif", span).with_attr("cond", cond)),
        }
        if let Some(e) = &mut iff {
            for b in body(c) {
                e.push(b);
            }
        }
    }
    iff
}

impl Cx<'_> {
    /// `srv_handler_<s>` for every service with a server: one request at a time.
    ///
    /// As `RosServiceHandler.to_scxml` (jani_generator/ros_helpers/ros_service_handler.py):
    /// a datamodel of the request's then the response's fields; state `waiting` with one
    /// transition per client, in the order the clients were collected, to
    /// `processing_client_<c>` (copy the request, forward it to the server); then one
    /// `processing_client_<c>` state per client whose only transition takes the server's
    /// response back to `waiting` and passes it on to that client.
    pub(super) fn service_handlers(&mut self) -> Vec<Element> {
        let mut out = Vec::new();
        for s in &self.services {
            if s.server.is_none() {
                continue;
            }
            let span = s.server_span;
            let key = &s.key;
            let (req, res) = (&s.fields.request, &s.fields.response);
            let mut m = machine(span, &format!("srv_handler_{key}"), "waiting");
            let dm = datamodel(span, &[req, res], &[]);
            if !dm.children.is_empty() {
                m.push(dm);
            }
            let mut waiting = Element::new("state", span).with_attr("id", "waiting");
            let mut busy = Vec::new();
            for c in &s.clients {
                let mut t = transition(
                    span,
                    &format!("srv_{key}_req_client_{c}"),
                    &format!("processing_client_{c}"),
                );
                take_fields(&mut t, span, req);
                let mut fwd = send(span, &format!("srv_{key}_request"), AUTO_TARGET);
                forward(&mut fwd, span, req);
                t.push(fwd);
                waiting.push(t);
                let mut st =
                    Element::new("state", span).with_attr("id", format!("processing_client_{c}"));
                let mut t = transition(span, &format!("srv_{key}_response"), "waiting");
                take_fields(&mut t, span, res);
                let mut back = send(span, &format!("srv_{key}_response_client_{c}"), AUTO_TARGET);
                forward(&mut back, span, res);
                t.push(back);
                st.push(t);
                busy.push(st);
            }
            m.push(waiting);
            for st in busy {
                m.push(st);
            }
            out.push(m);
        }
        out
    }

    /// `action_handler_<a>` for every action with a server; goal ids are client indices.
    ///
    /// As `RosActionHandler.to_scxml` (jani_generator/ros_helpers/ros_action_handler.py):
    /// goal id `i` is the `i`-th client collected; a datamodel of the goal's, feedback's and
    /// result's fields, then `goal_id` and `code`; state `waiting` with one goal-request
    /// transition per client, then feedback, then result; state `goal_requested` with
    /// accepted, then rejected. Each answer copies `code` (results) and `goal_id`, then
    /// the fields (`_generate_srv_event_transition`), and one `if`/`elseif` on the goal id
    /// picks the client.
    pub(super) fn action_handlers(&mut self) -> Vec<Element> {
        let mut out = Vec::new();
        for a in &self.actions {
            if a.server.is_none() {
                continue;
            }
            let span = a.server_span;
            let key = &a.key;
            let f = &a.fields;
            let ev = |s: &str| format!("action_{key}_{s}");
            let cl = |s: &str, c: &str| format!("action_{key}_{s}_client_{c}");
            let mut m = machine(span, &format!("action_handler_{key}"), "waiting");
            m.push(datamodel(
                span,
                &[&f.goal, &f.feedback, &f.result],
                &[("goal_id", "int32", "0"), ("code", "int32", "0")],
            ));
            let mut waiting = Element::new("state", span).with_attr("id", "waiting");
            for (i, c) in a.clients.iter().enumerate() {
                let mut t = transition(span, &cl("goal_req", c), "goal_requested");
                take_fields(&mut t, span, &f.goal);
                let mut s = send(span, &ev("goal_handle"), AUTO_TARGET);
                s.push(param(span, "goal_id", &i.to_string()));
                forward(&mut s, span, &f.goal);
                t.push(s);
                waiting.push(t);
            }
            let mut t = transition(span, &ev("feedback"), "waiting");
            t.push(assign(span, "goal_id", "_event.data.goal_id"));
            take_fields(&mut t, span, &f.feedback);
            if let Some(iff) = per_client(span, &a.clients, |c| {
                let mut s = send(span, &cl("feedback_handle", c), AUTO_TARGET);
                forward(&mut s, span, &f.feedback);
                vec![s]
            }) {
                t.push(iff);
            }
            waiting.push(t);
            let mut t = transition(span, &ev("result"), "waiting");
            t.push(assign(span, "code", "_event.data.code"));
            t.push(assign(span, "goal_id", "_event.data.goal_id"));
            take_fields(&mut t, span, &f.result);
            if let Some(iff) = per_client(span, &a.clients, |c| {
                let mut s = send(span, &cl("result_handle", c), AUTO_TARGET);
                s.push(param(span, "code", "code"));
                forward(&mut s, span, &f.result);
                vec![s]
            }) {
                t.push(iff);
            }
            waiting.push(t);
            m.push(waiting);
            let mut requested = Element::new("state", span).with_attr("id", "goal_requested");
            for (what, to) in [
                ("goal_accepted", "goal_accept"),
                ("goal_rejected", "goal_reject"),
            ] {
                let mut t = transition(span, &ev(what), "waiting");
                t.push(assign(span, "goal_id", "_event.data.goal_id"));
                if let Some(iff) = per_client(span, &a.clients, |c| {
                    vec![send(span, &cl(to, c), AUTO_TARGET)]
                }) {
                    t.push(iff);
                }
                requested.push(t);
            }
            m.push(requested);
            out.push(m);
        }
        out
    }

    /// The global timer (when any timer exists) and the nanoseconds in one time unit.
    ///
    /// As `make_global_timer_scxml` (jani_generator/ros_helpers/ros_timer.py): state `idle`
    /// sends itself `global_timer_tick_event` one time unit later on entry; its first
    /// transition (while `current_time < max_time`) adds the step, publishes `clock`, then
    /// has one `if` per timer, in the order the timers were collected, each sending the
    /// timer's `ros_time_rate.<name>`; its second goes to `timeout`. The timers are
    /// collected in declaration order over the machines in the order
    /// `generate_plain_scxml_models_and_timers` (jani_generator/scxml_helpers/
    /// top_level_interpreter.py) converts them: the node models in main-file order, then
    /// the behavior tree's root and plugins. So the tree's tick comes after every node
    /// model's timer of the same instant.
    ///
    /// `delays_ns` are the node models' `<send delay>`s written as durations (AS2FM drops
    /// them; hindsight waits for them, `crates/robot/src/load.rs`): they count as periods
    /// for the unit, so that each is a whole number of steps, but start no timer.
    pub(super) fn global_timer(
        &mut self,
        max_time_ns: u64,
        delays_ns: &[u64],
    ) -> (Option<Element>, u64) {
        let periods: Vec<u64> = self.timers.iter().map(|t| t.period_ns).collect();
        let lengths = || periods.iter().chain(delays_ns.iter().filter(|&&d| d > 0));
        // The coarsest of s, ms, us, ns in which every period, delay and max_time are whole.
        let unit = [1_000_000_000u64, 1_000_000, 1_000, 1]
            .into_iter()
            .find(|u| lengths().chain([&max_time_ns]).all(|p| p % u == 0))
            .unwrap_or(1);
        let step = lengths().fold(0, |g, p| gcd(g, *p / unit));
        let Some(first) = self.timers.first() else {
            return (None, unit);
        };
        let span = first.span;
        let name = super::GLOBAL_TIMER;
        let mut m = machine(span, name, "idle");
        m.push(Element::new("datamodel", span).with_child(data(
            span,
            "current_time",
            "int64",
            "0",
        )));
        let mut idle = Element::new("state", span).with_attr("id", "idle");
        idle.push(
            Element::new("onentry", span)
                .with_child(send(span, "global_timer_tick_event", name).with_attr("delay", "1")),
        );
        let mut tick = transition(span, "global_timer_tick_event", "idle");
        tick.set_attr("cond", format!("current_time < {}", max_time_ns / unit));
        tick.push(assign(
            span,
            "current_time",
            &format!("current_time + {step}"),
        ));
        let per_sec = 1_000_000_000 / unit;
        let (sec, nanosec) = if per_sec == 1 {
            ("current_time".to_string(), "0".to_string())
        } else {
            (
                format!("Math.floor(current_time / {per_sec})"),
                format!("current_time % {per_sec} * {unit}"),
            )
        };
        tick.push(
            send(span, "topic_clock_msg", AUTO_TARGET)
                .with_child(param(span, "ros_fields__sec", &sec))
                .with_child(param(span, "ros_fields__nanosec", &nanosec)),
        );
        for t in &self.timers {
            tick.push(
                Element::new("if", t.span)
                    .with_attr(
                        "cond",
                        format!("current_time % {} == 0", t.period_ns / unit),
                    )
                    .with_child(send(
                        t.span,
                        &format!("ros_time_rate.{}", t.name),
                        AUTO_TARGET,
                    )),
            );
        }
        idle.push(tick);
        idle.push(transition(span, "global_timer_tick_event", "timeout"));
        m.push(idle);
        m.push(Element::new("state", span).with_attr("id", "timeout"));
        (Some(m), step * unit)
    }
}
