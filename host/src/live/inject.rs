//! `hindsight run`'s input side: messages that processes replacing node models publish, read from iceoryx2 and posted into the running model.
//!
//! A process that plays a node model (`hindsight run --external NAME`) publishes each
//! of the model's topics in the layout [`super::publish`] defines, on the same service
//! `hindsight run` would have published it on. [`TopicSubscriber`] holds one subscriber
//! per such topic; at every model time unit the run drains them and hands each sample to
//! the simulator ([`crate::sim::Inbox`]), which posts it as if a machine had sent it.

use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use super::publish::TopicLayout;
use crate::sim::Inbox;

type Ipc = ipc::Service;
type RawSubscriber = Subscriber<Ipc, [u8], ()>;

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
    ) -> Result<TopicSubscriber, String> {
        let mut topics = Vec::new();
        for l in layouts {
            let svc = l.service(prefix);
            let name = super::service_name(&svc).map_err(|e| e.to_string())?;
            let factory = node
                .service_builder(&name)
                .publish_subscribe::<[u8]>()
                .open_or_create()
                .map_err(|e| format!("iceoryx2: {svc}: {e:?}"))?;
            let sub = factory
                .subscriber_builder()
                .create()
                .map_err(|e| format!("iceoryx2: {svc}: {e:?}"))?;
            let stats = InboundStats {
                service: svc,
                ..InboundStats::default()
            };
            topics.push((l, sub, stats, None));
        }
        Ok(TopicSubscriber { topics })
    }

    /// Takes every sample waiting on every topic and queues it in `inbox`.
    pub fn poll(&mut self, inbox: &mut Inbox) -> Result<(), String> {
        for (layout, sub, stats, last_seq) in &mut self.topics {
            loop {
                let sample = match sub.receive() {
                    Ok(Some(s)) => s,
                    Ok(None) => break,
                    Err(e) => return Err(format!("iceoryx2: {}: {e:?}", stats.service)),
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
