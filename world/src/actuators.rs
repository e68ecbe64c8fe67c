//! The actuators applied to the arena: wheels (differential drive, with each body's wheel base and speed limit),
//! LEDs, range-and-bearing emitter, pheromone deposit and the virtual gripper. Applied once per tick, after
//! control and before physics.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use swarm_contract::bodies::BodyModel;
use swarm_contract::messages::{ActuatorCommand, Drive, GripperAction, PHEROMONE_CHANNELS};

use crate::arena::{Arena, GripperEvent};
use crate::entities::{RobotId, TargetId, TargetState};
use crate::geometry::unit;
use crate::media::rab::RabMedium;

/// Default largest edge-to-edge gap in metres at which the virtual gripper reaches a target (the thesis' 7 mm);
/// the `virtual_gripper` actuator's `pickup_gap` overrides it.
pub const GRIPPER_REACH: f32 = 0.007;
/// Gap in metres between the robot's edge and a target it drops in front of itself.
pub const DROP_GAP: f32 = 0.001;

/// Clamps each wheel to +-`max_cm_s` (the e-puck's 12.8 cm/s), then applies the multiplicative Gaussian noise
/// `v <- v + v N(0, sigma)`.
pub fn wheel_speeds(
    commanded: [f32; 2],
    max_cm_s: f32,
    noise_std_dev: f32,
    rng: &mut ChaCha8Rng,
) -> [f32; 2] {
    let mut w = commanded.map(|v| {
        if v.is_finite() {
            v.clamp(-max_cm_s, max_cm_s)
        } else {
            0.0
        }
    });
    if noise_std_dev > 0.0
        && let Ok(normal) = Normal::new(0.0f32, noise_std_dev)
    {
        for v in &mut w {
            *v += *v * normal.sample(rng);
        }
    }
    w
}

/// The unicycle velocities of wheel speeds in cm/s on wheels `inter_wheel_distance` metres apart:
/// `v = (vl + vr) / 2` in m/s and `w = (vr - vl) / inter_wheel_distance` in rad/s.
pub fn unicycle(wheels_cm_s: [f32; 2], inter_wheel_distance: f32) -> (f32, f32) {
    let (l, r) = (wheels_cm_s[0] / 100.0, wheels_cm_s[1] / 100.0);
    ((l + r) / 2.0, (r - l) / inter_wheel_distance)
}

/// The wheel speeds in cm/s that drive `body` at forward speed `twist[0]` m/s and turn rate `twist[1]` rad/s,
/// each first clamped to the body's limits (non-finite values count as 0).
pub fn twist_to_wheels(twist: [f32; 2], body: &BodyModel) -> [f32; 2] {
    let finite = |x: f32| if x.is_finite() { x } else { 0.0 };
    let max_v = body.max_wheel_speed_cm_s / 100.0;
    let v = finite(twist[0]).clamp(-max_v, max_v);
    let w = finite(twist[1]).clamp(-body.max_turn_rate, body.max_turn_rate);
    let half = w * body.inter_wheel_distance / 2.0;
    [(v - half) * 100.0, (v + half) * 100.0]
}

/// Applies `command` to robot `id`, or holds it still when `command` is `None` (no command, or dead).
pub fn apply(
    arena: &mut Arena,
    rab: &mut RabMedium,
    id: RobotId,
    command: Option<&ActuatorCommand>,
) {
    let i = id.index();
    let dt = arena.dt();
    let Some(robot) = arena.robots.get_mut(i) else {
        return;
    };
    let Some(cmd) = command.filter(|_| robot.alive) else {
        robot.wheels = [0.0; 2];
        arena.physics.drive(robot.handles.body, 0.0, 0.0);
        return;
    };
    // A twist within the limits may ask one wheel for more than the wheel limit (full speed while turning):
    // the turn-rate limit, not the wheel limit, bounds it, as on a TurtleBot.
    let (commanded, max_wheel) = match cmd.drive {
        Drive::Wheels => (cmd.wheels, robot.body.max_wheel_speed_cm_s),
        Drive::Twist => (twist_to_wheels(cmd.twist, &robot.body), f32::INFINITY),
    };
    robot.wheels = wheel_speeds(
        commanded,
        max_wheel,
        robot.devices.wheel_noise_std_dev,
        &mut robot.rng.wheels,
    );
    let (v, w) = unicycle(robot.wheels, robot.body.inter_wheel_distance);
    arena.physics.drive(robot.handles.body, v, w);
    robot.led = cmd.led;
    robot.beacon = cmd.beacon;
    if let Some(opts) = robot.devices.rab
        && cmd.rab_len > 0
    {
        rab.send(
            id.0,
            robot.rab_range,
            cmd.rab_payload,
            cmd.rab_len.min(opts.data_size),
        );
    }
    let position = robot.position;
    for ch in 0..PHEROMONE_CHANNELS {
        arena
            .pheromone
            .deposit(ch, position, cmd.pheromone_deposit[ch]);
    }
    if robot.devices.distance_scanner {
        robot.scanner.command(cmd.scanner, cmd.scanner_setting, dt);
    }
    if robot.devices.gripper.is_some() {
        let gripper = &mut robot.gripper;
        match cmd.gripper {
            GripperAction::Hold => {}
            GripperAction::Pick => gripper.locked = true,
            GripperAction::Drop => {
                gripper.locked = false;
                gripper.lost = false;
            }
        }
        crate::gripper::command_turret(arena, id, cmd.turret_mode, cmd.turret, dt);
        return;
    }
    match cmd.gripper {
        GripperAction::Hold => {}
        GripperAction::Pick => pick(arena, id),
        GripperAction::Drop => drop_carried(arena, id),
    }
}

/// The nearest target lying in the arena within the gripper's reach of robot `id`.
pub fn target_in_reach(arena: &Arena, id: RobotId) -> Option<TargetId> {
    let robot = arena.robots.get(id.index())?;
    arena
        .targets
        .iter()
        .enumerate()
        .filter(|(_, t)| t.state == TargetState::InArena)
        .map(|(i, t)| (i, t.placed.gap_to_disc(robot.position, robot.body.radius)))
        .filter(|&(_, gap)| gap <= robot.devices.gripper_reach)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| TargetId(i as u32))
}

fn pick(arena: &mut Arena, id: RobotId) {
    if arena.robots[id.index()].carrying.is_some() {
        return;
    }
    let Some(target) = target_in_reach(arena, id) else {
        return;
    };
    let t = &mut arena.targets[target.index()];
    t.state = TargetState::Carried(id);
    arena.physics.set_enabled(t.handles, false);
    arena.robots[id.index()].carrying = Some(target);
    arena
        .gripper_events
        .push(GripperEvent::Picked { robot: id, target });
}

fn drop_carried(arena: &mut Arena, id: RobotId) {
    let robot = &arena.robots[id.index()];
    let Some(target) = robot.carrying else { return };
    let radius = arena.targets[target.index()].radius();
    let position = robot.position + unit(robot.heading) * (robot.body.radius + radius + DROP_GAP);
    arena.place_target(target, position);
    arena.gripper_events.push(GripperEvent::Dropped {
        robot: id,
        target,
        position,
    });
}

/// After physics: carried targets ride on their robots.
pub fn carry(arena: &mut Arena) {
    for t in &mut arena.targets {
        if let TargetState::Carried(robot) = t.state
            && let Some(r) = arena.robots.get(robot.index())
        {
            t.placed.set_pose(r.position, r.heading);
        }
    }
}
