//! Following a planned path with a differential-drive robot: pure pursuit of a point a short look-ahead along
//! the path, turning on the spot when that point is behind.

use crate::V2;
use crate::apf::velocity::Twist;
use crate::vec2::wrap;

/// How a robot follows a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pursuit {
    /// Waypoints closer than this are passed (m). Keep it below the planner's safety margin: the robot cuts the
    /// corners of the path by up to about this much.
    pub lookahead: f32,
    /// Top speed (m/s).
    pub max_speed: f32,
    /// Top turn rate (rad/s).
    pub max_turn_rate: f32,
    /// Turn rate per radian of heading error (1/s).
    pub k_w: f32,
    /// Speed per metre to the final point (1/s): the robot slows down as it arrives.
    pub k_v: f32,
}

impl Default for Pursuit {
    fn default() -> Self {
        Pursuit {
            lookahead: 0.05,
            max_speed: 0.2,
            max_turn_rate: 2.0,
            k_w: 3.0,
            k_v: 1.0,
        }
    }
}

/// The (v, w) that takes a robot at `position` facing `heading` along `path`; `progress` is the index of the
/// waypoint being pursued, advanced past the waypoints already within the look-ahead.
pub fn pursue(p: &Pursuit, path: &[V2], progress: &mut usize, position: V2, heading: f32) -> Twist {
    let Some(last) = path.len().checked_sub(1) else {
        return Twist { v: 0.0, w: 0.0 };
    };
    while *progress < last && (path[*progress] - position).length() < p.lookahead {
        *progress += 1;
    }
    *progress = (*progress).min(last);
    let target = path[*progress] - position;
    let error = wrap(target.angle() - heading);
    let remaining = (path[last] - position).length();
    let v = (p.max_speed * error.cos().max(0.0)).min(p.k_v * remaining);
    Twist {
        v,
        w: (p.k_w * error).clamp(-p.max_turn_rate, p.max_turn_rate),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_drives_ahead_turns_towards_the_next_point_and_slows_at_the_end() {
        let p = Pursuit::default();
        let path = [V2::ZERO, V2::new(1.0, 0.0), V2::new(1.0, 1.0)];
        let mut at = 0;
        let ahead = pursue(&p, &path, &mut at, V2::ZERO, 0.0);
        assert_eq!(at, 1);
        assert_eq!((ahead.v, ahead.w), (0.2, 0.0));
        // At the corner the next waypoint is to the left: full turn, no forward speed (cos 90 degrees).
        let corner = pursue(&p, &path, &mut at, V2::new(1.0, 0.0), 0.0);
        assert_eq!(at, 2);
        assert!(corner.v.abs() < 1e-6 && corner.w == 2.0);
        // Facing the last point from 0.1 m away: speed k_v times the remaining distance.
        let end = pursue(
            &p,
            &path,
            &mut at,
            V2::new(1.0, 0.9),
            std::f32::consts::FRAC_PI_2,
        );
        assert!((end.v - 0.1).abs() < 1e-5, "{}", end.v);
        assert_eq!(pursue(&p, &[], &mut 0, V2::ZERO, 0.0).v, 0.0);
    }
}
