//! `hindsight monitor --ros2 PROPS`: the properties `replay` checks on a recording,
//! judged live on a ROS 2 graph over DDS (see [`crate::live::dds`]).
//!
//! `PROPS` is what `replay` takes: a property file over ROS names (its `<ros_topic>` /
//! `<ros_service>` ports name topic and type), or a `.hspec` spec with `--bind
//! VAR=/topic.field` and `--topic-type /topic=pkg/msg/Type` (DDS needs the type to
//! subscribe). A service port reads the service's introspection events
//! (`/<service>/_service_event`), as it does in a recording.

use crate::{codegen, ros2};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;
use std::time::Duration;

use ros2::feed::{Port as BagPort, TopicFeed};

use super::monitor::MonitorArgs;
use super::replay::{bind_ports, discover_packages, file_ports, load_props_at, Packages};
use super::CliError;
use crate::live;
use crate::live::dds::{Settings, TopicSource};
use crate::props::PropertyFile;

/// A property file's tick on DDS when `--time-unit` does not name one: 1 ms.
const DEFAULT_UNIT_NS: u64 = 1_000_000;

/// Set by SIGINT / SIGTERM: the monitor flushes its outputs and exits 0.
static STOP: AtomicBool = AtomicBool::new(false);

/// The flag SIGINT / SIGTERM set, the handler installed on the first call (`monitor
/// --ros2`, `run --ros2`).
pub(crate) fn stop_flag() -> &'static AtomicBool {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        // ctrlc runs this on its own thread: only the flag is set here.
        let _ = ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed));
    });
    &STOP
}

/// A ROS type as DDS and the recordings name it: `pkg/msg/Type`, or for a service port
/// the service's event type `pkg/srv/Name_Event`.
fn full_type(written: &str, service: bool) -> Result<String, ros2::schema::SchemaError> {
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

/// Runs `hindsight monitor --ros2 PROPS`.
pub fn run(
    args: &MonitorArgs,
    props_path: &Path,
    serve: Option<std::net::SocketAddr>,
) -> Result<(), CliError> {
    let input = |m: String| CliError::Input(m);
    if args.config.is_some() {
        return Err(input(
            "--config is for iceoryx2 topics; --ros2 reads the topics PROPS names".into(),
        ));
    }
    let props = load_props_at(
        props_path,
        args.time_unit.as_deref(),
        DEFAULT_UNIT_NS,
        !args.bind.is_empty(),
    )?;
    let spec = &props.compiled;
    // Each port, its topic's type and the QoS its port names.
    let mut port_qos: Vec<Vec<(String, String)>> = Vec::new();
    let (ports, types): (Vec<BagPort>, Vec<Option<String>>) = match &props.file {
        Some(file) => {
            let ports = file_ports(file, spec)?;
            let declared = file_types(file);
            port_qos = declared
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
                .map_err(|e| input(e.to_string()))?;
            (ports, types)
        }
        None => {
            if !args.topic_type.is_empty() && args.bind.is_empty() {
                return Err(input("--topic-type goes with --bind".into()));
            }
            let ports = bind_ports(&args.bind, spec)?;
            let mut named: BTreeMap<String, String> = BTreeMap::new();
            for t in &args.topic_type {
                let Some((topic, ty)) = t.split_once('=') else {
                    return Err(input(format!(
                        "--topic-type {t}: expected /topic=pkg/msg/Type"
                    )));
                };
                named.insert(topic.trim().to_string(), ty.trim().to_string());
            }
            let types = ports
                .iter()
                .map(|p| match named.get(&p.topic) {
                    Some(t) => full_type(t, p.service.is_some())
                        .map(Some)
                        .map_err(|e| format!("--topic-type {}={t}: {e}", p.topic)),
                    None => Err(format!(
                        "--bind: DDS needs the type of `{}`: add --topic-type {}=pkg/msg/Type",
                        p.topic, p.topic
                    )),
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(input)?;
            (ports, types)
        }
    };
    if ports.is_empty() {
        return Err(input(format!(
            "{}: no variable reads a topic, so there is nothing to monitor",
            props_path.display()
        )));
    }
    // `--qos /topic=settings`, over what the ports name.
    let mut qos_flags: BTreeMap<String, String> = BTreeMap::new();
    for q in &args.qos {
        let Some((topic, settings)) = q.split_once('=') else {
            return Err(input(format!(
                "--qos {q}: expected /topic=reliability=best_effort,durability=transient_local,..."
            )));
        };
        let topic = topic.trim().to_string();
        ros2::dds::Qos::ros_default()
            .with_list(settings)
            .map_err(|e| input(format!("--qos {q}: {e}")))?;
        if !ports.iter().any(|p| p.recorded_topic() == topic) {
            return Err(input(format!("--qos {q}: no port reads `{topic}`")));
        }
        let all = qos_flags.entry(topic).or_default();
        all.push(',');
        all.push_str(settings);
    }
    // One reader per topic as recorded, with one type and one QoS.
    let mut topics: Vec<(String, String, ros2::dds::Qos)> = Vec::new();
    for (i, (p, t)) in ports.iter().zip(&types).enumerate() {
        let topic = p.recorded_topic();
        let Some(t) = t else {
            return Err(input(format!("port `{}`: its type is not written", p.name)));
        };
        let mut qos = ros2::dds::Qos::ros_default();
        for (k, v) in port_qos.get(i).map(Vec::as_slice).unwrap_or_default() {
            qos.set(k, v)
                .map_err(|e| input(format!("port `{}`: {e}", p.name)))?;
        }
        match topics.iter().find(|(name, _, _)| *name == topic) {
            Some((_, other, _)) if other != t => {
                return Err(input(format!(
                    "topic `{topic}` is read as `{other}` and as `{t}`: one topic has one type"
                )))
            }
            Some((_, _, other)) if *other != qos => {
                return Err(input(format!(
                    "topic `{topic}` is read with QoS {} and with {}: one topic has one reader \
                     (name the same QoS on every port of it)",
                    other.describe(),
                    qos.describe()
                )))
            }
            Some(_) => {}
            None => topics.push((topic, t.clone(), qos)),
        }
    }
    for (topic, _, qos) in &mut topics {
        if let Some(list) = qos_flags.get(topic.as_str()) {
            *qos = qos.with_list(list).map_err(|e| input(e.to_string()))?;
        }
    }
    let packages = discover_packages(props_path, args.interfaces.clone())?;
    let defs = Packages(packages);
    let mut sources = Vec::new();
    for (topic, type_name, qos) in topics {
        let feed = TopicFeed::new(&topic, &type_name, &ports, &defs, spec.strings())
            .map_err(|e| input(format!("topic `{topic}`: {e}")))?;
        let schema = ros2::schema::Schema::resolve(&type_name, &defs).map_err(|e| {
            input(format!(
                "topic `{topic}`: {e}: name its package's folder with --interfaces"
            ))
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
    let domain = ros2::dds::domain_id().map_err(|e| input(e.to_string()))?;
    let max_latency = match codegen::duration::parse(&args.max_latency) {
        Ok(ns) => Duration::from_nanos(ns),
        Err(m) => return Err(input(format!("--max-latency {}: {m}", args.max_latency))),
    };
    let speed = match args.speed {
        Some(s) => live::check_speed(s).map_err(|m| input(format!("--speed: {m}")))?,
        None => 1.0,
    };
    // A heartbeat every tick, but not more often than every millisecond of real time.
    let tick = spec.tick_ns().max(1);
    let heartbeat = (1_000_000f64 * speed / tick as f64).ceil().max(1.0) as u64;
    let settings = Settings {
        domain,
        heartbeat,
        speed,
        from_first_message: args.from_first_message,
        max_latency,
    };
    let mcap = args
        .record
        .as_deref()
        .map(ros2::write::McapWriter::create)
        .transpose()
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let mut out: Box<dyn Write + Send> = match &args.output {
        Some(p) => super::monitor::create(p)?,
        None => Box::new(std::io::stdout()),
    };
    let mut record: Option<Box<dyn Write + Send>> = None;
    if let Some(addr) = serve {
        let title = props_path.display().to_string();
        let server = live::serve::serve(
            addr,
            live::serve::page(&title, spec),
            args.serve_public,
            live::http::Limits::default(),
        )
        .map_err(|e| CliError::Failed(format!("--serve {addr}: {e}")))?;
        eprintln!("monitor: live page at http://{}/", server.addr);
        use live::serve::{Stream, Tee};
        out = Box::new(Tee::new(out, server.hub.clone(), Stream::Verdict));
        // The page's points are the input records, written for the page alone.
        record = Some(Box::new(Tee::new(
            Box::new(std::io::sink()),
            server.hub,
            Stream::Input,
        )));
    }
    let mut opts = super::monitor::options(args, out, record);
    live::dds::run(spec, sources, &settings, &mut opts, mcap, stop_flag())
        .map(|_| ())
        .map_err(|e| CliError::Failed(e.to_string()))
}
