//! On-line monitoring over iceoryx2: the `hindsight monitor` sidecar.
//!
//! Pipeline: a [`config::Config`] names iceoryx2 services and the byte layout of
//! their `[u8]` payloads -> [`Sidecar`] taps every publish-subscribe topic with one
//! extra subscriber and proxies every request-response service -> each sample is
//! stamped with the [`Clock`] (monotonic, quantised to the spec's unit, counting model
//! time when the system runs faster than real time), decoded
//! into variable sets and written to the input log ([`record::Input`]) -> the
//! [`engine::Engine`] steps the compiled monitors -> verdict changes go out as JSON
//! lines and on an optional iceoryx2 service. [`record::replay`] feeds a recorded
//! input log through the same engine off-line, so it prints the same verdicts.
//!
//! - [`config`]: the TOML config, checked against the spec (`file:line:col` errors).
//! - [`engine`]: five-valued verdicts and the loss rule (see its docs).
//! - [`record`]: the verdict line and input log formats; replay.
//! - [`mod@bench`]: throughput and added latency against a plain subscriber.
//! - [`dds`]: the same judging over a live ROS 2 graph (DDS), `monitor --ros2`;
//!   [`readers`]: its readers planned from the properties' ports.
//! - [`recording`]: properties judged over ROS 2 recordings (`replay`), and the ports
//!   that read topics and services.
//! - [`pace`]: `hindsight run`'s observer, pacing a simulation on the same [`Clock`];
//!   [`publish_dds`] and [`serve_dds`]: `run --ros2`'s topics and services on DDS.
//! - [`wiring`]: what `hindsight run` connects before its first step (publishers,
//!   the bridges to processes playing node models, DDS writers and services).
//! - [`serve`]: the live page (`--serve`): verdict lines streamed to a browser;
//!   [`http`]: its HTTP plumbing and limits.
//!
//! Taps never slow a publisher: the services keep iceoryx2's safe overflow, so a
//! full tap buffer drops the tap's oldest sample. Lost samples are found from a
//! sequence counter in the payload when the config names one, otherwise from a
//! drain that found the buffer full (a conservative "may have lost").
//!
//! # Crate
//!
//! `hindsight-live` depends on `monitor-core`, `codegen`, `hindsight-ros2` and the crates
//! a paced run needs (`hindsight-expr`, `hindsight-sim`, `hindsight-props`,
//! `hindsight-robot`), and on `hindsight-report` for the live page's script; not on
//! `hindsight-verify`. `hindsight`'s command line drives it (`monitor`, `run`).
//!
//! A monitor stepped from a compiled spec, point by point, as the sidecar does:
//!
//! ```
//! use hindsight_live::engine::{Engine, Verdict};
//! use monitor_core::Value;
//!
//! let spec = codegen::compile_spec(
//!     "unit 1ms; state x: int = 0; property low = H({x < 10});",
//!     "t.hspec",
//! )
//! .unwrap();
//! let x = spec.var_index("x").unwrap();
//! let mut engine = Engine::new(&spec, false).unwrap();
//! let mut out = Vec::new();
//! engine.point(0, &[(x, Value::Int(3))], "tick", &mut out).unwrap();
//! assert_eq!(out.last().unwrap().verdict, Verdict::CurrentlyTrue);
//! engine.point(5, &[(x, Value::Int(12))], "tick", &mut out).unwrap();
//! assert_eq!((out.last().unwrap().time, out.last().unwrap().verdict), (5, Verdict::False));
//! // Time going backwards is an error value, and changes nothing.
//! assert!(engine.point(4, &[], "tick", &mut out).is_err());
//! assert_eq!(engine.verdicts(), &[Some(Verdict::False)]);
//! ```

// `pub` only where another crate can reach it: internals are `pub(crate)` (issue 27).
#![warn(unreachable_pub)]

pub mod bench;
mod clock;
pub mod config;
pub mod dds;
pub mod engine;
mod error;
pub mod http;
pub mod inject;
pub mod pace;
pub mod publish;
pub mod publish_dds;
pub mod readers;
pub mod record;
pub mod recording;
pub mod serve;
pub mod serve_dds;
pub mod wiring;

// The crates below this one, under the paths its modules name them by (crate-private:
// this crate's API is its own modules).
use hindsight_expr as expr;
use hindsight_props as props;
use hindsight_report as report;
use hindsight_robot as robot;
use hindsight_sim::{model, sim};

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use codegen::Compiled;
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use monitor_core::Value;

pub use clock::{check_speed, Clock, SPEED_RANGE};
use config::{Action, Config, Layout, Wire};
use engine::{Change, Engine};
use error::ipc;
pub use error::LiveError;
use record::Input;

type Ipc = ipc::Service;
type Req = ActiveRequest<Ipc, [u8], (), [u8], ()>;
type Pending = PendingResponse<Ipc, [u8], (), [u8], ()>;

/// iceoryx2's own log to errors only, unless `IOX2_LOG_LEVEL` names a level (iceoryx2
/// warns on stderr about a missing config file); `monitor` and `run` call it first.
pub fn quiet_ipc_log() {
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Error);
}

/// Counts for one tapped topic or proxied service.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SourceStats {
    /// The service name.
    pub service: String,
    /// Samples or requests judged.
    pub samples: u64,
    /// Samples known or suspected lost.
    pub lost: u64,
    /// Samples or requests of the wrong size or with an invalid field.
    pub malformed: u64,
    /// New publishers seen after a first one (restarts).
    pub restarts: u64,
    /// Samples that arrived after points later than their sending were judged (DDS:
    /// from their source timestamps).
    pub late: u64,
    /// Requests refused by `filter` (or undeliverable).
    pub blocked: u64,
    /// Requests forwarded to the real service.
    pub forwarded: u64,
}

/// What a run of the sidecar saw.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// One entry per topic, then per service, in config order.
    pub sources: Vec<SourceStats>,
    /// Points judged (samples, requests and heartbeats).
    pub points: u64,
    /// Verdict lines written.
    pub verdict_lines: u64,
    /// With a [`Probe`]: `(sent, judged)` in nanoseconds since its epoch, per tapped sample.
    pub probed: Vec<(u64, u64)>,
}

/// Where the sidecar writes and how it waits.
pub struct Options {
    /// Verdict JSON lines.
    pub verdicts: Box<dyn Write + Send>,
    /// The input log for `--replay`, if wanted.
    pub record: Option<Box<dyn Write + Send>>,
    /// Report every verdict at every point, not only changes.
    pub every_point: bool,
    /// Sleep this long when nothing arrived (zero: busy polling).
    pub poll: Duration,
    /// Diagnostics (lost, malformed, restarts) as text lines, e.g. standard error.
    pub log: Box<dyn Write + Send>,
    /// Incremented after every judged sample or request (for tests and benchmarks that wait on progress).
    pub progress: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
    /// Benchmarks only: read a send time at this byte offset of every tapped sample.
    pub probe: Option<Probe>,
}

/// A latency probe for [`mod@bench`]: each tapped sample carries, as a little-endian
/// `u64` at `offset`, the nanoseconds since `epoch` when it was sent.
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    /// Byte offset of the send time.
    pub offset: usize,
    /// The publisher's time origin.
    pub epoch: Instant,
}

/// Parses an iceoryx2 service name.
pub fn service_name(s: &str) -> Result<ServiceName, LiveError> {
    ServiceName::new(s).map_err(|e| LiveError::ipc(format!("service name `{s}`"), e))
}

/// Opens the `[u8]` publish-subscribe service `svc` on `node`, or creates it with
/// iceoryx2's defaults: what `hindsight run` and the processes beside it agree on.
pub(crate) fn open_raw_topic(
    node: &Node<Ipc>,
    svc: &str,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, [u8], ()>, LiveError>
{
    let name = service_name(svc)?;
    node.service_builder(&name)
        .publish_subscribe::<[u8]>()
        .open_or_create()
        .map_err(ipc(svc))
}

/// Opens the `[u8]` publish-subscribe service `svc` on `node`, or creates it with room
/// for `buffer` samples per subscriber; one that exists with a smaller buffer is taken as
/// it is.
fn open_buffered_topic(
    node: &Node<Ipc>,
    svc: &str,
    buffer: usize,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, [u8], ()>, LiveError>
{
    let name = service_name(svc)?;
    let service = || node.service_builder(&name).publish_subscribe::<[u8]>();
    match service()
        .subscriber_max_buffer_size(buffer)
        .open_or_create()
    {
        Ok(f) => Ok(f),
        Err(_) => service().open().map_err(ipc(svc)),
    }
}

struct Tap {
    source: String,
    layout: Layout,
    seq: Option<config::Seq>,
    vars: Vec<String>,
    sub: Subscriber<Ipc, [u8], ()>,
    publishers: Vec<(UniquePublisherId, Option<u64>)>,
    last_sample: Option<u64>,
    stats: SourceStats,
}

struct Proxy {
    source: String,
    real: String,
    layout: Layout,
    action: Action,
    filter: Vec<String>,
    filter_ids: Vec<usize>,
    var_names: Vec<String>,
    error: Vec<u8>,
    server: Server<Ipc, [u8], (), [u8], ()>,
    client: Client<Ipc, [u8], (), [u8], ()>,
    inflight: Vec<(Req, Pending)>,
    stats: SourceStats,
}

/// The running sidecar's state between iterations.
struct Run<'c, 'o> {
    /// The clock is still to be anchored at the first message (`from_first_message`).
    anchor_pending: bool,
    spec: &'c Compiled,
    engine: Engine<'c>,
    opts: &'o mut Options,
    clock: Clock,
    changes: Vec<Change>,
    verdict_pub: Option<Publisher<Ipc, [u8], ()>>,
    points: u64,
    lines: u64,
    probed: Vec<(u64, u64)>,
    /// A sample or request has been judged.
    started: bool,
    /// The verdict lines were flushed since the last pass that found something.
    idle_flushed: bool,
}

impl<'c, 'o> Run<'c, 'o> {
    /// A run of `spec`'s monitors writing to `opts`, its input log opened with the
    /// `Start` record (the clock at `speed`; anchored at the first message when
    /// `from_first_message`).
    fn start(
        spec: &'c Compiled,
        opts: &'o mut Options,
        speed: f64,
        from_first_message: bool,
        verdict_pub: Option<Publisher<Ipc, [u8], ()>>,
    ) -> Result<Self, LiveError> {
        let engine = Engine::new(spec, opts.every_point).map_err(LiveError::Engine)?;
        let mut run = Run {
            spec,
            engine,
            opts,
            clock: Clock::with_speed(spec.tick_ns(), speed),
            changes: Vec::new(),
            verdict_pub,
            points: 0,
            lines: 0,
            probed: Vec::new(),
            started: false,
            anchor_pending: from_first_message,
            idle_flushed: false,
        };
        run.write_record(&Input::Start {
            unit_ns: spec.tick_ns(),
            speed,
        })?;
        Ok(run)
    }

    /// After one pass over the sources: `true` when something arrived (pass again at
    /// once); otherwise flushes the verdict lines, once per idle spell, and `false`.
    fn after_pass(&mut self, busy: bool) -> bool {
        if busy {
            self.idle_flushed = false;
            return true;
        }
        if !self.idle_flushed {
            let _ = self.opts.verdicts.flush();
            self.idle_flushed = true;
        }
        false
    }

    /// Flushes the verdict lines and the input log.
    fn flush(&mut self) -> Result<(), LiveError> {
        self.opts.verdicts.flush()?;
        if let Some(r) = self.opts.record.as_mut() {
            r.flush()?;
        }
        Ok(())
    }

    /// Writes one record to the input log, when recording.
    fn write_record(&mut self, input: &Input) -> Result<(), LiveError> {
        if let Some(rec) = self.opts.record.as_mut() {
            let line = serde_json::to_string(input).map_err(std::io::Error::from)?;
            writeln!(rec, "{line}")?;
        }
        Ok(())
    }

    /// Logs and applies one input (ticks, losses, restarts); the input log's path.
    fn feed(&mut self, input: Input) -> Result<(), LiveError> {
        self.write_record(&input)?;
        self.changes.clear();
        record::apply(self.spec, &mut self.engine, &input, &mut self.changes)
            .map_err(LiveError::Record)?;
        let point = matches!(input, Input::Tick { .. });
        let judged = matches!(input, Input::Loss { .. });
        self.emit(point, judged)
    }

    /// A decoded sample or request: logged (when recording) and judged directly,
    /// without the JSON round trip; `apply` in replay does the same engine calls.
    /// Returns whether a request may pass.
    fn judge(
        &mut self,
        time: u64,
        source: &str,
        sets: &[(usize, Value)],
        request: Option<(&[String], Option<&[usize]>)>,
    ) -> Result<bool, LiveError> {
        if self.opts.record.is_some() {
            let input = match request {
                None => Input::Sample {
                    time,
                    source: source.to_string(),
                    sets: record::sets_json(self.spec, sets),
                },
                Some((names, ids)) => Input::Request {
                    time,
                    source: source.to_string(),
                    sets: record::sets_json(self.spec, sets),
                    filter: ids.map(|_| names.to_vec()),
                },
            };
            self.write_record(&input)?;
        }
        self.changes.clear();
        self.started = true;
        let step = |e: monitor_core::StepError| {
            LiveError::Record(record::RecordError::Step(self.spec.describe(&e)))
        };
        let ok = match request {
            None => {
                self.engine
                    .point(time, sets, source, &mut self.changes)
                    .map_err(step)?;
                true
            }
            Some((_, ids)) => self
                .engine
                .request(time, sets, source, ids, &mut self.changes)
                .map_err(step)?,
        };
        self.emit(true, true)?;
        Ok(ok)
    }

    fn emit(&mut self, point: bool, judged: bool) -> Result<(), LiveError> {
        if point {
            self.points += 1;
        }
        for c in &self.changes {
            let line = record::verdict_line(self.spec, c);
            writeln!(self.opts.verdicts, "{line}")?;
            self.lines += 1;
            if let Some(p) = &self.verdict_pub {
                // A verdict subscriber that is gone or slow must not stop the monitor.
                if let Ok(s) = p.loan_slice_uninit(line.len()) {
                    let _ = s.write_from_slice(line.as_bytes()).send();
                }
            }
        }
        if judged {
            if let Some(p) = &self.opts.progress {
                p.fetch_add(1, Ordering::SeqCst);
            }
        }
        Ok(())
    }

    /// Says `note` about `source` and judges the loss of `count` samples that set `vars`.
    fn loss(
        &mut self,
        time: u64,
        source: &str,
        vars: &[String],
        count: u64,
        reason: &str,
        note: String,
    ) -> Result<(), LiveError> {
        self.note(format!("{source}: {note}"));
        self.feed(Input::Loss {
            time,
            source: source.to_string(),
            vars: vars.to_vec(),
            count,
            reason: reason.to_string(),
        })
    }

    fn note(&mut self, msg: String) {
        let _ = writeln!(self.opts.log, "monitor: {msg}");
    }

    /// A time no earlier than the engine's last point. With `from_first_message`, the
    /// first call (the first message) anchors the clock there ([`Clock::anchor_now`]).
    fn now(&mut self) -> u64 {
        if self.anchor_pending {
            self.anchor_pending = false;
            self.clock.anchor_now();
        }
        let t = self.clock.now();
        self.engine.last_time().map_or(t, |l| t.max(l))
    }

    /// A `Tick` when `heartbeat` (> 0) time units passed since the engine's last point;
    /// with `from_first_message`, none before the system's first message.
    fn heartbeat(&mut self, heartbeat: u64, from_first_message: bool) -> Result<(), LiveError> {
        if heartbeat == 0 || (from_first_message && !self.started) {
            return Ok(());
        }
        let now = self.clock.now();
        if self.engine.last_time().is_none_or(|l| now >= l + heartbeat) {
            let time = self.now();
            self.feed(Input::Tick { time })?;
        }
        Ok(())
    }

    fn drain_tap(
        &mut self,
        tap: &mut Tap,
        sets: &mut Vec<(usize, Value)>,
    ) -> Result<bool, LiveError> {
        let mut n = 0usize;
        loop {
            let sample = match tap.sub.receive() {
                Ok(Some(s)) => s,
                Ok(None) => break,
                Err(e) => {
                    self.note(format!("{}: receive failed: {e:?}", tap.source));
                    break;
                }
            };
            n += 1;
            let time = self.now();
            let bytes: &[u8] = sample.payload();
            let pid = sample.header().publisher_id();
            let seq = tap
                .seq
                .and_then(|s| s.ty.read(bytes, s.offset))
                .and_then(|v| match v {
                    Value::Int(i) => Some(i as u64),
                    _ => None,
                });
            // A publisher we have not seen after another one: a restart (or a second publisher).
            let known = tap.publishers.iter().position(|(p, _)| *p == pid);
            let idx = match known {
                Some(i) => i,
                None => {
                    if !tap.publishers.is_empty() {
                        let gap = time - tap.last_sample.unwrap_or(time).min(time);
                        tap.stats.restarts += 1;
                        self.note(format!(
                            "{}: new publisher after a gap of {gap} ticks",
                            tap.source
                        ));
                        self.feed(Input::Restart {
                            time,
                            source: tap.source.clone(),
                            gap,
                        })?;
                        // Keep the list small: a restarted publisher never comes back.
                        if tap.publishers.len() >= 8 {
                            tap.publishers.remove(0);
                        }
                    }
                    tap.publishers.push((pid, None));
                    tap.publishers.len() - 1
                }
            };
            if let (Some(s), Some(cfg)) = (seq, tap.seq) {
                if let Some(prev) = tap.publishers[idx].1 {
                    let modulus = if cfg.ty.size() == 8 {
                        0
                    } else {
                        1u64 << (8 * cfg.ty.size())
                    };
                    let expected = prev.wrapping_add(1);
                    let expected = if modulus == 0 {
                        expected
                    } else {
                        expected % modulus
                    };
                    if s != expected {
                        let lost = if modulus == 0 {
                            s.wrapping_sub(expected)
                        } else {
                            (s + modulus - expected) % modulus
                        };
                        tap.stats.lost += lost;
                        self.loss(
                            time,
                            &tap.source,
                            &tap.vars,
                            lost,
                            "sequence gap",
                            format!("{lost} samples lost (sequence {expected} to {s})"),
                        )?;
                    }
                }
                tap.publishers[idx].1 = Some(s);
            }
            tap.last_sample = Some(time);
            match tap.layout.decode(bytes, sets) {
                Ok(()) => {
                    tap.stats.samples += 1;
                    self.judge(time, &tap.source, sets, None)?;
                    if let Some(p) = self.opts.probe {
                        if let Some(Value::Int(sent)) = config::FieldTy::U64.read(bytes, p.offset) {
                            self.probed
                                .push((sent as u64, p.epoch.elapsed().as_nanos() as u64));
                        }
                    }
                }
                Err(m) => {
                    tap.stats.malformed += 1;
                    let reason = format!("malformed: {m}");
                    let note = format!("malformed sample: {m}");
                    self.loss(time, &tap.source, &tap.vars, 1, &reason, note)?;
                }
            }
        }
        if n > 0 && tap.seq.is_none() && n >= tap.sub.buffer_size() {
            // The buffer was full at some moment: the oldest samples may have been overwritten.
            tap.stats.lost += 1;
            let note = format!(
                "buffer of {} samples full, samples may be lost",
                tap.sub.buffer_size()
            );
            let time = self.now();
            self.loss(time, &tap.source, &tap.vars, 1, "buffer full", note)?;
        }
        Ok(n > 0)
    }

    /// Serves one proxy. Before judging a request it drains `taps` again, so a
    /// request is judged after every sample published before it was sent.
    fn serve(
        &mut self,
        px: &mut Proxy,
        taps: &mut [Tap],
        sets: &mut Vec<(usize, Value)>,
    ) -> Result<bool, LiveError> {
        let mut busy = false;
        loop {
            let req = match px.server.receive() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    self.note(format!("{}: receive failed: {e:?}", px.source));
                    break;
                }
            };
            busy = true;
            for tap in taps.iter_mut() {
                self.drain_tap(tap, sets)?;
            }
            let time = self.now();
            let bytes: &[u8] = req.payload();
            let allowed = match px.layout.decode(bytes, sets) {
                Ok(()) => {
                    px.stats.samples += 1;
                    let ids = (px.action == Action::Filter).then_some(px.filter_ids.as_slice());
                    self.judge(time, &px.source, sets, Some((&px.filter, ids)))?
                }
                Err(m) => {
                    px.stats.malformed += 1;
                    let reason = format!("malformed: {m}");
                    let note = format!("malformed request: {m}");
                    self.loss(time, &px.source, &px.var_names, 1, &reason, note)?;
                    // filter cannot judge it, so it does not pass; log forwards it.
                    px.action == Action::Log
                }
            };
            if !allowed {
                px.stats.blocked += 1;
                self.note(format!("{}: request blocked at time {time}", px.source));
                reply(&req, &px.error);
                continue;
            }
            let sent = px
                .client
                .loan_slice_uninit(bytes.len())
                .map_err(|e| format!("{e:?}"))
                .and_then(|r| {
                    r.write_from_slice(bytes)
                        .send()
                        .map_err(|e| format!("{e:?}"))
                });
            match sent {
                Ok(pending) if pending.number_of_server_connections() > 0 => {
                    px.stats.forwarded += 1;
                    px.inflight.push((req, pending));
                }
                Ok(_) => {
                    px.stats.blocked += 1;
                    self.note(format!(
                        "{}: no server on `{}`, answered with the error reply",
                        px.source, px.real
                    ));
                    reply(&req, &px.error);
                }
                Err(e) => {
                    px.stats.blocked += 1;
                    self.note(format!("{}: cannot forward: {e}", px.source));
                    reply(&req, &px.error);
                }
            }
        }
        // Responses back to the callers; a finished exchange is dropped on both sides.
        px.inflight.retain(|(req, pending)| {
            while let Ok(Some(resp)) = pending.receive() {
                reply(req, resp.payload());
                busy = true;
            }
            pending.is_connected() && req.is_connected()
        });
        Ok(busy)
    }
}

fn reply(req: &Req, bytes: &[u8]) {
    // A caller that went away cannot be answered; that is not the monitor's failure.
    if let Ok(r) = req.loan_slice_uninit(bytes.len()) {
        let _ = r.write_from_slice(bytes).send();
    }
}

/// The sidecar: owns the iceoryx2 node and ports; [`Sidecar::run`] judges until stopped.
pub struct Sidecar {
    // Ports first: fields drop in order, and the node must outlive its ports.
    taps: Vec<Tap>,
    proxies: Vec<Proxy>,
    verdict_pub: Option<Publisher<Ipc, [u8], ()>>,
    node: Node<Ipc>,
}

impl Sidecar {
    /// Creates the node, the tap subscribers, the proxy ports and the verdict publisher.
    /// The services are opened, or created when their publisher has not started yet.
    /// With `handle_signals`, SIGINT/SIGTERM make [`Sidecar::run`] flush and return
    /// (the CLI); tests and embedders stop it through its flag instead.
    pub fn new(config: &Config, spec: &Compiled, handle_signals: bool) -> Result<Self, LiveError> {
        let mode = if handle_signals {
            SignalHandlingMode::HandleTerminationRequests
        } else {
            SignalHandlingMode::Disabled
        };
        let node = NodeBuilder::new()
            .signal_handling_mode(mode)
            .create::<Ipc>()
            .map_err(ipc("node"))?;
        let names = |vars: &[usize]| -> Vec<String> {
            vars.iter().map(|&v| spec.vars()[v].name.clone()).collect()
        };
        let mut taps = Vec::new();
        for t in &config.topics {
            let factory = open_buffered_topic(&node, &t.service, t.buffer)?;
            if !factory.static_config().has_safe_overflow() {
                // A slow tap on such a service would make its publisher wait or drop for everyone.
                return Err(LiveError::Ipc {
                    at: t.service.clone(),
                    reason: "the service has no safe overflow, so a tap could block its \
                             publisher; create it with safe overflow (the iceoryx2 default)"
                        .into(),
                });
            }
            let sub = factory
                .subscriber_builder()
                .create()
                .map_err(ipc(&t.service))?;
            let var_ids = t.layout.vars();
            taps.push(Tap {
                source: t.service.clone(),
                layout: t.layout.clone(),
                seq: t.seq,
                vars: names(&var_ids),
                sub,
                publishers: Vec::new(),
                last_sample: None,
                stats: SourceStats {
                    service: t.service.clone(),
                    ..SourceStats::default()
                },
            });
        }
        let mut proxies = Vec::new();
        for s in &config.services {
            let front = node
                .service_builder(&service_name(&s.service)?)
                .request_response::<[u8], [u8]>()
                .open_or_create()
                .map_err(ipc(&s.service))?;
            let server = front
                .server_builder()
                .initial_max_slice_len(4096)
                .allocation_strategy(AllocationStrategy::PowerOfTwo)
                .create()
                .map_err(ipc(&s.service))?;
            let back = node
                .service_builder(&service_name(&s.real)?)
                .request_response::<[u8], [u8]>()
                .open_or_create()
                .map_err(ipc(&s.real))?;
            let client = back
                .client_builder()
                .initial_max_slice_len(s.layout.size)
                .allocation_strategy(AllocationStrategy::PowerOfTwo)
                .create()
                .map_err(ipc(&s.real))?;
            proxies.push(Proxy {
                source: s.service.clone(),
                real: s.real.clone(),
                layout: s.layout.clone(),
                action: s.action,
                filter_ids: s.properties.clone(),
                filter: s
                    .properties
                    .iter()
                    .map(|&p| spec.properties()[p].name.clone())
                    .collect(),
                var_names: names(&s.layout.vars()),
                error: s.error.clone(),
                server,
                client,
                inflight: Vec::new(),
                stats: SourceStats {
                    service: s.service.clone(),
                    ..SourceStats::default()
                },
            });
        }
        let verdict_pub = match &config.verdict_service {
            None => None,
            Some(v) => {
                let f = open_buffered_topic(&node, v, 256)?;
                Some(
                    f.publisher_builder()
                        .initial_max_slice_len(256)
                        .allocation_strategy(AllocationStrategy::PowerOfTwo)
                        .create()
                        .map_err(ipc(v))?,
                )
            }
        };
        Ok(Sidecar {
            node,
            taps,
            proxies,
            verdict_pub,
        })
    }

    /// Judges until `stop` is set (or, with signal handling, SIGINT/SIGTERM),
    /// then flushes every output. `config.heartbeat` adds empty points when idle
    /// (with `config.from_first_message`, only once a sample or request came);
    /// `config.speed` makes the clock count model time of a faster (or slower) system.
    pub fn run(
        mut self,
        config: &Config,
        spec: &Compiled,
        opts: &mut Options,
        stop: &AtomicBool,
    ) -> Result<Report, LiveError> {
        let poll = opts.poll;
        let verdict_pub = self.verdict_pub.take();
        let mut run = Run::start(
            spec,
            opts,
            config.speed,
            config.from_first_message,
            verdict_pub,
        )?;
        // Scripts start the monitored system after this line: every tap exists now.
        run.note(format!(
            "ready: {} topics tapped, {} services proxied",
            self.taps.len(),
            self.proxies.len()
        ));
        let _ = run.opts.log.flush();
        let mut sets = Vec::new();
        let mut last_cleanup = Instant::now();
        let mut idle_spins = 0u64;
        let result = loop {
            if stop.load(Ordering::Relaxed) {
                break Ok(());
            }
            let mut busy = false;
            for tap in &mut self.taps {
                match run.drain_tap(tap, &mut sets) {
                    Ok(b) => busy |= b,
                    Err(e) => return Err(e),
                }
            }
            for px in &mut self.proxies {
                busy |= run.serve(px, &mut self.taps, &mut sets)?;
            }
            run.heartbeat(config.heartbeat, config.from_first_message)?;
            if last_cleanup.elapsed() >= Duration::from_secs(1) {
                // Dead publishers' resources go, so a restarted one can connect.
                let _ = Node::<Ipc>::try_cleanup_dead_nodes(self.node.config());
                last_cleanup = Instant::now();
            }
            if run.after_pass(busy) {
                continue;
            }
            if poll.is_zero() {
                // Busy polling: yield instead of sleeping (a zero sleep still costs the
                // timer slack, about 50 us); look at the signals now and then.
                idle_spins += 1;
                if idle_spins % 1024 != 0 {
                    std::thread::yield_now();
                    continue;
                }
            }
            if self.node.wait(poll).is_err() {
                break Ok(());
            }
        };
        run.flush()?;
        // The verdict publisher goes before the node does.
        drop(run.verdict_pub.take());
        let mut sources: Vec<SourceStats> = self.taps.iter().map(|t| t.stats.clone()).collect();
        sources.extend(self.proxies.iter().map(|p| p.stats.clone()));
        for s in &sources {
            let _ = writeln!(
                run.opts.log,
                "monitor: {}: {} judged, {} lost, {} malformed, {} restarts, {} forwarded, {} blocked",
                s.service, s.samples, s.lost, s.malformed, s.restarts, s.forwarded, s.blocked
            );
        }
        let _ = run.opts.log.flush();
        result.map(|()| Report {
            sources,
            points: run.points,
            verdict_lines: run.lines,
            probed: run.probed,
        })
    }
}
