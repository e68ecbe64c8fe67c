//! The world's post office (runs with a `<messages>` medium): after each tick every outbox of the tick goes to the
//! messages medium, the medium's decisions to `messages.csv`, and every inbox to its participant for the next
//! tick (docs/messages.md).

use swarm_contract::mail::Mailbox;
use swarm_world::World;
use swarm_world::media::mail::{MessageRecord, MessageTally};
use swarm_world::recorder::Recorder;

use crate::faults::FaultDriver;
use crate::remote::Link;

/// Buffers for one run's messages, reused every tick.
pub struct PostOffice {
    outboxes: Vec<Mailbox>,
    inboxes: Vec<Mailbox>,
    up: Vec<bool>,
    records: Vec<MessageRecord>,
    tally: MessageTally,
}

impl PostOffice {
    /// How many messages had each fate so far, for `summary.json`'s `messages`.
    pub fn summary(&self) -> serde_json::Value {
        self.tally.to_json()
    }

    /// The post office of a world with a messages medium and `participants` participants; `None` without one.
    pub fn new(world: &World, participants: usize) -> Option<PostOffice> {
        world.has_mail().then(|| PostOffice {
            outboxes: Vec::new(),
            inboxes: (0..participants as u32).map(Mailbox::empty).collect(),
            up: vec![false; participants],
            records: Vec::new(),
            tally: MessageTally::default(),
        })
    }

    /// Routes the messages sent in the tick `link` just ran, records the decisions and posts what each
    /// participant receives in the next tick. Call it before the tick's record ends.
    pub fn after_tick(
        &mut self,
        link: &mut Link,
        world: &mut World,
        faults: &FaultDriver,
        recorder: &mut Recorder,
    ) {
        self.outboxes.clear();
        for (participant, up) in self.up.iter_mut().enumerate() {
            *up = faults.is_alive(participant);
            if !*up {
                continue;
            }
            if let Some(outbox) = link.outbox(participant as u32) {
                self.outboxes.push(outbox);
            }
        }
        world.route_mail(
            link.tick(),
            &self.outboxes,
            &self.up,
            &mut self.inboxes,
            &mut self.records,
        );
        recorder.record_messages(&self.records);
        self.tally.add(&self.records);
        self.records.clear();
        for (participant, inbox) in (0..).zip(self.inboxes.iter_mut()) {
            if !inbox.is_empty() {
                link.post(participant, inbox);
            }
        }
    }
}
