//! `hindsight monitor`: the on-line sidecar over iceoryx2, its off-line replay and its benchmark.

use crate::codegen;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use codegen::Compiled;

use super::verify::{load, ModelArgs};
use super::{compile_spec_file, read_file, CliError};
use crate::live::{self, config::Config, Options, Sidecar};

/// Arguments of `hindsight monitor`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct MonitorArgs {
    /// The properties: a spec (`.hspec`) whose unit is the clock's tick. A folder or an
    /// `.xml` file here is read as a model, as with --model.
    #[arg(long, value_name = "SPEC", required_unless_present_any = ["bench", "model", "ros2"], conflicts_with_all = ["model", "ros2"])]
    pub props: Option<PathBuf>,
    /// Monitor the guarantees of a model's property file, compiled exactly as `verify`
    /// compiles them (variables: the ports' ids; tick: the model's time unit). MODEL is a
    /// robot main file, a folder holding `main.xml`, or a plain SCXML model (with
    /// --time-unit). Assumptions are not monitored.
    #[arg(long, value_name = "MODEL")]
    pub model: Option<PathBuf>,
    /// With --model: the property file; default: the one the main file names, else
    /// MODEL/properties.xml.
    #[arg(long, value_name = "FILE")]
    pub model_props: Option<PathBuf>,
    /// With a robot --model: a folder of ROS interface packages, searched first (repeat
    /// for more); as for `verify`.
    #[arg(long = "interfaces", value_name = "DIR")]
    pub interfaces: Vec<PathBuf>,
    /// With a plain SCXML --model: the length of one model time step (`100ms`). With
    /// --ros2 and a property file: the monitor's tick (default 1ms), to which the bounds
    /// are converted exactly.
    #[arg(long, value_name = "DURATION")]
    pub time_unit: Option<String>,
    /// The sidecar config (TOML): topics to tap, services to proxy, payload layouts.
    #[arg(long, value_name = "FILE", required_unless_present_any = ["replay", "bench", "ros2"])]
    pub config: Option<PathBuf>,
    /// Live ROS 2 over DDS: judge PROPS (a property file over ROS names, as `replay`
    /// reads it, or a `.hspec` with --bind and --topic-type) on the topics it names, as
    /// a plain DDS participant (no ROS install): topics `rt/<name>`, ROS 2's type names
    /// and default QoS (reliable, volatile, keep last 10), the domain of ROS_DOMAIN_ID.
    /// --record FILE.mcap writes what was received as an MCAP file that `replay` reads.
    #[arg(long, value_name = "PROPS", conflicts_with_all = ["model", "config", "replay", "bench"])]
    pub ros2: Option<PathBuf>,
    /// With --ros2 and a `.hspec`: bind variable VAR to `/topic.field.path`, `/topic`
    /// (true at each message) or `/service:request.field` (`:response`), as for `replay`.
    #[arg(long = "bind", value_name = "VAR=SOURCE", requires = "ros2")]
    pub bind: Vec<String>,
    /// With --ros2 and --bind: the ROS type of a topic (`/battery=std_msgs/msg/Int32`;
    /// for a service, its `.srv` type); repeat for more.
    #[arg(long = "topic-type", value_name = "TOPIC=TYPE", requires = "ros2")]
    pub topic_type: Vec<String>,
    /// With --ros2: the QoS of a topic's reader, in ROS 2's names, over what its port
    /// names (`/battery=reliability=best_effort,durability=transient_local,depth=1`;
    /// settings `reliability`, `durability`, `history`, `depth`). Default: ROS 2's
    /// (reliable, volatile, keep last 10) or the `<ros_topic>` port's attributes.
    #[arg(long = "qos", value_name = "TOPIC=SETTINGS", requires = "ros2")]
    pub qos: Vec<String>,
    /// With --ros2: a sample whose source timestamp (the writer's clock) is more than
    /// this before a point already judged arrived late: the properties reading its
    /// topic are `unknown` from it, as after a lost sample (`0s`: never late).
    #[arg(
        long,
        value_name = "DURATION",
        default_value = "100ms",
        requires = "ros2"
    )]
    pub max_latency: String,
    /// Off-line: replay an input log written by `--record` and print its verdicts.
    #[arg(long, value_name = "LOG", conflicts_with_all = ["config", "record", "bench"])]
    pub replay: Option<PathBuf>,
    /// Verdict JSON lines to this file instead of standard output.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Serve a live page of the verdicts at ADDR (PORT, :PORT or HOST:PORT; a bare port
    /// listens on loopback only): open http://ADDR/ in a browser to watch every
    /// property's verdict and its timeline as verdicts arrive. The verdict output is
    /// written first and is complete whatever the page does. Port 0 picks a free port;
    /// the address is printed on standard error. An address beyond loopback needs
    /// --serve-public.
    #[arg(long, value_name = "ADDR", conflicts_with_all = ["replay", "bench"])]
    pub serve: Option<String>,
    /// Let --serve listen beyond loopback (`0.0.0.0:8080`, a LAN address): anyone who
    /// reaches that address sees the verdicts and inputs, without a password. Requests
    /// must name this machine (an IP address, `localhost` or its host name).
    #[arg(long, requires = "serve")]
    pub serve_public: bool,
    /// Write every judged input (samples, requests, heartbeats, losses) as JSON lines, for
    /// `--replay`. With --ros2: every sample received, as an MCAP file (ROS 2 profile)
    /// that `hindsight replay PROPS FILE.mcap` and the MCAP tools read.
    #[arg(long, value_name = "LOG")]
    pub record: Option<PathBuf>,
    /// The monitored system runs S times faster than real time (as `hindsight run --speed
    /// S` runs a model), so the clock counts model time: ticks = wall-clock time * S /
    /// unit, and bounds mean model seconds (with 1, wall-clock seconds). Overrides the
    /// config's `[clock] speed`. Recorded logs keep ticks of the unit, so --replay needs no speed.
    #[arg(long, value_name = "S", conflicts_with_all = ["replay", "bench"])]
    pub speed: Option<f64>,
    /// No heartbeat before the first sample or request, so a monitor started before the
    /// system does not judge the wait (its first point is the system's first message).
    /// Same as the config's `[clock] from_first_message = true`.
    #[arg(long, conflicts_with_all = ["replay", "bench"])]
    pub from_first_message: bool,
    /// Write every property's verdict at every point, not only changes.
    #[arg(long)]
    pub every_point: bool,
    /// Microseconds to sleep when nothing arrived (0: busy polling, lowest latency, one core).
    #[arg(long, value_name = "US", default_value_t = 100)]
    pub poll_us: u64,
    /// Measure samples per second and added latency against a plain subscriber, then exit.
    #[arg(long, conflicts_with_all = ["props", "model", "config", "replay"])]
    pub bench: bool,
    /// Benchmark: samples in the paced (latency) phase.
    #[arg(long, value_name = "N", default_value_t = 20_000, requires = "bench")]
    pub bench_samples: u64,
    /// Benchmark: rate of the paced phase, samples per second.
    #[arg(
        long,
        value_name = "HZ",
        default_value_t = 10_000.0,
        requires = "bench"
    )]
    pub bench_rate: f64,
    /// Benchmark: samples in the flood (throughput) phase.
    #[arg(long, value_name = "N", default_value_t = 200_000, requires = "bench")]
    pub bench_flood: u64,
}

const AFTER_HELP: &str = "\
How it works:
  Every [[topic]] of the config is an iceoryx2 publish-subscribe service with a
  `[u8]` payload of a fixed size. The monitor adds one subscriber (publishers are
  never blocked: a full buffer drops the monitor's oldest sample), stamps each
  sample with a monotonic clock in ticks of the spec's `unit`, sets the spec
  variables named by the layout, and steps the compiled monitors. Every
  [[service]] is a request-response service the monitor serves itself and
  forwards to the renamed real server (`NAME.real`); with `action = \"filter\"` a
  request that would make a listed property false is answered with the `error`
  reply and never reaches the server.

Verdicts (JSON lines, on change):
  {\"property\":\"battery_recurrence\",\"time\":12,\"verdict\":\"currently_false\",\"event\":\"museum/battery\"}
  true/false: final, no later point can change it; currently_true/currently_false:
  the verdict now; unknown: a sample the property reads was lost or malformed: the
  property restarts and is unknown for its largest time bound, then judges again.

Properties written once (--model):
  `--model examples/museum-guide` monitors the guarantees of the model's property
  file exactly as `hindsight verify` compiles them: the variables are the ports'
  ids (battery_level, battery_published, alarm, ...), the tick is the model's time
  unit (100 ms), and the bounds are in seconds as written (`within=\"1\"` is 10
  ticks). `hindsight run MODEL --layout` prints a config whose `var`/`event` names
  are those ids. Assumptions are not monitored: off-line they discard runs,
  on-line there is no run to discard.

Time: the clock counts ticks of the unit from the monitor's start. With --speed S
  (or `[clock] speed = S`) the system runs S times faster than real time, as
  `hindsight run --speed S` plays a model, and ticks = wall-clock time * S / unit:
  bounds mean model time (with S = 1, wall-clock time). Without samples, a
  heartbeat point every `[clock] heartbeat` ticks (default 1) lets a bounded
  property see its window expire (a late topic fails on time). Heartbeats start at
  once, so a recurrence fails while the monitor waits for a system started later;
  --from-first-message starts them with the first sample or request.
Loss: counted exactly from a `seq` counter in the payload, else suspected when a
  drain finds the tap's buffer full; either way the readers turn `unknown`.
Filter: a request is refused when it would turn a listed property from
  true/currently_true to false/currently_false; a refused request leaves no trace.

Robustness: a restarted publisher is picked up (the gap is reported), malformed
  samples are counted and reported, SIGINT/SIGTERM flush every file and exit 0.

Input log (--record): JSON lines, the first `{\"kind\":\"start\",\"unit_ns\":..}`, then
  every sample, request, heartbeat and loss in ticks of the unit (whatever the
  speed). --replay and `hindsight sweep MODEL --online LOG` read it back and refuse a
  log recorded in another unit.

Config example (see `hindsight::live::config` for every key):
  [[topic]]
  service = \"museum/battery\"
  size = 16
  event = \"battery_published\"
  seq = { offset = 8, type = \"u64\" }
  [[topic.field]]
  var = \"battery_level\"
  offset = 0
  type = \"i32\"

Examples:
  hindsight monitor --props museum.hspec --config museum.toml --record in.jsonl -o verdicts.jsonl
  hindsight monitor --props museum.hspec --replay in.jsonl     # the same verdicts, off-line
  hindsight monitor --props museum.hspec --config museum.toml --serve 8080
      # and open http://127.0.0.1:8080/ : every verdict and its timeline, live
      # (--serve 0.0.0.0:8080 --serve-public: the same page for the whole network)
  hindsight monitor --bench
The museum end to end, ten times faster than real time (two shells):
  hindsight run examples/museum-guide --layout > museum.toml
  hindsight monitor --model examples/museum-guide --config museum.toml --speed 10 \\
      --from-first-message --record run.jsonl
  hindsight run examples/museum-guide --speed 10 --duration 100s  # then Ctrl-C the monitor
  hindsight monitor --model examples/museum-guide --replay run.jsonl
  hindsight sweep examples/museum-guide --online run.jsonl --from 0.1s --to 7s

Live ROS 2 over DDS (--ros2): the same verdicts, losses (gaps in a writer's
  sequence numbers, samples that do not decode), restarts (a new writer) and
  heartbeats, on the topics a property file names:
  hindsight monitor --ros2 examples/museum-guide/properties.xml --record run.mcap
  hindsight replay examples/museum-guide/properties.xml run.mcap  # then, off-line
  hindsight monitor --ros2 spec.hspec --bind level=/battery.data \\
      --topic-type /battery=std_msgs/msg/Int32

Exit codes: 0 stopped by a signal, or replay/bench done; 2 bad spec, config or log; 1 iceoryx2, DDS or I/O failure.";

pub(crate) fn create(path: &PathBuf) -> Result<Box<dyn Write + Send>, CliError> {
    let f = std::fs::File::create(path)
        .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", path.display())))?;
    Ok(Box::new(std::io::BufWriter::new(f)))
}

/// Whether `--props PATH` names a model rather than a spec: a folder, or an `.xml` file.
fn is_model_path(path: &Path) -> bool {
    path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// The spec the monitor runs: `--props SPEC`, or the guarantees of `--model` (or of a
/// model given to `--props`).
fn spec_of(args: &MonitorArgs) -> Result<Compiled, CliError> {
    let model = match (&args.model, &args.props) {
        (Some(m), _) => m.clone(),
        (None, Some(p)) if is_model_path(p) => p.clone(),
        (None, Some(p)) => {
            if args.model_props.is_some() || args.time_unit.is_some() {
                return Err(CliError::Input(
                    "--model-props and --time-unit go with a model (--model MODEL)".into(),
                ));
            }
            return compile_spec_file(p);
        }
        (None, None) => {
            return Err(CliError::Input(
                "give the properties: --props SPEC or --model MODEL".into(),
            ))
        }
    };
    let from_props = args.model.is_none();
    guarantees_spec(&ModelArgs {
        model,
        props: args.model_props.clone(),
        time_unit: args.time_unit.clone(),
        events: None,
        interfaces: args.interfaces.clone(),
        ..ModelArgs::default()
    })
    .map_err(|e| match e {
        CliError::Input(m) if from_props => CliError::Input(format!(
            "{m}\nhint: --props read a folder or an .xml file as a model; a property file \
             goes with its model: --model MODEL --model-props FILE"
        )),
        other => other,
    })
}

/// The guarantees of a model's property file compiled into one spec, exactly as `verify`
/// compiles them: its variables are the ports' ids and its tick is the model's time unit.
/// Assumptions are left out (they are not monitored); a model without a time unit, or a
/// property file without guarantees, is an input error.
pub fn guarantees_spec(args: &ModelArgs) -> Result<Compiled, CliError> {
    let loaded = load(args)?;
    let props_path = loaded.props_path.clone();
    let (spec, left_out) = crate::verify::spec::guarantees(loaded, &args.model)
        .map_err(|e| CliError::Input(e.to_string()))?;
    if left_out > 0 {
        eprintln!(
            "monitor: {}: {left_out} assumption(s) not monitored (only guarantees are)",
            props_path.display()
        );
    }
    Ok(spec)
}

/// Runs `hindsight monitor`.
pub fn run(args: &MonitorArgs) -> Result<(), CliError> {
    // iceoryx2 warns on stderr about a missing config file; RUST_LOG-style `IOX2_LOG_LEVEL` overrides.
    live::quiet_ipc_log();
    if args.bench {
        let prefix = format!("hindsight-bench/{}", std::process::id());
        let r = live::bench::run(
            &prefix,
            args.bench_samples,
            args.bench_rate,
            args.bench_flood,
        )
        .map_err(|e| CliError::Failed(e.to_string()))?;
        print!("{r}");
        return Ok(());
    }
    // A bad address is refused before anything is loaded.
    let serve_addr = args
        .serve
        .as_deref()
        .map(live::serve::parse_addr)
        .transpose()
        .map_err(|m| CliError::Input(format!("--serve: {m}")))?;
    if let Some(addr) = serve_addr.filter(|a| !a.ip().is_loopback() && !args.serve_public) {
        return Err(CliError::Input(format!(
            "--serve {addr}: not a loopback address, so the page (every verdict and input, \
             without a password) would be offered to the network; add --serve-public to \
             mean it, or give a port alone (`--serve {}`) for this machine only",
            addr.port()
        )));
    }
    if let Some(props) = &args.ros2 {
        return super::monitor_ros2::run(args, props, serve_addr);
    }
    let spec = spec_of(args)?;
    let mut out: Box<dyn Write + Send> = match &args.output {
        Some(p) => create(p)?,
        None => Box::new(std::io::stdout()),
    };
    if let Some(log) = &args.replay {
        let text = read_file(log)?;
        let name = log.display().to_string();
        let (text, cut) = live::record::complete_records(&text, &name);
        if let Some(warning) = cut {
            eprintln!("{warning}");
        }
        let lines = live::record::replay(&spec, text, &name, args.every_point)
            .map_err(|e| CliError::Input(e.to_string()))?;
        let io = |e: std::io::Error| CliError::Failed(format!("output: {e}"));
        for l in lines {
            writeln!(out, "{l}").map_err(io)?;
        }
        return out.flush().map_err(io);
    }
    let Some(config_path) = &args.config else {
        return Err(CliError::Input("--config FILE is required".into()));
    };
    let text = read_file(config_path)?;
    let mut config = Config::parse(&text, &config_path.display().to_string(), &spec)?;
    config.from_first_message |= args.from_first_message;
    if let Some(s) = args.speed {
        config.speed =
            live::check_speed(s).map_err(|m| CliError::Input(format!("--speed: {m}")))?;
    }
    let mut record = args.record.as_ref().map(create).transpose()?;
    if let Some(addr) = serve_addr {
        let title = args
            .model
            .as_ref()
            .or(args.props.as_ref())
            .map_or_else(String::new, |p| p.display().to_string());
        let (o, r) = serve_page(addr, args.serve_public, &title, &spec, out, record)?;
        (out, record) = (o, Some(r));
    }
    let mut opts = options(args, out, record);
    let sidecar =
        Sidecar::new(&config, &spec, true).map_err(|e| CliError::Failed(e.to_string()))?;
    let stop = AtomicBool::new(false);
    sidecar
        .run(&config, &spec, &mut opts, &stop)
        .map(|_| ())
        .map_err(|e| CliError::Failed(e.to_string()))
}

/// Serves the live page (`--serve`) titled `title` for `spec`, says where on standard
/// error (and warns when it is offered beyond this machine), and returns the outputs with
/// the page beside them ([`live::serve::attach`]).
pub(super) fn serve_page(
    addr: std::net::SocketAddr,
    public: bool,
    title: &str,
    spec: &Compiled,
    verdicts: live::serve::Output,
    record: Option<live::serve::Output>,
) -> Result<(live::serve::Output, live::serve::Output), CliError> {
    let server = live::serve::serve(
        addr,
        live::serve::page(title, spec),
        public,
        live::http::Limits::default(),
    )
    .map_err(|e| CliError::Failed(format!("--serve {addr}: {e}")))?;
    eprintln!("monitor: live page at http://{}/", server.addr);
    if !server.addr.ip().is_loopback() {
        eprintln!(
            "monitor: warning: the live page is offered to the network at {} (every \
             interface for 0.0.0.0 or [::]): whoever reaches it sees every verdict and \
             input, without a password",
            server.addr
        );
    }
    Ok(live::serve::attach(&server, verdicts, record))
}

/// The sidecar's outputs: verdict lines to `verdicts`, the input log to `record`, notes on
/// standard error, waiting `--poll-us` when idle.
pub(super) fn options(
    args: &MonitorArgs,
    verdicts: Box<dyn Write + Send>,
    record: Option<Box<dyn Write + Send>>,
) -> Options {
    Options {
        verdicts,
        record,
        every_point: args.every_point,
        poll: Duration::from_micros(args.poll_us),
        log: Box::new(std::io::stderr()),
        probe: None,
        progress: None,
    }
}
