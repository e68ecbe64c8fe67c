//! Native controller `disc_wander`: a disc robot that wanders with its range finder and velocity commands.
//!
//! Each tick it looks at the range-finder rays within `cone` degrees of its heading. When the nearest of them is
//! closer than `safe_distance` metres (from the body centre), it turns on the spot at `turn_rate` rad/s towards
//! the side whose rays (within 90 degrees) see more free space, left on a tie; otherwise it drives straight at
//! `speed` m/s. Commands are (v, w) twists, so the world clamps them to the robot's `max_speed` and
//! `max_turn_rate`. Without a range finder it drives straight. Defaults: speed 0.2, turn_rate 1.5, cone 45,
//! safe_distance 0.35.

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;

/// Default forward speed in m/s.
pub const DEFAULT_SPEED: f32 = 0.2;
/// Default turn rate in rad/s.
pub const DEFAULT_TURN_RATE: f32 = 1.5;
/// Default half-width in degrees of the cone checked for obstacles.
pub const DEFAULT_CONE_DEG: f32 = 45.0;
/// Default distance in metres from the centre below which an obstacle in the cone makes the robot turn.
pub const DEFAULT_SAFE_DISTANCE: f32 = 0.35;

/// The wandering controller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscWander {
    speed: f32,
    turn_rate: f32,
    cone: f32,
    safe_distance: f32,
}

impl DiscWander {
    /// Registry name.
    pub const NAME: &'static str = "disc_wander";

    /// Reads `speed` (m/s), `turn_rate` (rad/s), `cone` (degrees) and `safe_distance` (m), all >= 0.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            speed: params.non_negative_f32_or("speed", DEFAULT_SPEED)?,
            turn_rate: params.non_negative_f32_or("turn_rate", DEFAULT_TURN_RATE)?,
            cone: params
                .non_negative_f32_or("cone", DEFAULT_CONE_DEG)?
                .to_radians(),
            safe_distance: params.non_negative_f32_or("safe_distance", DEFAULT_SAFE_DISTANCE)?,
        })
    }
}

/// The signed angle of ray `i` of `n`, in (-pi, pi].
fn ray_angle(i: usize, n: usize) -> f32 {
    let a = std::f32::consts::TAU * i as f32 / n as f32;
    if a > std::f32::consts::PI {
        a - std::f32::consts::TAU
    } else {
        a
    }
}

impl NativeController for DiscWander {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let ranges = frame.range_readings();
        let n = ranges.len();
        let blocked = ranges
            .iter()
            .enumerate()
            .filter(|&(i, _)| ray_angle(i, n).abs() <= self.cone)
            .any(|(_, &r)| r < self.safe_distance);
        if !blocked {
            command.set_twist(self.speed, 0.0);
            return;
        }
        // Free space per side, each ray's reading capped at twice the safe distance so one far wall does not
        // outweigh several near obstacles.
        let cap = 2.0 * self.safe_distance;
        let (mut left, mut right) = (0.0f32, 0.0f32);
        for (i, &r) in ranges.iter().enumerate() {
            let a = ray_angle(i, n);
            let free = r.min(cap);
            if a > 0.0 && a < std::f32::consts::FRAC_PI_2 {
                left += free;
            } else if a < 0.0 && a > -std::f32::consts::FRAC_PI_2 {
                right += free;
            }
        }
        let w = if left >= right {
            self.turn_rate
        } else {
            -self.turn_rate
        };
        command.set_twist(0.0, w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use swarm_contract::messages::Drive;

    fn twist_for(ranges: &[f32]) -> [f32; 2] {
        let mut c = DiscWander::from_params(&Params::default()).unwrap();
        let mut f = SensorFrame::empty(0);
        f.ranges_len = ranges.len() as u8;
        f.ranges[..ranges.len()].copy_from_slice(ranges);
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        assert_eq!(cmd.drive, Drive::Twist);
        cmd.twist
    }

    #[test]
    fn free_way_drives_straight() {
        assert_eq!(twist_for(&[f32::INFINITY; 20]), [0.2, 0.0]);
    }

    #[test]
    fn obstacle_ahead_turns_towards_the_freer_side() {
        // 20 rays, 18 degrees apart: rays 1-4 look left, 16-19 right.
        let mut r = [f32::INFINITY; 20];
        r[0] = 0.2;
        r[17] = 0.3;
        assert_eq!(
            twist_for(&r),
            [0.0, 1.5],
            "the right side is more cluttered"
        );
        let mut r = [f32::INFINITY; 20];
        r[0] = 0.2;
        r[2] = 0.3;
        assert_eq!(
            twist_for(&r),
            [0.0, -1.5],
            "the left side is more cluttered"
        );
    }

    #[test]
    fn obstacle_outside_the_cone_is_ignored() {
        let mut r = [f32::INFINITY; 20];
        r[5] = 0.1; // 90 degrees left
        assert_eq!(twist_for(&r), [0.2, 0.0]);
    }

    #[test]
    fn without_a_range_finder_it_drives_straight() {
        assert_eq!(twist_for(&[]), [0.2, 0.0]);
    }
}
