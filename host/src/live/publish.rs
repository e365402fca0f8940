//! `hindsight run`'s output side: the byte layout of each ROS topic of a model and an observer that publishes its messages over iceoryx2.
//!
//! Every event named `topic_<sanitized name>_msg` (AS2FM's naming, see
//! [`crate::robot::ros::topic_event`]) is a ROS topic; its messages go to the
//! publish-subscribe service `<prefix>/<topic name>` (the `__` of the sanitized
//! name turned back into `/`) with a `[u8]` payload in a fixed layout:
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

use crate::expr::{Ty, Value};
use crate::props::{Port, PortKind};
use crate::sim::{CompiledModel, EventId, Flow, Observer, SentMessage};

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

    /// The name the sidecar's config uses.
    pub fn name(self) -> &'static str {
        match self {
            WireTy::Bool => "bool",
            WireTy::I64 => "i64",
            WireTy::F64 => "f64",
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

/// The payload layout of one ROS topic of a model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicLayout {
    /// The model event (`topic_BatteryComponent__battery_level_msg`).
    pub event: EventId,
    /// The event's name.
    pub event_name: String,
    /// The ROS topic name without the leading `/` (`BatteryComponent/battery_level`).
    pub topic: String,
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
}

/// The layouts of every ROS topic of `model`, in event order, and a warning per
/// field that cannot be laid out (strings, arrays, structs).
pub fn layouts(model: &CompiledModel) -> (Vec<TopicLayout>, Vec<String>) {
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    for e in 0..model.event_count() {
        let event = EventId(e as u32);
        let name = model.event_name(event);
        let Some(sanitized) = name
            .strip_prefix("topic_")
            .and_then(|s| s.strip_suffix("_msg"))
        else {
            continue;
        };
        if sanitized.is_empty() {
            continue;
        }
        let topic = sanitized.replace("__", "/");
        let mut fields = Vec::new();
        let mut offset = 0;
        for (i, (pname, ty)) in model.event_params(event).iter().enumerate() {
            let wire = match ty {
                Ty::Bool => WireTy::Bool,
                Ty::Int => WireTy::I64,
                Ty::Float => WireTy::F64,
                other => {
                    warnings.push(format!(
                        "topic /{topic}: field `{}` ({other:?}) is not published \
                         (only bool, integer and float fields are)",
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
        out.push(TopicLayout {
            event,
            event_name: name.to_string(),
            topic,
            fields,
            event_var: None,
            seq_offset: offset,
            size: offset + 8,
        });
    }
    (out, warnings)
}

/// Names the spec variables of each layout after the property file's ports on the
/// same event: a `<state_var>` on a field names that field's `var`, an `<event_var>`
/// the topic's `event` (the first one wins).
pub fn name_from_ports(layouts: &mut [TopicLayout], model: &CompiledModel, ports: &[Port]) {
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
pub fn default_var(field: &str) -> String {
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
/// [`name_from_ports`] found them; otherwise the line (for a field, its whole
/// table) is written commented out, with a suggested name ([`default_var`]), to
/// be named after the spec's variables and uncommented.
pub fn layout_toml(layouts: &[TopicLayout], prefix: &str) -> String {
    let mut s = String::new();
    for l in layouts {
        let _ = writeln!(s, "# ROS topic /{} (model event {})", l.topic, l.event_name);
        let _ = writeln!(s, "[[topic]]");
        let _ = writeln!(s, "service = {}", toml_str(&l.service(prefix)));
        let _ = writeln!(s, "size = {}", l.size);
        match &l.event_var {
            Some(e) => {
                let _ = writeln!(s, "event = {}", toml_str(e));
            }
            None => {
                let _ = writeln!(s, "# event = \"...\"   # a spec event true at each sample");
            }
        }
        let _ = writeln!(s, "seq = {{ offset = {}, type = \"u64\" }}", l.seq_offset);
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
    ) -> Result<TopicPublisher, String> {
        let mut by_event = vec![None; model.event_count()];
        let mut topics = Vec::new();
        for l in layouts {
            let svc = l.service(prefix);
            let name = super::service_name(&svc).map_err(|e| e.to_string())?;
            let factory = node
                .service_builder(&name)
                .publish_subscribe::<[u8]>()
                .open_or_create()
                .map_err(|e| format!("iceoryx2: {svc}: {e:?}"))?;
            let publisher = factory
                .publisher_builder()
                .initial_max_slice_len(l.size)
                .create()
                .map_err(|e| format!("iceoryx2: {svc}: {e:?}"))?;
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

    /// Publishes `msg` if its event is a topic.
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
