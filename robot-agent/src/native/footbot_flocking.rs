//! Native controller `footbot_flocking`: a port of ARGoS' foot-bot flocking example, written from its documented
//! behaviour.
//!
//! The robot lights its beacon red and steers along the sum of two vectors:
//!
//! - towards the light: the light readings added as vectors (length = reading, direction = the sensor's angle),
//!   scaled to a quarter of `max_speed` when anything is seen;
//! - flocking: for every red blob the camera sees closer than 1.8 `target_distance`, the generalised
//!   Lennard-Jones term `-gain / d ((t / d)^(2e) - (t / d)^e)` along the blob's bearing (d and t in cm, e the
//!   `exponent`), averaged over those blobs and capped at `max_speed`.
//!
//! The vector becomes wheel speeds through ARGoS' wheel-turning rule ([`WheelTurning`]).
//!
//! Parameters as in the example's `<params>`: `<wheel_turning hard_turn_angle_threshold soft_turn_angle_threshold
//! no_turn_angle_threshold max_speed/>` (degrees, cm/s) and `<flocking target_distance gain exponent/>`; ARGoS
//! requires them all, here the example's values (90, 70, 10, 10; 75, 1000, 2) are the defaults.

use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;
use super::footbot::{WheelTurning, ring_sum};

/// Red, the colour flocking robots show on their beacon and look for.
const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };

/// The ARGoS example controller.
#[derive(Debug, Clone, PartialEq)]
pub struct FootbotFlocking {
    wheels: WheelTurning,
    target_distance: f32,
    gain: f32,
    exponent: f32,
}

impl FootbotFlocking {
    /// Registry name.
    pub const NAME: &'static str = "footbot_flocking";

    /// Reads the `wheel_turning.*` and `flocking.*` parameters.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            wheels: WheelTurning::from_params(params)?,
            target_distance: params.non_negative_f32_or("flocking.target_distance", 75.0)?,
            gain: params.f32_or("flocking.gain", 1000.0)?,
            exponent: params.f32_or("flocking.exponent", 2.0)?,
        })
    }

    /// The generalised Lennard-Jones term at `distance` cm: negative (repulsive) closer than the target
    /// distance, positive (attractive) beyond it.
    pub fn lennard_jones(&self, distance: f32) -> f32 {
        let n = (self.target_distance / distance).powf(self.exponent);
        -self.gain / distance * (n * n - n)
    }

    fn vector_to_light(&self, frame: &SensorFrame) -> (f32, f32) {
        let (x, y) = ring_sum(frame.light_readings());
        let length = x.hypot(y);
        if length > 0.0 {
            let scale = 0.25 * self.wheels.max_speed / length;
            (x * scale, y * scale)
        } else {
            (0.0, 0.0)
        }
    }

    fn flocking_vector(&self, frame: &SensorFrame) -> (f32, f32) {
        let (mut x, mut y, mut seen) = (0.0f32, 0.0f32, 0u32);
        for blob in frame.camera_blobs() {
            if blob.color == RED && blob.distance_cm < self.target_distance * 1.8 {
                let lj = self.lennard_jones(blob.distance_cm);
                let (s, c) = blob.bearing.sin_cos();
                x += lj * c;
                y += lj * s;
                seen += 1;
            }
        }
        if seen == 0 {
            return (0.0, 0.0);
        }
        let (x, y) = (x / seen as f32, y / seen as f32);
        let length = x.hypot(y);
        let max = self.wheels.max_speed;
        if length > max {
            (x * max / length, y * max / length)
        } else {
            (x, y)
        }
    }
}

impl NativeController for FootbotFlocking {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let light = self.vector_to_light(frame);
        let flock = self.flocking_vector(frame);
        command.wheels = self
            .wheels
            .wheels_towards((light.0 + flock.0, light.1 + flock.1));
        command.beacon = RED;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use swarm_contract::messages::CameraBlob;

    fn controller() -> FootbotFlocking {
        FootbotFlocking::from_params(&Params::default()).unwrap()
    }

    fn frame_with_blob(distance_cm: f32, bearing: f32) -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        f.camera_len = 1;
        f.camera[0] = CameraBlob {
            color: RED,
            bearing,
            distance_cm,
        };
        f
    }

    #[test]
    fn lennard_jones_is_zero_at_the_target_distance_and_repels_closer() {
        let c = controller();
        assert!(c.lennard_jones(75.0).abs() < 1e-6);
        assert!(c.lennard_jones(40.0) < 0.0);
        assert!(c.lennard_jones(100.0) > 0.0);
    }

    #[test]
    fn alone_in_the_dark_it_stands_still_with_its_beacon_red() {
        let mut c = controller();
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&SensorFrame::empty(0), &mut cmd);
        assert_eq!(cmd.wheels, [0.0, 0.0]);
        assert_eq!(cmd.beacon, RED);
    }

    #[test]
    fn a_light_straight_ahead_drives_it_forward_at_a_quarter_of_max_speed() {
        let mut c = controller();
        let mut f = SensorFrame::empty(0);
        f.light_len = 24;
        f.light[0] = 0.5;
        f.light[23] = 0.5;
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        assert!((cmd.wheels[0] - 2.5).abs() < 1e-4 && (cmd.wheels[1] - 2.5).abs() < 1e-4);
    }

    #[test]
    fn a_neighbour_too_close_behind_pushes_it_away_with_a_hard_turn_first() {
        let mut c = controller();
        let mut cmd = ActuatorCommand::idle(0, 1);
        // A neighbour 40 cm straight behind: the repulsion points ahead, so the robot drives straight on.
        c.step(&frame_with_blob(40.0, std::f32::consts::PI), &mut cmd);
        assert!(cmd.wheels[0] > 0.0 && cmd.wheels[0] == cmd.wheels[1]);
        // A neighbour 40 cm straight ahead: the repulsion points behind, beyond 90 degrees: spin.
        let mut c = controller();
        c.step(&frame_with_blob(40.0, 0.0), &mut cmd);
        assert_eq!(cmd.wheels[0].abs(), 10.0);
        assert_eq!(cmd.wheels[0], -cmd.wheels[1]);
    }

    #[test]
    fn a_far_neighbour_on_the_left_attracts_with_a_soft_turn() {
        let mut c = controller();
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&frame_with_blob(120.0, 0.5), &mut cmd);
        assert!(
            cmd.wheels[1] > cmd.wheels[0] && cmd.wheels[0] >= 0.0,
            "{:?}",
            cmd.wheels
        );
    }

    #[test]
    fn blobs_of_other_colours_and_beyond_the_cut_off_are_ignored() {
        let mut c = controller();
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&frame_with_blob(136.0, 0.5), &mut cmd);
        assert_eq!(cmd.wheels, [0.0, 0.0], "1.8 x 75 = 135 cm is the cut-off");
        let mut f = frame_with_blob(50.0, 0.5);
        f.camera[0].color = Rgb { r: 0, g: 255, b: 0 };
        c.step(&f, &mut cmd);
        assert_eq!(cmd.wheels, [0.0, 0.0]);
    }
}
