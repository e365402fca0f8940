//! `hindsight run`'s observer: a simulation paced on the wall clock, its messages published over iceoryx2.
//!
//! [`Paced`] is an [`Observer`]: at every model time it waits until the [`Clock`]
//! (the sidecar's, at the run's speed) reaches that time, publishes every send of a
//! ROS message, forwards requests and goals to the processes that serve them, and
//! hands what those processes send back to the simulator through [`Inbox`].

use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

use super::inject::{GoalBridge, ServiceBridge, ServiceServers, TopicSubscriber};
use super::publish::TopicPublisher;
use super::Clock;
use crate::sim::{Flow, Inbox, Observer, SentMessage};

type Ipc = ipc::Service;

/// Paces a run in wall-clock time and publishes its messages; fields are wired by the caller.
pub struct Paced<'n> {
    /// The iceoryx2 node (its `wait` also returns on SIGINT/SIGTERM).
    pub node: &'n Node<Ipc>,
    /// Publishes every ROS message the model sends.
    pub publisher: TopicPublisher,
    /// Topics that processes publish, posted into the model.
    pub inbound: TopicSubscriber,
    /// Requests and goals forwarded to the processes that serve them.
    pub services: ServiceBridge,
    /// Services the model serves to processes.
    pub servers: ServiceServers,
    /// Action goals forwarded to processes.
    pub goals: GoalBridge,
    /// The first error talking to processes.
    pub inbound_error: Option<super::LiveError>,
    /// Model time on the wall clock (the sidecar's clock, at the run's speed).
    pub clock: Clock,
    /// Set when a signal stopped the run.
    pub stopped: bool,
    /// Where the run's progress goes (the binary draws it).
    pub on_progress: ProgressReports<'n>,
}

impl Paced<'_> {
    /// Reports the progress at model time `time` (at most every `PROGRESS_EVERY`
    /// unless `force`).
    pub fn progress(&mut self, time: u64, force: bool) {
        let (publisher, inbound) = (&self.publisher, &self.inbound);
        self.on_progress.report(force, || RunProgress {
            time,
            published: publisher.published(),
            received: inbound
                .stats()
                .next()
                .is_some()
                .then(|| inbound.stats().map(|s| s.received).sum()),
            dds: false,
        });
    }
}

/// How often a paced run reports its progress.
pub(crate) const PROGRESS_EVERY: Duration = Duration::from_millis(500);

/// Where a paced run is, for the binary to draw as one line ([`RunProgress::line`]: `run:
/// model time 1.5 s (1500 steps), 12 samples published, 3 received`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunProgress {
    /// Model time, in the model's units.
    pub time: u64,
    /// Samples published so far.
    pub published: u64,
    /// Samples received from processes, when some topic comes in from one.
    pub received: Option<u64>,
    /// Published on DDS (`run --ros2`), not iceoryx2.
    pub dds: bool,
}

impl RunProgress {
    /// The line, with model time in seconds at `unit_ns` nanoseconds a unit.
    pub fn line(&self, unit_ns: u64) -> String {
        let secs = self.time as f64 * unit_ns as f64 / 1e9;
        let mut line = format!(
            "run: model time {secs:.1} s ({} steps), {} samples published",
            self.time, self.published
        );
        if self.dds {
            line.push_str(" on DDS");
        }
        if let Some(r) = self.received {
            line.push_str(&format!(", {r} received"));
        }
        line
    }
}

/// Hands a paced run's [`RunProgress`] to a callback, at most every `PROGRESS_EVERY`
/// unless forced: the observer's side of the progress line.
pub struct ProgressReports<'p> {
    last: Instant,
    sink: Box<dyn FnMut(&RunProgress) + 'p>,
}

impl<'p> ProgressReports<'p> {
    /// Reports to `sink`, the first time `PROGRESS_EVERY` from now.
    pub fn new(sink: impl FnMut(&RunProgress) + 'p) -> Self {
        ProgressReports {
            last: Instant::now(),
            sink: Box::new(sink),
        }
    }

    /// Calls the sink with `progress()` if it is due or `force`d.
    pub(crate) fn report(&mut self, force: bool, progress: impl FnOnce() -> RunProgress) {
        if !force && self.last.elapsed() < PROGRESS_EVERY {
            return;
        }
        self.last = Instant::now();
        (self.sink)(&progress());
    }
}

impl Observer for Paced<'_> {
    fn on_send(&mut self, time: u64, msg: &SentMessage<'_>) -> Flow {
        self.publisher.publish(msg);
        if let Err(e) = self
            .services
            .forward(msg)
            .and_then(|()| self.servers.answer(msg))
            .and_then(|()| self.goals.forward(msg))
        {
            self.inbound_error.get_or_insert(e);
        }
        let _ = time;
        Flow::Continue
    }

    fn on_time(&mut self, time: u64) -> Flow {
        let due = self.clock.due(time);
        loop {
            let now = Instant::now();
            if now >= due {
                break;
            }
            // `wait` also returns on SIGINT/SIGTERM (the node handles them).
            let step = (due - now).min(Duration::from_millis(200));
            if self.node.wait(step).is_err() {
                self.stopped = true;
                return Flow::Stop;
            }
        }
        self.progress(time, false);
        Flow::Continue
    }

    fn inputs(&mut self, _time: u64, inbox: &mut Inbox) {
        if let Err(e) = self.inbound.poll(inbox) {
            self.inbound_error.get_or_insert(e);
        }
        self.services.poll(inbox);
        self.servers.poll(inbox);
        self.goals.poll(inbox);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_progress_line_says_time_samples_and_where() {
        let p = RunProgress {
            time: 1500,
            published: 12,
            received: Some(3),
            dds: false,
        };
        assert_eq!(
            p.line(1_000_000),
            "run: model time 1.5 s (1500 steps), 12 samples published, 3 received"
        );
        let dds = RunProgress {
            received: None,
            dds: true,
            ..p
        };
        assert_eq!(
            dds.line(1_000_000),
            "run: model time 1.5 s (1500 steps), 12 samples published on DDS"
        );
    }

    #[test]
    fn reports_are_spaced_unless_forced() {
        let mut seen = Vec::new();
        {
            let mut reports = ProgressReports::new(|p: &RunProgress| seen.push(p.time));
            let at = |time| {
                move || RunProgress {
                    time,
                    published: 0,
                    received: None,
                    dds: false,
                }
            };
            // Not yet due: the first report comes PROGRESS_EVERY after the start.
            reports.report(false, at(1));
            reports.report(true, at(2));
            // Just reported: the next unforced one is not due.
            reports.report(false, at(3));
            reports.last -= PROGRESS_EVERY;
            reports.report(false, at(4));
        }
        assert_eq!(seen, [2, 4]);
    }
}
