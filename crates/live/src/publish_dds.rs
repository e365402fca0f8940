//! `hindsight run --ros2`: a seeded run's ROS messages published on DDS with ROS 2's names,
//! types and CDR, so a ROS 2 node (or `hindsight monitor --ros2`) listens to the model as
//! to a robot.
//!
//! # What is published
//!
//! | model event | DDS topic | DDS type |
//! |---|---|---|
//! | `topic_<t>_msg` | `rt/<t>` | `pkg::msg::dds_::Type_` |
//! | `srv_<s>_request` (the server receives a request) | `rt/<s>/_service_event` | `pkg::srv::dds_::Name_Event_` |
//! | `srv_<s>_response` (the server answers) | `rt/<s>/_service_event` | `pkg::srv::dds_::Name_Event_` |
//!
//! A service is published as ROS 2's service introspection publishes it (rcl
//! `rcl_service_introspection`, the `service_msgs/msg/ServiceEventInfo` header): a
//! `REQUEST_RECEIVED` (1) event with the request in `request[0]`, a `RESPONSE_SENT` (2)
//! event with the response in `response[0]`, the same `sequence_number` for a request
//! and its answer, `stamp` the wall-clock time of the send. That is what `ros2 bag record
//! --all-services` keeps and what a property file's `<ros_service>` ports read.
//!
//! With `--external NODE`, the services NODE called are served to ROS 2 clients on their
//! request and reply topics ([`super::serve_dds`]).
//!
//! A message is the type's zeros ([`ros2::cdr_write::Val::zero`]) with every field the
//! model's event carries (AS2FM's `ros_fields__a__b` parameters: `a.b`) set from the
//! sent values: booleans, integers, floats, strings and arrays of them. A field of
//! a struct type is left at its zeros (one warning). Actions (goal, feedback, result) are
//! not published on DDS (one warning each): their DDS form (`rt/<a>/_action/...` with
//! goal ids and the action services) is not built.
//!
//! Writers use ROS 2's default QoS (reliable, volatile, keep last 10), or what `--qos
//! /topic=...` names for a topic: a slow or absent reader loses the oldest samples, it
//! never slows the run; a transient-local writer keeps its last `depth` samples for
//! readers that join later.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime};

use ros2::cdr_write::{encode, EncodeError, Val};
use ros2::dds::{DdsError, Participant, Qos, Writer};
use ros2::schema::{Definitions, Schema};

use super::pace::{ProgressReports, RunProgress};
use super::publish::{wire_name, WireKind};
use super::Clock;
use crate::expr::{Ty, Value};
use crate::sim::{CompiledModel, EventId, Flow, Inbox, Observer, SentMessage};

/// `service_msgs/msg/ServiceEventInfo` event types (rosidl, `service_msgs`).
const REQUEST_RECEIVED: i64 = 1;
const RESPONSE_SENT: i64 = 2;

/// What one model event is published as.
#[derive(Clone, Debug)]
pub struct Route {
    /// The model event.
    pub event: EventId,
    /// The ROS topic written (`/a/b`, or `/s/_service_event`).
    pub topic: String,
    /// Its ROS type (`std_msgs/msg/Int32`, `pkg/srv/Name_Event`).
    pub type_name: String,
    /// The type, resolved.
    pub schema: Schema,
    /// For a service event: its kind and the service (`/s`), for the sequence numbers.
    pub service: Option<(i64, String)>,
    /// `(parameter index, field path in the message)` of every field the event carries.
    pub fields: Vec<(usize, String)>,
}

/// The ROS type of a topic or service of the model, as its declarations write it
/// (`std_msgs/Int32`): what [`plan`] asks for each ROS message of the model.
pub trait RosTypes {
    /// The type of topic `topic` (`/a/b`).
    fn topic(&self, topic: &str) -> Option<String>;
    /// The type of service `service` (`/s`).
    fn service(&self, service: &str) -> Option<String>;
}

impl RosTypes for BTreeMap<String, String> {
    fn topic(&self, topic: &str) -> Option<String> {
        self.get(&format!("topic {topic}")).cloned()
    }
    fn service(&self, service: &str) -> Option<String> {
        self.get(&format!("service {service}")).cloned()
    }
}

/// The ROS types a robot model declares (`<ros_topic_publisher topic type>`, the
/// subscribers, service servers and clients) in its node models and behavior-tree
/// plugins, keyed `topic /a/b` and `service /s` (see [`RosTypes`]). A file that does not
/// read is skipped: loading the model already reported it.
pub(crate) fn declared_types(main: &crate::robot::main_file::MainFile) -> BTreeMap<String, String> {
    fn walk(el: &crate::model::xml::Element, out: &mut BTreeMap<String, String>) {
        let key = match el.name.as_str() {
            "ros_topic_publisher" | "ros_topic_subscriber" => el
                .attr_value("topic")
                .map(|t| format!("topic {}", t.trim())),
            "ros_service_server" | "ros_service_client" => el
                .attr_value("service_name")
                .map(|t| format!("service {}", t.trim())),
            _ => None,
        };
        if let (Some(k), Some(ty)) = (key, el.attr_value("type")) {
            out.entry(k).or_insert_with(|| ty.trim().to_string());
        }
        for c in el.elements() {
            walk(c, out);
        }
    }
    let mut out = BTreeMap::new();
    let mut sm = crate::model::SourceMap::new();
    let plugins = main.behavior_tree.iter().flat_map(|b| b.plugins.iter());
    for input in main.node_models.iter().chain(plugins) {
        let Ok(text) = codegen::diag::read_source(&input.path) else {
            continue;
        };
        let id = sm.add(input.path.clone(), text);
        if let Ok(root) = crate::model::xml::parse(&sm, id) {
            walk(&root, &mut out);
        }
    }
    out
}

/// `ros_fields__pose__x` -> `pose.x`; other parameters are not message fields.
pub(crate) fn field_path(param: &str) -> Option<String> {
    param
        .strip_prefix("ros_fields__")
        .map(|p| p.replace("__", "."))
}

/// The routes of every topic and service message of `model`, in event order, and a
/// warning for each message or field that is not published.
pub fn plan(
    model: &CompiledModel,
    types: &dyn RosTypes,
    defs: &dyn Definitions,
) -> (Vec<Route>, Vec<String>) {
    let mut routes = Vec::new();
    let mut warnings = Vec::new();
    for e in 0..model.event_count() {
        let event = EventId(e as u32);
        let Some((name, kind)) = wire_name(model.event_name(event)) else {
            continue;
        };
        let (topic, written, service, prefix) = match kind {
            WireKind::Topic => {
                let topic = format!("/{name}");
                let Some(ty) = types.topic(&topic) else {
                    warnings.push(format!(
                        "topic {topic}: its type is not declared; not published on DDS"
                    ));
                    continue;
                };
                let Ok((pkg, n)) = ros2::schema::split_type_name(&ty) else {
                    warnings.push(format!("topic {topic}: `{ty}` is not a ROS type name"));
                    continue;
                };
                (topic, format!("{pkg}/msg/{n}"), None, "")
            }
            WireKind::Request | WireKind::Response => {
                let (s, side, prefix) = match kind {
                    WireKind::Request => (
                        name.trim_end_matches("/request"),
                        REQUEST_RECEIVED,
                        "request[0].",
                    ),
                    _ => (
                        name.trim_end_matches("/response"),
                        RESPONSE_SENT,
                        "response[0].",
                    ),
                };
                let srv = format!("/{s}");
                let Some(ty) = types.service(&srv) else {
                    warnings.push(format!(
                        "service {srv}: its type is not declared; its events are not published on DDS"
                    ));
                    continue;
                };
                let Ok((pkg, n)) = ros2::schema::split_type_name(&ty) else {
                    warnings.push(format!("service {srv}: `{ty}` is not a ROS type name"));
                    continue;
                };
                (
                    format!("{srv}/_service_event"),
                    format!("{pkg}/srv/{n}_Event"),
                    Some((side, srv)),
                    prefix,
                )
            }
            other => {
                // One warning per action, at its goal.
                if other == WireKind::Goal {
                    warnings.push(format!(
                        "action /{}: actions are not published on DDS (only topics and service events)",
                        name.trim_end_matches("/goal")
                    ));
                }
                continue;
            }
        };
        let schema = match Schema::resolve(&written, defs) {
            Ok(s) => s,
            Err(m) => {
                warnings.push(format!("{topic}: {m}; not published on DDS"));
                continue;
            }
        };
        let mut fields = Vec::new();
        let zero = Val::zero(&schema, 0);
        for (i, (pname, ty)) in model.event_params(event).iter().enumerate() {
            let Some(path) = field_path(pname) else {
                continue;
            };
            if !publishable(ty) {
                warnings.push(format!(
                    "{topic}: field `{path}` ({ty:?}) is published as zeros on DDS \
                     (only booleans, numbers, strings and arrays of them are carried)"
                ));
                continue;
            }
            let path = format!("{prefix}{path}");
            let mut probe = zero.clone();
            match probe.set(&schema, &path, Val::Int(0)) {
                Ok(()) => fields.push((i, path)),
                Err(m) => warnings.push(format!("{topic}: {m}; the field is not published")),
            }
        }
        routes.push(Route {
            event,
            topic,
            type_name: written,
            schema,
            service,
            fields,
        });
    }
    (routes, warnings)
}

fn publishable(ty: &Ty) -> bool {
    match ty {
        Ty::Bool | Ty::Int | Ty::Float | Ty::Str => true,
        Ty::Array(e, _) => matches!(**e, Ty::Bool | Ty::Int | Ty::Float | Ty::Str),
        _ => false,
    }
}

/// The message of `schema` that `msg` sends: the type's zeros with each of `fields`
/// (`(parameter, field path)`) set from the message's parameter, and the last field
/// that could not be set.
pub(crate) fn message_val(
    model: &CompiledModel,
    msg: &SentMessage<'_>,
    schema: &Schema,
    fields: &[(usize, String)],
) -> (Val, Result<(), EncodeError>) {
    let mut v = Val::zero(schema, 0);
    let mut result = Ok(());
    for (param, path) in fields {
        if let Some(x) = msg.param(*param).and_then(|x| val(model, x)) {
            if let Err(e) = v.set(schema, path, x) {
                result = Err(e);
            }
        }
    }
    (v, result)
}

/// A model value as a message value.
fn val(model: &CompiledModel, v: Value<'_>) -> Option<Val> {
    Some(match v {
        Value::Bool(b) => Val::Bool(b),
        Value::Int(i) => Val::Int(i),
        Value::Float(x) => Val::Float(x),
        Value::Str(s) => Val::Str(model.strings().get(s).to_string()),
        Value::List(l) => Val::Seq(l.iter().map(|x| val(model, x)).collect::<Option<_>>()?),
    })
}

/// Publishes the routes' messages on DDS.
pub struct DdsPublisher {
    /// Kept alive for its writers.
    _participant: Participant,
    /// Per event id: the index into `routes`.
    by_event: Vec<Option<usize>>,
    routes: Vec<(Route, usize)>,
    /// One writer per DDS topic, with its ROS name.
    writers: Vec<(String, Writer)>,
    /// Per service: the sequence number of its last request.
    service_seq: BTreeMap<String, i64>,
    published: u64,
    failed: u64,
    last_error: Option<String>,
}

impl DdsPublisher {
    /// Joins `domain` and creates one writer per topic (a service's requests and
    /// responses share its `_service_event` writer), with the QoS `qos` names for its ROS
    /// topic, ROS 2's default for the others.
    pub fn new(
        domain: u16,
        model: &CompiledModel,
        routes: Vec<Route>,
        qos: &BTreeMap<String, Qos>,
    ) -> Result<DdsPublisher, DdsError> {
        let participant = Participant::new(domain)?;
        let mut writers: Vec<(String, Writer)> = Vec::new();
        let mut by_event = vec![None; model.event_count()];
        let mut out = Vec::new();
        for r in routes {
            let w = match writers.iter().position(|(t, _)| *t == r.topic) {
                Some(w) => w,
                None => {
                    writers.push((
                        r.topic.clone(),
                        participant.writer(
                            &r.topic,
                            &r.type_name,
                            qos.get(&r.topic).copied().unwrap_or_else(Qos::ros_default),
                        )?,
                    ));
                    writers.len() - 1
                }
            };
            by_event[r.event.0 as usize] = Some(out.len());
            out.push((r, w));
        }
        Ok(DdsPublisher {
            _participant: participant,
            by_event,
            routes: out,
            writers,
            service_seq: BTreeMap::new(),
            published: 0,
            failed: 0,
            last_error: None,
        })
    }

    /// The ROS topics written.
    pub fn topics(&self) -> impl Iterator<Item = &str> {
        self.writers.iter().map(|(t, _)| t.as_str())
    }

    /// The topics of `wanted` no reader is matched with yet (an unknown name is never
    /// matched).
    pub fn unmatched<'w>(&self, wanted: &'w [String]) -> Vec<&'w str> {
        wanted
            .iter()
            .filter(|t| {
                !self
                    .writers
                    .iter()
                    .any(|(n, w)| n == t.as_str() && w.matched() > 0)
            })
            .map(String::as_str)
            .collect()
    }

    /// Waits (up to `max_wait` per topic) until the matched readers acknowledged every
    /// sample: the last messages of a run reach them before the process ends.
    pub fn flush(&self, max_wait: Duration) {
        for (_, w) in &self.writers {
            w.wait_acked(max_wait);
        }
    }

    /// Samples published so far.
    pub fn published(&self) -> u64 {
        self.published
    }

    /// Samples that could not be published, and the last reason.
    pub fn failed(&self) -> (u64, Option<&str>) {
        (self.failed, self.last_error.as_deref())
    }

    /// Publishes `msg` if its event has a route.
    pub fn publish(&mut self, model: &CompiledModel, msg: &SentMessage<'_>) {
        let Some(Some(i)) = self.by_event.get(msg.event().0 as usize) else {
            return;
        };
        let (route, w) = &self.routes[*i];
        let (mut v, mut result) = message_val(model, msg, &route.schema, &route.fields);
        if let Some((kind, service)) = &route.service {
            let seq = self.service_seq.entry(service.clone()).or_insert(0);
            if *kind == REQUEST_RECEIVED {
                *seq += 1;
            }
            let now = SystemTime::now()
                .duration_since(SystemTime::UNIX_EPOCH)
                .unwrap_or_default();
            for (path, x) in [
                ("info.event_type", Val::Int(*kind)),
                ("info.stamp.sec", Val::Int(now.as_secs() as i64)),
                (
                    "info.stamp.nanosec",
                    Val::Int(i64::from(now.subsec_nanos())),
                ),
                ("info.sequence_number", Val::Int(*seq)),
            ] {
                if let Err(e) = v.set(&route.schema, path, x) {
                    result = Err(e);
                }
            }
        }
        let result = result
            .and_then(|()| encode(&route.schema, &v))
            .map_err(|e| e.to_string())
            .and_then(|bytes| self.writers[*w].1.write(&bytes).map_err(|e| e.to_string()));
        match result {
            Ok(()) => self.published += 1,
            Err(e) => {
                self.failed += 1;
                self.last_error = Some(format!("{}: {e}", route.topic));
            }
        }
    }
}

/// `hindsight run --ros2`'s observer: paces the run on the wall clock and publishes every
/// routed message on DDS.
pub struct DdsPaced<'m> {
    /// The model (for its strings).
    pub model: &'m CompiledModel,
    /// The DDS writers.
    pub publisher: DdsPublisher,
    /// The services external nodes called, served to ROS 2 clients (`--external`).
    pub services: Option<super::serve_dds::DdsServices>,
    /// Model time on the wall clock.
    pub clock: Clock,
    /// Set by SIGINT / SIGTERM.
    pub stop: &'static AtomicBool,
    /// Set when a signal stopped the run.
    pub stopped: bool,
    /// Where the run's progress goes (the binary draws it).
    pub on_progress: ProgressReports<'m>,
}

impl DdsPaced<'_> {
    /// Reports the progress at model time `time` (at most every
    /// `super::pace::PROGRESS_EVERY` unless `force`).
    pub fn progress(&mut self, time: u64, force: bool) {
        let published = self.publisher.published();
        self.on_progress.report(force, || RunProgress {
            time,
            published,
            received: None,
            dds: true,
        });
    }
}

impl Observer for DdsPaced<'_> {
    fn on_send(&mut self, _time: u64, msg: &SentMessage<'_>) -> Flow {
        self.publisher.publish(self.model, msg);
        if let Some(s) = &mut self.services {
            s.answer(self.model, msg);
        }
        Flow::Continue
    }

    fn on_time(&mut self, time: u64) -> Flow {
        let due = self.clock.due(time);
        loop {
            if self.stop.load(Ordering::Relaxed) {
                self.stopped = true;
                return Flow::Stop;
            }
            let now = Instant::now();
            if now >= due {
                break;
            }
            std::thread::sleep((due - now).min(Duration::from_millis(50)));
        }
        self.progress(time, false);
        Flow::Continue
    }

    fn inputs(&mut self, _time: u64, inbox: &mut Inbox) {
        if let Some(s) = &mut self.services {
            s.poll(inbox);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_name_message_fields() {
        assert_eq!(field_path("ros_fields__data").as_deref(), Some("data"));
        assert_eq!(
            field_path("ros_fields__pose__position__x").as_deref(),
            Some("pose.position.x")
        );
        assert_eq!(field_path("goal_id"), None);
        assert!(publishable(&Ty::Array(Box::new(Ty::Float), None)));
        assert!(!publishable(&Ty::Struct(0)));
    }
}
