//! Mirror of the player contract until the runtime's player lands (removed on merge).

use swarm_runtime::messages::{ActuatorCommand, SensorFrame};

/// One event of a compiled supervisor set (mirrors `supervisor_gen::compiled::CompiledEvent`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledEvent {
    /// Event name as in the models.
    pub name: String,
    /// Whether the event is controllable.
    pub controllable: bool,
}

/// The callbacks the player calls (mirrors the runtime's `EventCallbacks`).
pub trait EventCallbacks {
    /// Check of an uncontrollable event.
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool;
    /// Action of a controllable event.
    fn act(&mut self, event: u8, frame: &SensorFrame, command: &mut ActuatorCommand);
}
