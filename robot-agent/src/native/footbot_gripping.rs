//! Native controller `footbot_gripping`: a port of ARGoS' foot-bot gripping example, written from its documented
//! behaviour. A scripted sequence, counted in control steps from 1:
//!
//! - steps 1-69: drive forward at 5 cm/s (towards the object in front);
//! - step 70: stop and lock the gripper (ARGoS' `LockPositive`), gripping what is within reach;
//! - steps 71-119: back up at 5 cm/s, pulling the object along;
//! - steps 120-169: unlock the gripper, still backing up (the object stays behind);
//! - from step 170: stop.

use swarm_contract::messages::{ActuatorCommand, GripperAction, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;

/// Wheel speed in cm/s of every move of the script.
const SPEED: f32 = 5.0;

/// The ARGoS example controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FootbotGripping {
    counter: u32,
}

impl FootbotGripping {
    /// Registry name.
    pub const NAME: &'static str = "footbot_gripping";

    /// Takes no parameters.
    pub fn from_params(_params: &Params) -> Result<Self, ParamError> {
        Ok(Self::default())
    }
}

impl NativeController for FootbotGripping {
    fn step(&mut self, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        self.counter = self.counter.saturating_add(1);
        match self.counter {
            ..70 => command.wheels = [SPEED, SPEED],
            70 => {
                command.wheels = [0.0, 0.0];
                command.gripper = GripperAction::Pick;
            }
            71..120 => command.wheels = [-SPEED, -SPEED],
            120..170 => command.gripper = GripperAction::Drop,
            _ => command.wheels = [0.0, 0.0],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_drives_locks_pulls_unlocks_and_stops() {
        let mut c = FootbotGripping::default();
        let mut cmd = ActuatorCommand::idle(0, 0);
        let frame = SensorFrame::empty(0);
        let mut at = |step: u32, cmd: &mut ActuatorCommand| {
            while c.counter < step {
                c.step(&frame, cmd);
            }
            (cmd.wheels, cmd.gripper)
        };
        assert_eq!(at(1, &mut cmd), ([5.0, 5.0], GripperAction::Hold));
        assert_eq!(at(70, &mut cmd), ([0.0, 0.0], GripperAction::Pick));
        assert_eq!(at(100, &mut cmd), ([-5.0, -5.0], GripperAction::Pick));
        assert_eq!(at(150, &mut cmd), ([-5.0, -5.0], GripperAction::Drop));
        assert_eq!(at(200, &mut cmd), ([0.0, 0.0], GripperAction::Drop));
    }
}
