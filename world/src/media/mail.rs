//! The messages medium (`<messages>`): the world's decision on every addressed message between the participants of
//! a run (robots, then coordinators), and the record of it.
//!
//! After tick k the world hands every outbox of the tick to [`MailMedium::route`], in participant order. Each
//! message is checked against the medium's limits in a fixed order (sender, count, size, address) and then, per
//! recipient, against the recipient's state, the medium's range, its loss and the recipient's inbox. Whatever
//! passes goes into the recipient's inbox for tick k + 1. Every decision is a [`MessageRecord`]. The loss draws
//! come from one seeded stream in that same order, so the same run gives the same records, wherever its agents
//! run.
//!
//! Range and loss model a radio between two bodies. A coordinator has no body: what it sends or receives is
//! subject to the limits only (it stands for a process on the network, not a robot).

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::config::MessagesMedium;
use swarm_contract::mail::{Address, FROM_WORLD, MAILBOX_CAPACITY, Mail, Mailbox, TO_WORLD};

use crate::geometry::Vec2;
use crate::rng::{self, Purpose};

/// What happened to a message, for one recipient or for the whole message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// In the recipient's inbox for the next tick.
    Delivered,
    /// The message claims another sender than the participant whose outbox holds it.
    ForgedSender,
    /// Beyond the medium's `max_per_tick` for its sender in this tick.
    OverTickLimit,
    /// Longer than the medium's `max_payload`.
    TooLong,
    /// Addressed to no participant of the run (or to its own sender).
    UnknownRecipient,
    /// A broadcast within a range that is not a positive finite number of metres.
    BadRange,
    /// A broadcast within range from a participant without a body (a coordinator).
    NoPosition,
    /// A broadcast within range that found no participant in range.
    NobodyInRange,
    /// The recipient is not taking part (dead, frozen, removed or not yet joined).
    RecipientDown,
    /// The recipient is farther from the sender than the medium's range.
    OutOfRange,
    /// Lost on the way (the medium's `loss`).
    Lost,
    /// The recipient's inbox already holds the most messages one tick delivers.
    InboxFull,
}

impl Fate {
    /// Every fate, in the order of [`Fate::index`].
    pub const ALL: [Fate; 12] = [
        Fate::Delivered,
        Fate::ForgedSender,
        Fate::OverTickLimit,
        Fate::TooLong,
        Fate::UnknownRecipient,
        Fate::BadRange,
        Fate::NoPosition,
        Fate::NobodyInRange,
        Fate::RecipientDown,
        Fate::OutOfRange,
        Fate::Lost,
        Fate::InboxFull,
    ];

    /// Its place in [`Fate::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// `delivered` or `dropped`, for the records.
    pub fn outcome(self) -> &'static str {
        match self {
            Fate::Delivered => "delivered",
            _ => "dropped",
        }
    }

    /// Why a message was dropped (empty when it was delivered), for the records.
    pub fn reason(self) -> &'static str {
        match self {
            Fate::Delivered => "",
            Fate::ForgedSender => "forged_sender",
            Fate::OverTickLimit => "over_tick_limit",
            Fate::TooLong => "too_long",
            Fate::UnknownRecipient => "unknown_recipient",
            Fate::BadRange => "bad_range",
            Fate::NoPosition => "no_position",
            Fate::NobodyInRange => "nobody_in_range",
            Fate::RecipientDown => "recipient_down",
            Fate::OutOfRange => "out_of_range",
            Fate::Lost => "lost",
            Fate::InboxFull => "inbox_full",
        }
    }
}

/// One decision of the medium: a row of `messages.csv`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MessageRecord {
    /// The tick the message was sent in (it is delivered in the next one).
    pub tick: u64,
    /// The sending participant (its outbox's owner, whatever the message claims).
    pub from: u32,
    /// The recipient this decision is about; for a message refused as a whole, the one it was addressed to, if
    /// it was addressed to one.
    pub to: Option<u32>,
    /// How the message was addressed.
    pub address: Address,
    /// Payload bytes.
    pub bytes: u16,
    /// What happened.
    pub fate: Fate,
}

/// How many of a run's decisions had each fate, for `summary.json`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct MessageTally {
    counts: [u64; Fate::ALL.len()],
}

impl MessageTally {
    /// Counts `records`.
    pub fn add(&mut self, records: &[MessageRecord]) {
        for record in records {
            self.counts[record.fate.index()] += 1;
        }
    }

    /// `{"delivered": n, "dropped": {"<reason>": n, ...}}`, reasons that never happened left out.
    pub fn to_json(&self) -> serde_json::Value {
        let dropped: serde_json::Map<String, serde_json::Value> = Fate::ALL[1..]
            .iter()
            .filter(|fate| self.counts[fate.index()] > 0)
            .map(|fate| (fate.reason().to_owned(), self.counts[fate.index()].into()))
            .collect();
        serde_json::json!({
            "delivered": self.counts[Fate::Delivered.index()],
            "dropped": dropped,
        })
    }
}

/// Where a participant is and whether it takes part, as the medium needs to know it for one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Participant {
    /// Whether it takes part in the tick (messages to a participant that does not are dropped).
    pub up: bool,
    /// Its body's centre; `None` for a coordinator.
    pub position: Option<Vec2>,
}

/// The messages medium of a run.
#[derive(Debug, Clone)]
pub struct MailMedium {
    range: Option<f32>,
    loss: f64,
    max_payload: usize,
    max_per_tick: usize,
    rng: ChaCha8Rng,
}

impl MailMedium {
    /// The medium of `config` for the run `seed`.
    pub fn new(config: &MessagesMedium, seed: u64) -> MailMedium {
        MailMedium {
            range: config.range.map(|r| r as f32),
            loss: config.loss,
            max_payload: config.max_payload as usize,
            max_per_tick: (config.max_per_tick as usize).min(MAILBOX_CAPACITY),
            rng: rng::stream(seed, Purpose::Messages, 0),
        }
    }

    /// Decides the fate of every message of `outboxes` (one per sending participant, in participant order) sent
    /// in `tick`: each delivered message goes into its recipient's entry of `inboxes` (one per participant,
    /// emptied first) or, addressed to [`TO_WORLD`], into `to_world` (emptied first; never lost, the world is no
    /// radio), and every decision into `records` (appended to).
    pub fn route(
        &mut self,
        tick: u64,
        outboxes: &[Mailbox],
        participants: &[Participant],
        inboxes: &mut [Mailbox],
        to_world: &mut Vec<Mail>,
        records: &mut Vec<MessageRecord>,
    ) {
        for inbox in inboxes.iter_mut() {
            inbox.clear();
        }
        to_world.clear();
        for outbox in outboxes {
            let from = outbox.owner;
            for (index, mail) in outbox.messages().iter().enumerate() {
                let record = |to, fate| MessageRecord {
                    tick,
                    from,
                    to,
                    address: mail.address(),
                    bytes: mail.len,
                    fate,
                };
                let refused = if mail.from != from {
                    Some(Fate::ForgedSender)
                } else if index >= self.max_per_tick {
                    Some(Fate::OverTickLimit)
                } else if usize::from(mail.len) > self.max_payload {
                    Some(Fate::TooLong)
                } else {
                    None
                };
                if let Some(fate) = refused {
                    let to = match mail.address() {
                        Address::To(to) => Some(to),
                        Address::All | Address::Within(_) => None,
                    };
                    records.push(record(to, fate));
                    continue;
                }
                let sender = participants.get(from as usize).and_then(|p| p.position);
                match mail.address() {
                    Address::To(TO_WORLD) => {
                        to_world.push(*mail);
                        records.push(record(Some(TO_WORLD), Fate::Delivered));
                    }
                    Address::To(to) if to == from || to as usize >= participants.len() => {
                        records.push(record(Some(to), Fate::UnknownRecipient));
                    }
                    Address::To(to) => {
                        let fate = self.deliver(mail, sender, to, participants, inboxes);
                        records.push(record(Some(to), fate));
                    }
                    Address::All => {
                        for to in (0..participants.len() as u32).filter(|&to| to != from) {
                            let fate = self.deliver(mail, sender, to, participants, inboxes);
                            records.push(record(Some(to), fate));
                        }
                    }
                    Address::Within(range) if !(range.is_finite() && range > 0.0) => {
                        records.push(record(None, Fate::BadRange));
                    }
                    Address::Within(range) => {
                        let Some(at) = sender else {
                            records.push(record(None, Fate::NoPosition));
                            continue;
                        };
                        let near = |p: &Participant| {
                            p.position.is_some_and(|q| (q - at).length() <= range)
                        };
                        let before = records.len();
                        for to in (0..participants.len() as u32)
                            .filter(|&to| to != from && near(&participants[to as usize]))
                        {
                            let fate = self.deliver(mail, sender, to, participants, inboxes);
                            records.push(record(Some(to), fate));
                        }
                        if records.len() == before {
                            records.push(record(None, Fate::NobodyInRange));
                        }
                    }
                }
            }
        }
    }

    /// Delivers the world's own `letters` (sent by the loop functions in `tick`, each addressed to one
    /// participant): they are neither lost nor out of range, but a participant that is down or has a full inbox
    /// does not get them, and every decision is recorded like a participant's message.
    pub fn post_letters(
        &mut self,
        tick: u64,
        letters: &[Mail],
        participants: &[Participant],
        inboxes: &mut [Mailbox],
        records: &mut Vec<MessageRecord>,
    ) {
        for mail in letters {
            let Address::To(to) = mail.address() else {
                continue;
            };
            let fate = if to as usize >= participants.len() {
                Fate::UnknownRecipient
            } else {
                self.deliver(mail, None, to, participants, inboxes)
            };
            records.push(MessageRecord {
                tick,
                from: FROM_WORLD,
                to: Some(to),
                address: mail.address(),
                bytes: mail.len,
                fate,
            });
        }
    }

    /// The fate of `mail` for recipient `to`, and the delivery itself when it gets through.
    fn deliver(
        &mut self,
        mail: &Mail,
        sender: Option<Vec2>,
        to: u32,
        participants: &[Participant],
        inboxes: &mut [Mailbox],
    ) -> Fate {
        let recipient = participants[to as usize];
        if !recipient.up {
            return Fate::RecipientDown;
        }
        if let (Some(a), Some(b)) = (sender, recipient.position) {
            if self.range.is_some_and(|range| (b - a).length() > range) {
                return Fate::OutOfRange;
            }
            if self.loss > 0.0 && self.rng.random_bool(self.loss) {
                return Fate::Lost;
            }
        }
        match inboxes.get_mut(to as usize).map(|inbox| inbox.push(*mail)) {
            Some(Ok(())) => Fate::Delivered,
            _ => Fate::InboxFull,
        }
    }
}

#[cfg(test)]
mod tests {
    use swarm_contract::config::Location;

    use super::*;

    fn medium(range: Option<f64>, loss: f64) -> MailMedium {
        MailMedium::new(
            &MessagesMedium {
                id: "net".into(),
                range,
                loss,
                max_payload: 16,
                max_per_tick: 2,
                location: Location::default(),
            },
            7,
        )
    }

    fn robot(x: f32) -> Participant {
        Participant {
            up: true,
            position: Some(Vec2::new(x, 0.0)),
        }
    }

    const COORDINATOR: Participant = Participant {
        up: true,
        position: None,
    };

    fn outbox(owner: u32, sends: &[(Address, &[u8])]) -> Mailbox {
        let mut outbox = Mailbox::empty(owner);
        for &(address, payload) in sends {
            outbox.send(address, payload).unwrap();
        }
        outbox
    }

    fn route(
        medium: &mut MailMedium,
        outboxes: &[Mailbox],
        participants: &[Participant],
    ) -> (Vec<Mailbox>, Vec<(Option<u32>, Fate)>) {
        let mut inboxes: Vec<Mailbox> =
            (0..participants.len() as u32).map(Mailbox::empty).collect();
        let mut records = Vec::new();
        medium.route(
            5,
            outboxes,
            participants,
            &mut inboxes,
            &mut Vec::new(),
            &mut records,
        );
        let fates = records.iter().map(|r| (r.to, r.fate)).collect();
        (inboxes, fates)
    }

    #[test]
    fn unicast_broadcast_and_ranged_broadcast_reach_whom_they_address() {
        let mut medium = medium(None, 0.0);
        let participants = [robot(0.0), robot(0.5), robot(3.0), COORDINATOR];
        let sent = [outbox(
            0,
            &[
                (Address::To(3), b"to the coordinator"[..8].as_ref()),
                (Address::Within(1.0), b"near"),
            ],
        )];
        let (inboxes, fates) = route(&mut medium, &sent, &participants);
        assert_eq!(
            fates,
            [(Some(3), Fate::Delivered), (Some(1), Fate::Delivered)]
        );
        assert_eq!(inboxes[3].messages()[0].payload(), b"to the c");
        assert_eq!(inboxes[3].messages()[0].from, 0);
        assert_eq!(inboxes[1].messages()[0].payload(), b"near");
        assert!(inboxes[2].is_empty());
        let all = [outbox(3, &[(Address::All, b"hi")])];
        let (inboxes, fates) = route(&mut medium, &all, &participants);
        assert_eq!(fates.len(), 3);
        let alone = [outbox(2, &[(Address::Within(1.0), b"anyone?")])];
        assert_eq!(
            route(&mut medium, &alone, &participants).1,
            [(None, Fate::NobodyInRange)]
        );
        assert!(inboxes[..3].iter().all(|inbox| inbox.messages().len() == 1));
    }

    #[test]
    fn limits_range_and_state_drop_what_they_must_and_say_why() {
        let mut medium = medium(Some(1.0), 0.0);
        let mut down = robot(0.2);
        down.up = false;
        let participants = [robot(0.0), robot(2.0), down, COORDINATOR];
        let mut forged = outbox(0, &[]);
        forged
            .push(Mail::new(1, Address::To(3), b"x").unwrap())
            .unwrap();
        let sent = [
            forged,
            outbox(
                1,
                &[
                    (Address::To(0), b"far"),
                    (Address::To(2), b"down"),
                    (Address::To(3), b"over the limit"),
                ],
            ),
            outbox(
                3,
                &[(Address::To(9), b"nobody"), (Address::To(0), &[1; 17])],
            ),
        ];
        let (inboxes, fates) = route(&mut medium, &sent, &participants);
        assert_eq!(
            fates,
            [
                (Some(3), Fate::ForgedSender),
                (Some(0), Fate::OutOfRange),
                (Some(2), Fate::RecipientDown),
                (Some(3), Fate::OverTickLimit),
                (Some(9), Fate::UnknownRecipient),
                (Some(0), Fate::TooLong),
            ]
        );
        assert!(inboxes.iter().all(Mailbox::is_empty));
        let coordinator = [outbox(
            3,
            &[(Address::Within(1.0), b"where?"), (Address::To(1), b"far")],
        )];
        let (_, fates) = route(&mut medium, &coordinator, &participants);
        assert_eq!(
            fates,
            [(None, Fate::NoPosition), (Some(1), Fate::Delivered)],
            "a coordinator has no position: range does not apply to it"
        );
    }

    #[test]
    fn loss_is_drawn_from_the_seeded_stream() {
        let participants = [robot(0.0), robot(0.1)];
        let sent: Vec<Mailbox> = (0..2)
            .map(|owner| outbox(owner, &[(Address::All, b"a"), (Address::All, b"b")]))
            .collect();
        let run = || {
            let mut medium = medium(None, 0.5);
            (0..50)
                .flat_map(|_| route(&mut medium, &sent, &participants).1)
                .collect::<Vec<_>>()
        };
        let fates = run();
        assert_eq!(fates, run());
        let lost = fates.iter().filter(|(_, f)| *f == Fate::Lost).count();
        assert!((50..150).contains(&lost), "{lost} of 200 lost");
    }

    #[test]
    fn letters_to_the_world_reach_it_whatever_the_loss_and_range() {
        let mut medium = medium(Some(0.1), 1.0);
        let participants = [robot(0.0), robot(5.0)];
        let sent = [
            outbox(0, &[(Address::To(TO_WORLD), b"stats")]),
            outbox(1, &[(Address::To(0), b"lost")]),
        ];
        let mut inboxes: Vec<Mailbox> = (0..2).map(Mailbox::empty).collect();
        let (mut to_world, mut records) = (Vec::new(), Vec::new());
        medium.route(
            1,
            &sent,
            &participants,
            &mut inboxes,
            &mut to_world,
            &mut records,
        );
        assert_eq!(to_world.len(), 1);
        assert_eq!(
            (to_world[0].from, to_world[0].payload()),
            (0, &b"stats"[..])
        );
        assert_eq!(records[0].to, Some(TO_WORLD));
        assert_eq!(records[0].fate, Fate::Delivered);
        assert_ne!(records[1].fate, Fate::Delivered);
        // The next tick starts with nothing for the world.
        medium.route(
            2,
            &[],
            &participants,
            &mut inboxes,
            &mut to_world,
            &mut records,
        );
        assert!(to_world.is_empty());
    }

    #[test]
    fn the_tally_counts_each_fate_under_its_reason() {
        assert!(
            Fate::ALL
                .iter()
                .enumerate()
                .all(|(i, fate)| fate.index() == i)
        );
        let mut medium = medium(Some(1.0), 0.0);
        let participants = [robot(0.0), robot(0.5), robot(3.0)];
        let sent = [outbox(0, &[(Address::All, b"hi")])];
        let mut inboxes: Vec<Mailbox> = (0..3).map(Mailbox::empty).collect();
        let mut records = Vec::new();
        medium.route(
            1,
            &sent,
            &participants,
            &mut inboxes,
            &mut Vec::new(),
            &mut records,
        );
        let mut tally = MessageTally::default();
        tally.add(&records);
        assert_eq!(
            tally.to_json(),
            serde_json::json!({"delivered": 1, "dropped": {"out_of_range": 1}})
        );
    }

    #[test]
    fn a_full_inbox_drops_the_rest() {
        let mut medium = MailMedium::new(
            &MessagesMedium {
                id: "net".into(),
                range: None,
                loss: 0.0,
                max_payload: 16,
                max_per_tick: MAILBOX_CAPACITY as u32,
                location: Location::default(),
            },
            1,
        );
        let participants = [robot(0.0), robot(0.1), robot(0.2)];
        let sends: Vec<(Address, &[u8])> = (0..20).map(|_| (Address::To(2), &b"m"[..])).collect();
        let sent = [outbox(0, &sends), outbox(1, &sends)];
        let (inboxes, fates) = route(&mut medium, &sent, &participants);
        assert_eq!(inboxes[2].messages().len(), MAILBOX_CAPACITY);
        let full = fates.iter().filter(|(_, f)| *f == Fate::InboxFull).count();
        assert_eq!(full, 40 - MAILBOX_CAPACITY);
    }
}
