//! Addressed messages between the participants of a run (robots and coordinators): the mail contract.
//!
//! A participant's agent puts the messages it sends in one tick into its *outbox*; the world reads every outbox
//! after the tick, decides each message's fate by the run's `<messages>` medium (range, loss, per-message and
//! per-tick limits) and writes what each participant receives into its *inbox*, which the participant reads with
//! its next frame. So a message sent in tick k arrives in tick k + 1, the world alone decides delivery, and every
//! message is recorded. The world, not the sender, fills in who sent a message: a sender that claims to be
//! another participant is refused (docs/messages.md).
//!
//! [`Mailbox`] is fixed-size `#[repr(C)]` plain data, like the frames and commands, so it travels through
//! iceoryx2 shared memory without serialisation; across hosts it is bincode-encoded with only the used messages
//! and payload bytes. The capacities here are hard limits of the layout; a medium's own limits may be lower.

use bincode::de::read::Reader;
use bincode::de::{BorrowDecoder, Decoder};
use bincode::enc::Encoder;
use bincode::error::{DecodeError, EncodeError};
use bincode::{BorrowDecode, Decode, Encode};
use iceoryx2::prelude::ZeroCopySend;
use thiserror::Error;

/// Largest payload of one message in bytes.
pub const MAIL_PAYLOAD_BYTES: usize = 256;
/// Most messages in one outbox or inbox per tick.
pub const MAILBOX_CAPACITY: usize = 32;
/// The `to` of a message for every participant (alone: all; with a range: those within it).
pub const TO_ALL: u32 = u32::MAX;
/// The `from` of a message the world itself sends: its loop functions acting as a task server (the navigation
/// task's goals and map, docs/messages.md). No participant has this index.
pub const FROM_WORLD: u32 = u32::MAX;
/// The address of the world itself (`Address::To(TO_WORLD)`): letters to its loop functions, such as a robot's
/// planning statistics for the task's judge (docs/messages.md). No participant has this index.
pub const TO_WORLD: u32 = u32::MAX - 1;
/// The `len` of a closed mailbox ([`Mailbox::closed`]).
const CLOSED: u32 = u32::MAX;

/// Whom a message is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Address {
    /// One participant, by its index in the run (robots 0..N, then the coordinators).
    To(u32),
    /// Every other participant.
    All,
    /// Every other robot whose centre is at most this many metres from the sender's (robots only: a
    /// coordinator has no position, so it sends nothing this way).
    Within(f32),
}

/// Why an outbox refused a message (the sender learns at once; nothing reaches the world).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum SendError {
    /// The outbox holds [`MAILBOX_CAPACITY`] messages already this tick.
    #[error("the outbox is full ({MAILBOX_CAPACITY} messages per tick)")]
    OutboxFull,
    /// The payload is longer than [`MAIL_PAYLOAD_BYTES`].
    #[error("a payload of {0} bytes is longer than the {MAIL_PAYLOAD_BYTES} a message holds")]
    TooLong(usize),
    /// The run has no `<messages>` medium: nothing can be sent.
    #[error("the run has no <messages> medium: nothing can be sent")]
    NoMedium,
}

/// One message.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
pub struct Mail {
    /// Index of the sender. In an outbox the agent's claim (the world refuses a message whose claim is not the
    /// outbox's owner); in an inbox what the world recorded.
    pub from: u32,
    /// Index of the recipient, or [`TO_ALL`].
    pub to: u32,
    /// With `to == TO_ALL`: 0 for everyone, otherwise the range in metres of a broadcast within range.
    pub range: f32,
    /// Number of meaningful payload bytes.
    pub len: u16,
    /// Payload; only the first `len` bytes are meaningful.
    pub payload: [u8; MAIL_PAYLOAD_BYTES],
}

impl Mail {
    /// A message from `from` to `address` with `payload` (at most [`MAIL_PAYLOAD_BYTES`]).
    pub fn new(from: u32, address: Address, payload: &[u8]) -> Result<Mail, SendError> {
        if payload.len() > MAIL_PAYLOAD_BYTES {
            return Err(SendError::TooLong(payload.len()));
        }
        let (to, range) = match address {
            Address::To(robot) => (robot, 0.0),
            Address::All => (TO_ALL, 0.0),
            Address::Within(range) => (TO_ALL, range),
        };
        let mut mail = Mail {
            from,
            to,
            range,
            len: payload.len() as u16,
            payload: [0; MAIL_PAYLOAD_BYTES],
        };
        mail.payload[..payload.len()].copy_from_slice(payload);
        Ok(mail)
    }

    /// Whom the message is for.
    pub fn address(&self) -> Address {
        match (self.to, self.range) {
            (TO_ALL, range) if range != 0.0 => Address::Within(range),
            (TO_ALL, _) => Address::All,
            (robot, _) => Address::To(robot),
        }
    }

    /// The meaningful payload bytes.
    pub fn payload(&self) -> &[u8] {
        &self.payload[..usize::from(self.len).min(MAIL_PAYLOAD_BYTES)]
    }
}

/// The messages one participant sends (outbox) or receives (inbox) in one tick.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
pub struct Mailbox {
    /// Tick the messages belong to: the tick they were sent in (outbox) or are delivered in (inbox).
    pub tick: u64,
    /// Index of the participant whose mailbox this is.
    pub owner: u32,
    /// Number of valid entries in `mail`.
    pub len: u32,
    /// The messages, in order.
    pub mail: [Mail; MAILBOX_CAPACITY],
}

const EMPTY_MAIL: Mail = Mail {
    from: 0,
    to: 0,
    range: 0.0,
    len: 0,
    payload: [0; MAIL_PAYLOAD_BYTES],
};

impl Mailbox {
    /// An empty mailbox of `owner`.
    pub fn empty(owner: u32) -> Mailbox {
        Mailbox {
            tick: 0,
            owner,
            len: 0,
            mail: [EMPTY_MAIL; MAILBOX_CAPACITY],
        }
    }

    /// The outbox of a robot in a run without a `<messages>` medium: it holds nothing and refuses every message
    /// ([`SendError::NoMedium`]).
    pub fn closed(owner: u32) -> Mailbox {
        Mailbox {
            len: CLOSED,
            ..Mailbox::empty(owner)
        }
    }

    /// The valid messages.
    pub fn messages(&self) -> &[Mail] {
        let len = if self.len == CLOSED { 0 } else { self.len };
        &self.mail[..(len as usize).min(MAILBOX_CAPACITY)]
    }

    /// Whether it holds no message.
    pub fn is_empty(&self) -> bool {
        self.messages().is_empty()
    }

    /// Empties it (the messages' bytes stay until overwritten; only `len` counts); a closed one stays closed.
    pub fn clear(&mut self) {
        if self.len != CLOSED {
            self.len = 0;
        }
    }

    /// Appends `mail`.
    pub fn push(&mut self, mail: Mail) -> Result<(), SendError> {
        if self.len == CLOSED {
            return Err(SendError::NoMedium);
        }
        let at = self.len as usize;
        if at >= MAILBOX_CAPACITY {
            return Err(SendError::OutboxFull);
        }
        self.mail[at] = mail;
        self.len += 1;
        Ok(())
    }

    /// Appends a message from the owner to `address`.
    pub fn send(&mut self, address: Address, payload: &[u8]) -> Result<(), SendError> {
        self.push(Mail::new(self.owner, address, payload)?)
    }
}

// Across hosts a mailbox is encoded with only its valid messages and each message with only its payload bytes:
// an empty mailbox costs a few bytes, not 8.7 kB.
impl Encode for Mailbox {
    fn encode<E: Encoder>(&self, encoder: &mut E) -> Result<(), EncodeError> {
        self.tick.encode(encoder)?;
        self.owner.encode(encoder)?;
        let messages = self.messages();
        (messages.len() as u32).encode(encoder)?;
        for mail in messages {
            mail.from.encode(encoder)?;
            mail.to.encode(encoder)?;
            mail.range.encode(encoder)?;
            mail.payload().encode(encoder)?;
        }
        Ok(())
    }
}

impl<Context> Decode<Context> for Mailbox {
    fn decode<D: Decoder<Context = Context>>(decoder: &mut D) -> Result<Self, DecodeError> {
        let mut mailbox = Mailbox::empty(0);
        mailbox.tick = u64::decode(decoder)?;
        mailbox.owner = u32::decode(decoder)?;
        let len = u32::decode(decoder)?;
        if len as usize > MAILBOX_CAPACITY {
            return Err(DecodeError::OtherString(format!(
                "a mailbox of {len} messages (at most {MAILBOX_CAPACITY})"
            )));
        }
        for mail in &mut mailbox.mail[..len as usize] {
            mail.from = u32::decode(decoder)?;
            mail.to = u32::decode(decoder)?;
            mail.range = f32::decode(decoder)?;
            let bytes = u64::decode(decoder)?;
            if bytes > MAIL_PAYLOAD_BYTES as u64 {
                return Err(DecodeError::OtherString(format!(
                    "a payload of {bytes} bytes (at most {MAIL_PAYLOAD_BYTES})"
                )));
            }
            let bytes = bytes as usize;
            decoder.claim_bytes_read(bytes)?;
            decoder.reader().read(&mut mail.payload[..bytes])?;
            mail.len = bytes as u16;
        }
        mailbox.len = len;
        Ok(mailbox)
    }
}

impl<'de, Context> BorrowDecode<'de, Context> for Mailbox {
    fn borrow_decode<D: BorrowDecoder<'de, Context = Context>>(
        decoder: &mut D,
    ) -> Result<Self, DecodeError> {
        Self::decode(decoder)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> bincode::config::Configuration {
        bincode::config::standard()
    }

    #[test]
    fn addresses_survive_the_layout() {
        for address in [Address::To(7), Address::All, Address::Within(0.5)] {
            assert_eq!(Mail::new(1, address, b"x").unwrap().address(), address);
        }
    }

    #[test]
    fn an_outbox_refuses_what_its_layout_cannot_hold() {
        let mut outbox = Mailbox::empty(3);
        assert_eq!(
            outbox.send(Address::All, &[0; MAIL_PAYLOAD_BYTES + 1]),
            Err(SendError::TooLong(MAIL_PAYLOAD_BYTES + 1))
        );
        for _ in 0..MAILBOX_CAPACITY {
            outbox.send(Address::To(1), b"hi").unwrap();
        }
        assert_eq!(
            outbox.send(Address::To(1), b"hi"),
            Err(SendError::OutboxFull)
        );
        assert_eq!(outbox.messages().len(), MAILBOX_CAPACITY);
        assert!(outbox.messages().iter().all(|m| m.from == 3));
    }

    #[test]
    fn a_closed_outbox_refuses_everything_and_stays_closed() {
        let mut outbox = Mailbox::closed(2);
        assert_eq!(outbox.send(Address::All, b"x"), Err(SendError::NoMedium));
        outbox.clear();
        assert_eq!(outbox.send(Address::All, b"x"), Err(SendError::NoMedium));
        assert!(outbox.is_empty());
    }

    #[test]
    fn the_wire_form_carries_only_what_is_used() {
        let mut mailbox = Mailbox::empty(4);
        mailbox.tick = 99;
        mailbox.send(Address::Within(1.5), b"hello").unwrap();
        mailbox
            .send(Address::To(2), &[7; MAIL_PAYLOAD_BYTES])
            .unwrap();
        let bytes = bincode::encode_to_vec(mailbox, config()).unwrap();
        assert!(bytes.len() < 300, "{} bytes", bytes.len());
        let (back, used): (Mailbox, usize) = bincode::decode_from_slice(&bytes, config()).unwrap();
        assert_eq!(used, bytes.len());
        assert_eq!(back.tick, 99);
        assert_eq!(back.owner, 4);
        assert_eq!(back.messages(), mailbox.messages());
        let empty = bincode::encode_to_vec(Mailbox::empty(4), config()).unwrap();
        assert!(empty.len() <= 4, "{} bytes", empty.len());
    }

    #[test]
    fn hostile_wire_forms_are_refused() {
        let mut long = Vec::new();
        for value in [1u64, 2, u64::from(MAILBOX_CAPACITY as u32 + 1)] {
            bincode::encode_into_std_write(value, &mut long, config()).unwrap();
        }
        assert!(bincode::decode_from_slice::<Mailbox, _>(&long, config()).is_err());
        let mut mailbox = Mailbox::empty(1);
        mailbox.send(Address::All, b"abc").unwrap();
        let mut bytes = bincode::encode_to_vec(mailbox, config()).unwrap();
        // The payload's length prefix is the byte before its three bytes: claim more than a message holds.
        let at = bytes.len() - 4;
        bytes[at] = 251;
        bytes.splice(at + 1..at + 1, [0x01, 0x01]);
        assert!(bincode::decode_from_slice::<Mailbox, _>(&bytes, config()).is_err());
        for cut in 0..bytes.len() {
            let _ = bincode::decode_from_slice::<Mailbox, _>(&bytes[..cut], config());
        }
    }
}
