//! The geometry of carrying a box together: where each robot grips it, where its centre must be for a pose of
//! the box, and the box's waypoints with their headings.

use swarm_navigation::V2;
use swarm_navigation::vec2::wrap;
use swarm_navigation::wire::transport::{Object, face_distance, face_normal};

/// A pose of the box: its centre and heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Centre (m).
    pub centre: V2,
    /// Heading (rad).
    pub angle: f32,
}

impl Pose {
    /// `local`, a point of the box's own frame, in the world.
    pub fn to_world(self, local: V2) -> V2 {
        self.centre + local.rotated(self.angle)
    }

    /// `world`, a point of the world, in the box's own frame.
    pub fn to_local(self, world: V2) -> V2 {
        (world - self.centre).rotated(-self.angle)
    }
}

/// Where a robot of `radius` stands `beyond` metres out from the centre of its face, and the heading that faces
/// the box.
pub fn face_point(object: &Object, radius: f32, beyond: f32) -> (V2, f32) {
    let pose = Pose {
        centre: object.centre,
        angle: object.angle,
    };
    let n = face_normal(object.face);
    let out = n * (face_distance(object.half, object.face) + radius + beyond);
    let point = pose.to_world(out);
    (point, (pose.centre - point).angle())
}

/// The box's waypoints along `path` (its centre's points), with headings turning evenly with the distance
/// travelled from `start_angle` to `goal_angle` (the shorter way round).
pub fn along(path: &[V2], start_angle: f32, goal_angle: f32) -> Vec<Pose> {
    let total: f32 = path.windows(2).map(|w| (w[1] - w[0]).length()).sum();
    let turn = wrap(goal_angle - start_angle);
    let mut done = 0.0;
    path.iter()
        .enumerate()
        .map(|(i, &centre)| {
            if i > 0 {
                done += (centre - path[i - 1]).length();
            }
            let share = if total > 0.0 { done / total } else { 1.0 };
            Pose {
                centre,
                angle: start_angle + turn * share,
            }
        })
        .collect()
}

/// Most steps of a path a robot keeps (a local path's, a global path's points less one): tiny step parameters
/// or a long path cannot make it unbounded.
pub const MAX_STEPS: usize = 4096;

/// The method's local path (`GENERATE_PATH`): from `start` to the goal in equal steps of at most `step` metres
/// and `angle_step` radians (at most [`MAX_STEPS`] steps), the pose interpolated linearly.
pub fn straight(start: Pose, goal: V2, goal_angle: f32, step: f32, angle_step: f32) -> Vec<Pose> {
    let turn = wrap(goal_angle - start.angle);
    let distance = (goal - start.centre).length();
    let steps = ((distance / step).ceil())
        .max((turn.abs() / angle_step).ceil())
        .clamp(1.0, MAX_STEPS as f32) as usize;
    (0..=steps)
        .map(|i| {
            let share = i as f32 / steps as f32;
            Pose {
                centre: start.centre + (goal - start.centre) * share,
                angle: start.angle + turn * share,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(face: u8, angle: f32) -> Object {
        Object {
            centre: V2::new(2.0, 1.0),
            angle,
            half: V2::new(0.3, 0.4),
            goal: V2::new(5.0, 1.0),
            goal_angle: 0.0,
            team: 2,
            lift_by: 2,
            face,
            tolerance: 0.02,
            angle_tolerance: 0.05,
            plans: 0,
        }
    }

    fn close(a: V2, b: V2) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn robots_stand_at_their_face_facing_the_box() {
        let (p, heading) = face_point(&object(0, 0.0), 0.1, 0.0);
        assert!(close(p, V2::new(2.4, 1.0)) && (heading - std::f32::consts::PI).abs() < 1e-5);
        // Turned a quarter: face +y of the box points to -x.
        let (p, heading) = face_point(&object(1, std::f32::consts::FRAC_PI_2), 0.1, 0.0);
        assert!(close(p, V2::new(1.5, 1.0)), "{p:?}");
        assert!(heading.abs() < 1e-5);
    }

    #[test]
    fn a_robot_keeps_its_place_on_the_box_and_the_path_turns_evenly() {
        let start = Pose {
            centre: V2::new(1.0, 1.0),
            angle: 0.5,
        };
        let robot = V2::new(1.4, 1.2);
        let offset = start.to_local(robot);
        assert!(close(start.to_world(offset), robot));
        let path = [V2::new(0.0, 0.0), V2::new(1.0, 0.0), V2::new(1.0, 3.0)];
        let poses = along(&path, 3.0, -3.0);
        // The shorter way round from 3 to -3 rad is +0.28 rad, a quarter of it after 1 m of 4.
        let turn = wrap(-6.0);
        assert!((poses[1].angle - (3.0 + turn / 4.0)).abs() < 1e-5);
        assert!((poses[2].angle - (3.0 + turn)).abs() < 1e-5);
        let line = straight(start, V2::new(2.0, 1.0), 0.5 + 1.0, 0.2, 0.1);
        assert_eq!(line.len(), 11, "10 steps: the turn needs more than the 1 m");
        assert!(close(line[10].centre, V2::new(2.0, 1.0)) && (line[10].angle - 1.5).abs() < 1e-5);
        // A step of a micrometre still gives a bounded path that ends at the goal.
        let fine = straight(start, V2::new(2.0, 1.0), 1.5, 1e-6, 1e-6);
        assert_eq!(fine.len(), MAX_STEPS + 1);
        assert!(close(fine[MAX_STEPS].centre, V2::new(2.0, 1.0)));
    }
}
