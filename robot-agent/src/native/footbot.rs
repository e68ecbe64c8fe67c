//! What ARGoS' foot-bot example controllers share: summing a 24-sensor ring as vectors, and the three-mode
//! wheel-turning rule that steers along a vector.

use std::sync::LazyLock;

use swarm_contract::bodies::FOOTBOT_SENSOR_ANGLES_DEG;

use crate::params::{ParamError, Params};

/// (cos, sin) of each foot-bot ring sensor's angle.
static RING: LazyLock<[(f32, f32); FOOTBOT_SENSOR_ANGLES_DEG.len()]> = LazyLock::new(|| {
    FOOTBOT_SENSOR_ANGLES_DEG.map(|a| {
        let (s, c) = a.to_radians().sin_cos();
        (c, s)
    })
});

/// The sum of a foot-bot ring's readings as vectors: reading i has length `readings[i]` and the direction of
/// sensor i (proximity and light sensors share the ring's angles).
pub fn ring_sum(readings: &[f32]) -> (f32, f32) {
    readings
        .iter()
        .zip(RING.iter())
        .fold((0.0, 0.0), |(x, y), (r, (c, s))| (x + r * c, y + r * s))
}

/// Which wheel rule applies; kept between ticks (the rule has hysteresis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Turning {
    None,
    Soft,
    Hard,
}

/// ARGoS' wheel-turning rule of the flocking and foraging examples. A vector becomes wheel speeds through three
/// modes: no turn (both wheels at the vector's length, capped at `max_speed`), soft turn (the inner wheel slowed
/// and the outer sped up in proportion to the angle) and hard turn (spin at `max_speed`). A soft turn starts
/// beyond `no_turn_angle_threshold`, a hard one beyond `hard_turn_angle_threshold`, and a hard turn ends within
/// `soft_turn_angle_threshold`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelTurning {
    hard_turn: f32,
    soft_turn: f32,
    no_turn: f32,
    /// Wheel speed cap in cm/s.
    pub max_speed: f32,
    turning: Turning,
}

impl WheelTurning {
    /// Reads `wheel_turning.hard_turn_angle_threshold`, `.soft_turn_angle_threshold`,
    /// `.no_turn_angle_threshold` (degrees) and `.max_speed` (cm/s); ARGoS requires them, here the examples'
    /// values (90, 70, 10, 10) are the defaults.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let angle = |name: &str, default: f32| {
            params
                .non_negative_f32_or(name, default)
                .map(f32::to_radians)
        };
        Ok(Self {
            hard_turn: angle("wheel_turning.hard_turn_angle_threshold", 90.0)?,
            soft_turn: angle("wheel_turning.soft_turn_angle_threshold", 70.0)?,
            no_turn: angle("wheel_turning.no_turn_angle_threshold", 10.0)?,
            max_speed: params.non_negative_f32_or("wheel_turning.max_speed", 10.0)?,
            turning: Turning::None,
        })
    }

    /// Wheel speeds (left, right) in cm/s that steer along `(x, y)`, updating the turning mode.
    pub fn wheels_towards(&mut self, (x, y): (f32, f32)) -> [f32; 2] {
        let angle = y.atan2(x);
        let off = angle.abs();
        let base = x.hypot(y).min(self.max_speed);
        self.turning = match self.turning {
            Turning::Hard if off <= self.soft_turn => Turning::Soft,
            other => other,
        };
        self.turning = match self.turning {
            Turning::Soft if off > self.hard_turn => Turning::Hard,
            Turning::Soft if off <= self.no_turn => Turning::None,
            Turning::None if off > self.hard_turn => Turning::Hard,
            Turning::None if off > self.no_turn => Turning::Soft,
            other => other,
        };
        let (inner, outer) = match self.turning {
            Turning::None => (base, base),
            Turning::Soft => {
                let factor = (self.hard_turn - off) / self.hard_turn;
                (base * factor, base * (2.0 - factor))
            }
            Turning::Hard => (-self.max_speed, self.max_speed),
        };
        if angle > 0.0 {
            [inner, outer]
        } else {
            [outer, inner]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> WheelTurning {
        WheelTurning::from_params(&Params::default()).unwrap()
    }

    #[test]
    fn straight_ahead_drives_both_wheels_at_the_length_capped_at_max_speed() {
        assert_eq!(rule().wheels_towards((4.0, 0.0)), [4.0, 4.0]);
        assert_eq!(rule().wheels_towards((40.0, 0.0)), [10.0, 10.0]);
    }

    #[test]
    fn behind_spins_and_the_spin_lasts_until_within_the_soft_threshold() {
        let mut r = rule();
        assert_eq!(r.wheels_towards((-1.0, 0.1)), [-10.0, 10.0]);
        // 80 degrees left: still beyond the 70-degree soft threshold, so the hard turn goes on.
        let (s, c) = 80f32.to_radians().sin_cos();
        assert_eq!(r.wheels_towards((5.0 * c, 5.0 * s)), [-10.0, 10.0]);
        // 60 degrees: soft.
        let (s, c) = 60f32.to_radians().sin_cos();
        let w = r.wheels_towards((5.0 * c, 5.0 * s));
        assert!(w[0] > 0.0 && w[1] > w[0], "{w:?}");
    }

    #[test]
    fn ring_sum_of_opposite_equal_readings_cancels() {
        let mut readings = [0.0f32; 24];
        readings[0] = 0.5;
        readings[12] = 0.5;
        let (x, y) = ring_sum(&readings);
        assert!(x.abs() < 1e-6 && y.abs() < 1e-6);
    }
}
