//! Binding a profile's callbacks to the events of a loaded supervisor set, and the per-tick dispatcher.
//!
//! Binding happens once at startup and matches names in both directions: every supervisor event needs a callback
//! of the right kind, and every callback must name a supervisor event. All mismatches are reported together in
//! one [`BindError`]. The resulting [`Bound`] dispatcher indexes a table by event id: no string lookup and no
//! allocation per tick.

use std::fmt;

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::EventCallbacks;
use swarm_contract::supervisor_gen::compiled::CompiledEvent;
use thiserror::Error;

use crate::profile::{Procedure, Profile};

/// Why a profile does not fit a supervisor set; lists every mismatch at once.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub struct BindError {
    /// The profile that was bound.
    pub profile: &'static str,
    /// Supervisor events with no callback: (name, controllable).
    pub missing: Vec<(String, bool)>,
    /// Callbacks naming events the supervisors do not have.
    pub unknown: Vec<String>,
    /// Events whose callback kind contradicts their controllability: (name, controllable in the supervisors).
    pub wrong_kind: Vec<(String, bool)>,
}

fn kind(controllable: bool) -> &'static str {
    if controllable {
        "controllable"
    } else {
        "uncontrollable"
    }
}

impl fmt::Display for BindError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "profile `{}` does not fit the supervisors", self.profile)?;
        if !self.missing.is_empty() {
            write!(f, "\n  supervisor events without a callback:")?;
            for (i, (name, controllable)) in self.missing.iter().enumerate() {
                let sep = if i == 0 { " " } else { ", " };
                write!(f, "{sep}`{name}` ({})", kind(*controllable))?;
            }
        }
        if !self.unknown.is_empty() {
            write!(f, "\n  callbacks for events the supervisors do not have:")?;
            for (i, name) in self.unknown.iter().enumerate() {
                let sep = if i == 0 { " " } else { ", " };
                write!(f, "{sep}`{name}`")?;
            }
        }
        for (name, controllable) in &self.wrong_kind {
            let (has, needs) = if *controllable {
                ("a check", "an action")
            } else {
                ("an action", "a check")
            };
            write!(
                f,
                "\n  `{name}` is {} in the supervisors, so it needs {needs}, but the profile has {has}",
                kind(*controllable)
            )?;
        }
        Ok(())
    }
}

/// A profile bound to a supervisor set: the robot's memory plus an event-id-indexed procedure table.
pub struct Bound<P: Profile> {
    state: P,
    table: Box<[Procedure<P>]>,
}

impl<P: Profile> Bound<P> {
    /// The robot's profile memory (for inspection and tests).
    pub fn state(&self) -> &P {
        &self.state
    }
}

/// Binds `P`'s procedures to `events` (index = event id), or lists every mismatch.
pub fn bind<P: Profile>(state: P, events: &[CompiledEvent]) -> Result<Bound<P>, BindError> {
    let mut table = Vec::with_capacity(events.len());
    let mut missing = Vec::new();
    let mut wrong_kind = Vec::new();
    for event in events {
        match P::PROCEDURES.iter().find(|(name, _)| *name == event.name) {
            Some((_, procedure)) if procedure.is_action() == event.controllable => {
                table.push(*procedure)
            }
            Some(_) => wrong_kind.push((event.name.clone(), event.controllable)),
            None => missing.push((event.name.clone(), event.controllable)),
        }
    }
    let unknown: Vec<String> = P::PROCEDURES
        .iter()
        .filter(|(name, _)| !events.iter().any(|e| e.name == *name))
        .map(|(name, _)| (*name).to_owned())
        .collect();
    if missing.is_empty() && unknown.is_empty() && wrong_kind.is_empty() {
        Ok(Bound {
            state,
            table: table.into_boxed_slice(),
        })
    } else {
        Err(BindError {
            profile: P::NAME,
            missing,
            unknown,
            wrong_kind,
        })
    }
}

/// The messages of a bound profile: its [`Profile::receive`] and [`Profile::send`], whatever its memory type.
pub trait Talk {
    /// Takes in the tick's messages before the supervisors step.
    fn receive(&mut self, inbox: &Mailbox);
    /// Sends what the step left to send.
    fn send(&mut self, outbox: &mut Mailbox);
}

impl<P: Profile> Talk for Bound<P> {
    #[unsafe(link_section = "swarm_hot")]
    fn receive(&mut self, inbox: &Mailbox) {
        self.state.receive(inbox);
    }

    #[unsafe(link_section = "swarm_hot")]
    fn send(&mut self, outbox: &mut Mailbox) {
        self.state.send(outbox);
    }
}

impl<P: Profile> EventCallbacks for Bound<P> {
    #[unsafe(link_section = "swarm_hot")]
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool {
        match self.table.get(usize::from(event)) {
            Some(Procedure::Check(check)) => check(&self.state, frame),
            _ => {
                debug_assert!(
                    false,
                    "player asked to check event {event}, which is not an uncontrollable event"
                );
                false
            }
        }
    }

    #[unsafe(link_section = "swarm_hot")]
    fn act(&mut self, event: u8, frame: &SensorFrame, command: &mut ActuatorCommand) {
        match self.table.get(usize::from(event)) {
            Some(Procedure::Act(act)) => act(&mut self.state, frame, command),
            _ => debug_assert!(
                false,
                "player asked to act on event {event}, which is not a controllable event"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{ParamError, Params};
    use swarm_contract::mail::Address;

    /// A two-event profile that counts actions, enough to test binding rules.
    struct Counter {
        acted: u32,
    }

    fn seen(_: &Counter, frame: &SensorFrame) -> bool {
        frame.proximity[0] > 0.5
    }

    fn count(state: &mut Counter, _: &SensorFrame, command: &mut ActuatorCommand) {
        state.acted += 1;
        command.wheels = [1.0, 1.0];
    }

    impl Profile for Counter {
        const NAME: &'static str = "counter";
        const TALKS: bool = true;
        const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
            ("seen", Procedure::Check(seen)),
            ("count", Procedure::Act(count)),
        ];

        fn from_params(_: &Params) -> Result<Self, ParamError> {
            Ok(Counter { acted: 0 })
        }

        fn receive(&mut self, inbox: &Mailbox) {
            self.acted += inbox.messages().len() as u32;
        }

        fn send(&mut self, outbox: &mut Mailbox) {
            let _ = outbox.send(Address::All, &self.acted.to_le_bytes());
        }
    }

    fn ev(name: &str, controllable: bool) -> CompiledEvent {
        CompiledEvent {
            name: name.to_owned(),
            controllable,
        }
    }

    #[test]
    fn events_are_dispatched_by_id_in_supervisor_order() {
        let events = [ev("count", true), ev("seen", false)];
        let mut bound = bind(Counter { acted: 0 }, &events).unwrap();
        let mut frame = SensorFrame::empty(0);
        frame.proximity[0] = 0.9;
        let mut command = ActuatorCommand::idle(0, 1);
        assert!(bound.check(1, &frame));
        bound.act(0, &frame, &mut command);
        assert_eq!(bound.state().acted, 1);
        assert_eq!(command.wheels, [1.0, 1.0]);
    }

    #[test]
    fn a_bound_profile_receives_and_sends_through_its_memory() {
        let events = [ev("count", true), ev("seen", false)];
        let mut bound = bind(Counter { acted: 0 }, &events).unwrap();
        let mut inbox = Mailbox::empty(0);
        inbox.send(Address::To(0), b"one").unwrap();
        inbox.send(Address::To(0), b"two").unwrap();
        bound.receive(&inbox);
        bound.act(0, &SensorFrame::empty(0), &mut ActuatorCommand::idle(0, 1));
        let mut outbox = Mailbox::empty(0);
        bound.send(&mut outbox);
        assert_eq!(outbox.messages()[0].payload(), 3u32.to_le_bytes());
    }

    #[test]
    fn binding_lists_missing_and_unknown_events_in_one_message() {
        let events = [ev("count", true), ev("go", true), ev("bumped", false)];
        let err = bind(Counter { acted: 0 }, &events).err().unwrap();
        assert_eq!(
            err.to_string(),
            "profile `counter` does not fit the supervisors\n  \
             supervisor events without a callback: `go` (controllable), `bumped` (uncontrollable)\n  \
             callbacks for events the supervisors do not have: `seen`"
        );
    }

    #[test]
    fn binding_rejects_a_check_for_a_controllable_event() {
        let events = [ev("count", true), ev("seen", true)];
        let err = bind(Counter { acted: 0 }, &events).err().unwrap();
        assert_eq!(
            err.to_string(),
            "profile `counter` does not fit the supervisors\n  \
             `seen` is controllable in the supervisors, so it needs an action, but the profile has a check"
        );
    }
}
