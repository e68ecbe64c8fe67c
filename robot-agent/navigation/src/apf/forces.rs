//! The forces of AMR-APF, one function per equation of the method (numbers as in docs/navigation.md), and the
//! classic forces of Khatib's field for the baseline. Angles are radians; every force is in units of the
//! attraction `F_A`.

use std::f32::consts::FRAC_PI_2;

use super::{Field, Params, TurnRule};
use crate::V2;
use crate::vec2::{sign, wrap};

/// Eq. 1: the attraction towards the goal, of constant magnitude `f_a` (zero at the goal itself).
pub fn attraction(f_a: f32, position: V2, goal: V2) -> V2 {
    let to_goal = goal - position;
    let d = to_goal.length();
    if d > 0.0 {
        to_goal * (f_a / d)
    } else {
        V2::ZERO
    }
}

/// The gain `C_o` of eq. 2, calibrated so that the base repulsion equals the attraction `f_a` exactly on the
/// caution circle: `C_o = F_A / (1/rho_c - 1/rho_p)^2`.
pub fn repulsion_gain(f_a: f32, field: &Field) -> f32 {
    let span = 1.0 / field.caution - 1.0 / field.proximity;
    f_a / (span * span)
}

/// The distance from `field`'s centre to `position` (clamped below at `min_distance`) and the unit vector
/// pointing away from the centre (+x when the two coincide).
fn away_from(field: &Field, position: V2, min_distance: f32) -> (f32, V2) {
    let away = position - field.centre;
    let d = away.length();
    let unit = if d > 0.0 {
        away * (1.0 / d)
    } else {
        V2::new(1.0, 0.0)
    };
    (d.max(min_distance), unit)
}

/// Eq. 2: the base repulsion of `field` on a robot at `position`: `C_o (1/d - 1/rho_p)^2` away from the centre
/// within the proximity radius, zero outside it.
pub fn base_repulsion(f_a: f32, field: &Field, position: V2, min_distance: f32) -> V2 {
    let (d, unit) = away_from(field, position, min_distance);
    if d > field.proximity {
        return V2::ZERO;
    }
    let k = 1.0 / d - 1.0 / field.proximity;
    unit * (repulsion_gain(f_a, field) * k * k)
}

/// Eq. 3, the direction of the adaptive force: the base force's direction `base_angle` turned by
/// `-90 deg * sign(psi) * T`.
pub fn adaptive_angle(base_angle: f32, psi: f32, turn: f32) -> f32 {
    base_angle - FRAC_PI_2 * sign(psi) * turn
}

/// The angle of `direction` relative to the bearing from `position` to `centre`, wrapped (the paper's `psi`
/// for a heading, `phi` for the goal direction).
pub fn relative_to_bearing(direction: V2, position: V2, centre: V2) -> f32 {
    wrap(direction.angle() - (centre - position).angle())
}

/// `T` of eq. 3 for an obstacle: heading almost straight at it (`|psi| <= threshold`), turn to the side of the
/// goal (`sign(phi psi)`); otherwise keep circling the way the robot already turns (1).
pub fn obstacle_turn(psi: f32, phi: f32, threshold: f32) -> f32 {
    if psi.abs() <= threshold {
        sign(phi * psi)
    } else {
        1.0
    }
}

/// The adaptive force of the same magnitude as `base` (eq. 3), or zero when `base` is zero.
fn adaptive(base: V2, psi: f32, turn: f32) -> V2 {
    let magnitude = base.length();
    if magnitude == 0.0 {
        return V2::ZERO;
    }
    V2::from_angle(adaptive_angle(base.angle(), psi, turn)) * magnitude
}

/// Eq. 4: an obstacle's (or stopped robot's, or virtual obstacle's) force on a robot at `position` heading
/// `heading` towards `goal`: base repulsion plus, when `adaptive` is on, the adaptive force.
/// `params` gives `F_A`, the threshold angle and the distance clamp.
pub fn obstacle_force(
    params: &Params,
    field: &Field,
    position: V2,
    heading: f32,
    goal: V2,
    adaptive_on: bool,
) -> V2 {
    let base = base_repulsion(params.attraction, field, position, params.min_distance);
    let threshold = params.threshold_angle;
    if !adaptive_on || base == V2::ZERO {
        return base;
    }
    let phi = relative_to_bearing(goal - position, position, field.centre);
    let psi = relative_to_bearing(V2::from_angle(heading), position, field.centre);
    // Heading exactly at the centre: sign(0) would lose the goal side, so the tie goes towards it.
    let psi = if psi == 0.0 {
        f32::EPSILON.copysign(phi)
    } else {
        psi
    };
    base + adaptive(base, psi, obstacle_turn(psi, phi, threshold))
}

/// Two moving robots as eq. 6 sees them, from robot i's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Encounter {
    /// `psi^i_ij`: robot i's heading relative to its line of sight to j.
    pub psi_i: f32,
    /// `psi^j_ji`: robot j's heading relative to its line of sight to i.
    pub psi_j: f32,
    /// Robot i's priority.
    pub priority_i: f32,
    /// Robot j's priority.
    pub priority_j: f32,
    /// Whether i wins a priority tie (the lower participant index does).
    pub i_wins_ties: bool,
}

/// `T` of eq. 6 for robot i under `rule` (see [`TurnRule`]).
pub fn robot_turn(rule: TurnRule, e: &Encounter) -> f32 {
    let i_more_important =
        e.priority_i > e.priority_j || (e.priority_i == e.priority_j && e.i_wins_ties);
    match rule {
        TurnRule::Described if e.psi_i * e.psi_j > 0.0 => 1.0,
        TurnRule::Described => {
            if i_more_important {
                -1.0
            } else {
                1.0
            }
        }
        TurnRule::Literal => {
            let difference = if e.priority_i == e.priority_j {
                if e.i_wins_ties { 1.0 } else { -1.0 }
            } else {
                e.priority_i - e.priority_j
            };
            sign(e.psi_i * e.psi_j * difference)
        }
    }
}

/// Eq. 7: a moving robot j's force on robot i: base repulsion (eq. 2 with j in the obstacle's place) plus,
/// when `adaptive_on`, the adaptive force of the same magnitude turned by eq. 6's `T`.
pub fn moving_robot_force(
    f_a: f32,
    field: &Field,
    position: V2,
    rule: TurnRule,
    encounter: &Encounter,
    adaptive_on: bool,
    min_distance: f32,
) -> V2 {
    let base = base_repulsion(f_a, field, position, min_distance);
    if !adaptive_on || base == V2::ZERO {
        return base;
    }
    base + adaptive(base, encounter.psi_i, robot_turn(rule, encounter))
}

/// Khatib's spring attraction `C_a (g - r)`, with `C_a = f_a` per metre: the classic field's attraction equals
/// AMR-APF's at one metre from the goal and grows with the distance.
pub fn spring_attraction(f_a: f32, position: V2, goal: V2) -> V2 {
    (goal - position) * f_a
}

/// Khatib's classic repulsion `eta (1/d - 1/rho_p) / d^2` away from the centre within the proximity radius,
/// with `eta` calibrated like eq. 2's gain so that it equals `f_a` on the caution circle.
pub fn khatib_repulsion(f_a: f32, field: &Field, position: V2, min_distance: f32) -> V2 {
    let (d, unit) = away_from(field, position, min_distance);
    if d > field.proximity {
        return V2::ZERO;
    }
    let shape = |d: f32| (1.0 / d - 1.0 / field.proximity) / (d * d);
    unit * (f_a * shape(d) / shape(field.caution))
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    const EPS: f32 = 1e-4;

    fn close(a: V2, b: V2) -> bool {
        (a - b).length() < EPS
    }

    fn field() -> Field {
        // A 0.3 m obstacle at the origin seen by a 0.105 m robot with 0.1 m caution: rho_c = 0.505,
        // rho_p = 1.105.
        Field {
            centre: V2::ZERO,
            caution: 0.505,
            proximity: 1.105,
        }
    }

    #[test]
    fn attraction_has_constant_magnitude() {
        assert!(close(
            attraction(1.0, V2::new(0.0, 0.0), V2::new(3.0, 4.0)),
            V2::new(0.6, 0.8)
        ));
        assert!(close(
            attraction(2.0, V2::new(1.0, 1.0), V2::new(1.0, 1.1)),
            V2::new(0.0, 2.0)
        ));
        assert_eq!(
            attraction(1.0, V2::new(1.0, 1.0), V2::new(1.0, 1.0)),
            V2::ZERO
        );
    }

    #[test]
    fn base_repulsion_equals_the_attraction_on_the_caution_circle() {
        // C_o = 1 / (1/0.505 - 1/1.105)^2 = 1 / (1.980198 - 0.904977)^2 = 0.864977
        assert!((repulsion_gain(1.0, &field()) - 0.864_977).abs() < 1e-4);
        let on_caution = base_repulsion(1.0, &field(), V2::new(0.0, 0.505), 0.01);
        assert!(close(on_caution, V2::new(0.0, 1.0)));
        // At d = 0.8: 0.864977 * (1.25 - 0.904977)^2 = 0.102968, pointing away (-x here).
        let inside = base_repulsion(1.0, &field(), V2::new(-0.8, 0.0), 0.01);
        assert!(close(inside, V2::new(-0.102_968, 0.0)), "{inside:?}");
        assert_eq!(
            base_repulsion(1.0, &field(), V2::new(1.2, 0.0), 0.01),
            V2::ZERO
        );
    }

    #[test]
    fn distance_is_clamped_and_a_coincident_centre_pushes_along_x() {
        let f = base_repulsion(1.0, &field(), V2::ZERO, 0.01);
        // 0.864977 * (100 - 0.904977)^2 = 8493.9
        assert!((f.x - 8493.9).abs() < 1.0 && f.y == 0.0, "{f:?}");
    }

    #[test]
    fn adaptive_angle_turns_the_base_force_by_a_right_angle() {
        assert!((adaptive_angle(PI, 0.2, 1.0) - PI / 2.0).abs() < EPS);
        assert!((adaptive_angle(PI, -0.2, 1.0) - 3.0 * PI / 2.0).abs() < EPS);
        assert!((adaptive_angle(0.0, 0.0, -1.0) - PI / 2.0).abs() < EPS);
    }

    #[test]
    fn heading_at_an_obstacle_the_robot_is_sent_round_its_goal_side() {
        // Robot at (-0.8, 0) heading +x straight at the obstacle, goal ahead and a little to the left (+y).
        let position = V2::new(-0.8, 0.0);
        let left_goal = V2::new(3.0, 0.5);
        let f = obstacle_force(&Params::default(), &field(), position, 0.0, left_goal, true);
        // psi = 0 -> sign +1; phi > 0 -> T = +1; the base force points -x (angle pi) and the adaptive one at
        // pi - 90 deg = +y: the sum is base magnitude * (-1, 1).
        assert!(close(f, V2::new(-0.102_968, 0.102_968)), "{f:?}");
        let right_goal = V2::new(3.0, -0.5);
        let f = obstacle_force(
            &Params::default(),
            &field(),
            position,
            0.0,
            right_goal,
            true,
        );
        assert!(close(f, V2::new(-0.102_968, -0.102_968)), "{f:?}");
        // Total = radial rotated by 45 degrees and scaled by sqrt 2.
        assert!((f.length() - 0.102_968 * 2f32.sqrt()).abs() < EPS);
    }

    #[test]
    fn off_the_threshold_the_robot_keeps_circling_its_way() {
        let threshold = 30f32.to_radians();
        let position = V2::new(-0.8, 0.0);
        // Heading 60 degrees left of the bearing, goal to the right: T = 1, the push stays on the left.
        let heading = 60f32.to_radians();
        assert_eq!(obstacle_turn(heading, -0.3, threshold), 1.0);
        let f = obstacle_force(
            &Params::default(),
            &field(),
            position,
            heading,
            V2::new(3.0, -0.5),
            true,
        );
        assert!(f.y > 0.0, "{f:?}");
        // Switched off, only the radial force is left.
        let f = obstacle_force(
            &Params::default(),
            &field(),
            position,
            heading,
            V2::new(3.0, -0.5),
            false,
        );
        assert!(close(f, V2::new(-0.102_968, 0.0)));
    }

    fn encounter(psi_i: f32, psi_j: f32, priority_i: f32, priority_j: f32) -> Encounter {
        Encounter {
            psi_i,
            psi_j,
            priority_i,
            priority_j,
            i_wins_ties: true,
        }
    }

    #[test]
    fn head_on_robots_turn_the_same_way_and_side_approaches_split_by_priority() {
        // Head-on: headings on opposite sides of the line of sight: both T = +1.
        let head_on = encounter(0.1, 0.1, 1.0, 2.0);
        assert_eq!(robot_turn(TurnRule::Described, &head_on), 1.0);
        let mirrored = encounter(0.1, 0.1, 2.0, 1.0);
        assert_eq!(robot_turn(TurnRule::Described, &mirrored), 1.0);
        // Side approach: the more important robot gets -1, the other +1.
        assert_eq!(
            robot_turn(TurnRule::Described, &encounter(0.3, -0.2, 2.0, 1.0)),
            -1.0
        );
        assert_eq!(
            robot_turn(TurnRule::Described, &encounter(-0.2, 0.3, 1.0, 2.0)),
            1.0
        );
        // The literal formula always splits the two.
        assert_eq!(robot_turn(TurnRule::Literal, &head_on), -1.0);
        assert_eq!(robot_turn(TurnRule::Literal, &mirrored), 1.0);
    }

    #[test]
    fn head_on_robots_are_pushed_to_their_own_left() {
        let f_i = Field {
            centre: V2::new(0.6, 0.0),
            caution: 0.31,
            proximity: 0.91,
        };
        // Robot i at the origin heading +x (slightly up), robot j at (0.6, 0) heading -x (slightly down).
        let e = encounter(0.05, 0.05, 1.0, 1.0);
        let f = moving_robot_force(1.0, &f_i, V2::ZERO, TurnRule::Described, &e, true, 0.01);
        assert!(f.x < 0.0 && f.y > 0.0, "{f:?}");
        let f_j = Field {
            centre: V2::ZERO,
            ..f_i
        };
        let e = Encounter {
            i_wins_ties: false,
            ..e
        };
        let f = moving_robot_force(
            1.0,
            &f_j,
            V2::new(0.6, 0.0),
            TurnRule::Described,
            &e,
            true,
            0.01,
        );
        assert!(f.x > 0.0 && f.y < 0.0, "{f:?}");
    }

    #[test]
    fn khatib_forces_are_calibrated_like_the_adaptive_ones() {
        assert!(close(
            spring_attraction(1.0, V2::ZERO, V2::new(2.0, 0.0)),
            V2::new(2.0, 0.0)
        ));
        let on_caution = khatib_repulsion(1.0, &field(), V2::new(0.0, -0.505), 0.01);
        assert!(close(on_caution, V2::new(0.0, -1.0)));
        // d = 0.8: (1.25 - 0.904977) / 0.64 = 0.539099; on the caution circle (1.980198 - 0.904977) / 0.255025
        // = 4.216136; ratio 0.127866.
        let inside = khatib_repulsion(1.0, &field(), V2::new(0.8, 0.0), 0.01);
        assert!(close(inside, V2::new(0.127_866, 0.0)), "{inside:?}");
    }
}
