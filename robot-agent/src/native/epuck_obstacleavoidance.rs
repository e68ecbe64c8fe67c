//! Native controller `epuck_obstacleavoidance`: a port of ARGoS' e-puck obstacle-avoidance example.
//!
//! Each tick: take the strongest of proximity sensors 0, 1, 7, 6 (in that order, so earlier sensors win ties).
//! Nothing seen (all four zero): straight, wheels (v, v). Strongest is 0 or 1 (front left): turn right, (v, 0).
//! Strongest is 7 or 6 (front right): turn left, (0, v). v is the `velocity` parameter in cm/s (default 12.8).

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;

/// Default wheel speed in cm/s.
pub const DEFAULT_VELOCITY: f32 = 12.8;

/// The sensors the example looks at, in the order it scans them.
const SCANNED: [usize; 4] = [0, 1, 7, 6];

/// The ARGoS example controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpuckObstacleAvoidance {
    velocity: f32,
}

impl EpuckObstacleAvoidance {
    /// Registry name.
    pub const NAME: &'static str = "epuck_obstacleavoidance";

    /// Reads `velocity` (cm/s, >= 0).
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
        })
    }
}

impl NativeController for EpuckObstacleAvoidance {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let v = self.velocity;
        let mut strongest = SCANNED[0];
        for &i in &SCANNED[1..] {
            if frame.proximity[i] > frame.proximity[strongest] {
                strongest = i;
            }
        }
        command.wheels = if frame.proximity[strongest] <= 0.0 {
            [v, v]
        } else if strongest <= 1 {
            [v, 0.0]
        } else {
            [0.0, v]
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wheels_for(readings: &[(usize, f32)]) -> [f32; 2] {
        let mut c = EpuckObstacleAvoidance::from_params(&Params::default()).unwrap();
        let mut f = SensorFrame::empty(0);
        for &(i, v) in readings {
            f.proximity[i] = v;
        }
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        cmd.wheels
    }

    #[test]
    fn nothing_seen_drives_straight() {
        assert_eq!(wheels_for(&[]), [12.8, 12.8]);
    }

    #[test]
    fn nothing_seen_ignores_rear_sensors() {
        assert_eq!(wheels_for(&[(3, 0.9), (4, 0.9)]), [12.8, 12.8]);
    }

    #[test]
    fn strongest_sensor_0_turns_right() {
        assert_eq!(wheels_for(&[(0, 0.8), (7, 0.3)]), [12.8, 0.0]);
    }

    #[test]
    fn strongest_sensor_1_turns_right() {
        assert_eq!(wheels_for(&[(1, 0.5), (6, 0.2)]), [12.8, 0.0]);
    }

    #[test]
    fn strongest_sensor_7_turns_left() {
        assert_eq!(wheels_for(&[(0, 0.3), (7, 0.8)]), [0.0, 12.8]);
    }

    #[test]
    fn strongest_sensor_6_turns_left() {
        assert_eq!(wheels_for(&[(1, 0.1), (6, 0.4)]), [0.0, 12.8]);
    }

    #[test]
    fn tie_between_0_and_7_turns_right() {
        assert_eq!(wheels_for(&[(0, 0.5), (7, 0.5)]), [12.8, 0.0]);
    }

    #[test]
    fn velocity_parameter_sets_the_wheel_speed() {
        let mut c =
            EpuckObstacleAvoidance::from_params(&Params::new([("velocity", "6.4")])).unwrap();
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&SensorFrame::empty(0), &mut cmd);
        assert_eq!(cmd.wheels, [6.4, 6.4]);
    }
}
