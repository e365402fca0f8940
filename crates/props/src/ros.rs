//! Property files written against ROS names: `<ros_topic>` / `<ros_service>` ports and
//! specification patterns (`pattern="response" ... within time_unit`).
//!
//! A ROS port observes the message that AS2FM's translation (and ours) sends for the
//! ROS communication, whichever machines send and receive it:
//!
//! | port | observed message |
//! |---|---|
//! | `<ros_topic topic="/a/b">` (or `topic_name`) | `topic_a__b_msg`, every publication |
//! | `<ros_service service_name="/s" event="request">` | `srv_s_request`, the server receiving a request |
//! | `<ros_service service_name="/s" event="response">` | `srv_s_response`, the server answering |
//!
//! A `<state_var id type field expr>` takes the message field `field` (`a.b` for nested
//! fields: parameter `ros_fields__a__b`); an `<event_var id>` is true at each message.
//!
//! Patterns become Past-MTL formulas judged at the end of a run (every formula starts
//! with `H`, or is `P` for existence). With `e`, `r`, `q` the atoms of the attributes:
//!
//! | pattern | formula |
//! |---|---|
//! | `absence event=e` | `H !e` |
//! | `absence event=e before=q` | `H(e -> P q)`: no `e` until the first `q` |
//! | `absence event=e after=q` | `H(e -> !P q)`: no `e` from the first `q` on |
//! | `existence event=e` (or `<event>` child) | `P e` |
//! | `universality event=e` | `H e` |
//! | `precedence event=e after=q` | `H(e -> P q)`: every `e` has a `q` before (or with) it |
//! | `response event=q response=r [within=w]` | `H !((!r) S[w:] (q && !r))`: every `q` is answered by `r` within `w` (without `within`, by the end of the run) |
//! | `recurrence event=e within=w` | `H(P[w:] true -> P[:w] e)`: `e` at least every `w` |
//!
//! `within` is a number in `time_unit` (`s`, `ms`, `us`, `ns`; default `s`) and is
//! converted exactly to the model's time unit when the formulas are compiled.

use super::error::PropsErrorKind;
use super::read::FileReader;
use super::source::{Location, SourceText};
use super::{Port, Property, ANY};
use crate::model::xml::Element;

/// The message name of a ROS topic in the translated model: `/a/b` -> `topic_a__b_msg`.
pub fn topic_event(topic: &str) -> String {
    format!("topic_{}_msg", ros_name(topic))
}

/// The message name of a service request or response as the server sees it.
pub fn service_event(service: &str, response: bool) -> String {
    let part = if response { "response" } else { "request" };
    format!("srv_{}_{part}", ros_name(service))
}

/// The message name of a client's request to a service's handler (`response` false), or of
/// the handler's answer to that client: `srv_<s>_req_client_<c>`, `srv_<s>_response_client_<c>`.
pub fn service_client_event(service: &str, client: &str, response: bool) -> String {
    let part = if response { "response" } else { "req" };
    format!("srv_{}_{part}_client_{client}", ros_name(service))
}

/// An action's message `part` (`goal_handle`, `goal_accepted`, `feedback`, `result`, ...):
/// `action_<a>_<part>`.
pub fn action_event(action: &str, part: &str) -> String {
    format!("action_{}_{part}", ros_name(action))
}

/// A ROS name as AS2FM spells it inside event names: no leading `/`, `/` -> `__`.
fn ros_name(name: &str) -> String {
    name.trim_start_matches('/').replace('/', "__")
}

/// The QoS attributes of a `<ros_topic>` port and their values: ROS 2's own names, those
/// of rclcpp's QoS overrides (`qos_overrides./topic.subscription.reliability`; ROS 2
/// design article "ROS 2 QoS configurability") and of `ros2 bag record
/// --qos-profile-overrides-path`. `depth` takes a count (no list). AS2FM's ports name no
/// QoS; a port without them reads with ROS 2's default (reliable, volatile, keep last 10).
pub const QOS_SETTINGS: [(&str, &[&str]); 4] = [
    (
        "reliability",
        &["reliable", "best_effort", "system_default"],
    ),
    (
        "durability",
        &["volatile", "transient_local", "system_default"],
    ),
    ("history", &["keep_last", "keep_all", "system_default"]),
    ("depth", &[]),
];

impl<'a> FileReader<'_, 'a> {
    /// `<ros_topic topic|topic_name type [event="publish"] [reliability durability history
    /// depth]>` with its variables; the QoS attributes are ROS 2's names for them (see
    /// [`QOS_SETTINGS`]).
    pub(super) fn ros_topic(&mut self, element: &Element, ports: &mut Vec<Port>) {
        self.check_attrs(
            element,
            &[
                "topic",
                "topic_name",
                "type",
                "event",
                "reliability",
                "durability",
                "history",
                "depth",
            ],
        );
        let name = match (
            Self::attr(element, "topic").is_some(),
            Self::attr(element, "topic_name").is_some(),
        ) {
            (_, false) => self.required_name(element, "topic"),
            (false, true) => self.required_name(element, "topic_name"),
            (true, true) => {
                self.error(
                    self.at(element.span),
                    PropsErrorKind::BadValue {
                        attribute: "topic_name".to_owned(),
                        value: String::new(),
                        expected: "either `topic` or `topic_name`, not both".to_owned(),
                    },
                );
                None
            }
        };
        let qos = self.ros_qos(element);
        self.ros_type(element, false, qos);
        if let Some((event, at)) = self.optional(element, "event") {
            if event.as_str() != "publish" {
                self.bad_value(at, "event", event.as_str(), "\"publish\"");
            }
        }
        if let Some(name) = name {
            self.ros_variables(element, &topic_event(&name), ports);
        }
    }

    /// `<ros_service service_name type event="request|response">` with its variables.
    pub(super) fn ros_service(&mut self, element: &Element, ports: &mut Vec<Port>) {
        self.check_attrs(element, &["service_name", "type", "event"]);
        let name = self.required_name(element, "service_name");
        self.ros_type(element, true, Vec::new());
        let response = match self.required(element, "event") {
            Some((event, _)) if event.as_str() == "request" => Some(false),
            Some((event, _)) if event.as_str() == "response" => Some(true),
            Some((event, at)) => {
                self.bad_value(at, "event", event.as_str(), "\"request\" or \"response\"");
                None
            }
            None => None,
        };
        if let (Some(name), Some(response)) = (name, response) {
            self.ros_variables(element, &service_event(&name, response), ports);
        }
    }

    /// The port's `type`, kept to be checked against the model's interfaces, with the
    /// QoS it names.
    fn ros_type(&mut self, element: &Element, service: bool, qos: Vec<(String, String)>) {
        if let Some(type_name) = self.required_name(element, "type") {
            if let Some((_, at)) = self.optional(element, "type") {
                self.ros_types.push(super::RosTypeUse {
                    type_name,
                    service,
                    at,
                    qos,
                });
            }
        }
    }

    /// The QoS attributes of a `<ros_topic>`, checked, in [`QOS_SETTINGS`] order.
    fn ros_qos(&mut self, element: &Element) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (key, values) in QOS_SETTINGS {
            let Some((value, at)) = self.optional(element, key) else {
                continue;
            };
            let v = value.as_str();
            let ok = if values.is_empty() {
                v.parse::<u32>().is_ok_and(|d| (1..=1 << 20).contains(&d))
            } else {
                values.contains(&v)
            };
            if ok {
                out.push((key.to_string(), v.to_string()));
            } else {
                let expected = if values.is_empty() {
                    "a count of samples from 1 to 1048576".to_string()
                } else {
                    values
                        .iter()
                        .map(|x| format!("\"{x}\""))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                self.bad_value(at, key, v, &expected);
            }
        }
        out
    }

    /// The `<state_var id type field expr>` and `<event_var id>` children of a ROS port.
    fn ros_variables(&mut self, element: &Element, event: &str, ports: &mut Vec<Port>) {
        for var in element.elements() {
            let Some(kind) = self.port_variable(element, var, "field", |field| {
                format!("ros_fields__{}", field.replace('.', "__"))
            }) else {
                continue;
            };
            if let (Some(id), Some(kind)) = (self.required_id(var), kind) {
                ports.push(Port {
                    id,
                    kind,
                    event: event.to_owned(),
                    origin: ANY.to_owned(),
                    target: ANY.to_owned(),
                    at: self.at(var.span),
                });
            }
        }
    }

    fn bad_value(&mut self, at: Location, attribute: &str, value: &str, expected: &str) {
        self.error(
            at,
            PropsErrorKind::BadValue {
                attribute: attribute.to_owned(),
                value: value.to_owned(),
                expected: expected.to_owned(),
            },
        );
    }

    /// `<property id pattern=...>`: a specification pattern turned into a formula.
    pub(super) fn pattern_property(&mut self, element: &Element) -> Option<Property> {
        self.check_attrs(
            element,
            &[
                "id",
                "pattern",
                "variant",
                "event",
                "response",
                "before",
                "after",
                "within",
                "time_unit",
            ],
        );
        let id = self.required_id(element);
        let (pattern, pattern_at) = self.required(element, "pattern")?;
        // The condition may be an attribute or an `<event>` child; a `<scope>` child
        // may say `globally`.
        let mut event = self.optional(element, "event").map(|(v, _)| v);
        for child in element.elements() {
            match child.name.as_str() {
                "event" if event.is_none() => {
                    self.check_attrs_allow_text(child, &[]);
                    event = self.element_text(child);
                }
                "scope" => {
                    self.check_attrs(child, &["type"]);
                    if let Some((scope, at)) = self.required(child, "type") {
                        if scope.as_str() != "globally" {
                            self.bad_value(at, "type", scope.as_str(), "\"globally\"");
                        }
                    }
                }
                _ => self.unknown_child(child, element, "<event> or <scope>"),
            }
        }
        let atom = |text: &SourceText| {
            let mut out = SourceText::generated("{", text.location(0));
            out.push_source(text);
            out.push_generated("}", text.location(text.as_str().len()));
            out
        };
        let attr = |reader: &mut Self, name: &'static str| {
            reader.optional(element, name).map(|(v, _)| atom(&v))
        };
        let (before, after, response) = (
            attr(self, "before"),
            attr(self, "after"),
            attr(self, "response"),
        );
        let within = self.within(element);
        let Some(event) = event.map(|e| atom(&e)) else {
            self.error(
                self.at(element.span),
                PropsErrorKind::MissingAttribute {
                    element: "property".to_owned(),
                    name: "event",
                },
            );
            return None;
        };
        let at = self.at(element.span);
        let mut f = SourceText::empty();
        let g = |f: &mut SourceText, s: &str| f.push_generated(s, at);
        let used_ok = match pattern.as_str() {
            "absence" => match (&before, &after) {
                (None, None) => {
                    g(&mut f, "H !");
                    f.push_source(&event);
                    true
                }
                (Some(q), None) | (None, Some(q)) => {
                    g(&mut f, "H(");
                    f.push_source(&event);
                    g(
                        &mut f,
                        if before.is_some() {
                            " -> P "
                        } else {
                            " -> !P "
                        },
                    );
                    f.push_source(q);
                    g(&mut f, ")");
                    true
                }
                (Some(_), Some(_)) => false,
            },
            "existence" => {
                g(&mut f, "P ");
                f.push_source(&event);
                before.is_none() && after.is_none()
            }
            "universality" => {
                g(&mut f, "H ");
                f.push_source(&event);
                before.is_none() && after.is_none()
            }
            "precedence" => match &after {
                Some(q) => {
                    g(&mut f, "H(");
                    f.push_source(&event);
                    g(&mut f, " -> P ");
                    f.push_source(q);
                    g(&mut f, ")");
                    before.is_none()
                }
                None => false,
            },
            "response" => match &response {
                Some(r) => {
                    let bound = within.as_ref().map_or(String::new(), |w| format!("[{w}:]"));
                    g(&mut f, "H !((!");
                    f.push_source(r);
                    g(&mut f, &format!(") S{bound} ("));
                    f.push_source(&event);
                    g(&mut f, " && !");
                    f.push_source(r);
                    g(&mut f, "))");
                    before.is_none() && after.is_none()
                }
                None => false,
            },
            "recurrence" => match &within {
                Some(w) => {
                    g(&mut f, &format!("H(P[{w}:] true -> P[:{w}] "));
                    f.push_source(&event);
                    g(&mut f, ")");
                    before.is_none() && after.is_none()
                }
                None => false,
            },
            other => {
                self.bad_value(
                    pattern_at,
                    "pattern",
                    other,
                    "one of absence, existence, universality, precedence, response, recurrence",
                );
                return None;
            }
        };
        if !used_ok {
            let expected = match pattern.as_str() {
                "absence" => "`event` and at most one of `before` / `after`",
                "precedence" => "`event` and `after` (the condition that must come first)",
                "response" => "`event` (the trigger), `response` and optionally `within`",
                "recurrence" => "`event` and `within`",
                _ => "`event` only",
            };
            self.bad_value(pattern_at, "pattern", pattern.as_str(), expected);
            return None;
        }
        Some(Property {
            id: id?,
            formula: f,
            at,
            converted: true,
        })
    }

    /// `within` with `time_unit` as a bound with a unit suffix (`6200ms`), or `None`.
    fn within(&mut self, element: &Element) -> Option<String> {
        let unit = match self.optional(element, "time_unit") {
            None => "s".to_owned(),
            Some((unit, at)) => {
                let u = unit.as_str();
                if codegen::duration::TimeUnit::from_suffix(u).is_none() {
                    let expected = format!("one of {}", codegen::duration::UNITS_TEXT);
                    self.bad_value(at, "time_unit", u, &expected);
                }
                u.to_owned()
            }
        };
        let (within, at) = self.optional(element, "within")?;
        let w = within.as_str().trim();
        let number = !w.is_empty()
            && w.chars().all(|c| c.is_ascii_digit() || c == '.')
            && w.chars().filter(|&c| c == '.').count() <= 1
            && !w.starts_with('.')
            && !w.ends_with('.');
        if !number {
            self.bad_value(at, "within", w, "a non-negative number");
            return None;
        }
        Some(format!("{w}{unit}"))
    }
}
