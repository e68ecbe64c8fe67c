//! What `place` finds and checks: the box to carry, the team and its faces, the formation's radius, the planner's
//! map, and a goal the formation can stand at and reach.

use swarm_navigation::V2;
use swarm_navigation::planning::theta_star::SearchError;

use super::config::Settings;
use super::formation::{FACES, faces, front_face, radius};
use super::map::Area;
use crate::arena::Arena;
use crate::geometry::Shape;
use crate::loop_functions::navigation::planning::reference;
use crate::physics::Motion;

/// The task as laid out in the arena.
#[derive(Debug, Clone)]
pub(super) struct Site {
    /// Index of the box among the arena's obstacles.
    pub object: usize,
    /// Half its size along its own axes.
    pub half: V2,
    /// Grips that lift it.
    pub lift_by: u8,
    /// Robot i's face.
    pub faces: Vec<u8>,
    /// The formation's radius.
    pub radius: f32,
    /// Where the formation may go.
    pub area: Area,
}

impl Site {
    /// Finds the box of `settings` in `arena` and checks that the run's robots can carry it to its goal; the error
    /// says why not.
    pub fn new(settings: &Settings, arena: &Arena) -> Result<Site, String> {
        let name = &settings.object;
        let Some((object, o)) = arena
            .obstacles
            .iter()
            .enumerate()
            .find(|(_, o)| o.name == *name)
        else {
            return Err(format!(
                "`object` names `{name}`, which is no box of the arena"
            ));
        };
        let Shape::Rect { half } = o.placed.shape else {
            return Err(format!(
                "`object` `{name}` is a cylinder; the object to carry must be a box"
            ));
        };
        if o.motion == Motion::Fixed {
            return Err(format!(
                "box `{name}` is not movable: the object to carry needs `movable=\"true\"`"
            ));
        }
        let Some(lift_by) = o.lift_by else {
            return Err(format!(
                "box `{name}` has no `lift_by`: no number of grippers lifts it, so it cannot be carried"
            ));
        };
        let team = arena.robots.len();
        if team == 0 {
            return Err(format!("the run has no robots to carry box `{name}`"));
        }
        if team > FACES {
            return Err(format!(
                "the run has {team} robots; every robot is in the team and a box has {FACES} faces, so at most \
                 {FACES}"
            ));
        }
        let grippers = arena
            .robots
            .iter()
            .filter(|r| r.devices.gripper.is_some())
            .count();
        if lift_by as usize > grippers {
            return Err(format!(
                "box `{name}` needs {lift_by} grips to be lifted (`lift_by`), and the run has {grippers} robots with \
                 a `footbot_gripper`"
            ));
        }
        let start = V2::new(o.placed.position.x, o.placed.position.y);
        let faces = faces(front_face(o.placed.angle(), settings.goal - start), team);
        let half = V2::new(half.x, half.y);
        let robot_radius = arena
            .robots
            .iter()
            .map(|r| r.body.radius)
            .fold(0.0, f32::max);
        let radius = radius(half, &faces, robot_radius, settings.margin);
        let area = Area::new(arena, radius);
        let goal = settings.goal;
        if let Some(problem) = area.goal_problem(arena, goal) {
            return Err(problem);
        }
        if reference(start, goal, &area.discs, area.bounds, radius) == Err(SearchError::Unreachable)
        {
            return Err(format!(
                "the goal ({}, {}) is unreachable for the formation (radius {radius} m) from the start ({}, {}) of \
                 box `{name}`: static obstacles wall it off",
                goal.x, goal.y, start.x, start.y
            ));
        }
        Ok(Site {
            object,
            half,
            // At most `FACES` robots grip at once, so the count fits.
            lift_by: u8::try_from(lift_by).unwrap_or(u8::MAX),
            faces,
            radius,
            area,
        })
    }
}
