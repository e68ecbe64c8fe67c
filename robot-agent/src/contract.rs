//! Mirror of the player contract until the runtime's player lands (removed on merge).

use swarm_runtime::messages::{ActuatorCommand, SensorFrame};

/// The callbacks the player calls (mirrors the runtime's `EventCallbacks`).
pub trait EventCallbacks {
    /// Check of an uncontrollable event.
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool;
    /// Action of a controllable event.
    fn act(&mut self, event: u8, frame: &SensorFrame, command: &mut ActuatorCommand);
}
