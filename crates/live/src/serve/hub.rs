//! The live page's hub: where the sidecar's lines (verdicts and input records) meet
//! the page connections. [`Tee`] publishes each complete line it writes; each
//! connection has a queue bounded in bytes, and a full queue drops its page instead of
//! making the judging thread wait.

use std::collections::VecDeque;
use std::io::Write;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use crate::http::Limits;

/// The shortest time between two writes to one page (the page draws at most once per
/// animation frame, about 16 ms, anyway).
pub(super) const BATCH: Duration = Duration::from_millis(10);

/// Lines of each stream the page can get on (re)connecting; older ones are only in the
/// verdict file (and the input log).
pub const HISTORY: usize = 100_000;

/// What one queued event counts for beyond its line (its id, time and framing), so that
/// a queue of short lines is bounded too.
pub(super) const EVENT_OVERHEAD: usize = 64;

/// What a published line is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// A verdict line.
    Verdict = 0,
    /// An input record (`live::record::Input` as JSON).
    Input = 1,
}

impl Stream {
    pub(super) fn key(self) -> &'static str {
        match self {
            Stream::Verdict => "verdict",
            Stream::Input => "input",
        }
    }
}

/// One published line: its sequence number (the event id), when it was published
/// (milliseconds since the Unix epoch, for the page's delay figure) and its stream.
#[derive(Clone, Debug)]
pub(super) struct Published {
    pub(super) id: u64,
    pub(super) sent_ms: u64,
    pub(super) stream: Stream,
    pub(super) line: Arc<str>,
}

impl Published {
    /// What it counts for in a connection's queue.
    pub(super) fn cost(&self) -> usize {
        self.line.len() + EVENT_OVERHEAD
    }
}

/// The events queued for one page connection, bounded in bytes.
#[derive(Default)]
pub(super) struct Queue {
    pub(super) items: VecDeque<Published>,
    pub(super) bytes: usize,
    /// Dropped by the hub (its queue overflowed) or ended by its thread: nothing more is
    /// queued, and its thread ends.
    pub(super) closed: bool,
    /// Its thread waits for the next event (only then does publishing wake it).
    pub(super) waiting: bool,
}

/// One page connection's side of the hub.
#[derive(Default)]
pub(super) struct Subscriber {
    pub(super) queue: Mutex<Queue>,
    pub(super) ready: Condvar,
}

impl Subscriber {
    /// Ends the subscription (the thread is gone or the page was dropped).
    pub(super) fn close(&self) {
        if let Ok(mut q) = self.queue.lock() {
            q.closed = true;
            q.items.clear();
            q.bytes = 0;
        }
        self.ready.notify_one();
    }
}

pub(super) struct HubState {
    /// Verdict lines and input records, each its own history (inputs are many more).
    pub(super) history: [VecDeque<Published>; 2],
    pub(super) next_id: u64,
    pub(super) subscribers: Vec<Arc<Subscriber>>,
    /// Bytes a connection may have queued ([`Limits::queue_bytes`]).
    pub(super) queue_bytes: usize,
}

/// Where verdict lines meet the page's connections. The sidecar's judging thread
/// publishes; locks are held only to copy or queue a few items, never across a socket's
/// I/O, and a full queue drops its page instead of waiting for it: the judge never waits
/// for a page.
pub struct Hub {
    state: Mutex<HubState>,
}

impl Default for Hub {
    fn default() -> Hub {
        Hub::new(Limits::default().queue_bytes)
    }
}

/// A piece of the history read by a connection: the events, and how many lines before
/// and among them are no longer held.
pub(super) struct Piece {
    pub(super) events: Vec<Published>,
    pub(super) skipped: u64,
}

impl Hub {
    pub(super) fn new(queue_bytes: usize) -> Hub {
        Hub {
            state: Mutex::new(HubState {
                history: [VecDeque::new(), VecDeque::new()],
                next_id: 0,
                subscribers: Vec::new(),
                queue_bytes,
            }),
        }
    }

    /// Publishes one line of `stream` (without its newline) to every connection.
    pub fn publish(&self, stream: Stream, line: &str) {
        let Ok(mut s) = self.state.lock() else {
            return;
        };
        let p = Published {
            id: s.next_id,
            sent_ms: now_ms(),
            stream,
            line: line.into(),
        };
        s.next_id += 1;
        let history = &mut s.history[stream as usize];
        if history.len() == HISTORY {
            history.pop_front();
        }
        history.push_back(p.clone());
        // Never waits on a page: each queue's lock is held by its thread only to take
        // the queued events. A connection that is gone is forgotten; one whose queue
        // would pass its bound is dropped (its queue emptied at once, its thread closes
        // the connection, the page reconnects with `Last-Event-ID`).
        let bound = s.queue_bytes;
        s.subscribers.retain(|sub| {
            let Ok(mut q) = sub.queue.lock() else {
                return false;
            };
            if q.closed {
                return false;
            }
            let keep = q.bytes + p.cost() <= bound;
            if keep {
                q.bytes += p.cost();
                q.items.push_back(p.clone());
            } else {
                q.closed = true;
                q.items.clear();
                q.bytes = 0;
            }
            let wake = q.waiting || !keep;
            drop(q);
            if wake {
                sub.ready.notify_one();
            }
            keep
        });
    }

    /// The events after `after` (all with `None`) still held, in the order they were
    /// published, at most `max_bytes` of them (at least one), and how many lines up to
    /// the last of them are no longer held. When that reaches the newest line, the
    /// connection is subscribed in the same step (nothing published in between is
    /// missed) and its subscriber is returned too.
    pub(super) fn catch_up(
        &self,
        after: Option<u64>,
        max_bytes: usize,
    ) -> Option<(Piece, Option<Arc<Subscriber>>)> {
        let mut s = self.state.lock().ok()?;
        let start = after.map_or(0, |a| a.saturating_add(1));
        let [v, i] = &s.history;
        let (mut a, mut b) = (
            v.partition_point(|p| p.id < start),
            i.partition_point(|p| p.id < start),
        );
        let (mut events, mut bytes, mut skipped, mut next) = (Vec::new(), 0, 0u64, start);
        loop {
            let p = match (v.get(a), i.get(b)) {
                (Some(x), Some(y)) if x.id < y.id => {
                    a += 1;
                    x
                }
                (_, Some(y)) => {
                    b += 1;
                    y
                }
                (Some(x), None) => {
                    a += 1;
                    x
                }
                (None, None) => break,
            };
            if !events.is_empty() && bytes + p.cost() > max_bytes {
                return Some((Piece { events, skipped }, None));
            }
            skipped += p.id - next;
            next = p.id + 1;
            bytes += p.cost();
            events.push(p.clone());
        }
        skipped += s.next_id.saturating_sub(next);
        let sub = Arc::new(Subscriber::default());
        s.subscribers.push(sub.clone());
        Some((Piece { events, skipped }, Some(sub)))
    }

    /// The verdict lines after `after` (all with `None`) and before `end`, at most
    /// `max_bytes` of them (at least one): the next piece of `/verdicts.jsonl`.
    pub(super) fn verdicts(
        &self,
        after: Option<u64>,
        end: u64,
        max_bytes: usize,
    ) -> Vec<Published> {
        let Ok(s) = self.state.lock() else {
            return Vec::new();
        };
        let h = &s.history[Stream::Verdict as usize];
        let from = h.partition_point(|p| after.is_some_and(|a| p.id <= a));
        let mut bytes = 0;
        h.range(from..)
            .take_while(|p| p.id < end)
            .take_while(|p| {
                bytes += p.cost();
                bytes - p.cost() == 0 || bytes <= max_bytes
            })
            .cloned()
            .collect()
    }

    /// The id the next line will get.
    pub(super) fn next_id(&self) -> u64 {
        self.state.lock().map_or(0, |s| s.next_id)
    }

    /// How many connections are subscribed (for the tests).
    #[cfg(test)]
    pub(super) fn subscribers(&self) -> usize {
        self.state.lock().map_or(0, |s| s.subscribers.len())
    }
}

pub(super) fn now_ms() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64)
}

/// A writer that passes every byte to `inner` and then each complete line to a [`Hub`].
pub struct Tee {
    inner: Box<dyn Write + Send>,
    hub: Arc<Hub>,
    stream: Stream,
    partial: Vec<u8>,
}

impl Tee {
    /// Writes to `inner`, publishing its lines to `hub` as lines of `stream`.
    pub fn new(inner: Box<dyn Write + Send>, hub: Arc<Hub>, stream: Stream) -> Tee {
        Tee {
            inner,
            hub,
            stream,
            partial: Vec::new(),
        }
    }
}

impl Write for Tee {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        // The file first: what reaches the page is always already in the output.
        let n = self.inner.write(buf)?;
        let mut rest = &buf[..n];
        while let Some(i) = rest.iter().position(|&b| b == b'\n') {
            self.partial.extend_from_slice(&rest[..i]);
            self.hub
                .publish(self.stream, &String::from_utf8_lossy(&self.partial));
            self.partial.clear();
            rest = &rest[i + 1..];
        }
        self.partial.extend_from_slice(rest);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}
