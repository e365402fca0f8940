//! `hindsight monitor --ros2 PROPS`: the properties `replay` checks on a recording,
//! judged live on a ROS 2 graph over DDS (see [`crate::live::dds`]).
//!
//! `PROPS` is what `replay` takes: a property file over ROS names (its `<ros_topic>` /
//! `<ros_service>` ports name topic and type), or a `.hspec` spec with `--bind
//! VAR=/topic.field` and `--topic-type /topic=pkg/msg/Type` (DDS needs the type to
//! subscribe). A service port reads the service's introspection events
//! (`/<service>/_service_event`), as it does in a recording.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;
use std::time::Duration;

use super::monitor::MonitorArgs;
use super::replay::load_props_at;
use super::CliError;
use crate::codegen;
use crate::live;
use crate::live::dds::Settings;
use crate::live::readers::{plan, ReaderInput};

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
    if props.file.is_none() && !args.topic_type.is_empty() && args.bind.is_empty() {
        return Err(input("--topic-type goes with --bind".into()));
    }
    let sources = plan(ReaderInput {
        path: props_path,
        file: props.file.as_ref(),
        compiled: spec,
        bind: &args.bind,
        topic_type: &args.topic_type,
        qos: &args.qos,
        interfaces: args.interfaces.clone(),
    })
    .map_err(|e| {
        if e.is_internal() {
            CliError::Failed(e.to_string())
        } else {
            input(e.to_string())
        }
    })?;
    let domain = live::dds::domain_id().map_err(|e| input(e.to_string()))?;
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
        .map(live::dds::McapWriter::create)
        .transpose()
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let mut out: Box<dyn Write + Send> = match &args.output {
        Some(p) => super::monitor::create(p)?,
        None => Box::new(std::io::stdout()),
    };
    let mut record: Option<Box<dyn Write + Send>> = None;
    if let Some(addr) = serve {
        let title = props_path.display().to_string();
        let (o, r) = super::monitor::serve_page(addr, args.serve_public, &title, spec, out, None)?;
        (out, record) = (o, Some(r));
    }
    let mut opts = super::monitor::options(args, out, record);
    live::dds::run(spec, sources, &settings, &mut opts, mcap, stop_flag())
        .map(|_| ())
        .map_err(|e| CliError::Failed(e.to_string()))
}
