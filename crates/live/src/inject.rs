//! `hindsight run`'s input side: messages that processes replacing node models publish or answer, read from iceoryx2 and posted into the running model.
//!
//! A process that plays a node model (`hindsight run --external NAME`) publishes each
//! of the model's topics in the layout [`super::publish`] defines, on the same service
//! `hindsight run` would have published it on. [`TopicSubscriber`] holds one subscriber
//! per such topic; at every model time unit the run drains them and hands each sample to
//! the simulator ([`crate::sim::Inbox`]), which posts it as if a machine had sent it.
//!
//! A service the process serves is an iceoryx2 request-response service named after the
//! ROS service (`<prefix>/NotifyUserComponent/StartAlarm`, `[u8]` both ways). When the
//! model's server would receive a request (`srv_<s>_request`), [`ServiceBridge`] sends it
//! there in the request's layout; the answer, in the response's layout, is posted into
//! the model as the server's `srv_<s>_response` at the next model time unit.

use std::collections::VecDeque;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::port::server::Server;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use super::publish::TopicLayout;
use super::LiveError;
use crate::sim::{Inbox, SentMessage, EXTERNAL};

type Ipc = ipc::Service;
type RawSubscriber = Subscriber<Ipc, [u8], ()>;
type RawClient = Client<Ipc, [u8], (), [u8], ()>;
type Pending = PendingResponse<Ipc, [u8], (), [u8], ()>;
type RawServer = Server<Ipc, [u8], (), [u8], ()>;
type Active = ActiveRequest<Ipc, [u8], (), [u8], ()>;

/// Counts of what came in on one topic.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InboundStats {
    /// The service name.
    pub service: String,
    /// Samples posted into the model.
    pub received: u64,
    /// Samples of the wrong size or with a bad `bool` byte: counted, never posted.
    pub malformed: u64,
    /// Samples missing from the `seq` counter (the publisher restarted, or the run's
    /// buffer overflowed).
    pub lost: u64,
}

/// Subscribers to the topics processes publish into the run.
pub struct TopicSubscriber {
    topics: Vec<(TopicLayout, RawSubscriber, InboundStats, Option<u64>)>,
}

impl TopicSubscriber {
    /// Opens (or creates) one service per layout under `prefix` on `node`, with a
    /// subscriber each.
    pub fn new(
        node: &Node<Ipc>,
        layouts: Vec<TopicLayout>,
        prefix: &str,
    ) -> Result<TopicSubscriber, LiveError> {
        let mut topics = Vec::new();
        for l in layouts {
            let svc = l.service(prefix);
            let factory = super::open_raw_topic(node, &svc)?;
            let sub = factory
                .subscriber_builder()
                .create()
                .map_err(|e| LiveError::ipc(&svc, e))?;
            let stats = InboundStats {
                service: svc,
                ..InboundStats::default()
            };
            topics.push((l, sub, stats, None));
        }
        Ok(TopicSubscriber { topics })
    }

    /// Takes every sample waiting on every topic and queues it in `inbox`.
    pub fn poll(&mut self, inbox: &mut Inbox) -> Result<(), LiveError> {
        for (layout, sub, stats, last_seq) in &mut self.topics {
            loop {
                let sample = match sub.receive() {
                    Ok(Some(s)) => s,
                    Ok(None) => break,
                    Err(e) => return Err(LiveError::ipc(&stats.service, e)),
                };
                match layout.decode(sample.payload()) {
                    Some((params, seq)) => {
                        if let Some(prev) = *last_seq {
                            // A smaller seq: a restarted publisher, not a loss.
                            if seq > prev + 1 {
                                stats.lost += seq - prev - 1;
                            }
                        }
                        *last_seq = Some(seq);
                        stats.received += 1;
                        inbox.push(layout.event, params);
                    }
                    None => stats.malformed += 1,
                }
            }
        }
        Ok(())
    }

    /// What came in on each topic so far.
    pub fn stats(&self) -> impl Iterator<Item = &InboundStats> {
        self.topics.iter().map(|t| &t.2)
    }
}

/// Counts of one bridged service.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ServiceStats {
    /// The request-response service name.
    pub service: String,
    /// Requests sent to the process.
    pub requests: u64,
    /// Responses posted into the model.
    pub answered: u64,
    /// Requests sent while no server was connected: the model's client waits for ever,
    /// as a ROS client of a missing server does.
    pub unanswered: u64,
    /// Responses of the wrong size or with a bad `bool` byte: counted, never posted.
    pub malformed: u64,
}

/// A client of one request-response service a process serves: requests out in a layout,
/// answers matched to their requests in order (`T`: what the caller keeps per request).
struct Outgoing<T> {
    client: RawClient,
    pending: VecDeque<(Pending, T)>,
    seq: u64,
    stats: ServiceStats,
}

impl<T> Outgoing<T> {
    /// A client of `prefix/path`, the service opened or created.
    fn open(
        node: &Node<Ipc>,
        prefix: &str,
        path: String,
        max_len: usize,
    ) -> Result<Self, LiveError> {
        let svc = prefixed(prefix, path);
        let name = super::service_name(&svc)?;
        let client = node
            .service_builder(&name)
            .request_response::<[u8], [u8]>()
            .open_or_create()
            .map_err(|e| LiveError::ipc(&svc, e))?
            .client_builder()
            .initial_max_slice_len(max_len)
            .create()
            .map_err(|e| LiveError::ipc(&svc, e))?;
        Ok(Outgoing {
            client,
            pending: VecDeque::new(),
            seq: 0,
            stats: ServiceStats {
                service: svc,
                ..ServiceStats::default()
            },
        })
    }

    /// Sends `msg` in `layout`; without a server it counts as unanswered.
    fn send(
        &mut self,
        layout: &TopicLayout,
        msg: &SentMessage<'_>,
        keep: T,
    ) -> Result<(), LiveError> {
        let seq = self.seq;
        self.seq += 1;
        let service = &self.stats.service;
        let pending = self
            .client
            .loan_slice_uninit(layout.size)
            .map_err(|e| LiveError::ipc(service, e))
            .and_then(|r| {
                let mut r = r.write_from_fn(|_| 0u8);
                layout.encode(msg, seq, r.payload_mut());
                r.send().map_err(|e| LiveError::ipc(service, e))
            })?;
        self.stats.requests += 1;
        if pending.number_of_server_connections() == 0 {
            self.stats.unanswered += 1;
        } else {
            self.pending.push_back((pending, keep));
        }
        Ok(())
    }

    /// Hands each answer that arrived to `answer` (which says whether it was well formed);
    /// one answer per request, and a server that went away answers nothing.
    fn receive(&mut self, mut answer: impl FnMut(&[u8], &T) -> bool) {
        let mut k = 0;
        while k < self.pending.len() {
            let mut done = false;
            while let Ok(Some(resp)) = self.pending[k].0.receive() {
                if answer(resp.payload(), &self.pending[k].1) {
                    self.stats.answered += 1;
                } else {
                    self.stats.malformed += 1;
                }
                done = true;
            }
            if done || !self.pending[k].0.is_connected() {
                if !done {
                    self.stats.unanswered += 1;
                }
                self.pending.remove(k);
            } else {
                k += 1;
            }
        }
    }
}

/// Bridged entries found by the id of a model event they take: built once, read per message.
struct ByEvent<T> {
    /// Per event id: the index into `entries` if the event is bridged.
    index: Vec<Option<usize>>,
    entries: Vec<T>,
}

impl<T> ByEvent<T> {
    fn new(event_count: usize) -> Self {
        ByEvent {
            index: vec![None; event_count],
            entries: Vec::new(),
        }
    }

    /// Adds `entry`, found from each of `events`.
    fn push(&mut self, events: impl IntoIterator<Item = crate::sim::EventId>, entry: T) {
        for e in events {
            if let Some(slot) = self.index.get_mut(e.0 as usize) {
                *slot = Some(self.entries.len());
            }
        }
        self.entries.push(entry);
    }

    /// The entry `msg`'s event goes to, if any.
    fn of(&mut self, msg: &SentMessage<'_>) -> Option<&mut T> {
        let i = (*self.index.get(msg.event().0 as usize)?)?;
        self.entries.get_mut(i)
    }
}

/// Clients of the services processes serve: requests out, responses into the model.
pub struct ServiceBridge {
    /// `(request layout, response layout, client)`, found by the request's event.
    services: ByEvent<(TopicLayout, TopicLayout, Outgoing<()>)>,
}

impl ServiceBridge {
    /// Opens (or creates) one request-response service per `(service path, request
    /// layout, response layout)` under `prefix`, with a client each.
    pub fn new(
        node: &Node<Ipc>,
        event_count: usize,
        services: Vec<(String, TopicLayout, TopicLayout)>,
        prefix: &str,
    ) -> Result<ServiceBridge, LiveError> {
        let mut out = ByEvent::new(event_count);
        for (path, request, response) in services {
            let client = Outgoing::open(node, prefix, path, request.size)?;
            out.push([request.event], (request, response, client));
        }
        Ok(ServiceBridge { services: out })
    }

    /// Sends `msg` to its process if it is a request of a bridged service.
    pub fn forward(&mut self, msg: &SentMessage<'_>) -> Result<(), LiveError> {
        if msg.origin() == EXTERNAL {
            return Ok(());
        }
        let Some((request, _, client)) = self.services.of(msg) else {
            return Ok(());
        };
        client.send(request, msg, ())
    }

    /// Takes every response that arrived and queues it in `inbox`, oldest request first.
    pub fn poll(&mut self, inbox: &mut Inbox) {
        for (_, response, client) in &mut self.services.entries {
            client.receive(|bytes, ()| match response.decode(bytes) {
                Some((params, _seq)) => {
                    inbox.push(response.event, params);
                    true
                }
                None => false,
            });
        }
    }

    /// What each bridged service did so far.
    pub fn stats(&self) -> impl Iterator<Item = &ServiceStats> {
        self.services.entries.iter().map(|s| &s.2.stats)
    }
}

/// How the model's answer to a process's call becomes the iceoryx2 response.
pub enum Answer {
    /// A service's response: the answer event's parameters in this layout.
    Layout(TopicLayout),
    /// An action's goal response: one byte, 1 for the `accept` event, 0 for `reject`,
    /// then a `u64` seq.
    Goal {
        /// The handler's accept of the client's goal.
        accept: crate::sim::EventId,
        /// The handler's reject of the client's goal.
        reject: crate::sim::EventId,
    },
}

impl Answer {
    fn size(&self) -> usize {
        match self {
            Answer::Layout(l) => l.size,
            Answer::Goal { .. } => 9,
        }
    }

    fn events(&self) -> Vec<crate::sim::EventId> {
        match self {
            Answer::Layout(l) => vec![l.event],
            Answer::Goal { accept, reject } => vec![*accept, *reject],
        }
    }
}

struct Served {
    request: TopicLayout,
    response: Answer,
    server: RawServer,
    /// Requests posted into the model, oldest first: the model answers in order.
    waiting: VecDeque<Active>,
    seq: u64,
    stats: ServiceStats,
}

/// Servers of the model's services and actions that processes call: requests and goals
/// into the model, its answers back.
pub struct ServiceServers {
    /// Found by the events of the model's answers to a client.
    services: ByEvent<Served>,
}

impl ServiceServers {
    /// Opens (or creates) one request-response service per `(service or action path, the
    /// client's request or goal layout, the answer)` under `prefix`, with a server each.
    pub fn new(
        node: &Node<Ipc>,
        event_count: usize,
        services: Vec<(String, TopicLayout, Answer)>,
        prefix: &str,
    ) -> Result<ServiceServers, LiveError> {
        let mut out = ByEvent::new(event_count);
        for (path, request, response) in services {
            let svc = prefixed(prefix, path);
            let name = super::service_name(&svc)?;
            let server = node
                .service_builder(&name)
                .request_response::<[u8], [u8]>()
                .open_or_create()
                .map_err(|e| LiveError::ipc(&svc, e))?
                .server_builder()
                .initial_max_slice_len(response.size())
                .create()
                .map_err(|e| LiveError::ipc(&svc, e))?;
            let served = Served {
                request,
                waiting: VecDeque::new(),
                seq: 0,
                stats: ServiceStats {
                    service: svc,
                    ..ServiceStats::default()
                },
                response,
                server,
            };
            out.push(served.response.events(), served);
        }
        Ok(ServiceServers { services: out })
    }

    /// Takes every request that arrived and queues it in `inbox` as the client's request.
    /// A malformed request is counted and gets no answer.
    pub fn poll(&mut self, inbox: &mut Inbox) {
        for s in &mut self.services.entries {
            while let Ok(Some(req)) = s.server.receive() {
                match s.request.decode(req.payload()) {
                    Some((params, _seq)) => {
                        s.stats.requests += 1;
                        inbox.push(s.request.event, params);
                        s.waiting.push_back(req);
                    }
                    None => s.stats.malformed += 1,
                }
            }
        }
    }

    /// Answers the oldest waiting request with `msg` if it is the model's answer to a
    /// bridged client.
    pub fn answer(&mut self, msg: &SentMessage<'_>) -> Result<(), LiveError> {
        let Some(s) = self.services.of(msg) else {
            return Ok(());
        };
        let Some(req) = s.waiting.pop_front() else {
            return Ok(());
        };
        let seq = s.seq;
        s.seq += 1;
        if !req.is_connected() {
            // The caller went away: nobody to answer.
            s.stats.unanswered += 1;
            return Ok(());
        }
        let response = &s.response;
        req.loan_slice_uninit(response.size())
            .map_err(|e| LiveError::ipc(&s.stats.service, e))
            .and_then(|r| {
                let mut r = r.write_from_fn(|_| 0u8);
                let out = r.payload_mut();
                match response {
                    Answer::Layout(l) => l.encode(msg, seq, out),
                    Answer::Goal { accept, .. } => {
                        out[0] = u8::from(msg.event() == *accept);
                        out[1..9].copy_from_slice(&seq.to_le_bytes());
                    }
                }
                r.send().map_err(|e| LiveError::ipc(&s.stats.service, e))
            })?;
        s.stats.answered += 1;
        Ok(())
    }

    /// What each served service did so far (`requests`: from processes; `answered`: by
    /// the model).
    pub fn stats(&self) -> impl Iterator<Item = &ServiceStats> {
        self.services.entries.iter().map(|s| &s.stats)
    }
}

/// `prefix/path`, or `path` with an empty prefix.
fn prefixed(prefix: &str, path: String) -> String {
    let p = prefix.trim_end_matches('/');
    if p.is_empty() {
        path
    } else {
        format!("{p}/{path}")
    }
}

/// One action whose goals go to a process.
pub struct GoalRoute {
    /// The request-response service path without prefix (the action's name).
    pub path: String,
    /// The layout of the server's goal event (`action_<a>_goal_handle`).
    pub goal: TopicLayout,
    /// Index of `goal_id` among the goal event's parameters.
    pub goal_id: usize,
    /// `action_<a>_goal_accepted` and the index of its `goal_id`.
    pub accepted: (crate::sim::EventId, usize),
    /// `action_<a>_goal_rejected` and the index of its `goal_id`.
    pub rejected: (crate::sim::EventId, usize),
}

/// Clients of the actions processes serve: goals out, accepts and rejects into the model.
pub struct GoalBridge {
    /// Each route with its client, which keeps each goal's id until its answer.
    actions: Vec<(GoalRoute, Outgoing<i64>)>,
}

impl GoalBridge {
    /// Opens (or creates) one request-response service per route under `prefix`.
    pub fn new(
        node: &Node<Ipc>,
        routes: Vec<GoalRoute>,
        prefix: &str,
    ) -> Result<GoalBridge, LiveError> {
        let mut actions = Vec::new();
        for route in routes {
            let client = Outgoing::open(node, prefix, route.path.clone(), route.goal.size)?;
            actions.push((route, client));
        }
        Ok(GoalBridge { actions })
    }

    /// Sends `msg` to its process if it is a goal of a bridged action.
    pub fn forward(&mut self, msg: &SentMessage<'_>) -> Result<(), LiveError> {
        if msg.origin() == EXTERNAL {
            return Ok(());
        }
        let Some((route, client)) = self
            .actions
            .iter_mut()
            .find(|(r, _)| r.goal.event == msg.event())
        else {
            return Ok(());
        };
        let goal_id = match msg.param(route.goal_id) {
            Some(crate::expr::Value::Int(g)) => g,
            _ => 0,
        };
        client.send(&route.goal, msg, goal_id)
    }

    /// Posts each answer that arrived as the server's accept or reject of its goal.
    pub fn poll(&mut self, inbox: &mut Inbox) {
        for (route, client) in &mut self.actions {
            client.receive(|bytes, &goal_id| match bytes {
                [b @ (0 | 1), _, _, _, _, _, _, _, _] => {
                    let (event, at) = if *b == 1 {
                        route.accepted
                    } else {
                        route.rejected
                    };
                    inbox.push(event, vec![(at, crate::sim::Scalar::Int(goal_id))]);
                    true
                }
                _ => false,
            });
        }
    }

    /// What each bridged action's goals did so far.
    pub fn stats(&self) -> impl Iterator<Item = &ServiceStats> {
        self.actions.iter().map(|(_, c)| &c.stats)
    }
}
