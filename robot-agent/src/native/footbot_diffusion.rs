//! Native controller `footbot_diffusion`: a port of ARGoS' foot-bot diffusion example, written from its
//! documented behaviour.
//!
//! Each tick: add the 24 proximity readings as vectors (length = reading, direction = the sensor's angle on the
//! foot-bot ring) and divide by 24. If that vector points within `alpha` degrees of the heading and is shorter
//! than `delta`, go straight, wheels (v, v); otherwise turn away from it: (v, 0) when it points left, (0, v) when
//! it points right or straight behind. `v` is `velocity` in cm/s. Defaults as in ARGoS: alpha 10, delta 0.5,
//! velocity 2.5.

use swarm_contract::bodies::FOOTBOT_SENSOR_ANGLES_DEG;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;
use super::footbot::ring_sum;

/// Default half-width in degrees of the go-straight cone.
pub const DEFAULT_ALPHA_DEG: f32 = 10.0;
/// Default length of the mean proximity vector below which the way is clear.
pub const DEFAULT_DELTA: f32 = 0.5;
/// Default wheel speed in cm/s.
pub const DEFAULT_VELOCITY: f32 = 2.5;

/// The ARGoS example controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootbotDiffusion {
    alpha: f32,
    delta: f32,
    velocity: f32,
}

impl FootbotDiffusion {
    /// Registry name.
    pub const NAME: &'static str = "footbot_diffusion";

    /// Reads `alpha` (degrees, >= 0), `delta` (>= 0) and `velocity` (cm/s, >= 0).
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            alpha: params
                .non_negative_f32_or("alpha", DEFAULT_ALPHA_DEG)?
                .to_radians(),
            delta: params.non_negative_f32_or("delta", DEFAULT_DELTA)?,
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
        })
    }
}

impl NativeController for FootbotDiffusion {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let (x, y) = ring_sum(frame.proximity_readings());
        let n = FOOTBOT_SENSOR_ANGLES_DEG.len() as f32;
        let (x, y) = (x / n, y / n);
        let angle = y.atan2(x);
        let v = self.velocity;
        command.wheels = if angle.abs() <= self.alpha && x.hypot(y) < self.delta {
            [v, v]
        } else if angle > 0.0 {
            [v, 0.0]
        } else {
            [0.0, v]
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wheels_for(params: &Params, readings: &[(usize, f32)]) -> [f32; 2] {
        let mut c = FootbotDiffusion::from_params(params).unwrap();
        let mut f = SensorFrame::empty(0);
        f.proximity_len = 24;
        for &(i, v) in readings {
            f.proximity[i] = v;
        }
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        cmd.wheels
    }

    fn example() -> Params {
        Params::new([("alpha", "7.5"), ("delta", "0.1"), ("velocity", "5")])
    }

    #[test]
    fn nothing_seen_drives_straight() {
        assert_eq!(wheels_for(&example(), &[]), [5.0, 5.0]);
    }

    #[test]
    fn defaults_are_arguments_of_the_example() {
        assert_eq!(wheels_for(&Params::default(), &[]), [2.5, 2.5]);
    }

    #[test]
    fn obstacle_on_the_left_turns_right() {
        // Sensor 4 points 67.5 degrees left.
        assert_eq!(wheels_for(&example(), &[(4, 0.9)]), [5.0, 0.0]);
    }

    #[test]
    fn obstacle_on_the_right_turns_left() {
        // Sensor 20 points 307.5 degrees, i.e. 52.5 degrees right.
        assert_eq!(wheels_for(&example(), &[(20, 0.9)]), [0.0, 5.0]);
    }

    #[test]
    fn close_obstacle_ahead_turns_although_its_angle_is_within_alpha() {
        // Four front sensors (7.5 and 22.5 degrees either side), slightly stronger on the left: the mean vector
        // points 0.6 degrees left, inside alpha, but is 0.156 long, beyond delta.
        let front = [(0, 1.0), (1, 1.0), (23, 1.0), (22, 0.9)];
        assert_eq!(wheels_for(&example(), &front), [5.0, 0.0]);
    }

    #[test]
    fn faint_obstacle_dead_ahead_is_ignored() {
        assert_eq!(wheels_for(&example(), &[(0, 0.5), (23, 0.5)]), [5.0, 5.0]);
    }
}
