//! The arena: the entity sets, the physics that moves them and the pheromone field, plus the operations loop
//! functions may use on them (ARGoS' `MoveEntity`, `RemoveEntity`, floor colour). This is the state a tick
//! changes; the order of a tick lives in `world`.

use crate::entities::{
    FloorRegion, Light, Obstacle, ObstacleId, Robot, RobotId, Target, TargetId, TargetState,
};
use crate::geometry::Vec2;
use crate::media::pheromone::PheromoneField;
use crate::physics::Physics;

/// Why a physical gripper let go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReleaseCause {
    /// Its controller unlocked it.
    Opened,
    /// Holding on took more than the gripper's `max_force` (`gripper::load`).
    Overloaded,
    /// The robot died.
    Died,
}

impl ReleaseCause {
    /// The name `events.csv` gives a release for this cause.
    pub fn event_name(self) -> &'static str {
        match self {
            ReleaseCause::Opened => "gripper:release",
            ReleaseCause::Overloaded => "gripper:lost",
            ReleaseCause::Died => "gripper:release_on_death",
        }
    }
}

/// What the grippers (virtual and physical) did in the last tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GripperEvent {
    /// A robot picked a target up.
    Picked {
        /// The robot.
        robot: RobotId,
        /// The target.
        target: TargetId,
    },
    /// A robot dropped a target at `position`.
    Dropped {
        /// The robot.
        robot: RobotId,
        /// The target.
        target: TargetId,
        /// Where the target now lies.
        position: Vec2,
    },
    /// A robot's physical gripper gripped a movable obstacle.
    Gripped {
        /// The robot.
        robot: RobotId,
        /// The object.
        obstacle: ObstacleId,
    },
    /// Enough grippers hold an obstacle to lift it; reported for each robot holding it.
    Lifted {
        /// A robot holding it.
        robot: RobotId,
        /// The object.
        obstacle: ObstacleId,
    },
    /// A lifted obstacle is back on the ground (a grip let go); reported for each robot that let go of it in
    /// that tick and each robot still holding it.
    Lowered {
        /// A robot holding it.
        robot: RobotId,
        /// The object.
        obstacle: ObstacleId,
    },
    /// A robot's physical gripper let go of a movable obstacle.
    Released {
        /// The robot.
        robot: RobotId,
        /// The object.
        obstacle: ObstacleId,
        /// Why.
        cause: ReleaseCause,
    },
}

/// The simulated arena.
pub struct Arena {
    /// Robots, by [`RobotId`].
    pub robots: Vec<Robot>,
    /// Walls, boxes and cylinders.
    pub obstacles: Vec<Obstacle>,
    /// Targets.
    pub targets: Vec<Target>,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Floor regions, later ones drawn over earlier ones; the floor is white elsewhere.
    pub floor: Vec<FloorRegion>,
    /// The pheromone field.
    pub pheromone: PheromoneField,
    /// Lower corner of the arena.
    pub min: Vec2,
    /// Upper corner of the arena.
    pub max: Vec2,
    /// Ticks completed (0 before the first step).
    pub tick: u64,
    /// Ticks per simulated second.
    pub ticks_per_second: u32,
    /// Gripper events of the last tick.
    pub gripper_events: Vec<GripperEvent>,
    /// The robots with a physical gripper, in index order (the only ones the gripper update visits).
    pub(crate) gripping_robots: Vec<RobotId>,
    /// The obstacles that robots can lift (`lift_by`), in index order.
    pub(crate) liftable: Vec<ObstacleId>,
    pub(crate) physics: Physics,
}

impl Arena {
    /// Moves `robot` to `position` facing `heading` (radians), at rest; for loop functions placing robots
    /// before the run.
    pub fn place_robot(&mut self, robot: crate::entities::RobotId, position: Vec2, heading: f32) {
        let Some(r) = self.robots.get_mut(robot.index()) else {
            return;
        };
        r.position = position;
        r.heading = heading;
        r.wheels = [0.0; 2];
        self.physics.teleport(r.handles.body, position, heading);
    }

    /// Simulated seconds per tick.
    pub fn dt(&self) -> f32 {
        1.0 / self.ticks_per_second as f32
    }

    /// Grey level of the floor regions at `p` (1 white where no region lies).
    pub fn floor_grey(&self, p: Vec2) -> f32 {
        crate::entities::floor_grey(&self.floor, p)
    }

    /// Takes a target out of the run (for example when it is delivered home); a carrier lets go of it.
    pub fn remove_target(&mut self, target: TargetId) {
        let Some(t) = self.targets.get_mut(target.index()) else {
            return;
        };
        if let TargetState::Carried(robot) = t.state
            && let Some(r) = self.robots.get_mut(robot.index())
        {
            r.carrying = None;
        }
        t.state = TargetState::Removed;
        self.physics.set_enabled(t.handles, false);
    }

    /// Puts a target back into the arena at `position` (out of any gripper).
    pub fn place_target(&mut self, target: TargetId, position: Vec2) {
        let Some(t) = self.targets.get_mut(target.index()) else {
            return;
        };
        if let TargetState::Carried(robot) = t.state
            && let Some(r) = self.robots.get_mut(robot.index())
        {
            r.carrying = None;
        }
        t.state = TargetState::InArena;
        t.placed.set_pose(position, t.placed.angle());
        self.physics
            .teleport(t.handles.body, position, t.placed.angle());
        self.physics.set_enabled(t.handles, true);
    }

    /// Moves a robot to a new pose and stops it.
    pub fn move_robot(&mut self, robot: RobotId, position: Vec2, heading: f32) {
        let Some(r) = self.robots.get_mut(robot.index()) else {
            return;
        };
        r.position = position;
        r.heading = heading;
        self.physics.teleport(r.handles.body, position, heading);
    }
}
