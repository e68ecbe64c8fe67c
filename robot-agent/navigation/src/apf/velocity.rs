//! From force to velocity (the method leaves the law open; docs/navigation.md gives the one used here): the
//! force resolved along the heading sets the forward speed, its angle to the heading the turn rate.

use super::Params;
use crate::V2;

/// A velocity command: forward speed in m/s and turn rate in rad/s (counter-clockwise positive).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Twist {
    /// Forward speed.
    pub v: f32,
    /// Turn rate.
    pub w: f32,
}

/// `v = clamp(k_v F_par / F_A, 0, 1) v_max`, `w = clamp(k_w atan2(F_perp, F_par), -w_max, w_max)` with
/// `F_par = F . h` and `F_perp = (h x F)_z`.
pub fn twist(params: &Params, heading: f32, force: V2) -> Twist {
    let h = V2::from_angle(heading);
    let (along, across) = (force.dot(h), h.cross(force));
    Twist {
        v: (params.k_v * along / params.attraction).clamp(0.0, 1.0) * params.max_speed,
        w: (params.k_w * across.atan2(along)).clamp(-params.max_turn_rate, params.max_turn_rate),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_twists() {
        let p = Params::default();
        // Force straight ahead with the attraction's magnitude: full speed, no turn.
        assert_eq!(twist(&p, 0.0, V2::new(1.0, 0.0)), Twist { v: 0.22, w: 0.0 });
        // Half the attraction ahead: half speed.
        let half = twist(&p, 0.0, V2::new(0.5, 0.0));
        assert!((half.v - 0.11).abs() < 1e-6);
        // 30 degrees to the left: v = cos 30 * 0.22, w = 2 * 0.5236 = 1.0472.
        let left = twist(&p, 0.0, V2::from_angle(30f32.to_radians()));
        assert!(
            (left.v - 0.190_526).abs() < 1e-5
                && (left.w - 2.0 * std::f32::consts::FRAC_PI_6).abs() < 1e-5
        );
        // Behind and to the right: no forward speed, the turn clamped at -2.84.
        let behind = twist(&p, 0.0, V2::new(-1.0, -0.1));
        assert_eq!(behind, Twist { v: 0.0, w: -2.84 });
        // The heading rotates the frame: heading +y and a force along +y is straight ahead.
        let up = twist(&p, std::f32::consts::FRAC_PI_2, V2::new(0.0, 2.0));
        assert!((up.v - 0.22).abs() < 1e-6 && up.w.abs() < 1e-5);
    }
}
