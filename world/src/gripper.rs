//! The physical gripper (`footbot_gripper`, with `footbot_turret` to turn it): a robot grips a movable box or
//! cylinder at its gripper point, so that several robots can hold one object and pull or carry it together.
//!
//! As on ARGoS' foot-bot, the object is held rigidly by the turret, and the turret turns about the robot's centre:
//! in position or speed mode the object is welded to the turret's frame (rapier fixed joint) and turns with it; a
//! passive turret turns freely, so the object is pinned to the robot's centre by a revolute joint.
//!
//! The gripper point sits on the body's edge, in the direction of the heading plus the turret's angle. A locked
//! gripper that holds nothing grips the first movable obstacle (in configuration order) whose outline is within
//! [`GRIP_REACH`] of that point, after the physics step; it holds it until:
//!
//! - its controller unlocks it (the object is released where it is);
//! - holding the robot back takes more than the gripper's `max_force` ([`load`]: the grip is lost under load; the
//!   gripper then stays open until its controller unlocks and locks it again, so it does not snap back at once);
//! - the robot dies (a dead robot's gripper opens).
//!
//! Each of these is a [`GripperEvent`] of the tick. The turret turns at most [`TURRET_MAX_SPEED`]: a sudden turn
//! would yank the object out of the gripper.

use rapier2d::prelude::ImpulseJointHandle;

use crate::arena::{Arena, GripperEvent, ReleaseCause};
use crate::entities::{ObstacleId, RobotId};
use crate::geometry::{Vec2, unit};
use crate::physics::{MOVABLE_DAMPING, Motion};
use swarm_contract::messages::Turret;

/// Largest gap in metres between the gripper point and an object's outline at which a locked gripper grips it.
pub const GRIP_REACH: f32 = 0.01;
/// Default largest force in newtons a grip holds before it is lost (`max_force` of `footbot_gripper`): a grip holds
/// a foot-bot pulling at 5 cm/s against a fixed load (1.6 N) and gives when it pulls at 10 cm/s (3.2 N).
pub const DEFAULT_MAX_FORCE: f32 = 2.5;

/// Fastest the turret turns, in radians per second: a position command gets there at this speed, a speed
/// command is capped at it.
pub const TURRET_MAX_SPEED: f32 = std::f32::consts::PI;

/// What a robot's physical gripper holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grip {
    /// The object.
    pub obstacle: ObstacleId,
    /// The joint that holds it to the robot.
    pub joint: ImpulseJointHandle,
    /// Whether the joint is the passive turret's (revolute at the robot's centre) rather than a weld.
    pub passive: bool,
    /// Where the gripper holds the object, in the object's frame.
    pub point_on_object: Vec2,
}

/// The state of a robot's physical gripper and turret.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GripperState {
    /// Whether the controller asked it to close.
    pub locked: bool,
    /// What it holds.
    pub holding: Option<Grip>,
    /// Whether it lost its last grip under load and waits to be unlocked before it grips again.
    pub lost: bool,
    /// Turret angle in radians, counter-clockwise from the heading.
    pub turret: f32,
    /// How the turret moves.
    pub turret_mode: Turret,
}

/// The arena point where robot `robot`'s gripper is.
pub fn gripper_point(arena: &Arena, robot: RobotId) -> Option<Vec2> {
    let r = arena.robots.get(robot.index())?;
    Some(r.position + unit(r.heading + r.gripper.turret) * r.body.radius)
}

/// The load on robot `robot`'s grip in newtons: the force it would take to hold the robot back from the velocity
/// its wheels commanded to the velocity it reached, `mass |v_commanded - v_reached| / tick length`. Robots are
/// driven by setting their velocity, so this is what their motors would have to push against the grip.
pub fn load(arena: &Arena, robot: RobotId) -> f32 {
    let Some(r) = arena.robots.get(robot.index()) else {
        return 0.0;
    };
    let (speed, _) = crate::actuators::unicycle(r.wheels, r.body.inter_wheel_distance);
    let commanded = unit(r.heading) * speed;
    let reached = arena.physics.velocity(r.handles.body);
    r.body.mass * (commanded - reached).length() / arena.dt()
}

/// Lets go of what robot `robot` holds, for `cause`.
pub fn release(arena: &mut Arena, robot: RobotId, cause: ReleaseCause) {
    let Some(r) = arena.robots.get_mut(robot.index()) else {
        return;
    };
    let Some(grip) = r.gripper.holding.take() else {
        return;
    };
    arena.physics.unpin(grip.joint);
    arena.gripper_events.push(GripperEvent::Released {
        robot,
        obstacle: grip.obstacle,
        cause,
    });
}

/// After a physics step: releases what unlocked, overloaded or dead grippers hold, then lets every locked,
/// empty gripper grip what is within reach.
pub fn update(arena: &mut Arena) {
    for k in 0..arena.gripping_robots.len() {
        let id = arena.gripping_robots[k];
        let i = id.index();
        follow_passively(arena, id);
        let r = &arena.robots[i];
        let Some(options) = r.devices.gripper else {
            continue;
        };
        // A robot that dies lets go at once (`World::set_alive`), so a holder here is alive.
        match r.gripper.holding {
            Some(_) if !r.gripper.locked => release(arena, id, ReleaseCause::Opened),
            Some(_) if load(arena, id) > options.max_force => {
                release(arena, id, ReleaseCause::Overloaded);
                arena.robots[i].gripper.lost = true;
            }
            Some(_) => {}
            None if r.alive && r.gripper.locked && !r.gripper.lost => grip(arena, id),
            None => {}
        }
    }
    lift_or_lower(arena);
}

/// Lifts every liftable obstacle that at least `lift_by` grippers hold, and lowers the others: a lifted object
/// has no ground friction (it rides on its carriers), a lowered one the friction of every movable object.
fn lift_or_lower(arena: &mut Arena) {
    for k in 0..arena.liftable.len() {
        let obstacle = arena.liftable[k];
        let holding = |r: &&RobotId| {
            arena.robots[r.index()]
                .gripper
                .holding
                .is_some_and(|g| g.obstacle == obstacle)
        };
        let holders = arena.gripping_robots.iter().filter(holding).count() as u32;
        let o = &mut arena.obstacles[obstacle.index()];
        let lifted = o.lift_by.is_some_and(|n| holders >= n);
        if lifted == o.lifted {
            continue;
        }
        o.lifted = lifted;
        let damping = if lifted { 0.0 } else { MOVABLE_DAMPING };
        arena.physics.set_damping(o.handles.body, damping);
        // Reported for every robot that holds it now and, when it comes down, every robot that let go of it in
        // this tick (robot order); the events only grow, so the earlier ones are read up to their count now.
        if !lifted {
            for i in 0..arena.gripper_events.len() {
                if let GripperEvent::Released {
                    robot, obstacle: o, ..
                } = arena.gripper_events[i]
                    && o == obstacle
                {
                    arena
                        .gripper_events
                        .push(GripperEvent::Lowered { robot, obstacle });
                }
            }
        }
        for &robot in arena.gripping_robots.iter().filter(holding) {
            arena.gripper_events.push(if lifted {
                GripperEvent::Lifted { robot, obstacle }
            } else {
                GripperEvent::Lowered { robot, obstacle }
            });
        }
    }
}

/// Keeps a passive turret's angle pointing at where the held object is gripped (the joint lets it turn freely;
/// this only keeps the gripper point where the object is).
fn follow_passively(arena: &mut Arena, robot: RobotId) {
    let r = &arena.robots[robot.index()];
    let Some(grip) = r.gripper.holding.filter(|g| g.passive) else {
        return;
    };
    let object = arena.obstacles[grip.obstacle.index()].handles.body;
    let Some(point) = arena.physics.point_on(object, grip.point_on_object) else {
        return;
    };
    let to = point - r.position;
    let turret = crate::geometry::wrap_angle(to.y.atan2(to.x) - r.heading);
    arena.robots[robot.index()].gripper.turret = turret;
}

/// The joint that holds `object` to robot `robot` as things are now: a weld at the turret's frame, or for a
/// passive turret a revolute joint at the robot's centre.
fn attach(
    arena: &mut Arena,
    robot: RobotId,
    object: ObstacleId,
) -> Option<(ImpulseJointHandle, bool)> {
    let r = &arena.robots[robot.index()];
    let (robot_body, centre, turret, radius) =
        (r.handles.body, r.position, r.gripper.turret, r.body.radius);
    let passive = r.gripper.turret_mode == Turret::Passive;
    let object_body = arena.obstacles[object.index()].handles.body;
    let joint = if passive {
        arena.physics.pin(robot_body, object_body, centre)?
    } else {
        arena
            .physics
            .weld(robot_body, object_body, unit(turret) * radius, turret)?
    };
    Some((joint, passive))
}

/// Applies a turret command to robot `robot`: its mode, and its angle (`Position`) or speed (`Speed`) in the tick
/// of `dt` seconds; a held object turns with it, and changing to or from passive changes how it is held.
pub fn command_turret(arena: &mut Arena, robot: RobotId, mode: Turret, setting: f32, dt: f32) {
    let Some(r) = arena.robots.get_mut(robot.index()) else {
        return;
    };
    let gripper = &mut r.gripper;
    gripper.turret_mode = mode;
    let step = TURRET_MAX_SPEED * dt;
    let turned = match mode {
        Turret::Position if setting.is_finite() => {
            let to_go = crate::geometry::wrap_angle(setting - gripper.turret);
            Some(gripper.turret + to_go.clamp(-step, step))
        }
        Turret::Speed if setting.is_finite() => {
            Some(gripper.turret + (setting * dt).clamp(-step, step))
        }
        _ => None,
    };
    if let Some(angle) = turned {
        gripper.turret = crate::geometry::wrap_angle(angle);
    }
    let (turret, radius) = (gripper.turret, r.body.radius);
    let Some(grip) = gripper.holding else {
        return;
    };
    if grip.passive != (mode == Turret::Passive) {
        arena.physics.unpin(grip.joint);
        if let Some((joint, passive)) = attach(arena, robot, grip.obstacle) {
            arena.robots[robot.index()].gripper.holding = Some(Grip {
                joint,
                passive,
                ..grip
            });
        }
    } else if !grip.passive {
        arena
            .physics
            .move_weld(grip.joint, unit(turret) * radius, turret);
    }
}

/// Grips the first movable obstacle within reach of robot `robot`'s gripper point.
fn grip(arena: &mut Arena, robot: RobotId) {
    let Some(point) = gripper_point(arena, robot) else {
        return;
    };
    let Some((index, obstacle)) = arena.obstacles.iter().enumerate().find(|(_, o)| {
        matches!(o.motion, Motion::Movable { .. }) && o.placed.signed_distance(point) <= GRIP_REACH
    }) else {
        return;
    };
    let Some(point_on_object) = arena.physics.local_point(obstacle.handles.body, point) else {
        return;
    };
    let obstacle = ObstacleId(index as u32);
    let Some((joint, passive)) = attach(arena, robot, obstacle) else {
        return;
    };
    arena.robots[robot.index()].gripper.holding = Some(Grip {
        obstacle,
        joint,
        passive,
        point_on_object,
    });
    arena
        .gripper_events
        .push(GripperEvent::Gripped { robot, obstacle });
}
