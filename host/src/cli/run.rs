//! `hindsight run`: one seeded simulation of a model, paced in wall-clock time, its ROS topics published over iceoryx2 (or, with `--ros2`, on DDS as a ROS 2 robot publishes them: [`crate::live::publish_dds`]).

use std::io::IsTerminal;
use std::sync::atomic::Ordering;
use std::time::Instant;

use super::progress::draw_line;
use super::verify::{load_without, ModelArgs};
use super::CliError;
use crate::live::dds::{domain_id, service_topics};
use crate::live::pace::{Paced, ProgressReports};
use crate::live::publish::layout_toml;
use crate::live::publish_dds::{DdsPaced, DdsPublisher};
use crate::live::serve_dds::DdsServices;
use crate::live::wiring::{
    dds_services, describe, node, topic_layouts, topic_qos, Bridges, DdsPlan, Wiring,
};
use crate::live::{check_speed, quiet_ipc_log, Clock};
use crate::verify::load::Loaded;
use crate::verify::replay::{end_text, play_run};

/// Arguments of `hindsight run`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = AFTER_HELP)]
pub struct RunArgs {
    /// The model and its properties, as for `verify`.
    #[command(flatten)]
    pub input: ModelArgs,
    /// Model time per wall-clock time: 1 is real time, 10 ten times faster.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub speed: f64,
    /// The study seed: the run is run `--run` of `verify --seed N` (the same seed, the same run).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub seed: u64,
    /// Which run of the study to play (run k uses xoshiro256++ stream k of the seed), e.g. a
    /// failing run that `verify --save-failing` named.
    #[arg(long, value_name = "K", default_value_t = 0)]
    pub run: u64,
    /// The prefix of every service name: topic `/a/b` is published on `PREFIX/a/b`.
    #[arg(long, value_name = "P", default_value = "hindsight")]
    pub prefix: String,
    /// Model time to run (`100s`, or steps); default: the main file's `max_time`, else 10,000 steps.
    #[arg(long, value_name = "T")]
    pub duration: Option<String>,
    /// Print each message's service and payload layout as `hindsight monitor` config (TOML),
    /// with a `[clock]` for `--speed` (model time from the first message), then exit.
    #[arg(long)]
    pub layout: bool,
    /// A node model (its `<scxml name>`) that a real process plays instead: it is left out
    /// of the run, what the process publishes on the node's topics is posted into the
    /// model, the requests of services and the goals of actions the node served go to the
    /// process, and the process may call the services and actions the node called (repeat
    /// for several).
    #[arg(long, value_name = "NAME")]
    pub external: Vec<String>,
    /// Publish on ROS 2 over DDS instead of iceoryx2: topic `/a/b` on DDS topic `rt/a/b`
    /// with type `pkg::msg::dds_::Type_`, CDR-encoded, ROS 2's default QoS, domain
    /// `ROS_DOMAIN_ID`; services as their introspection events `/<service>/_service_event`.
    #[arg(long)]
    pub ros2: bool,
    /// With --ros2: before the first step, wait (up to 60 s) until a reader on the graph
    /// subscribes to TOPIC (a ROS name, `/a/b` or `/<service>/_service_event`), then 5 s
    /// for discovery to finish on the reader's side, so that it gets the run from its
    /// first message (repeat for several).
    #[arg(long, value_name = "TOPIC", requires = "ros2")]
    pub wait_match: Vec<String>,
    /// With --ros2: the QoS of a topic's writer, in ROS 2's names
    /// (`/battery=reliability=best_effort,durability=transient_local,depth=1`; settings
    /// `reliability`, `durability`, `history`, `depth`); default ROS 2's (reliable,
    /// volatile, keep last 10). Repeat for several topics.
    #[arg(long = "qos", value_name = "TOPIC=SETTINGS", requires = "ros2")]
    pub qos: Vec<String>,
}

const AFTER_HELP: &str = "\
What it does:
  Loads the model as `hindsight verify` does and runs ONE simulation (run --run
  of `verify --seed`, the same steps up to --duration), paced so that model time t happens at wall-clock start + t / speed.
  Every message on a ROS topic (the event `topic_<name>_msg`) is published on
  the iceoryx2 publish-subscribe service `PREFIX/<topic name>` (`/` kept) as it
  is sent. Services keep iceoryx2's safe overflow: a slow subscriber loses its
  oldest samples, it never slows the run.

Payload (`[u8]`, little-endian, no padding), from the message's fields in order:
  bool: 1 byte (0/1); every integer: i64, 8 bytes; every float: f64, 8 bytes;
  strings, arrays and structs are left out (with a warning);
  then a u64 `seq`: 0, 1, 2, ... per topic, so a subscriber counts lost samples.
  std_msgs/Int32 `data` is 16 bytes: data i64 at 0, seq u64 at 8.

Services and actions are published too, as the server sees them:
  PREFIX/<service>/request and /response, PREFIX/<action>/goal, /feedback, /result.

Replacing a component by a process (--external NAME):
  The node model NAME is left out; its timers stop with it. Every topic it
  published is read from PREFIX/<topic> in the same layout (fields, then seq) and
  posted into the model at the next model time unit; the topics it subscribed to
  are published as usual. A service it served is the iceoryx2 request-response
  service PREFIX/<service>: the model's requests go there in the request's layout,
  and the process's answer (the response's layout, fields then seq) is posted as the
  server's response. A service it called is served by the run under the same name:
  a process's request (the request's layout) goes to the model's server, and the
  model's answer comes back. An action it served takes goals on the request-response
  service PREFIX/<action> (request: the goal's layout with goal_id; answer: 1 byte,
  1 accepted or 0 rejected, then a u64 seq) and the process publishes its feedback
  and results on PREFIX/<action>/feedback and /result (layouts from --layout; the
  result's code is 4 succeeded, 5 canceled, 6 aborted). An action it called is
  served by the run on PREFIX/<action>: a process's goal (the goal's layout) goes to
  the model's server and the answer is the same accept byte; feedback and results
  are on the run's PREFIX/<action>/feedback and /result. Malformed samples and
  answers are counted, never posted. Example
  (a battery written in Rust that publishes every 1.2 s):
  hindsight run examples/museum-guide --external BatteryComponent --speed 5 &
  cargo run -p hindsight --example battery_component -- --period 1.2s --speed 5

Monitoring it (--layout names `event` and `var` after the property file's
  <event_var> and <state_var> on each topic; other fields are commented out):
  hindsight run examples/museum-guide --layout > museum.toml
  hindsight monitor --props examples/specs/museum.hspec --config museum.toml &
  hindsight run examples/museum-guide --speed 10

On ROS 2 over DDS (--ros2), no ROS install needed:
  The run joins DDS domain ROS_DOMAIN_ID (0 when unset) as a plain DDS participant
  and publishes what a ROS 2 robot running the model would: topic /a/b on DDS topic
  rt/a/b, type pkg/msg/T as pkg::msg::dds_::T_, the message CDR-encoded from its
  .msg definition (the model's fields set, every other field zero), with ROS 2's
  default QoS (reliable, volatile, keep last 10) or what --qos names for a topic
  (--qos /a/b=durability=transient_local,depth=1). Each service the model serves is
  published as ROS 2's service introspection publishes it: on /<service>/_service_event
  (type pkg/srv/Name_Event), a REQUEST_RECEIVED event with the request, then a
  RESPONSE_SENT event with the response, one sequence_number for both. A ROS 2 node
  (`ros2 topic echo`, `ros2 bag record`) or `hindsight monitor --ros2` listens to it.
  With --external NAME, a ROS 2 client may stand in for the node NAME where it calls
  the model's services: its requests on rq/<service>Request (the request id header
  rmw_cyclonedds writes, then the request) go to the model's server, and the answer
  goes back on rr/<service>Reply with the same header. Not supported over DDS (warned,
  never silent): the rest of an --external node (its topics, the services it serves,
  actions), Fast DDS clients (they carry the request id differently), actions (their
  goals, feedback and results are not published) and --layout (iceoryx2 only).
  --wait-match TOPIC holds the first step until a subscriber to TOPIC is matched,
  then 5 s more for the subscriber's side of DDS discovery, so a monitor started
  first sees the run from its first message.

The museum guide's properties.xml, checked live on DDS and on the recording:
  hindsight monitor --ros2 examples/museum-guide/properties.xml --speed 2 \
      --from-first-message --record museum.mcap &
  hindsight run examples/museum-guide --ros2 --speed 2 --duration 80s \
      --wait-match /BatteryComponent/battery_level
  kill -INT %1
  hindsight replay examples/museum-guide/properties.xml museum.mcap --time-unit 1ms --changes

Progress goes to stderr; SIGINT/SIGTERM end the run cleanly (exit 0).
Plain SCXML models need --time-unit (e.g. 100ms) to be paced.

Exit codes: 0 the run ended (or was stopped); 2 bad model or argument; 1 iceoryx2 or DDS
failure.";

/// Runs `hindsight run`.
pub fn run(args: &RunArgs) -> Result<(), CliError> {
    if args.ros2 {
        return run_ros2(args);
    }
    quiet_ipc_log();
    check_speed(args.speed).map_err(|m| CliError::Input(format!("--speed: {m}")))?;
    let (loaded, external) = load_without(&args.input, &args.external)?;
    let model = &loaded.model;
    let (topics, warnings) = topic_layouts(model, &loaded.file.ports);
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if !external.is_empty() && loaded.events != crate::verify::options::EventSemantics::As2fm {
        return Err(CliError::Input(
            "--external needs --events as2fm (messages from processes are posted as AS2FM's \
             translation sends them)"
                .into(),
        ));
    }
    if args.layout {
        // The sidecar of this run counts model time from the run's first message.
        println!(
            "# `hindsight run --speed {}`: the sidecar's clock counts model time from the \
             run's first message.\n[clock]\nspeed = {:?}\nfrom_first_message = true\n",
            args.speed, args.speed
        );
        print!("{}", layout_toml(&topics, &args.prefix));
        return Ok(());
    }
    // The monitor taps what processes publish too: the layout above keeps their topics.
    for c in &external {
        eprintln!("run: {} is played by a process: {}", c.name, describe(c));
    }
    let wiring = Wiring::plan(model, topics, &external);
    for w in &wiring.warnings {
        eprintln!("warning: {w}");
    }
    let Some(unit_ns) = loaded.unit_ns else {
        return Err(CliError::Input(format!(
            "{}: the model has no time unit; give --time-unit (e.g. 100ms) to pace it",
            args.input.model.display()
        )));
    };
    if wiring.topics.is_empty() {
        eprintln!(
            "warning: the model has no ROS topics (events `topic_*_msg`); nothing is published"
        );
    }
    let max_time = loaded
        .max_time(args.duration.as_deref())
        .map_err(|m| CliError::Input(format!("--duration: {m}")))?;
    let node = node().map_err(|e| CliError::Failed(e.to_string()))?;
    let bridges = Bridges::open(&node, model, wiring, &args.prefix)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let tty = std::io::stderr().is_terminal();
    let mut live = Paced {
        node: &node,
        publisher: bridges.publisher,
        inbound: bridges.inbound,
        services: bridges.services,
        servers: bridges.servers,
        goals: bridges.goals,
        inbound_error: None,
        clock: Clock::with_speed(unit_ns, args.speed),
        stopped: false,
        on_progress: ProgressReports::new(move |p| draw_line(&p.line(unit_ns), tty)),
    };
    let outcome = play_paced(&loaded, max_time, args, (&mut live, Paced::progress), tty);
    let (failed, why) = live.publisher.failed();
    if failed > 0 {
        eprintln!(
            "warning: {failed} samples could not be published (last: {})",
            why.unwrap_or("?")
        );
    }
    for st in live.inbound.stats() {
        eprintln!(
            "run: from {}: {} samples posted, {} malformed, {} lost",
            st.service, st.received, st.malformed, st.lost
        );
    }
    for st in live.services.stats() {
        eprintln!(
            "run: service {}: {} requests, {} answered, {} unanswered, {} malformed answers",
            st.service, st.requests, st.answered, st.unanswered, st.malformed
        );
    }
    for st in live.servers.stats() {
        eprintln!(
            "run: serving {}: {} requests from processes, {} answered, {} callers gone, {} malformed",
            st.service, st.requests, st.answered, st.unanswered, st.malformed
        );
    }
    for st in live.goals.stats() {
        eprintln!(
            "run: action {}: {} goals, {} answered, {} unanswered, {} malformed answers",
            st.service, st.requests, st.answered, st.unanswered, st.malformed
        );
    }
    if let Some(e) = &live.inbound_error {
        eprintln!("warning: reading from external components failed: {e}");
    }
    say_end(&outcome, live.stopped);
    Ok(())
}

/// How long `--wait-match` waits after the writers matched their subscribers, for the
/// subscribers to match the writers (measured: up to 2.6 s between the two on a loaded
/// 2-core machine with the museum's 21 writers).
const SETTLE: std::time::Duration = std::time::Duration::from_secs(5);

/// Runs `hindsight run --ros2`: the run's topics and service events on DDS.
fn run_ros2(args: &RunArgs) -> Result<(), CliError> {
    let input = CliError::Input;
    check_speed(args.speed).map_err(|m| input(format!("--speed: {m}")))?;
    if args.layout {
        return Err(input(
            "--layout prints the iceoryx2 payload layout; with --ros2 the payload is the \
             message's CDR (its .msg definition)"
                .into(),
        ));
    }
    let domain = domain_id().map_err(|e| input(e.to_string()))?;
    let Some(main_path) = crate::verify::load::main_file_of(&args.input.model) else {
        return Err(input(format!(
            "{}: --ros2 needs a robot model (a main file whose node models declare their \
             ROS topics and services with types)",
            args.input.model.display()
        )));
    };
    let (loaded, external) = load_without(&args.input, &args.external)?;
    let model = &loaded.model;
    // Over DDS a node played by a ROS 2 process may call the model's services; what else
    // it does is not bridged (said, not silent).
    let (service_routes, said) = dds_services(model, &external);
    for w in &said {
        eprintln!("warning: {w}");
    }
    let DdsPlan {
        routes,
        packages,
        mut warnings,
    } = DdsPlan::new(&main_path, args.input.interfaces.clone(), model)
        .map_err(|e| input(e.to_string()))?;
    let services = if service_routes.is_empty() {
        None
    } else {
        Some(
            DdsServices::new(domain, model, service_routes, &packages, &mut warnings)
                .map_err(|e| CliError::Failed(e.to_string()))?,
        )
    };
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if let Some(s) = &services {
        for st in s.stats() {
            let (rq, rr) = service_topics(&st.service);
            eprintln!(
                "run: serving {} to ROS 2 clients on {rq} and {rr}",
                st.service
            );
        }
    }
    let Some(unit_ns) = loaded.unit_ns else {
        return Err(input(format!(
            "{}: the model has no time unit; give --time-unit (e.g. 100ms) to pace it",
            args.input.model.display()
        )));
    };
    let max_time = loaded
        .max_time(args.duration.as_deref())
        .map_err(|m| input(format!("--duration: {m}")))?;
    let qos = topic_qos(&args.qos, &routes).map_err(|e| input(e.to_string()))?;
    let publisher = DdsPublisher::new(domain, model, routes, &qos)
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let topics: Vec<&str> = publisher.topics().collect();
    for t in &args.wait_match {
        if !topics.contains(&t.as_str()) {
            return Err(input(format!(
                "--wait-match {t}: the run does not publish it (it publishes {})",
                topics.join(", ")
            )));
        }
    }
    eprintln!(
        "run: publishing {} topics on DDS domain {domain}: {}",
        topics.len(),
        topics.join(", ")
    );
    // Set by SIGINT / SIGTERM: the run stops at its next step, exit 0.
    let stop = super::monitor_ros2::stop_flag();
    let start = Instant::now();
    loop {
        let missing = publisher.unmatched(&args.wait_match);
        if missing.is_empty() {
            break;
        }
        if stop.load(Ordering::Relaxed) {
            return Ok(());
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            return Err(CliError::Failed(format!(
                "--wait-match: no reader subscribed to {} within 60 s on DDS domain {domain}",
                missing.join(", ")
            )));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    if !args.wait_match.is_empty() {
        // A writer matches a reader when it learns of the reader; the reader learns of
        // the writer separately, and what is written before that is lost to it (a
        // volatile reader). Give the subscribers' side of discovery time to finish.
        eprintln!(
            "run: subscribers matched; starting in {} s",
            SETTLE.as_secs()
        );
        let start = Instant::now();
        while start.elapsed() < SETTLE {
            if stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }
    let tty = std::io::stderr().is_terminal();
    let mut live = DdsPaced {
        model,
        publisher,
        services,
        clock: Clock::with_speed(unit_ns, args.speed),
        stop,
        stopped: false,
        on_progress: ProgressReports::new(move |p| draw_line(&p.line(unit_ns), tty)),
    };
    let outcome = play_paced(
        &loaded,
        max_time,
        args,
        (&mut live, DdsPaced::progress),
        tty,
    );
    // Reliable delivery of the last messages before the participant goes.
    live.publisher.flush(std::time::Duration::from_secs(2));
    if let Some(s) = &live.services {
        s.flush(std::time::Duration::from_secs(2));
        for st in s.stats() {
            eprintln!(
                "run: serving {} on DDS: {} requests from ROS 2 clients, {} answered, {} malformed{}",
                st.service,
                st.requests,
                st.answered,
                st.malformed,
                st.last_error
                    .as_deref()
                    .map_or(String::new(), |e| format!(" (last error: {e})"))
            );
        }
    }
    let (failed, why) = live.publisher.failed();
    if failed > 0 {
        eprintln!(
            "warning: {failed} samples could not be published (last: {})",
            why.unwrap_or("?")
        );
        if args.wait_match.is_empty() {
            // Seen here: at --speed 10 without it, writes blocked while a monitor started
            // beside the run was still being discovered; with it nothing was lost.
            eprintln!(
                "hint: a subscriber that DDS is still discovering when the run starts can \
                 make writes block; start it first and pass --wait-match TOPIC for the \
                 topics it reads, so that the first step waits for it"
            );
        }
    }
    say_end(&outcome, live.stopped);
    Ok(())
}

/// Plays run `args.run` of seed `args.seed` into `live`, the iceoryx2 or the DDS side
/// paced in wall-clock time, and reports its progress once more at the end (the line
/// closed on a terminal).
fn play_paced<L: crate::verify::replay::Observer>(
    loaded: &Loaded,
    max_time: u64,
    args: &RunArgs,
    (live, progress): (&mut L, fn(&mut L, u64, bool)),
    tty: bool,
) -> crate::verify::replay::RunOutcome {
    let outcome = play_run(
        &loaded.model,
        loaded.events,
        max_time,
        (args.seed, args.run),
        live,
    );
    progress(live, outcome.time, true);
    if tty {
        eprintln!();
    }
    outcome
}

/// The last line of `run`: the model step the run ended at and why.
fn say_end(outcome: &crate::verify::replay::RunOutcome, stopped: bool) {
    let how = if stopped {
        "stopped by a signal".to_string()
    } else {
        end_text(&outcome.end)
    };
    eprintln!("run: ended at model step {}: {how}", outcome.time);
}
