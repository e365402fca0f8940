//! The DDS readers of `monitor --ros2`: one per topic the ports read, each with its one
//! ROS type and QoS, from a property file's `<ros_topic>` / `<ros_service>` declarations
//! or from `--bind` and `--topic-type` over a `.hspec` spec, `--qos` on top.
//!
//! [`plan`] checks what the ports ask for (one type and one QoS per topic, every type
//! resolvable) and builds the [`TopicSource`]s that [`crate::dds::run`] reads.

use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

use codegen::Compiled;
use ros2::dds::{DdsError, Qos};
use ros2::feed::{PlanError, Port, TopicFeed};
use ros2::schema::{Schema, SchemaError};

use crate::dds::TopicSource;
use crate::props::PropertyFile;
use crate::recording::{bind_ports, file_ports, BindError, PackageErrors, Packages, PortError};

/// What the monitor's readers are planned from.
pub struct ReaderInput<'a> {
    /// The properties' file (its name in errors, and where interface packages are
    /// looked for beside and above).
    pub path: &'a std::path::Path,
    /// The property file read, or `None` for a `.hspec` spec.
    pub file: Option<&'a PropertyFile>,
    /// The compiled properties.
    pub compiled: &'a Compiled,
    /// `--bind VAR=SOURCE` (a `.hspec` spec's variables).
    pub bind: &'a [String],
    /// `--topic-type /topic=pkg/msg/Type` (with `--bind`).
    pub topic_type: &'a [String],
    /// `--qos /topic=SETTINGS`.
    pub qos: &'a [String],
    /// `--interfaces DIR`, searched first for the types.
    pub interfaces: Vec<PathBuf>,
}

/// Why the readers cannot be planned. `Display` gives the message `monitor --ros2` prints.
#[derive(Debug)]
pub enum ReaderError {
    /// A property file's port that no topic can feed.
    Port(PortError),
    /// A `--bind` option that does not bind.
    Bind(BindError),
    /// A type name that is not `pkg/Type` or `pkg/msg/Type`; `flag` is the
    /// `--topic-type` option it came from, if any.
    TypeName {
        /// The `--topic-type` option as given, if the type came from one.
        flag: Option<String>,
        /// Why the name is refused.
        error: SchemaError,
    },
    /// A `--topic-type` option that is not `/topic=pkg/msg/Type`.
    TopicTypeSyntax(String),
    /// A bound topic whose type no `--topic-type` names.
    NoTopicType(String),
    /// No variable reads a topic (the properties' file named).
    NothingToMonitor(PathBuf),
    /// A `--qos` option that is not `/topic=SETTINGS`.
    QosSyntax(String),
    /// A `--qos` option whose settings do not read.
    QosFlag {
        /// The option as given.
        flag: String,
        /// Why.
        error: DdsError,
    },
    /// A `--qos` option naming a topic no port reads.
    QosTopic {
        /// The option as given.
        flag: String,
        /// The topic.
        topic: String,
    },
    /// A port whose type is not written.
    Untyped(String),
    /// A port whose QoS settings do not read.
    PortQos {
        /// The port.
        port: String,
        /// Why.
        error: DdsError,
    },
    /// Two ports read one topic as two types.
    TwoTypes {
        /// The topic.
        topic: String,
        /// The first type.
        first: String,
        /// The other.
        second: String,
    },
    /// Two ports read one topic with two QoS.
    TwoQos {
        /// The topic.
        topic: String,
        /// The first QoS, described.
        first: String,
        /// The other.
        second: String,
    },
    /// `--qos` settings that do not apply to a topic's QoS.
    Qos(DdsError),
    /// Interface packages that do not read.
    Packages(PackageErrors),
    /// A topic whose ports its type cannot feed.
    Feed {
        /// The topic.
        topic: String,
        /// Why.
        error: PlanError,
    },
    /// A topic whose type does not resolve.
    Schema {
        /// The topic.
        topic: String,
        /// Why.
        error: SchemaError,
    },
}

impl ReaderError {
    /// Whether the fault is the program's rather than the input's.
    pub fn is_internal(&self) -> bool {
        matches!(self, ReaderError::Port(p) if p.is_internal())
    }
}

impl fmt::Display for ReaderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReaderError::Port(e) => e.fmt(f),
            ReaderError::Bind(e) => e.fmt(f),
            ReaderError::TypeName { flag: None, error } => error.fmt(f),
            ReaderError::TypeName {
                flag: Some(flag),
                error,
            } => write!(f, "--topic-type {flag}: {error}"),
            ReaderError::TopicTypeSyntax(t) => {
                write!(f, "--topic-type {t}: expected /topic=pkg/msg/Type")
            }
            ReaderError::NoTopicType(topic) => write!(
                f,
                "--bind: DDS needs the type of `{topic}`: add --topic-type {topic}=pkg/msg/Type"
            ),
            ReaderError::NothingToMonitor(path) => write!(
                f,
                "{}: no variable reads a topic, so there is nothing to monitor",
                path.display()
            ),
            ReaderError::QosSyntax(q) => write!(
                f,
                "--qos {q}: expected /topic=reliability=best_effort,durability=transient_local,..."
            ),
            ReaderError::QosFlag { flag, error } => write!(f, "--qos {flag}: {error}"),
            ReaderError::QosTopic { flag, topic } => {
                write!(f, "--qos {flag}: no port reads `{topic}`")
            }
            ReaderError::Untyped(port) => write!(f, "port `{port}`: its type is not written"),
            ReaderError::PortQos { port, error } => write!(f, "port `{port}`: {error}"),
            ReaderError::TwoTypes {
                topic,
                first,
                second,
            } => write!(
                f,
                "topic `{topic}` is read as `{first}` and as `{second}`: one topic has one type"
            ),
            ReaderError::TwoQos {
                topic,
                first,
                second,
            } => write!(
                f,
                "topic `{topic}` is read with QoS {first} and with {second}: one topic has one \
                 reader (name the same QoS on every port of it)"
            ),
            ReaderError::Qos(e) => e.fmt(f),
            ReaderError::Packages(e) => e.fmt(f),
            ReaderError::Feed { topic, error } => write!(f, "topic `{topic}`: {error}"),
            ReaderError::Schema { topic, error } => write!(
                f,
                "topic `{topic}`: {error}: name its package's folder with --interfaces"
            ),
        }
    }
}

impl std::error::Error for ReaderError {}

/// A ROS type as DDS and the recordings name it: `pkg/msg/Type`, or for a service port
/// the service's event type `pkg/srv/Name_Event`.
fn full_type(written: &str, service: bool) -> Result<String, SchemaError> {
    let (pkg, name) = ros2::schema::split_type_name(written)?;
    Ok(if service {
        format!("{pkg}/srv/{name}_Event")
    } else {
        format!("{pkg}/msg/{name}")
    })
}

/// A port's declared type, whether it is a service's, and the QoS it names.
type Declared = (String, bool, Vec<(String, String)>);

/// The type of each port of a property file: the `type` of the `<ros_topic>` or
/// `<ros_service>` element that declares it, with the QoS it names. The reader records
/// one type per element, at its start tag, before the element's variables: a port's
/// type is the last one written before it.
fn file_types(file: &PropertyFile) -> Vec<Option<Declared>> {
    file.ports
        .iter()
        .map(|p| {
            let at = (p.at.line, p.at.column);
            file.ros_types
                .iter()
                .rev()
                .find(|t| (t.at.line, t.at.column) < at)
                .map(|t| (t.type_name.clone(), t.service, t.qos.clone()))
        })
        .collect()
}

/// Each port, its full type if known, and the QoS its port names.
type Typed = (Vec<Port>, Vec<Option<String>>, Vec<Vec<(String, String)>>);

/// The ports of the properties and their types: a property file's declarations, or
/// `--bind` with `--topic-type`.
fn typed_ports(input: &ReaderInput<'_>) -> Result<Typed, ReaderError> {
    let spec = input.compiled;
    if let Some(file) = input.file {
        let ports = file_ports(file, spec).map_err(ReaderError::Port)?;
        let declared = file_types(file);
        let port_qos = declared
            .iter()
            .map(|t| t.as_ref().map(|t| t.2.clone()).unwrap_or_default())
            .collect();
        let types = declared
            .into_iter()
            .zip(&ports)
            .map(|(t, p)| {
                t.map(|(name, service, _)| full_type(&name, service || p.service.is_some()))
                    .transpose()
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|error| ReaderError::TypeName { flag: None, error })?;
        return Ok((ports, types, port_qos));
    }
    let ports = bind_ports(input.bind, spec).map_err(ReaderError::Bind)?;
    let mut named: BTreeMap<String, String> = BTreeMap::new();
    for t in input.topic_type {
        let Some((topic, ty)) = t.split_once('=') else {
            return Err(ReaderError::TopicTypeSyntax(t.clone()));
        };
        named.insert(topic.trim().to_string(), ty.trim().to_string());
    }
    let types = ports
        .iter()
        .map(|p| match named.get(&p.topic) {
            Some(t) => full_type(t, p.service.is_some())
                .map(Some)
                .map_err(|error| ReaderError::TypeName {
                    flag: Some(format!("{}={t}", p.topic)),
                    error,
                }),
            None => Err(ReaderError::NoTopicType(p.topic.clone())),
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((ports, types, Vec::new()))
}

/// One reader per topic the properties read, each with its type, the variables it sets
/// and its QoS (ROS 2's default, what the ports name, then `--qos`).
pub fn plan(input: ReaderInput<'_>) -> Result<Vec<TopicSource>, ReaderError> {
    let spec = input.compiled;
    let (ports, types, port_qos) = typed_ports(&input)?;
    if ports.is_empty() {
        return Err(ReaderError::NothingToMonitor(input.path.to_path_buf()));
    }
    // `--qos /topic=settings`, over what the ports name.
    let mut qos_flags: BTreeMap<String, String> = BTreeMap::new();
    for q in input.qos {
        let Some((topic, settings)) = q.split_once('=') else {
            return Err(ReaderError::QosSyntax(q.clone()));
        };
        let topic = topic.trim().to_string();
        Qos::ros_default()
            .with_list(settings)
            .map_err(|error| ReaderError::QosFlag {
                flag: q.clone(),
                error,
            })?;
        if !ports.iter().any(|p| p.recorded_topic() == topic) {
            return Err(ReaderError::QosTopic {
                flag: q.clone(),
                topic,
            });
        }
        let all = qos_flags.entry(topic).or_default();
        all.push(',');
        all.push_str(settings);
    }
    // One reader per topic as recorded, with one type and one QoS.
    let mut topics: Vec<(String, String, Qos)> = Vec::new();
    for (i, (p, t)) in ports.iter().zip(&types).enumerate() {
        let topic = p.recorded_topic();
        let Some(t) = t else {
            return Err(ReaderError::Untyped(p.name.clone()));
        };
        let mut qos = Qos::ros_default();
        for (k, v) in port_qos.get(i).map(Vec::as_slice).unwrap_or_default() {
            qos.set(k, v).map_err(|error| ReaderError::PortQos {
                port: p.name.clone(),
                error,
            })?;
        }
        match topics.iter().find(|(name, _, _)| *name == topic) {
            Some((_, other, _)) if other != t => {
                return Err(ReaderError::TwoTypes {
                    topic,
                    first: other.clone(),
                    second: t.clone(),
                })
            }
            Some((_, _, other)) if *other != qos => {
                return Err(ReaderError::TwoQos {
                    topic,
                    first: other.describe(),
                    second: qos.describe(),
                })
            }
            Some(_) => {}
            None => topics.push((topic, t.clone(), qos)),
        }
    }
    for (topic, _, qos) in &mut topics {
        if let Some(list) = qos_flags.get(topic.as_str()) {
            *qos = qos.with_list(list).map_err(ReaderError::Qos)?;
        }
    }
    let defs = Packages::discover(input.path, input.interfaces).map_err(ReaderError::Packages)?;
    let mut sources = Vec::new();
    for (topic, type_name, qos) in topics {
        let feed =
            TopicFeed::new(&topic, &type_name, &ports, &defs, spec.strings()).map_err(|error| {
                ReaderError::Feed {
                    topic: topic.clone(),
                    error,
                }
            })?;
        let schema = Schema::resolve(&type_name, &defs).map_err(|error| ReaderError::Schema {
            topic: topic.clone(),
            error,
        })?;
        let vars = ports
            .iter()
            .filter(|p| p.recorded_topic() == topic)
            .map(|p| p.name.clone())
            .collect();
        sources.push(TopicSource {
            topic,
            type_name,
            feed,
            vars,
            schema_text: schema.ros2msg_text(),
            qos,
        });
    }
    Ok(sources)
}
