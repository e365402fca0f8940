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
pub fn type_name(ros_type: &str) -> Result<String, String> {
    let parts: Vec<&str> = ros_type.trim().split('/').collect();
    let (pkg, kind, name) = match parts.as_slice() {
        [p, n] => (*p, "msg", *n),
        [p, k @ ("msg" | "srv" | "action"), n] => (*p, *k, *n),
        _ => {
            return Err(format!(
                "`{ros_type}`: not a ROS type name (`pkg/Type` or `pkg/msg/Type`)"
            ))
        }
    };
    let ok = |s: &str| {
        !s.is_empty()
            && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
            && !s.as_bytes()[0].is_ascii_digit()
    };
    if !ok(pkg) || !ok(name) {
        return Err(format!(
            "`{ros_type}`: not a ROS type name (`pkg/Type` or `pkg/msg/Type`)"
        ));
    }
    Ok(format!("{pkg}::{kind}::dds_::{name}_"))
}

/// The highest domain ROS 2 allows on Linux (its port mapping leaves room for 232).
pub const MAX_DOMAIN_ID: u16 = 232;

/// The domain: `ROS_DOMAIN_ID` (a number from 0 to 232), 0 when unset or empty.
pub fn domain_id() -> Result<u16, String> {
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(s) if s.trim().is_empty() => Ok(0),
        Ok(s) => match s.trim().parse::<u16>() {
            Ok(d) if d <= MAX_DOMAIN_ID => Ok(d),
            _ => Err(format!(
                "ROS_DOMAIN_ID={s}: expected a domain from 0 to {MAX_DOMAIN_ID}"
            )),
        },
    }
}

/// The QoS of a reader or writer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (else best effort).
    pub reliable: bool,
    /// Transient local (else volatile).
    pub transient_local: bool,
    /// Keep last `depth` samples.
    pub depth: i32,
}

impl Qos {
    /// ROS 2's default profile (`rmw_qos_profile_default`): reliable, volatile, keep
    /// last 10.
    pub fn ros_default() -> Qos {
        Qos {
            reliable: true,
            transient_local: false,
            depth: 10,
        }
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
        QosPolicyBuilder::new()
            .reliability(reliability)
            .durability(durability)
            .history(History::KeepLast {
                depth: self.depth.max(1),
            })
            .build()
    }
}

/// The pause between two writers of one participant (see [`Participant::writer`]).
pub const WRITER_PACE: std::time::Duration = std::time::Duration::from_millis(50);

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

fn dds_err<E: std::fmt::Debug>(what: String) -> impl FnOnce(E) -> String {
    move |e| format!("DDS: {what}: {e:?}")
}

impl Participant {
    /// Joins domain `domain` (see [`domain_id`]).
    pub fn new(domain: u16) -> Result<Participant, String> {
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

    fn topic(&self, ros_topic: &str, ros_type: &str, qos: Qos) -> Result<rustdds::Topic, String> {
        let name = topic_name(ros_topic);
        let ty = type_name(ros_type)?;
        self.dp
            .create_topic(name.clone(), ty, &qos.policies(), TopicKind::NoKey)
            .map_err(dds_err(format!("topic `{name}`")))
    }

    /// A reader of ROS topic `ros_topic` (`/a/b`) of type `ros_type` (`pkg/msg/Type`).
    pub fn reader(&self, ros_topic: &str, ros_type: &str, qos: Qos) -> Result<Reader, String> {
        let topic = self.topic(ros_topic, ros_type, qos)?;
        let reader = self
            .subscriber
            .create_datareader_no_key::<Raw, RawAdapter>(&topic, Some(qos.policies()))
            .map_err(dds_err(format!("reader of `{}`", topic_name(ros_topic))))?;
        Ok(Reader {
            reader,
            dds_topic: topic_name(ros_topic),
        })
    }

    /// A writer of ROS topic `ros_topic` of type `ros_type`.
    ///
    /// Writers are created at most one per [`WRITER_PACE`]: rustdds 0.13's
    /// `create_datawriter` holds its discovery database's write lock while it hands the
    /// writer to the participant's event loop over a channel of 10, and that loop takes
    /// the same lock to drain it; creating writers faster than the loop drains them
    /// deadlocks the process (seen with the museum's 21 writers on a loaded machine).
    pub fn writer(&self, ros_topic: &str, ros_type: &str, qos: Qos) -> Result<Writer, String> {
        if self.writers.get() > 0 {
            std::thread::sleep(WRITER_PACE);
        }
        self.writers.set(self.writers.get() + 1);
        let topic = self.topic(ros_topic, ros_type, qos)?;
        let writer = self
            .publisher
            .create_datawriter_no_key::<Raw, RawAdapter>(&topic, Some(qos.policies()))
            .map_err(dds_err(format!("writer of `{}`", topic_name(ros_topic))))?;
        Ok(Writer {
            writer,
            matched: std::cell::Cell::new(0),
            dds_topic: topic_name(ros_topic),
        })
    }
}

impl Reader {
    /// Takes every sample that has arrived (never waits), appending to `out`.
    pub fn take(&mut self, out: &mut Vec<Received>) -> Result<(), String> {
        loop {
            let batch = self
                .reader
                .take(64, ReadCondition::not_read())
                .map_err(dds_err(format!("take from `{}`", self.dds_topic)))?;
            let n = batch.len();
            for s in batch {
                let id = s.sample_info().sample_identity();
                out.push(Received {
                    writer: id.writer_guid.to_bytes(),
                    seq: i64::from(id.sequence_number),
                    data: s.into_value().0,
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
    /// reader: keep-last history drops the oldest unacknowledged sample).
    pub fn write(&self, cdr: &[u8]) -> Result<(), String> {
        self.writer
            .write(Raw(cdr.to_vec()), None)
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
            assert!(type_name(bad).unwrap_err().contains(bad), "{bad}");
        }
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
