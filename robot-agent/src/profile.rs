//! What an operational-procedure profile is (docs/ptsct.md 8.1, layer 3): per-robot memory plus one callback per event.
//!
//! A profile is a type holding one robot's memory and parameters; its [`Profile::PROCEDURES`] table maps the event
//! names the models use to plain function pointers. Controllable events get an action on the
//! [`ActuatorCommand`]; uncontrollable events get a pure check of the [`SensorFrame`] (docs/ptsct.md 8.2). A profile
//! never sees the world or the supervisors: only the frame of the current tick and its own memory. A profile that
//! talks (docs/messages.md) reads the tick's messages into its memory before the supervisors step
//! ([`Profile::receive`]), so that checks can see them, and sends what its actions left to send after the step
//! ([`Profile::send`]).

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};

/// The operational procedure of one event.
pub enum Procedure<S> {
    /// Check of an uncontrollable event: whether it occurred in this tick's frame. Level-triggered and pure.
    Check(fn(&S, &SensorFrame) -> bool),
    /// Action of a controllable event: runs after the supervisors moved and may update the robot's memory.
    Act(fn(&mut S, &SensorFrame, &mut ActuatorCommand)),
}

impl<S> Clone for Procedure<S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S> Copy for Procedure<S> {}

impl<S> Procedure<S> {
    /// Whether this procedure serves a controllable event (an action) rather than an uncontrollable one (a check).
    pub fn is_action(&self) -> bool {
        matches!(self, Procedure::Act(_))
    }
}

/// A profile: one robot's memory, built from the controller's `<params>`, plus its callback table.
pub trait Profile: Sized + Send + 'static {
    /// The name configs use for this profile (`<params profile="...">`); the registry key.
    const NAME: &'static str;
    /// Event name -> procedure, one entry per event the profile serves.
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)];

    /// Whether the robot talks: only then are [`Profile::receive`] and [`Profile::send`] called. A profile that
    /// overrides them sets it to true.
    const TALKS: bool = false;

    /// A fresh robot memory with parameters read from `params`.
    fn from_params(params: &Params) -> Result<Self, ParamError>;

    /// Takes in the messages delivered this tick, before the supervisors step: a message an uncontrollable event
    /// waits for becomes memory its check reads. By default messages are ignored. Must not allocate.
    fn receive(&mut self, inbox: &Mailbox) {
        let _ = inbox;
    }

    /// Puts into `outbox` (empty at the start of every tick) what this tick's actions left in memory to send,
    /// after the supervisors stepped. By default nothing is sent. Must not allocate.
    fn send(&mut self, outbox: &mut Mailbox) {
        let _ = outbox;
    }
}
