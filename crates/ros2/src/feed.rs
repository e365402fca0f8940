//! From a recording to monitor points: every message is one point, at which the ports
//! on its topic set their variables.
//!
//! # Ports
//!
//! A [`Port`] binds a monitor variable to a topic: an event variable is true at each
//! message of the topic, a state variable takes a field's value (a field path,
//! `crate::cdr::parse_path`). A port of a service (`<ros_service service_name="/s"
//! event="request">`) reads the service's introspection topic `/s/_service_event` and
//! only its events of one kind ([`ServiceSide`]): the request as the server received it
//! (`REQUEST_RECEIVED`) or the response as the server sent it (`RESPONSE_SENT`), the
//! moments the model's `srv_<s>_request` / `srv_<s>_response` messages stand for; its
//! field `f` is read as `request[0].f` (or `response[0].f`).
//!
//! # Time
//!
//! A point's time is the message's log time (rosbag2's receive time) or, with
//! [`TimeSource::Header`], its `header.stamp`, in nanoseconds since the first message's
//! time. A time before the previous point's is an error naming the message.
//!
//! # Errors
//!
//! Every error about a message names its topic and its index on that topic (from 1)
//! and the file: a message that does not decode, a field a port reads that the type
//! lacks, a type whose definition is not found.

use std::path::Path;

use monitor_core::{Ty, Value};

use crate::bag::{BagError, Connection, Recording, Visit};
use crate::cdr::{CdrError, Decoder, FieldError};
use crate::schema::{Definitions, Ros2MsgDefs, Schema, SchemaError};

/// Why the ports of a topic cannot read its type (the caller names the topic).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PlanError {
    /// The definition the recording embeds does not resolve.
    Embedded(SchemaError),
    /// The type is not embedded and the interface packages do not define it.
    NotEmbedded {
        /// The ROS type.
        type_name: String,
        /// Why it does not resolve.
        error: SchemaError,
    },
    /// `--time header` on a type without `header.stamp`.
    NoHeader(Box<FieldError>),
    /// A service port on a topic whose type is not a service event.
    NotServiceEvent(Box<FieldError>),
    /// A port reads a field the type lacks (or of another kind).
    Port {
        /// The port's variable.
        name: String,
        /// Why.
        error: Box<FieldError>,
    },
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Embedded(e) => write!(f, "{e}"),
            PlanError::NotEmbedded { type_name, error } => write!(
                f,
                "{error}: the recording does not embed the definition of `{type_name}`; name its package's folder with --interfaces (or source its ROS workspace)"
            ),
            PlanError::NoHeader(e) => write!(f, "--time header needs a `header` field: {e}"),
            PlanError::NotServiceEvent(e) => write!(f, "not a service event: {e}"),
            PlanError::Port { name, error } => write!(f, "port `{name}`: {error}"),
        }
    }
}

impl std::error::Error for PlanError {}

/// What is wrong with one message (the caller names the topic and the index).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MessageError {
    /// It does not decode as its type.
    Cdr(CdrError),
    /// Its `header.stamp` is before 1970.
    BeforeEpoch {
        /// `header.stamp.sec`.
        sec: i64,
        /// `header.stamp.nanosec`.
        nanosec: i64,
    },
    /// A field a port reads is past the end of an array in this message.
    Absent {
        /// The field path.
        path: String,
    },
    /// Its time is before the previous message's.
    Backwards {
        /// Which time.
        time: TimeSource,
        /// Its time, ns since the epoch.
        at: u64,
        /// The previous message's.
        previous: u64,
    },
}

impl std::fmt::Display for MessageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MessageError::Cdr(e) => write!(f, "{e}"),
            MessageError::BeforeEpoch { sec, nanosec } => {
                write!(f, "header.stamp {sec}s {nanosec}ns is before 1970")
            }
            MessageError::Absent { path } => write!(
                f,
                "`{path}` is not in this message (an array on its path is shorter)"
            ),
            MessageError::Backwards { time, at, previous } => {
                let what = match time {
                    TimeSource::Header => "header stamp",
                    TimeSource::Log => "log time",
                };
                write!(
                    f,
                    "its {what} {at} ns is before the previous message's ({previous} ns)"
                )
            }
        }
    }
}

impl std::error::Error for MessageError {}

/// Why a replay stopped: the recording, a topic's ports, a message, or the caller's
/// `on_point` (error `E`). Every variant names the file, and the topic and the message's
/// index on it (from 1) where one is at fault.
#[derive(Debug)]
pub enum ReplayError<E> {
    /// The recording does not read.
    Bag(BagError),
    /// The ports of `topic` cannot read its type.
    Topic {
        /// The recording.
        file: String,
        /// The topic.
        topic: String,
        /// Why (boxed: errors are rare, results are passed around on every message).
        error: Box<PlanError>,
    },
    /// Message `index` of `topic` is bad.
    Message {
        /// The recording.
        file: String,
        /// The topic.
        topic: String,
        /// The message's index on the topic, from 1.
        index: u64,
        /// The topic's type.
        type_name: String,
        /// Why (boxed, as above).
        error: Box<MessageError>,
    },
    /// `on_point` refused the point of message `index` of `topic`.
    Point {
        /// The recording.
        file: String,
        /// The topic.
        topic: String,
        /// The message's index on the topic, from 1.
        index: u64,
        /// The caller's error.
        error: E,
    },
}

impl<E> ReplayError<E> {
    /// The same error with `on_point`'s error mapped by `f` (to describe it).
    pub fn map_point<F>(self, f: impl FnOnce(E) -> F) -> ReplayError<F> {
        match self {
            ReplayError::Bag(e) => ReplayError::Bag(e),
            ReplayError::Topic { file, topic, error } => ReplayError::Topic { file, topic, error },
            ReplayError::Message {
                file,
                topic,
                index,
                type_name,
                error,
            } => ReplayError::Message {
                file,
                topic,
                index,
                type_name,
                error,
            },
            ReplayError::Point {
                file,
                topic,
                index,
                error,
            } => ReplayError::Point {
                file,
                topic,
                index,
                error: f(error),
            },
        }
    }
}

impl<E> From<BagError> for ReplayError<E> {
    fn from(e: BagError) -> Self {
        ReplayError::Bag(e)
    }
}

impl<E: std::fmt::Display> std::fmt::Display for ReplayError<E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReplayError::Bag(e) => write!(f, "{e}"),
            ReplayError::Topic { file, topic, error } => {
                write!(f, "{file}: topic `{topic}`: {error}")
            }
            ReplayError::Message {
                file,
                topic,
                index,
                type_name,
                error,
            } => write!(
                f,
                "{file}: topic `{topic}` message {index} (type `{type_name}`): {error}"
            ),
            ReplayError::Point {
                file,
                topic,
                index,
                error,
            } => write!(f, "{file}: topic `{topic}` message {index}: {error}"),
        }
    }
}

impl<E: std::fmt::Debug + std::fmt::Display> std::error::Error for ReplayError<E> {}

/// Where a point's time comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TimeSource {
    /// The recording's log (receive) time.
    #[default]
    Log,
    /// The message's `header.stamp` (`sec`, `nanosec`).
    Header,
}

/// Which service events a service port reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ServiceSide {
    /// `REQUEST_RECEIVED` (1): the server got a request; fields under `request[0]`.
    Request,
    /// `RESPONSE_SENT` (2): the server answered; fields under `response[0]`.
    Response,
}

/// `service_msgs/msg/ServiceEventInfo`'s event types (rosidl, `service_msgs`).
const REQUEST_RECEIVED: i64 = 1;
const RESPONSE_SENT: i64 = 2;

/// What a port reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Read {
    /// True at each message (an event variable).
    Event,
    /// A field's value (a state variable).
    Field(String),
}

/// One variable bound to a topic.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Port {
    /// The monitor variable's index.
    pub var: usize,
    /// Its type.
    pub ty: Ty,
    /// The topic (for a service port, the service's name).
    pub topic: String,
    /// What is read.
    pub read: Read,
    /// For a service port: which events.
    pub service: Option<ServiceSide>,
    /// The variable's name, for errors.
    pub name: String,
}

impl Port {
    /// The topic the port's messages are recorded on.
    pub fn recorded_topic(&self) -> String {
        match self.service {
            None => self.topic.clone(),
            Some(_) => format!("{}/_service_event", self.topic.trim_end_matches('/')),
        }
    }
}

/// One point: its time and the variables set.
#[derive(Clone, Copy, Debug)]
pub struct Point<'a> {
    /// Nanoseconds since the first message.
    pub time_ns: u64,
    /// `(variable, value)` for each port that read this message.
    pub sets: &'a [(usize, Value)],
    /// The message's topic.
    pub topic: &'a str,
    /// Its index on that topic, from 1.
    pub index: u64,
}

/// What was read.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// Messages (points) in the recording.
    pub messages: u64,
    /// `(topic, messages)` of every topic, in order of first appearance.
    pub topics: Vec<(String, u64)>,
}

/// One port of a connection: `(var, slot read or None for true, (slot, value) the
/// message must have there for a service event's kind)`.
type PortSet = (usize, Option<usize>, Option<(usize, i64)>);

/// How one connection's messages set variables.
struct Plan {
    decoder: Option<Decoder>,
    sets: Vec<PortSet>,
    /// Slots of `header.stamp.sec` / `nanosec`.
    stamp: Option<(usize, usize)>,
    count: u64,
    topic: String,
}

impl Plan {
    /// Decodes one message into `sets` (cleared first); returns its header stamp in
    /// nanoseconds when the plan reads it. Errors say what is wrong with the message
    /// (the caller names the topic and the message).
    fn read(
        &self,
        data: &[u8],
        slots: &mut Vec<Value>,
        present: &mut Vec<bool>,
        sets: &mut Vec<(usize, Value)>,
    ) -> Result<Option<u64>, MessageError> {
        sets.clear();
        let Some(d) = &self.decoder else {
            for &(var, _, _) in &self.sets {
                sets.push((var, Value::Bool(true)));
            }
            return Ok(None);
        };
        if slots.len() < d.slots() {
            slots.resize(d.slots(), Value::Bool(false));
            present.resize(d.slots(), false);
        }
        d.decode(data, slots, present).map_err(MessageError::Cdr)?;
        let mut stamp = None;
        if let Some((s, n)) = self.stamp {
            // A decoder built by `plan` reads both as integers.
            let (Value::Int(sec), Value::Int(nsec)) = (slots[s], slots[n]) else {
                unreachable!("header.stamp is read as two integers")
            };
            let ns = sec
                .checked_mul(1_000_000_000)
                .and_then(|x| x.checked_add(nsec))
                .and_then(|x| u64::try_from(x).ok());
            let Some(ns) = ns else {
                return Err(MessageError::BeforeEpoch { sec, nanosec: nsec });
            };
            stamp = Some(ns);
        }
        for &(var, slot, when) in &self.sets {
            if let Some((s, want)) = when {
                if slots[s] != Value::Int(want) {
                    continue;
                }
            }
            match slot {
                None => sets.push((var, Value::Bool(true))),
                Some(s) if present[s] => sets.push((var, slots[s])),
                Some(s) => {
                    return Err(MessageError::Absent {
                        path: d.slot_path(s).to_string(),
                    })
                }
            }
        }
        Ok(stamp)
    }
}

/// One topic's messages turned into variable sets, one message at a time: the live
/// path (`hindsight monitor --ros2`), where messages come from DDS instead of a file.
pub struct TopicFeed {
    plan: Plan,
    slots: Vec<Value>,
    present: Vec<bool>,
    sets: Vec<(usize, Value)>,
}

impl TopicFeed {
    /// The feed of the ports of `ports` that read `topic` (as recorded: a service port
    /// reads `/s/_service_event`), whose messages are of type `type_name` defined by
    /// `defs`. Errors name the port or the type.
    pub fn new(
        topic: &str,
        type_name: &str,
        ports: &[Port],
        defs: &dyn Definitions,
        strings: &[String],
    ) -> Result<TopicFeed, PlanError> {
        let conn = Connection {
            topic: topic.to_string(),
            type_name: type_name.to_string(),
            definition: None,
        };
        Ok(TopicFeed {
            plan: plan(&conn, ports, defs, TimeSource::Log, strings)?,
            slots: Vec::new(),
            present: Vec::new(),
            sets: Vec::new(),
        })
    }

    /// The variables one message sets (its CDR bytes with their 4-byte header). An
    /// error says what is wrong with the message; the caller names topic and index.
    pub fn read(&mut self, data: &[u8]) -> Result<&[(usize, Value)], MessageError> {
        self.plan
            .read(data, &mut self.slots, &mut self.present, &mut self.sets)?;
        Ok(&self.sets)
    }
}

/// Reads `input` and calls `on_point` with every message as a point.
///
/// `defs` gives the definitions of types the recording does not embed (a `.db3` file);
/// `strings` are the spec's string constants (see [`Decoder::new`]).
pub fn replay<E>(
    input: &Path,
    ports: &[Port],
    defs: &dyn Definitions,
    time: TimeSource,
    strings: &[String],
    on_point: &mut dyn FnMut(Point<'_>) -> Result<(), E>,
) -> Result<Summary, ReplayError<E>> {
    let rec = Recording::open(input)?;
    let shown = input.display().to_string();
    run(
        &mut |visit| rec.for_each(visit),
        &shown,
        ports,
        defs,
        time,
        strings,
        on_point,
    )
}

/// [`replay`] of an MCAP file held in memory (the fuzz target's and the bench's entry).
pub fn replay_mcap_bytes<E>(
    bytes: &[u8],
    ports: &[Port],
    defs: &dyn Definitions,
    time: TimeSource,
    strings: &[String],
    on_point: &mut dyn FnMut(Point<'_>) -> Result<(), E>,
) -> Result<Summary, ReplayError<E>> {
    run(
        &mut |visit| crate::bag::mcap_bytes(bytes, "<mcap>", &mut Vec::new(), visit),
        "<mcap>",
        ports,
        defs,
        time,
        strings,
        on_point,
    )
}

/// What reads the messages: a recording's [`Recording::for_each`] or [`crate::bag::mcap_bytes`].
type Source<'s, E> = dyn FnMut(&mut Visit<'_, ReplayError<E>>) -> Result<(), ReplayError<E>> + 's;

fn run<E>(
    source: &mut Source<'_, E>,
    shown: &str,
    ports: &[Port],
    defs: &dyn Definitions,
    time: TimeSource,
    strings: &[String],
    on_point: &mut dyn FnMut(Point<'_>) -> Result<(), E>,
) -> Result<Summary, ReplayError<E>> {
    let mut plans: Vec<Option<Plan>> = Vec::new();
    let mut slots: Vec<Value> = Vec::new();
    let mut present: Vec<bool> = Vec::new();
    let mut sets: Vec<(usize, Value)> = Vec::new();
    let mut first: Option<u64> = None;
    let mut last = 0u64;
    let mut messages = 0u64;
    source(&mut |conns, msg| {
        if plans.len() <= msg.conn {
            plans.resize_with(conns.len(), || None);
        }
        let plan = match &mut plans[msg.conn] {
            Some(p) => p,
            slot => {
                let p = plan(&conns[msg.conn], ports, defs, time, strings).map_err(|error| {
                    ReplayError::Topic {
                        file: shown.to_string(),
                        topic: conns[msg.conn].topic.clone(),
                        error: Box::new(error),
                    }
                })?;
                slot.insert(p)
            }
        };
        plan.count += 1;
        messages += 1;
        let at = |error| ReplayError::Message {
            file: shown.to_string(),
            topic: plan.topic.clone(),
            index: plan.count,
            type_name: conns[msg.conn].type_name.clone(),
            error: Box::new(error),
        };
        let stamp = plan
            .read(msg.data, &mut slots, &mut present, &mut sets)
            .map_err(at)?;
        let abs = stamp.unwrap_or(msg.log_time);
        let origin = *first.get_or_insert(abs);
        let Some(t) = abs.checked_sub(origin).filter(|t| *t >= last) else {
            return Err(at(MessageError::Backwards {
                time,
                at: abs,
                previous: origin + last,
            }));
        };
        last = t;
        on_point(Point {
            time_ns: t,
            sets: &sets,
            topic: &plan.topic,
            index: plan.count,
        })
        .map_err(|error| ReplayError::Point {
            file: shown.to_string(),
            topic: plan.topic.clone(),
            index: plan.count,
            error,
        })
    })?;
    let mut topics: Vec<(String, u64)> = Vec::new();
    for p in plans.iter().flatten() {
        match topics.iter_mut().find(|(t, _)| *t == p.topic) {
            Some((_, n)) => *n += p.count,
            None => topics.push((p.topic.clone(), p.count)),
        }
    }
    Ok(Summary { messages, topics })
}

/// The plan of one connection: its decoder (when a port reads a field, a service
/// event's kind, or the header stamp) and its ports.
fn plan(
    conn: &Connection,
    ports: &[Port],
    defs: &dyn Definitions,
    time: TimeSource,
    strings: &[String],
) -> Result<Plan, PlanError> {
    let mine: Vec<&Port> = ports
        .iter()
        .filter(|p| p.recorded_topic() == conn.topic)
        .collect();
    let needs_decoder = time == TimeSource::Header
        || mine
            .iter()
            .any(|p| p.service.is_some() || matches!(p.read, Read::Field(_)));
    let mut out = Plan {
        decoder: None,
        sets: Vec::new(),
        stamp: None,
        count: 0,
        topic: conn.topic.clone(),
    };
    if !needs_decoder {
        out.sets = mine.iter().map(|p| (p.var, None, None)).collect();
        return Ok(out);
    }
    let schema = match &conn.definition {
        Some(text) => {
            let local = Ros2MsgDefs::parse(&conn.type_name, text).map_err(PlanError::Embedded)?;
            Schema::resolve(&conn.type_name, &local).map_err(PlanError::Embedded)?
        }
        None => Schema::resolve(&conn.type_name, defs).map_err(|error| PlanError::NotEmbedded {
            type_name: conn.type_name.clone(),
            error,
        })?,
    };
    let mut d = Decoder::new(schema, strings);
    if time == TimeSource::Header {
        let sec = d.add("header.stamp.sec", Ty::Int);
        let nsec = d.add("header.stamp.nanosec", Ty::Int);
        match (sec, nsec) {
            (Ok(s), Ok(n)) => out.stamp = Some((s, n)),
            (Err(e), _) | (_, Err(e)) => return Err(PlanError::NoHeader(Box::new(e))),
        }
    }
    for p in mine {
        let when = match p.service {
            None => None,
            Some(side) => {
                let s = d
                    .add("info.event_type", Ty::Int)
                    .map_err(|e| PlanError::NotServiceEvent(Box::new(e)))?;
                Some((
                    s,
                    match side {
                        ServiceSide::Request => REQUEST_RECEIVED,
                        ServiceSide::Response => RESPONSE_SENT,
                    },
                ))
            }
        };
        let slot = match &p.read {
            Read::Event => None,
            Read::Field(f) => {
                let path = match p.service {
                    None => f.clone(),
                    Some(ServiceSide::Request) => format!("request[0].{f}"),
                    Some(ServiceSide::Response) => format!("response[0].{f}"),
                };
                Some(d.add(&path, p.ty).map_err(|error| PlanError::Port {
                    name: p.name.clone(),
                    error: Box::new(error),
                })?)
            }
        };
        out.sets.push((p.var, slot, when));
    }
    out.decoder = Some(d);
    Ok(out)
}
