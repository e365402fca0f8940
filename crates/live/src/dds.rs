//! On-line monitoring of a live ROS 2 graph over DDS: `hindsight monitor --ros2 PROPS`.
//!
//! One DDS participant ([`ros2::dds::Participant`]) reads every topic a port names
//! (`rt/<topic>`, ROS 2's type names and default QoS); each sample is CDR-decoded by the
//! recordings' reader ([`ros2::feed::TopicFeed`]), stamped with the iceoryx2 sidecar's
//! [`Clock`](crate::Clock) and judged by the same steps as an iceoryx2 sample (`Run`), so the verdict
//! lines, the input log for `--serve`, heartbeats, losses and restarts are the
//! sidecar's:
//!
//! - **loss**: a gap in a writer's RTPS sequence numbers counts the samples missed
//!   exactly (a reliable writer whose keep-last history dropped them, a best-effort
//!   one); a sample that does not decode is one loss, with the topic and index;
//! - **restart**: a sample from a writer (GUID) not seen before, after another, is a
//!   restart with the gap since the last sample;
//! - **lateness**: a sample's source timestamp (the writer's clock, RTPS `INFO_TS`),
//!   placed on the monitor's clock, is its sending tick; when a point later than that
//!   by more than `max_latency` has already been judged (a heartbeat or another
//!   topic's sample), the verdicts since were reached without it: the properties
//!   reading its topic are `unknown` from it, by the loss rule (event `late /topic`),
//!   and the sample is then judged at its arrival. A sample sent before the monitor's
//!   clock started (or, with `--from-first-message`, before the first message), or
//!   before the first sample of its writer reached the monitor (DDS discovery still
//!   under way, a transient-local writer's history), is not late: the monitor could not
//!   have known of it. A sample that does not decode is a loss as such, not also late.
//!   Writer and monitor on two machines need their clocks synchronised to well within
//!   `max_latency`;
//! - **heartbeats** every `heartbeat` ticks keep a silent topic's bounded properties
//!   failing on time;
//! - **never blocked**: samples are taken without waiting; a slow or dead publisher
//!   only means no samples.
//!
//! With `--record FILE.mcap` every received sample is written, as it came, to an MCAP
//! file (ROS 2 profile: `ros2msg` schemas, `cdr` messages), which `hindsight replay` and
//! any MCAP tool read. A sample's log time is when it was received and judged, on the
//! system's clock: the wall-clock time of the first sample recorded plus the monitor's
//! time since it (at `--speed S`, S times the wall-clock time), so that `replay` with the
//! monitor's unit judges every sample at the time the live monitor did.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, SystemTime};

use codegen::Compiled;
use ros2::dds::{Participant, Reader, Received};
use ros2::feed::TopicFeed;

// The items of `hindsight-ros2` that `hindsight`'s command line names (it depends on this
// crate, not on `hindsight-ros2`): the DDS domain (`ROS_DOMAIN_ID`), a service's request
// and reply topics, and the MCAP writer of `--record`; and `Qos`, the type of a
// `TopicSource`'s field.
pub use ros2::dds::{domain_id, service_topics, Qos};
pub use ros2::write::McapWriter;

use super::record::Input;
use super::{LiveError, Options, Report, Run, SourceStats};

/// One topic to read and what its samples set.
pub struct TopicSource {
    /// The ROS topic as recorded (`/battery`; a service port's `/s/_service_event`).
    pub topic: String,
    /// Its ROS type (`std_msgs/msg/Int32`, `pkg/srv/Name_Event`).
    pub type_name: String,
    /// Decodes a sample into variable sets.
    pub feed: TopicFeed,
    /// The names of the variables it sets (what a loss makes unknown).
    pub vars: Vec<String>,
    /// The type in `ros2msg` form, for `--record`.
    pub schema_text: String,
    /// The reader's QoS.
    pub qos: Qos,
}

/// How the monitor runs.
pub struct Settings {
    /// The DDS domain.
    pub domain: u16,
    /// A heartbeat point every this many ticks without a sample (0: none).
    pub heartbeat: u64,
    /// The system runs this many times faster than real time.
    pub speed: f64,
    /// No heartbeat before the first sample.
    pub from_first_message: bool,
    /// A sample sent more than this (wall-clock time) before a point already judged is
    /// late (zero: no sample is late).
    pub max_latency: Duration,
}

struct Tap {
    source: TopicSource,
    reader: Reader,
    /// Writers seen, with the last sequence number of each and the tick their first
    /// sample arrived at.
    writers: Vec<([u8; 16], i64, u64)>,
    last_sample: Option<u64>,
    /// Samples received on the topic (the index errors name, from 1).
    received: u64,
    channel: Option<u16>,
    stats: SourceStats,
}

/// Reads the topics until `stop` is set, judging every sample; then flushes every
/// output (and finishes the MCAP file).
pub fn run(
    spec: &Compiled,
    sources: Vec<TopicSource>,
    settings: &Settings,
    opts: &mut Options,
    mut mcap: Option<McapWriter>,
    stop: &AtomicBool,
) -> Result<Report, LiveError> {
    let dds = LiveError::Dds;
    let participant = Participant::new(settings.domain).map_err(dds)?;
    let mut taps = Vec::new();
    for source in sources {
        let reader = participant
            .reader(&source.topic, &source.type_name, source.qos)
            .map_err(dds)?;
        let channel = match &mut mcap {
            None => None,
            Some(m) => Some(
                m.add_topic(&source.topic, &source.type_name, &source.schema_text)
                    .map_err(LiveError::Mcap)?,
            ),
        };
        taps.push(Tap {
            stats: SourceStats {
                service: source.topic.clone(),
                ..SourceStats::default()
            },
            source,
            reader,
            writers: Vec::new(),
            last_sample: None,
            received: 0,
            channel,
        });
    }
    let poll = opts.poll;
    let mut run = Run::start(
        spec,
        opts,
        settings.speed,
        settings.from_first_message,
        None,
    )?;
    run.note(format!(
        "ready: {} topics read on DDS domain {}",
        taps.len(),
        settings.domain
    ));
    let _ = run.opts.log.flush();
    let mut buf: Vec<Received> = Vec::new();
    // The recording's clock: the wall-clock time of the first sample recorded, minus its
    // judged time (see `sample`).
    let mut record_base: Option<u64> = None;
    let result = loop {
        if stop.load(Ordering::Relaxed) {
            break Ok(());
        }
        let mut busy = false;
        for tap in &mut taps {
            if let Err(m) = tap.reader.take(&mut buf) {
                run.note(format!("{}: {m}", tap.source.topic));
            }
            busy |= !buf.is_empty();
            for r in buf.drain(..) {
                sample(
                    &mut run,
                    tap,
                    &r,
                    settings.max_latency,
                    mcap.as_mut().map(|m| (m, &mut record_base)),
                )?;
            }
        }
        run.heartbeat(settings.heartbeat, settings.from_first_message)?;
        if run.after_pass(busy) {
            continue;
        }
        std::thread::sleep(if poll.is_zero() {
            Duration::from_micros(10)
        } else {
            poll
        });
    };
    run.flush()?;
    if let Some(m) = mcap {
        m.finish().map_err(LiveError::Mcap)?;
    }
    let sources: Vec<SourceStats> = taps.iter().map(|t| t.stats.clone()).collect();
    for s in &sources {
        let _ = writeln!(
            run.opts.log,
            "monitor: {}: {} judged, {} lost, {} malformed, {} restarts, {} late",
            s.service, s.samples, s.lost, s.malformed, s.restarts, s.late
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

/// The tick `r` was sent at on the monitor's clock, and the last point judged, when a
/// point more than `max_latency` after its sending was judged before it came (see the
/// module's docs); `None` when it is on time, has no source timestamp or was sent
/// before the clock started.
fn late(run: &Run<'_, '_>, r: &Received, max_latency: Duration) -> Option<(u64, u64)> {
    if max_latency.is_zero() {
        return None;
    }
    let sent_ns = r.source_ns?;
    let now_ns = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .ok()?
        .as_nanos();
    // A source time ahead of ours (clock skew) is taken as sent now.
    let age = Duration::from_nanos(
        u64::try_from(now_ns.saturating_sub(u128::from(sent_ns))).unwrap_or(u64::MAX),
    );
    let sent = run.clock.ticks_ago(age)?;
    let last = run.engine.last_time()?;
    let allowed = run.clock.ticks(max_latency);
    (sent.saturating_add(allowed) < last).then_some((sent, last))
}

/// Judges one sample of `tap`: restart, loss and lateness first, then its variables.
fn sample(
    run: &mut Run<'_, '_>,
    tap: &mut Tap,
    r: &Received,
    max_latency: Duration,
    mcap: Option<(&mut McapWriter, &mut Option<u64>)>,
) -> Result<(), LiveError> {
    let time = run.now();
    // Before this sample's own point: the last point judged without it.
    let late = late(run, r, max_latency);
    tap.received += 1;
    let topic = tap.source.topic.clone();
    let idx = match tap.writers.iter().position(|(w, _, _)| *w == r.writer) {
        Some(i) => i,
        None => {
            if !tap.writers.is_empty() {
                let gap = time - tap.last_sample.unwrap_or(time).min(time);
                tap.stats.restarts += 1;
                run.note(format!("{topic}: new publisher after a gap of {gap} ticks"));
                run.feed(Input::Restart {
                    time,
                    source: topic.clone(),
                    gap,
                })?;
                // A restarted writer never comes back: keep the list small.
                if tap.writers.len() >= 8 {
                    tap.writers.remove(0);
                }
            }
            // The first sample of a writer: nothing before it is counted as lost (a
            // volatile reader joining late never had the earlier ones).
            tap.writers.push((r.writer, r.seq - 1, time));
            tap.writers.len() - 1
        }
    };
    let prev = tap.writers[idx].1;
    if r.seq > prev + 1 {
        let lost = (r.seq - prev - 1) as u64;
        tap.stats.lost += lost;
        run.loss(
            time,
            &topic,
            &tap.source.vars,
            lost,
            "sequence gap",
            format!(
                "{lost} samples lost before sample {} (writer sequence {} after {prev})",
                tap.received, r.seq
            ),
        )?;
    }
    tap.writers[idx].1 = tap.writers[idx].1.max(r.seq);
    tap.last_sample = Some(time);
    // Sent before its writer's first sample reached the monitor (discovery still under
    // way, or a transient-local writer's history): the monitor could not have known of
    // it, so it is not late.
    let first_arrival = tap.writers[idx].2;
    let late = late.filter(|(sent, _)| *sent >= first_arrival);
    // A sample that does not decode is a loss by itself (below), late or not.
    let decoded = tap.source.feed.read(&r.data);
    if let (Some((sent, last)), Ok(_)) = (late, &decoded) {
        tap.stats.late += 1;
        run.loss(
            time,
            &topic,
            &tap.source.vars,
            1,
            super::record::LATE,
            format!(
                "sample {} is late: sent at tick {sent}, after points up to tick {last} were \
                 judged (--max-latency {} ms)",
                tap.received,
                max_latency.as_millis()
            ),
        )?;
    }
    if let (Some((m, base)), Some(channel)) = (mcap, tap.channel) {
        // A sample's log time is the time it is judged at, on the system's clock: the
        // wall-clock time of the first sample recorded, plus the judged time since it (at
        // --speed S, S times the wall-clock time since). `replay` with the monitor's unit
        // then puts every sample at the time it was judged live.
        let at = time.saturating_mul(run.spec.tick_ns());
        let base = *base.get_or_insert_with(|| {
            SystemTime::now()
                .duration_since(SystemTime::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos() as u64)
                .saturating_sub(at)
        });
        m.write(
            channel,
            tap.received as u32,
            base.saturating_add(at),
            &r.data,
        )
        .map_err(LiveError::Mcap)?;
    }
    match decoded {
        Ok(sets) => {
            tap.stats.samples += 1;
            run.judge(time, &topic, sets, None)?;
        }
        Err(m) => {
            tap.stats.malformed += 1;
            let note = format!(
                "sample {} (type `{}`) is malformed: {m}",
                tap.received, tap.source.type_name
            );
            run.loss(
                time,
                &topic,
                &tap.source.vars,
                1,
                &format!("malformed: {m}"),
                note,
            )?;
        }
    }
    Ok(())
}
