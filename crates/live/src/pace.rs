//! `hindsight run`'s observer: a simulation paced on the wall clock, its messages published over iceoryx2.
//!
//! [`Paced`] is an [`Observer`]: at every model time it waits until the [`Clock`]
//! (the sidecar's, at the run's speed) reaches that time, publishes every send of a
//! ROS message, forwards requests and goals to the processes that serve them, and
//! hands what those processes send back to the simulator through [`Inbox`].

use std::io::Write;
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
    /// Nanoseconds per model time unit (for the progress line).
    pub unit_ns: u64,
    /// Set when a signal stopped the run.
    pub stopped: bool,
    /// When the last progress line was written.
    pub last_progress: Instant,
    /// Whether stderr is a terminal (progress overwrites one line).
    pub tty: bool,
}

impl Paced<'_> {
    /// Writes a progress line (at most every 500 ms unless `force`).
    pub fn progress(&mut self, time: u64, force: bool) {
        if !force && self.last_progress.elapsed() < Duration::from_millis(500) {
            return;
        }
        self.last_progress = Instant::now();
        let secs = time as f64 * self.unit_ns as f64 / 1e9;
        let received: u64 = self.inbound.stats().map(|s| s.received).sum();
        let mut line = format!(
            "run: model time {secs:.1} s ({time} steps), {} samples published",
            self.publisher.published()
        );
        if self.inbound.stats().next().is_some() {
            line.push_str(&format!(", {received} received"));
        }
        let mut err = std::io::stderr().lock();
        let _ = if self.tty {
            write!(err, "\r{line}")
        } else {
            writeln!(err, "{line}")
        };
        let _ = err.flush();
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
