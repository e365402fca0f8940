//! Live ROS 2 over DDS: a plain DDS participant (no ROS install) that reads and writes
//! ROS 2 topics as serialised CDR, on the `rustdds` RTPS stack.
//!
//! # How ROS 2 maps onto DDS
//!
//! ROS 2's DDS middlewares (rmw_cyclonedds, rmw_fastrtps) name things by a fixed rule,
//! which any DDS participant can follow to join the graph (ROS 2 design article "Topic
//! and Service name mapping to DDS"; rmw_dds_common `get_type_name`,
//! rosidl_typesupport_introspection's `dds_` namespace):
//!
//! - a topic `/a/b` is the DDS topic `rt/a/b` ([`topic_name`]);
//! - a type `pkg/msg/Type` is the DDS type `pkg::msg::dds_::Type_` ([`type_name`]), a
//!   service event `pkg/srv/Name_Event` is `pkg::srv::dds_::Name_Event_`;
//! - the default QoS (rmw `rmw_qos_profile_default`) is reliable, volatile, keep last 10
//!   ([`Qos::ros_default`]);
//! - the domain is `ROS_DOMAIN_ID` (0 when unset), [`domain_id`].
//!
//! A sample's payload is the message's CDR (the 2-byte representation identifier and two
//! option bytes, then the body), which [`crate::cdr::Decoder`] reads. The reader asks for
//! nothing else: topics are keyless (ROS 2 has no keyed topics).

use rustdds::no_key::{DataReader, DataWriter, Decode, DefaultDecoder, DeserializerAdapter};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{
    DomainParticipant, QosPolicies, QosPolicyBuilder, ReadCondition, RepresentationIdentifier,
    TopicKind,
};

/// One sample as received: its CDR bytes, with the 4-byte encapsulation header
/// (representation identifier and options) that [`crate::cdr`] expects.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Raw(pub Vec<u8>);

/// The adapter that hands a sample's bytes over as they came (rustdds decodes nothing).
pub struct RawAdapter;

/// [`RawAdapter`]'s decoder: prefixes the representation identifier again.
#[derive(Clone, Copy)]
pub struct RawDecoder;

impl<'de> Decode<'de, Raw> for RawDecoder {
    type Error = std::convert::Infallible;

    fn decode_bytes(
        self,
        input_bytes: &'de [u8],
        encoding: RepresentationIdentifier,
    ) -> Result<Raw, Self::Error> {
        let mut v = Vec::with_capacity(input_bytes.len() + 4);
        v.extend_from_slice(&encoding.to_bytes());
        v.extend_from_slice(&[0, 0]);
        v.extend_from_slice(input_bytes);
        Ok(Raw(v))
    }
}

/// Every representation a writer may offer: a sample in one our CDR reader does not read
/// (XCDR2, parameter lists) still arrives, and its decoding error names the topic and
/// the sample instead of it vanishing inside the DDS stack.
static ENCODINGS: [RepresentationIdentifier; 8] = [
    RepresentationIdentifier::CDR_LE,
    RepresentationIdentifier::CDR_BE,
    RepresentationIdentifier::CDR2_LE,
    RepresentationIdentifier::CDR2_BE,
    RepresentationIdentifier::D_CDR2_LE,
    RepresentationIdentifier::D_CDR2_BE,
    RepresentationIdentifier::PL_CDR_LE,
    RepresentationIdentifier::PL_CDR_BE,
];

impl DeserializerAdapter<Raw> for RawAdapter {
    type Error = std::convert::Infallible;
    type Decoded = Raw;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &ENCODINGS
    }

    fn transform_decoded(decoded: Raw) -> Raw {
        decoded
    }
}

impl DefaultDecoder<Raw> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}

/// Why a write failed (the serializer never fails; rustdds's own errors are carried).
#[derive(Debug)]
pub struct RawWriteError(String);

impl std::fmt::Display for RawWriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for RawWriteError {}

/// Why a DDS name, setting or operation failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DdsError {
    /// `ROS_DOMAIN_ID` is not a domain ROS 2 allows (the value as set).
    Domain(String),
    /// A ROS type name that has no DDS name (the name as written).
    TypeName(String),
    /// A QoS setting that is not one of ROS 2's names for it.
    Qos {
        /// The setting (`reliability`, `durability`, `history`, `depth`).
        key: String,
        /// The value as written.
        value: String,
        /// What is accepted.
        expected: &'static str,
    },
    /// The DDS stack refused: what was being done, and its error.
    Stack {
        /// What was being done (`reader of `rt/a``).
        what: String,
        /// rustdds's error.
        error: String,
    },
}

impl std::fmt::Display for DdsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DdsError::Domain(s) => write!(
                f,
                "ROS_DOMAIN_ID={s}: expected a domain from 0 to {MAX_DOMAIN_ID}"
            ),
            DdsError::TypeName(t) => write!(
                f,
                "`{t}`: not a ROS type name (`pkg/Type` or `pkg/msg/Type`)"
            ),
            DdsError::Qos {
                key,
                value,
                expected,
            } => write!(f, "QoS {key}=`{value}`: expected {expected}"),
            DdsError::Stack { what, error } => write!(f, "DDS: {what}: {error}"),
        }
    }
}

impl std::error::Error for DdsError {}

impl rustdds::no_key::SerializerAdapter<Raw> for RawAdapter {
    type Error = RawWriteError;

    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }

    fn to_bytes(value: &Raw) -> Result<bytes::Bytes, RawWriteError> {
        match value.0.get(..2) {
            Some([0, 1]) => Ok(bytes::Bytes::copy_from_slice(&value.0[4..])),
            _ => Err(RawWriteError(
                "a sample to write is little-endian CDR with its 4-byte header".into(),
            )),
        }
    }
}

/// The DDS name of ROS topic `/a/b`: `rt/a/b`.
pub fn topic_name(ros_topic: &str) -> String {
    format!("rt/{}", ros_topic.trim_start_matches('/'))
}

/// The DDS type name of ROS type `pkg/Type` or `pkg/msg/Type` (`pkg::msg::dds_::Type_`),
/// of a service's `pkg/srv/Name_Event` (`pkg::srv::dds_::Name_Event_`).
pub fn type_name(ros_type: &str) -> Result<String, DdsError> {
    let parts: Vec<&str> = ros_type.trim().split('/').collect();
    let (pkg, kind, name) = match parts.as_slice() {
        [p, n] => (*p, "msg", *n),
        [p, k @ ("msg" | "srv" | "action"), n] => (*p, *k, *n),
        _ => return Err(DdsError::TypeName(ros_type.to_string())),
    };
    let ok = |s: &str| {
        !s.is_empty()
            && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
            && !s.as_bytes()[0].is_ascii_digit()
    };
    if !ok(pkg) || !ok(name) {
        return Err(DdsError::TypeName(ros_type.to_string()));
    }
    Ok(format!("{pkg}::{kind}::dds_::{name}_"))
}

/// The DDS topics of ROS service `/a/s`: requests on `rq/a/sRequest`, replies on
/// `rr/a/sReply` (ROS 2 design article "Topic and Service name mapping to DDS";
/// rmw_cyclonedds_cpp `rmw_init_cs`: `make_fqtopic(ROS_SERVICE_REQUESTER_PREFIX, name,
/// "Request")` and `(ROS_SERVICE_RESPONSE_PREFIX, name, "Reply")`).
pub fn service_topics(ros_service: &str) -> (String, String) {
    let s = ros_service.trim_start_matches('/');
    (format!("rq/{s}Request"), format!("rr/{s}Reply"))
}

/// The highest domain ROS 2 allows on Linux (its port mapping leaves room for 232).
pub(crate) const MAX_DOMAIN_ID: u16 = 232;

/// The domain: `ROS_DOMAIN_ID` (a number from 0 to 232), 0 when unset or empty.
pub fn domain_id() -> Result<u16, DdsError> {
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(s) if s.trim().is_empty() => Ok(0),
        Ok(s) => match s.trim().parse::<u16>() {
            Ok(d) if d <= MAX_DOMAIN_ID => Ok(d),
            _ => Err(DdsError::Domain(s)),
        },
    }
}

/// The QoS of a reader or writer: the four policies a ROS 2 QoS profile sets that matter
/// between two DDS participants (rmw `rmw_qos_profile_t`: reliability, durability,
/// history and depth; deadline, lifespan and liveliness keep DDS's defaults, which are
/// also ROS 2's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (else best effort).
    pub reliable: bool,
    /// Transient local (else volatile): a writer keeps its last `depth` samples for
    /// readers that join later, and a transient-local reader asks for them.
    pub transient_local: bool,
    /// Keep all samples (else keep last `depth`).
    pub keep_all: bool,
    /// Keep last `depth` samples.
    pub depth: i32,
}

/// The largest `depth` taken (rmw takes a `size_t`; DDS an `int32`).
pub const MAX_DEPTH: i32 = 1 << 20;

impl Qos {
    /// ROS 2's default profile (`rmw_qos_profile_default`): reliable, volatile, keep
    /// last 10.
    pub fn ros_default() -> Qos {
        Qos {
            reliable: true,
            transient_local: false,
            keep_all: false,
            depth: 10,
        }
    }

    /// Sets one policy by ROS 2's names for it, the names of rclcpp's QoS overrides
    /// (`qos_overrides./topic.publisher.reliability`, ROS 2 design article "ROS 2 QoS
    /// configurability") and of `ros2 bag record --qos-profile-overrides-path`:
    /// `reliability` = `reliable` | `best_effort`, `durability` = `volatile` |
    /// `transient_local`, `history` = `keep_last` | `keep_all`, `depth` = a count from 1.
    /// `system_default` keeps ROS 2's default.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), DdsError> {
        let bad = |expected| DdsError::Qos {
            key: key.to_string(),
            value: value.to_string(),
            expected,
        };
        let default = Qos::ros_default();
        match (key, value) {
            ("reliability", "reliable") => self.reliable = true,
            ("reliability", "best_effort") => self.reliable = false,
            ("reliability", "system_default") => self.reliable = default.reliable,
            ("reliability", _) => return Err(bad("`reliable`, `best_effort` or `system_default`")),
            ("durability", "volatile") => self.transient_local = false,
            ("durability", "transient_local") => self.transient_local = true,
            ("durability", "system_default") => self.transient_local = default.transient_local,
            ("durability", _) => {
                return Err(bad("`volatile`, `transient_local` or `system_default`"))
            }
            ("history", "keep_last") => self.keep_all = false,
            ("history", "keep_all") => self.keep_all = true,
            ("history", "system_default") => self.keep_all = default.keep_all,
            ("history", _) => return Err(bad("`keep_last`, `keep_all` or `system_default`")),
            ("depth", _) => match value.parse::<i32>() {
                Ok(d) if (1..=MAX_DEPTH).contains(&d) => self.depth = d,
                _ => return Err(bad("a count of samples from 1 to 1048576")),
            },
            _ => {
                return Err(bad(
                    "a setting `reliability`, `durability`, `history` or `depth`",
                ))
            }
        }
        Ok(())
    }

    /// Settings `key=value,key=value` ([`Qos::set`]) over `self`.
    pub fn with_list(mut self, list: &str) -> Result<Qos, DdsError> {
        for item in list.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let (k, v) = item.split_once('=').unwrap_or((item, ""));
            self.set(k.trim(), v.trim())?;
        }
        Ok(self)
    }

    /// The profile in [`Qos::set`]'s names: `reliable, volatile, keep_last 10`.
    pub fn describe(&self) -> String {
        format!(
            "{}, {}, {}",
            if self.reliable {
                "reliable"
            } else {
                "best_effort"
            },
            if self.transient_local {
                "transient_local"
            } else {
                "volatile"
            },
            if self.keep_all {
                "keep_all".to_string()
            } else {
                format!("keep_last {}", self.depth)
            }
        )
    }

    fn policies(self) -> QosPolicies {
        let reliability = if self.reliable {
            Reliability::Reliable {
                max_blocking_time: rustdds::Duration::from_millis(100),
            }
        } else {
            Reliability::BestEffort
        };
        let durability = if self.transient_local {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        };
        let history = if self.keep_all {
            History::KeepAll
        } else {
            History::KeepLast {
                depth: self.depth.max(1),
            }
        };
        QosPolicyBuilder::new()
            .reliability(reliability)
            .durability(durability)
            .history(history)
            .build()
    }
}

/// The pause between two writers of one participant (see [`Participant::writer`]).
pub(crate) const WRITER_PACE: std::time::Duration = std::time::Duration::from_millis(50);

/// A DDS participant on one domain, with one subscriber and one publisher.
pub struct Participant {
    /// Writers created so far.
    writers: std::cell::Cell<usize>,
    // Readers and writers hold their own handles; the participant outlives them in use.
    dp: DomainParticipant,
    subscriber: rustdds::Subscriber,
    publisher: rustdds::Publisher,
}

/// One sample taken from a [`Reader`].
#[derive(Clone, Debug)]
pub struct Received {
    /// The writer's GUID: a new one on a topic is a new (or restarted) publisher.
    pub writer: [u8; 16],
    /// The writer's sequence number (from 1, one more per sample written).
    pub seq: i64,
    /// The CDR bytes with their 4-byte header.
    pub data: Vec<u8>,
    /// When the writer wrote it (its source timestamp, RTPS `INFO_TS`), in nanoseconds
    /// since the UNIX epoch on the writer's clock; `None` when the writer sent none.
    pub source_ns: Option<u64>,
}

/// An RTPS time (seconds and 2^-32 fractions since the UNIX epoch, RTPS 2.3 9.3.2.1)
/// in nanoseconds; `None` for the reserved zero, invalid and infinite times.
fn rtps_nanos(t: rustdds::Timestamp) -> Option<u64> {
    if t == rustdds::Timestamp::ZERO
        || t == rustdds::Timestamp::INVALID
        || t == rustdds::Timestamp::INFINITE
    {
        return None;
    }
    let ticks = t.to_ticks();
    let frac = ((ticks & 0xFFFF_FFFF) * 1_000_000_000) >> 32;
    Some((ticks >> 32) * 1_000_000_000 + frac)
}

/// A keyless reader of one ROS topic.
pub struct Reader {
    reader: DataReader<Raw, RawAdapter>,
    /// The DDS topic name.
    pub dds_topic: String,
}

/// A keyless writer of one ROS topic.
pub struct Writer {
    writer: DataWriter<Raw, RawAdapter>,
    /// Readers matched, from the last publication-matched status.
    matched: std::cell::Cell<usize>,
    /// The DDS topic name.
    pub dds_topic: String,
}

fn dds_err<E: std::fmt::Debug>(what: String) -> impl FnOnce(E) -> DdsError {
    move |e| DdsError::Stack {
        what,
        error: format!("{e:?}"),
    }
}

impl Participant {
    /// Joins domain `domain` (see [`domain_id`]).
    pub fn new(domain: u16) -> Result<Participant, DdsError> {
        let dp = DomainParticipant::new(domain)
            .map_err(dds_err(format!("cannot join domain {domain}")))?;
        let qos = QosPolicyBuilder::new().build();
        let subscriber = dp
            .create_subscriber(&qos)
            .map_err(dds_err("subscriber".into()))?;
        let publisher = dp
            .create_publisher(&qos)
            .map_err(dds_err("publisher".into()))?;
        Ok(Participant {
            writers: std::cell::Cell::new(0),
            dp,
            subscriber,
            publisher,
        })
    }

    fn topic(&self, name: &str, ty: String, qos: Qos) -> Result<rustdds::Topic, DdsError> {
        self.dp
            .create_topic(name.to_string(), ty, &qos.policies(), TopicKind::NoKey)
            .map_err(dds_err(format!("topic `{name}`")))
    }

    /// A reader of ROS topic `ros_topic` (`/a/b`) of type `ros_type` (`pkg/msg/Type`).
    pub fn reader(&self, ros_topic: &str, ros_type: &str, qos: Qos) -> Result<Reader, DdsError> {
        self.dds_reader(&topic_name(ros_topic), type_name(ros_type)?, qos)
    }

    /// A reader of the DDS topic `dds_topic` of DDS type `dds_type`, named as DDS names
    /// them (a service's `rq/<s>Request`, see [`service_topics`]).
    pub fn dds_reader(
        &self,
        dds_topic: &str,
        dds_type: String,
        qos: Qos,
    ) -> Result<Reader, DdsError> {
        let topic = self.topic(dds_topic, dds_type, qos)?;
        let reader = self
            .subscriber
            .create_datareader_no_key::<Raw, RawAdapter>(&topic, Some(qos.policies()))
            .map_err(dds_err(format!("reader of `{dds_topic}`")))?;
        Ok(Reader {
            reader,
            dds_topic: dds_topic.to_string(),
        })
    }

    /// A writer of ROS topic `ros_topic` of type `ros_type`.
    ///
    /// Writers are created at most one per `WRITER_PACE`: rustdds 0.13's
    /// `create_datawriter` holds its discovery database's write lock while it hands the
    /// writer to the participant's event loop over a channel of 10, and that loop takes
    /// the same lock to drain it; creating writers faster than the loop drains them
    /// deadlocks the process (seen with the museum's 21 writers on a loaded machine).
    pub fn writer(&self, ros_topic: &str, ros_type: &str, qos: Qos) -> Result<Writer, DdsError> {
        self.dds_writer(&topic_name(ros_topic), type_name(ros_type)?, qos)
    }

    /// A writer of the DDS topic `dds_topic` of DDS type `dds_type` (see
    /// [`Participant::dds_reader`]), paced as [`Participant::writer`].
    pub fn dds_writer(
        &self,
        dds_topic: &str,
        dds_type: String,
        qos: Qos,
    ) -> Result<Writer, DdsError> {
        if self.writers.get() > 0 {
            std::thread::sleep(WRITER_PACE);
        }
        self.writers.set(self.writers.get() + 1);
        let topic = self.topic(dds_topic, dds_type, qos)?;
        let writer = self
            .publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&topic, Some(qos.policies()))
            .map_err(dds_err(format!("writer of `{dds_topic}`")))?;
        Ok(Writer {
            writer,
            matched: std::cell::Cell::new(0),
            dds_topic: dds_topic.to_string(),
        })
    }
}

impl Reader {
    /// Takes every sample that has arrived (never waits), appending to `out`.
    pub fn take(&mut self, out: &mut Vec<Received>) -> Result<(), DdsError> {
        loop {
            let batch = self
                .reader
                .take(64, ReadCondition::not_read())
                .map_err(dds_err(format!("take from `{}`", self.dds_topic)))?;
            let n = batch.len();
            for s in batch {
                let info = s.sample_info();
                let id = info.sample_identity();
                let source_ns = info.source_timestamp().and_then(rtps_nanos);
                out.push(Received {
                    writer: id.writer_guid.to_bytes(),
                    seq: i64::from(id.sequence_number),
                    data: s.into_value().0,
                    source_ns,
                });
            }
            if n < 64 {
                return Ok(());
            }
        }
    }
}

impl Writer {
    /// How many readers on the graph this writer is matched with (discovery found them
    /// and their QoS is compatible).
    pub fn matched(&self) -> usize {
        // rustdds 0.13 leaves `get_matched_subscriptions` unimplemented (`todo!`): the
        // count comes from the writer's publication-matched status events instead.
        use rustdds::StatusEvented;
        while let Some(s) = self.writer.try_recv_status() {
            if let rustdds::DataWriterStatus::PublicationMatched { current, .. } = s {
                self.matched
                    .set(usize::try_from(current.count()).unwrap_or(0));
            }
        }
        self.matched.get()
    }

    /// Waits up to `max_wait` until every matched reader acknowledged every sample
    /// written (reliable QoS), so a process that ends next loses none in flight; `false`
    /// when some were still unacknowledged.
    pub fn wait_acked(&self, max_wait: std::time::Duration) -> bool {
        matches!(self.writer.wait_for_acknowledgments(max_wait), Ok(true))
    }

    /// Writes one sample: little-endian CDR with its 4-byte header (never waits for a
    /// reader: keep-last history drops the oldest unacknowledged sample), stamped with
    /// the wall-clock time as its source timestamp, as ROS 2's middlewares stamp theirs.
    pub fn write(&self, cdr: &[u8]) -> Result<(), DdsError> {
        self.writer
            .write(Raw(cdr.to_vec()), Some(rustdds::Timestamp::now()))
            .map_err(dds_err(format!("write to `{}`", self.dds_topic)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ros_names_map_to_dds_names() {
        assert_eq!(topic_name("/battery"), "rt/battery");
        assert_eq!(topic_name("/a/b"), "rt/a/b");
        assert_eq!(
            type_name("std_msgs/Int32").unwrap(),
            "std_msgs::msg::dds_::Int32_"
        );
        assert_eq!(
            type_name("sensor_msgs/msg/BatteryState").unwrap(),
            "sensor_msgs::msg::dds_::BatteryState_"
        );
        assert_eq!(
            type_name("example_interfaces/srv/AddTwoInts_Event").unwrap(),
            "example_interfaces::srv::dds_::AddTwoInts_Event_"
        );
        for bad in ["Int32", "a/b/c/d", "std_msgs/", "std msgs/Int32", "p/foo/T"] {
            assert!(
                type_name(bad).unwrap_err().to_string().contains(bad),
                "{bad}"
            );
        }
    }

    #[test]
    fn services_map_to_request_and_reply_topics() {
        assert_eq!(
            service_topics("/adder/add"),
            (
                "rq/adder/addRequest".to_string(),
                "rr/adder/addReply".to_string()
            )
        );
        assert_eq!(
            type_name("example_interfaces/srv/AddTwoInts_Request").unwrap(),
            "example_interfaces::srv::dds_::AddTwoInts_Request_"
        );
    }

    #[test]
    fn qos_settings_take_ros_2s_names() {
        let q = Qos::ros_default()
            .with_list("reliability=best_effort, durability=transient_local,depth=1")
            .unwrap();
        assert!(!q.reliable && q.transient_local && !q.keep_all && q.depth == 1);
        assert_eq!(q.describe(), "best_effort, transient_local, keep_last 1");
        let q = q
            .with_list("history=keep_all,reliability=system_default")
            .unwrap();
        assert!(q.reliable && q.keep_all);
        assert_eq!(
            Qos::ros_default().describe(),
            "reliable, volatile, keep_last 10"
        );
        for bad in [
            "reliability=sometimes",
            "depth=0",
            "depth=x",
            "colour=red",
            "durability",
        ] {
            let e = Qos::ros_default().with_list(bad).unwrap_err().to_string();
            assert!(e.starts_with("QoS "), "{bad}: {e}");
        }
    }

    #[test]
    fn rtps_times_are_nanoseconds_since_the_epoch() {
        let t = rustdds::Timestamp::from_ticks((5u64 << 32) | (1u64 << 31));
        assert_eq!(rtps_nanos(t), Some(5_500_000_000));
        assert_eq!(rtps_nanos(rustdds::Timestamp::INVALID), None);
    }

    #[test]
    fn the_raw_adapter_keeps_the_bytes_and_the_byte_order() {
        let le = RawDecoder
            .decode_bytes(&[5, 0, 0, 0], RepresentationIdentifier::CDR_LE)
            .unwrap();
        assert_eq!(le.0, [0, 1, 0, 0, 5, 0, 0, 0]);
        let be = RawDecoder
            .decode_bytes(&[0, 0, 0, 5], RepresentationIdentifier::CDR_BE)
            .unwrap();
        assert_eq!(be.0, [0, 0, 0, 0, 0, 0, 0, 5]);
        use rustdds::no_key::SerializerAdapter;
        assert_eq!(&RawAdapter::to_bytes(&le).unwrap()[..], [5, 0, 0, 0]);
        assert!(RawAdapter::to_bytes(&be).is_err());
    }
}
