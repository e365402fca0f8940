//! `hindsight run`'s wire: the byte layout of each ROS message of a model, an observer that publishes them over iceoryx2, and the decoder for messages a process sends in.
//!
//! Every ROS message of the translated model (AS2FM's event names, see
//! [`crate::props::ros::topic_event`]) goes to a publish-subscribe service whose
//! name is the ROS name (the `__` of the sanitized name turned back into `/`)
//! under a prefix:
//!
//! | model event | service |
//! |---|---|
//! | `topic_<t>_msg` | `<prefix>/<t>` (every publication) |
//! | `srv_<s>_request` | `<prefix>/<s>/request` (the server receiving a request) |
//! | `srv_<s>_response` | `<prefix>/<s>/response` (the server answering) |
//! | `action_<a>_goal_handle` | `<prefix>/<a>/goal` (the server receiving a goal) |
//! | `action_<a>_feedback` | `<prefix>/<a>/feedback` |
//! | `action_<a>_result` | `<prefix>/<a>/result` |
//!
//! Each payload is `[u8]` in a fixed layout:
//!
//! - the event's parameters in the order of its parameter list
//!   ([`CompiledModel::event_params`]), packed without padding:
//!   `bool` one byte (0 or 1), every integer as `i64` little-endian (8 bytes),
//!   every float as `f64` little-endian (8 bytes);
//! - strings, arrays and structs are left out (one warning per field);
//! - last, a `u64` little-endian `seq`: 0 for the topic's first message, +1 for
//!   each later one, so a subscriber counts lost samples exactly.
//!
//! [`layout_toml`] prints the layouts in the format of the sidecar's config
//! ([`super::config`]), so `hindsight monitor` can tap the services directly.

use std::fmt::Write as _;

use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;

type Ipc = ipc::Service;
type RawPublisher = Publisher<Ipc, [u8], ()>;

use super::config::Wire as _;
use crate::expr::{Ty, Value};
use crate::props::{Port, PortKind};
use crate::sim::{CompiledModel, EventId, Flow, Observer, Scalar, SentMessage};

/// The type of one payload field as `hindsight run` writes it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireTy {
    /// One byte, 0 or 1.
    Bool,
    /// `i64` little-endian (every integer width of the model).
    I64,
    /// `f64` little-endian (`float32` and `float64`).
    F64,
}

impl WireTy {
    /// Bytes in the payload.
    pub fn size(self) -> usize {
        match self {
            WireTy::Bool => 1,
            WireTy::I64 | WireTy::F64 => 8,
        }
    }

    /// The sidecar's field type of the same bytes.
    pub(crate) fn field_ty(self) -> super::config::FieldTy {
        match self {
            WireTy::Bool => super::config::FieldTy::Bool,
            WireTy::I64 => super::config::FieldTy::I64,
            WireTy::F64 => super::config::FieldTy::F64,
        }
    }

    /// The name the sidecar's config uses.
    pub fn name(self) -> &'static str {
        match self {
            WireTy::Bool => codegen::scalar::Scalar::Bool.spec_name(),
            WireTy::I64 => codegen::scalar::Scalar::I64.spec_name(),
            WireTy::F64 => codegen::scalar::Scalar::F64.spec_name(),
        }
    }
}

/// One field of a topic's payload.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WireField {
    /// The message field, dotted (`data`, `pose.position.x`; a parameter that is not
    /// AS2FM's `ros_fields__a__b` keeps its name).
    pub name: String,
    /// Index in the event's parameter list.
    pub param: usize,
    /// The spec variable the property file names for it (`<state_var field=...>`), if any.
    pub var: Option<String>,
    /// Byte offset in the payload.
    pub offset: usize,
    /// How it is written.
    pub ty: WireTy,
}

/// What kind of ROS message a layout carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WireKind {
    /// A topic publication.
    Topic,
    /// A service request, as the server receives it.
    Request,
    /// A service response, as the server sends it.
    Response,
    /// An action goal, as the server receives it.
    Goal,
    /// An action feedback.
    Feedback,
    /// An action result.
    Result,
}

impl WireKind {
    /// How a person calls it (`topic`, `service request`, ...).
    pub fn describe(self) -> &'static str {
        match self {
            WireKind::Topic => "topic",
            WireKind::Request => "service request",
            WireKind::Response => "service response",
            WireKind::Goal => "action goal",
            WireKind::Feedback => "action feedback",
            WireKind::Result => "action result",
        }
    }
}

/// The ROS name and kind of a model event that carries a ROS message, `None` for others:
/// `topic_a__b_msg` -> (`a/b`, topic), `srv_s_request` -> (`s/request`, request), ...
pub(crate) fn wire_name(event: &str) -> Option<(String, WireKind)> {
    let table: [(&str, &str, &str, WireKind); 6] = [
        ("topic_", "_msg", "", WireKind::Topic),
        ("srv_", "_request", "/request", WireKind::Request),
        ("srv_", "_response", "/response", WireKind::Response),
        ("action_", "_goal_handle", "/goal", WireKind::Goal),
        ("action_", "_feedback", "/feedback", WireKind::Feedback),
        ("action_", "_result", "/result", WireKind::Result),
    ];
    table.iter().find_map(|(pre, suf, tail, kind)| {
        let core = event.strip_prefix(pre)?.strip_suffix(suf)?;
        (!core.is_empty()).then(|| (format!("{}{tail}", core.replace("__", "/")), *kind))
    })
}

/// The payload layout of one ROS message of a model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicLayout {
    /// The model event (`topic_BatteryComponent__battery_level_msg`).
    pub event: EventId,
    /// The event's name.
    pub event_name: String,
    /// The service path without prefix: the ROS name without the leading `/`, plus
    /// `/request`, `/goal`, ... for services and actions (`BatteryComponent/battery_level`).
    pub topic: String,
    /// What it carries.
    pub kind: WireKind,
    /// The fields, in parameter order.
    pub fields: Vec<WireField>,
    /// The event variable the property file names for the topic (`<event_var>`), if any.
    pub event_var: Option<String>,
    /// Offset of the `u64` sequence counter (the last 8 bytes).
    pub seq_offset: usize,
    /// Total payload bytes.
    pub size: usize,
}

impl TopicLayout {
    /// The iceoryx2 service name under `prefix` (`prefix/BatteryComponent/battery_level`).
    pub fn service(&self, prefix: &str) -> String {
        let p = prefix.trim_end_matches('/');
        if p.is_empty() {
            self.topic.clone()
        } else {
            format!("{p}/{}", self.topic)
        }
    }

    /// Writes one message's payload into `buf` (exactly [`Self::size`] bytes).
    pub fn encode(&self, msg: &SentMessage<'_>, seq: u64, buf: &mut [u8]) {
        for f in &self.fields {
            let at = &mut buf[f.offset..f.offset + f.ty.size()];
            match (f.ty, msg.param(f.param)) {
                (WireTy::Bool, Some(Value::Bool(b))) => at[0] = u8::from(b),
                (WireTy::I64, Some(Value::Int(i))) => at.copy_from_slice(&i.to_le_bytes()),
                (WireTy::F64, Some(Value::Float(x))) => at.copy_from_slice(&x.to_le_bytes()),
                // The model is type-checked; a missing value writes zeros.
                _ => at.fill(0),
            }
        }
        buf[self.seq_offset..self.seq_offset + 8].copy_from_slice(&seq.to_le_bytes());
    }

    /// Reads a payload written in this layout (by [`Self::encode`] or a process that
    /// speaks it): the parameters it sets and its `seq`; `None` if it is not exactly
    /// [`Self::size`] bytes or a field holds no valid value. Fields are read by the
    /// sidecar's own reader ([`super::config::Wire::read`]), so `run` and `monitor`
    /// accept the same payloads (a `bool` byte is 0 or 1, a float is finite).
    pub fn decode(&self, buf: &[u8]) -> Option<(Vec<(usize, Scalar)>, u64)> {
        if buf.len() != self.size {
            return None;
        }
        let mut out = Vec::with_capacity(self.fields.len());
        for f in &self.fields {
            let v = match f.ty.field_ty().read(buf, f.offset)? {
                monitor_core::Value::Bool(b) => Scalar::Bool(b),
                monitor_core::Value::Int(i) => Scalar::Int(i),
                monitor_core::Value::Float(x) => Scalar::Float(x),
                monitor_core::Value::Str(_) => return None,
            };
            out.push((f.param, v));
        }
        let seq = u64::from_le_bytes(
            buf.get(self.seq_offset..self.seq_offset + 8)?
                .try_into()
                .ok()?,
        );
        Some((out, seq))
    }
}

/// The layouts of every ROS message of `model` (`wire_name`), in event order, and a
/// warning per field that cannot be laid out (strings, arrays, structs).
pub fn layouts(model: &CompiledModel) -> (Vec<TopicLayout>, Vec<String>) {
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    for e in 0..model.event_count() {
        let event = EventId(e as u32);
        let Some((topic, kind)) = wire_name(model.event_name(event)) else {
            continue;
        };
        out.push(layout_of(model, event, topic, kind, &mut warnings));
    }
    (out, warnings)
}

/// The layout of any event's parameters, published under `topic` as a `kind`; a warning
/// per field that cannot be laid out.
pub(crate) fn layout_of(
    model: &CompiledModel,
    event: EventId,
    topic: String,
    kind: WireKind,
    warnings: &mut Vec<String>,
) -> TopicLayout {
    let mut fields = Vec::new();
    let mut offset = 0;
    for (i, (pname, ty)) in model.event_params(event).iter().enumerate() {
        let wire = match ty {
            Ty::Bool => WireTy::Bool,
            Ty::Int => WireTy::I64,
            Ty::Float => WireTy::F64,
            other => {
                warnings.push(format!(
                    "{} /{topic}: field `{}` ({other:?}) is not published \
                     (only bool, integer and float fields are)",
                    kind.describe(),
                    field_name(pname)
                ));
                continue;
            }
        };
        fields.push(WireField {
            name: field_name(pname),
            param: i,
            var: None,
            offset,
            ty: wire,
        });
        offset += wire.size();
    }
    TopicLayout {
        event,
        event_name: model.event_name(event).to_string(),
        topic,
        kind,
        fields,
        event_var: None,
        seq_offset: offset,
        size: offset + 8,
    }
}

/// Names the spec variables of each layout after the property file's ports on the
/// same event: a `<state_var>` on a field names that field's `var`, an `<event_var>`
/// the topic's `event` (the first one wins).
pub(crate) fn name_from_ports(layouts: &mut [TopicLayout], model: &CompiledModel, ports: &[Port]) {
    for l in layouts {
        for p in ports.iter().filter(|p| p.event == l.event_name) {
            match &p.kind {
                PortKind::Event => {
                    l.event_var.get_or_insert_with(|| p.id.clone());
                }
                PortKind::State { param, .. } => {
                    let idx = model.param_index(l.event, param);
                    if let Some(f) = l.fields.iter_mut().find(|f| Some(f.param) == idx) {
                        f.var.get_or_insert_with(|| p.id.clone());
                    }
                }
                _ => {}
            }
        }
    }
}

/// `ros_fields__pose__x` → `pose.x`.
fn field_name(param: &str) -> String {
    match param.strip_prefix("ros_fields__") {
        Some(path) => path.replace("__", "."),
        None => param.to_string(),
    }
}

/// A spec variable name for a field: `pose.x` → `pose_x`.
pub(crate) fn default_var(field: &str) -> String {
    field.replace('.', "_")
}

fn toml_str(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(o, "\\u{:04x}", c as u32);
            }
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

/// The layouts as `[[topic]]` tables of the sidecar's config.
///
/// A topic's `event` and a field's `var` are the property file's names when
/// `name_from_ports` found them; otherwise the line (for a field, its whole
/// table) is written commented out, with a suggested name (`default_var`), to
/// be named after the spec's variables and uncommented. A message the property file
/// names nothing of is written commented out as a whole: tapping it would only cost.
pub fn layout_toml(layouts: &[TopicLayout], prefix: &str) -> String {
    let mut s = String::new();
    for l in layouts {
        let named = l.event_var.is_some() || l.fields.iter().any(|f| f.var.is_some());
        let all = if named { "" } else { "# " };
        let _ = writeln!(
            s,
            "# ROS {} /{} (model event {}){}",
            l.kind.describe(),
            l.topic,
            l.event_name,
            if named {
                ""
            } else {
                ": the property file names nothing of it"
            }
        );
        let _ = writeln!(s, "{all}[[topic]]");
        let _ = writeln!(s, "{all}service = {}", toml_str(&l.service(prefix)));
        let _ = writeln!(s, "{all}size = {}", l.size);
        match &l.event_var {
            Some(e) => {
                let _ = writeln!(s, "event = {}", toml_str(e));
            }
            None => {
                let _ = writeln!(s, "# event = \"...\"   # a spec event true at each sample");
            }
        }
        let _ = writeln!(
            s,
            "{all}seq = {{ offset = {}, type = \"u64\" }}",
            l.seq_offset
        );
        for f in &l.fields {
            let (c, var) = match &f.var {
                Some(v) => ("", v.clone()),
                None => ("# ", default_var(&f.name)),
            };
            let _ = writeln!(s, "{c}[[topic.field]]");
            let _ = writeln!(s, "{c}name = {}", toml_str(&f.name));
            let _ = writeln!(s, "{c}var = {}", toml_str(&var));
            let _ = writeln!(s, "{c}offset = {}", f.offset);
            let _ = writeln!(s, "{c}type = \"{}\"", f.ty.name());
        }
        s.push('\n');
    }
    s
}

/// An [`Observer`] that publishes every message of a laid-out topic on its service.
pub struct TopicPublisher {
    /// Per event id: the index into `topics`, if the event is a topic.
    by_event: Vec<Option<usize>>,
    topics: Vec<(TopicLayout, RawPublisher, u64)>,
    published: u64,
    failed: u64,
    last_error: Option<String>,
}

impl TopicPublisher {
    /// Opens (or creates) one service per layout under `prefix` on `node`, with a
    /// publisher each. Services keep iceoryx2's safe overflow: a slow subscriber
    /// loses its oldest samples and never blocks the run.
    pub fn new(
        node: &Node<Ipc>,
        model: &CompiledModel,
        layouts: Vec<TopicLayout>,
        prefix: &str,
    ) -> Result<TopicPublisher, super::LiveError> {
        let mut by_event = vec![None; model.event_count()];
        let mut topics = Vec::new();
        for l in layouts {
            let svc = l.service(prefix);
            let factory = super::open_raw_topic(node, &svc)?;
            let publisher = factory
                .publisher_builder()
                .initial_max_slice_len(l.size)
                .create()
                .map_err(|e| super::LiveError::ipc(&svc, e))?;
            by_event[l.event.0 as usize] = Some(topics.len());
            topics.push((l, publisher, 0));
        }
        Ok(TopicPublisher {
            by_event,
            topics,
            published: 0,
            failed: 0,
            last_error: None,
        })
    }

    /// Samples published so far.
    pub fn published(&self) -> u64 {
        self.published
    }

    /// Samples that iceoryx2 refused, and the last reason.
    pub fn failed(&self) -> (u64, Option<&str>) {
        (self.failed, self.last_error.as_deref())
    }

    /// Publishes `msg` if its event is laid out (a topic that a process publishes into
    /// the run is not: `hindsight run` leaves it out of the layouts it gives here).
    pub fn publish(&mut self, msg: &SentMessage<'_>) {
        let Some(Some(i)) = self.by_event.get(msg.event().0 as usize) else {
            return;
        };
        let (layout, publisher, seq) = &mut self.topics[*i];
        let result = publisher
            .loan_slice_uninit(layout.size)
            .map_err(|e| format!("{e:?}"))
            .and_then(|sample| {
                let mut sample = sample.write_from_fn(|_| 0u8);
                layout.encode(msg, *seq, sample.payload_mut());
                sample.send().map_err(|e| format!("{e:?}"))
            });
        *seq += 1;
        match result {
            Ok(_) => self.published += 1,
            Err(e) => {
                self.failed += 1;
                self.last_error = Some(format!("{}: {e}", layout.topic));
            }
        }
    }
}

impl Observer for TopicPublisher {
    fn on_send(&mut self, _time: u64, msg: &SentMessage<'_>) -> Flow {
        self.publish(msg);
        Flow::Continue
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ros_messages_get_their_ros_names() {
        let cases = [
            ("topic_a__b_msg", Some(("a/b", WireKind::Topic))),
            (
                "srv_Notify__Start_request",
                Some(("Notify/Start/request", WireKind::Request)),
            ),
            ("srv_s_response", Some(("s/response", WireKind::Response))),
            ("action_nav_goal_handle", Some(("nav/goal", WireKind::Goal))),
            (
                "action_nav_feedback",
                Some(("nav/feedback", WireKind::Feedback)),
            ),
            ("action_nav_result", Some(("nav/result", WireKind::Result))),
            // What clients and handlers see is the same message again: not republished.
            ("srv_s_response_client_c", None),
            ("srv_s_req_client_c", None),
            ("action_nav_result_handle_client_c", None),
            ("topic__msg", None),
            ("bt_1_tick", None),
        ];
        for (event, want) in cases {
            let got = wire_name(event);
            assert_eq!(got.as_ref().map(|(n, k)| (n.as_str(), *k)), want, "{event}");
        }
    }

    #[test]
    fn decode_reads_what_encode_layout_says_and_refuses_bad_payloads() {
        let layout = TopicLayout {
            event: EventId(3),
            event_name: "topic_t_msg".into(),
            topic: "t".into(),
            kind: WireKind::Topic,
            fields: vec![
                WireField {
                    name: "ok".into(),
                    param: 0,
                    var: None,
                    offset: 0,
                    ty: WireTy::Bool,
                },
                WireField {
                    name: "n".into(),
                    param: 2,
                    var: None,
                    offset: 1,
                    ty: WireTy::I64,
                },
                WireField {
                    name: "x".into(),
                    param: 1,
                    var: None,
                    offset: 9,
                    ty: WireTy::F64,
                },
            ],
            event_var: None,
            seq_offset: 17,
            size: 25,
        };
        let mut buf = vec![0u8; 25];
        buf[0] = 1;
        buf[1..9].copy_from_slice(&(-7i64).to_le_bytes());
        buf[9..17].copy_from_slice(&2.5f64.to_le_bytes());
        buf[17..25].copy_from_slice(&42u64.to_le_bytes());
        let (params, seq) = layout.decode(&buf).unwrap();
        assert_eq!(seq, 42);
        assert_eq!(
            params,
            vec![
                (0, Scalar::Bool(true)),
                (2, Scalar::Int(-7)),
                (1, Scalar::Float(2.5))
            ]
        );
        assert!(layout.decode(&buf[..24]).is_none(), "short");
        buf[0] = 2;
        assert!(layout.decode(&buf).is_none(), "a bool byte of 2");
        // The sidecar's rule for floats: a NaN is no value.
        buf[0] = 1;
        buf[9..17].copy_from_slice(&f64::NAN.to_le_bytes());
        assert!(layout.decode(&buf).is_none(), "a NaN");
    }
}
