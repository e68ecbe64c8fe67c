//! Native controller `mail_probe`: sends and answers addressed messages (docs/messages.md) on a schedule, and shows
//! how many it received on its LEDs, so that the run's records carry both sides: the world's decisions in
//! `messages.csv`, what the agent actually read in `trajectory.csv`'s `led_r` (capped at 255). For checking the
//! messages medium end to end, and as the smallest example of a controller that talks. The robot does not move.
//!
//! Parameters:
//! - `send`: whom to send to: a participant index, `all`, or `within:R` (metres); absent: it sends nothing.
//! - `every` (default 1) and `start` (default 1): it sends in ticks `start`, `start + every`, ...
//! - `count` (default 1): messages per sending tick.
//! - `bytes` (default 8): payload length; the payload starts with the sender's index and the tick (two
//!   little-endian `u32`, as far as they fit) and is zero after that.
//! - `claim`: the sender index its messages claim (default: its own; another index forges, and the world refuses).
//! - `echo` (default false): answer every message received with its payload, to its sender.

use swarm_contract::mail::{Address, Mail, Mailbox};
use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;

/// The probe.
#[derive(Debug, Clone, PartialEq)]
pub struct MailProbe {
    send: Option<Address>,
    every: u64,
    start: u64,
    count: u32,
    bytes: usize,
    claim: Option<u32>,
    echo: bool,
}

impl MailProbe {
    /// Registry name.
    pub const NAME: &'static str = "mail_probe";

    /// Reads the parameters above.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let send = match params.get("send") {
            None => None,
            Some(raw) => Some(parse_address(raw).ok_or_else(|| ParamError::Malformed {
                name: "send".into(),
                value: raw.to_owned(),
                expected: "a participant index, `all` or `within:R` with R in metres",
            })?),
        };
        let bytes = params.whole_or("bytes", 8usize)?;
        if bytes > swarm_contract::mail::MAIL_PAYLOAD_BYTES {
            return Err(ParamError::Malformed {
                name: "bytes".into(),
                value: bytes.to_string(),
                expected: "at most 256 (the largest payload a message holds)",
            });
        }
        Ok(Self {
            send,
            every: params.whole_or("every", 1u64)?.max(1),
            start: params.whole_or("start", 1u64)?,
            count: params.whole_or("count", 1u32)?,
            bytes,
            claim: params
                .get("claim")
                .map(|_| params.whole_or("claim", 0u32))
                .transpose()?,
            echo: params.get("echo").is_some_and(|v| v.trim() == "true"),
        })
    }

    fn sends_in(&self, tick: u64) -> bool {
        tick >= self.start && (tick - self.start).is_multiple_of(self.every)
    }
}

fn parse_address(raw: &str) -> Option<Address> {
    let raw = raw.trim();
    if raw == "all" {
        return Some(Address::All);
    }
    if let Some(range) = raw.strip_prefix("within:") {
        return range.trim().parse().ok().map(Address::Within);
    }
    raw.parse().ok().map(Address::To)
}

impl NativeController for MailProbe {
    fn step(&mut self, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        command.wheels = [0.0, 0.0];
    }

    fn step_with_mail(
        &mut self,
        frame: &SensorFrame,
        inbox: &Mailbox,
        outbox: &mut Mailbox,
        command: &mut ActuatorCommand,
    ) {
        self.step(frame, command);
        let received = inbox.messages();
        command.led = Rgb {
            r: received.len().min(255) as u8,
            g: 0,
            b: 0,
        };
        if self.echo {
            for mail in received {
                // A full outbox only means fewer echoes; the world never sees them.
                let _ = outbox.send(Address::To(mail.from), mail.payload());
            }
        }
        let Some(address) = self.send.filter(|_| self.sends_in(frame.tick)) else {
            return;
        };
        let mut payload = [0u8; swarm_contract::mail::MAIL_PAYLOAD_BYTES];
        payload[..4].copy_from_slice(&outbox.owner.to_le_bytes());
        payload[4..8].copy_from_slice(&(frame.tick as u32).to_le_bytes());
        let from = self.claim.unwrap_or(outbox.owner);
        for _ in 0..self.count {
            let Ok(mail) = Mail::new(from, address, &payload[..self.bytes]) else {
                return;
            };
            if outbox.push(mail).is_err() {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(probe: &mut MailProbe, tick: u64, inbox: &Mailbox) -> (Mailbox, ActuatorCommand) {
        let mut frame = SensorFrame::empty(2);
        frame.tick = tick;
        let mut outbox = Mailbox::empty(2);
        let mut command = ActuatorCommand::idle(2, tick);
        probe.step_with_mail(&frame, inbox, &mut outbox, &mut command);
        (outbox, command)
    }

    #[test]
    fn it_sends_on_its_schedule_and_echoes_what_it_reads() {
        let params = Params::new([
            ("send", "within:0.5"),
            ("every", "3"),
            ("start", "2"),
            ("count", "2"),
            ("bytes", "10"),
            ("echo", "true"),
        ]);
        let mut probe = MailProbe::from_params(&params).unwrap();
        let mut inbox = Mailbox::empty(2);
        inbox
            .push(Mail::new(7, Address::All, b"ping").unwrap())
            .unwrap();
        let (outbox, command) = step(&mut probe, 1, &inbox);
        assert_eq!(command.led.r, 1);
        assert_eq!(outbox.messages().len(), 1);
        assert_eq!(outbox.messages()[0].address(), Address::To(7));
        assert_eq!(outbox.messages()[0].payload(), b"ping");
        let (outbox, _) = step(&mut probe, 5, &Mailbox::empty(2));
        assert_eq!(outbox.messages().len(), 2);
        let sent = outbox.messages()[0];
        assert_eq!(sent.address(), Address::Within(0.5));
        assert_eq!(sent.payload()[..8], [2, 0, 0, 0, 5, 0, 0, 0]);
        assert_eq!(sent.payload().len(), 10);
        assert!(step(&mut probe, 6, &Mailbox::empty(2)).0.is_empty());
    }

    #[test]
    fn a_claim_forges_the_sender_and_bad_parameters_are_named() {
        let mut probe =
            MailProbe::from_params(&Params::new([("send", "0"), ("claim", "5")])).unwrap();
        let (outbox, _) = step(&mut probe, 1, &Mailbox::empty(2));
        assert_eq!(outbox.messages()[0].from, 5);
        for (name, value) in [("send", "everyone"), ("bytes", "300"), ("every", "-1")] {
            let err = MailProbe::from_params(&Params::new([(name, value)])).unwrap_err();
            assert!(err.to_string().contains(name), "{err}");
        }
    }
}
