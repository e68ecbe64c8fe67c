//! The team round the box: which face each robot takes, and the radius of the disc the formation fills (what
//! the global planner plans round obstacles for).
//!
//! Faces are numbered in the box's own frame: 0 +x, 1 +y, 2 -x, 3 -y. The front face is the one whose outward
//! normal, at the box's start pose, points most towards the goal (the lowest number on a tie, face 0 when the
//! goal is the start). Robots by index take the front face, the face opposite it, the face clockwise from the
//! front, then the last one.

use swarm_navigation::V2;
use swarm_navigation::wire::transport::{face_distance, face_normal};

/// Faces of a box: the most robots a team can have.
pub(super) const FACES: usize = 4;

/// The face, 0 to 3, whose outward normal for a box at heading `angle` (rad) points most along `towards`.
pub(super) fn front_face(angle: f32, towards: V2) -> u8 {
    let mut best = (0, f32::NEG_INFINITY);
    for face in 0..FACES as u8 {
        let along = face_normal(face).rotated(angle).dot(towards);
        if along > best.1 {
            best = (face, along);
        }
    }
    best.0
}

/// The faces of the robots of rank 0, 1, ... (at most [`FACES`]) with the front face `front`: the front, the
/// opposite face, the face clockwise from the front, the face counter-clockwise from it.
pub(super) fn faces(front: u8, team: usize) -> Vec<u8> {
    [0, 2, 3, 1]
        .iter()
        .take(team)
        .map(|turn| (front + turn) % FACES as u8)
        .collect()
}

/// The formation's radius: the larger of the box's half-diagonal and, over the faces in use, the distance from
/// the box's centre to the face plus two robot radii (the far side of a robot at that face), plus `margin`.
pub(super) fn radius(half: V2, faces: &[u8], robot_radius: f32, margin: f32) -> f32 {
    faces
        .iter()
        .map(|&face| face_distance(half, face) + 2.0 * robot_radius)
        .fold(half.length(), f32::max)
        + margin
}

#[cfg(test)]
mod tests {
    use std::f32::consts::{FRAC_PI_2, PI};

    use super::*;

    #[test]
    fn front_face_has_its_normal_most_towards_the_goal() {
        // A box at heading 0: the goal to the north-east, more north than east.
        assert_eq!(front_face(0.0, V2::new(1.0, 2.0)), 1);
        assert_eq!(front_face(0.0, V2::new(2.0, 1.0)), 0);
        assert_eq!(front_face(0.0, V2::new(-2.0, 1.0)), 2);
        assert_eq!(front_face(0.0, V2::new(0.5, -2.0)), 3);
        // Turned a quarter: its +x face looks north.
        assert_eq!(front_face(FRAC_PI_2, V2::new(0.1, 1.0)), 0);
        assert_eq!(front_face(FRAC_PI_2, V2::new(1.0, 0.1)), 3);
        assert_eq!(front_face(PI, V2::new(1.0, 0.1)), 2);
        // A goal at the start: face 0.
        assert_eq!(front_face(1.0, V2::ZERO), 0);
    }

    #[test]
    fn ranks_take_front_opposite_clockwise_then_counter_clockwise() {
        assert_eq!(faces(1, 4), vec![1, 3, 0, 2]);
        assert_eq!(faces(0, 3), vec![0, 2, 3]);
        assert_eq!(faces(3, 2), vec![3, 1]);
        assert_eq!(faces(2, 1), vec![2]);
        assert_eq!(faces(0, 9).len(), FACES);
    }

    #[test]
    fn formation_radius_is_the_farthest_robot_or_corner_plus_the_margin() {
        let half = V2::new(0.3, 0.1);
        // Front and back on the x faces: 0.3 + 2 x 0.085 = 0.47 beats the half-diagonal 0.316.
        assert!((radius(half, &[0, 2], 0.085, 0.1) - 0.57).abs() < 1e-6);
        // On the y faces only: 0.1 + 0.17 = 0.27 is inside the half-diagonal.
        assert!((radius(half, &[1, 3], 0.085, 0.0) - half.length()).abs() < 1e-6);
        // A third robot on a y face changes nothing, the x face still rules.
        assert!((radius(half, &[0, 2, 3], 0.085, 0.1) - 0.57).abs() < 1e-6);
        assert!((radius(half, &[1, 3, 0], 0.2, 0.05) - 0.75).abs() < 1e-6);
    }
}
