//! Actuators and physics: differential drive, clamping, contacts, the virtual gripper and dead robots.

use crate::common::{TPS, builder, drive, frames, wall, wheels};
use swarm_contract::config::faults::DeadBodies;
use swarm_contract::messages::{ActuatorCommand, GripperAction, Rgb};
use swarm_world::arena::GripperEvent;
use swarm_world::devices::Devices;
use swarm_world::entities::{ROBOT_RADIUS, RobotId, TargetState};
use swarm_world::geometry::{Placed, Shape, Vec2};

const DT: f32 = 1.0 / TPS as f32;

#[test]
fn equal_wheel_speeds_move_v_times_k_dt_along_the_heading() {
    let mut b = builder();
    b.robot(
        "r",
        "c",
        Vec2::ZERO,
        std::f32::consts::FRAC_PI_4,
        Devices::PROXIMITY_ONLY,
    );
    let mut world = b.build();
    drive(&mut world, 20, wheels(10.0, 10.0));
    let r = &world.arena.robots[0];
    let expected = 0.10 * 20.0 * DT; // 10 cm/s for 1 s
    let moved = r.position;
    assert!((moved.length() - expected).abs() < 1e-4, "moved {moved:?}");
    assert!((moved.y.atan2(moved.x) - std::f32::consts::FRAC_PI_4).abs() < 1e-3);
    assert!((r.heading - std::f32::consts::FRAC_PI_4).abs() < 1e-5);
}

#[test]
fn opposite_wheels_pivot_in_place_at_speed_difference_over_axle() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    let mut world = b.build();
    drive(&mut world, 10, wheels(-5.0, 5.0));
    let r = &world.arena.robots[0];
    let omega = 0.10 / 0.053; // (vr - vl) / 0.053 with speeds in m/s
    assert!(
        (r.heading - omega * 10.0 * DT).abs() < 1e-3,
        "heading {}",
        r.heading
    );
    assert!(
        r.position.length() < 1e-4,
        "a pivot does not translate: {:?}",
        r.position
    );
}

#[test]
fn wheel_speeds_are_clamped_to_12_8_cm_per_second() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    let mut world = b.build();
    drive(&mut world, 20, wheels(50.0, 50.0));
    assert!((world.arena.robots[0].position.x - 0.128).abs() < 1e-4);
    assert_eq!(world.arena.robots[0].wheels, [12.8, 12.8]);
}

#[test]
fn thesis_turn_right_pivots_about_the_right_wheel() {
    // turn-right: left wheel 2.5 cm/s, right wheel 0: v = 1.25 cm/s, w = -2.5 / 5.3 rad/s.
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    let mut world = b.build();
    drive(&mut world, 1, wheels(2.5, 0.0));
    assert!((world.arena.robots[0].heading - (-0.025 / 0.053 * DT)).abs() < 1e-5);
}

#[test]
fn robot_driving_into_a_wall_stops_at_it_and_counts_one_collision() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    wall(&mut b, Vec2::new(0.3, 0.0), Vec2::new(0.1, 1.0));
    let mut world = b.build();
    drive(&mut world, 100, wheels(12.8, 12.8));
    let r = &world.arena.robots[0];
    assert!(
        r.position.x <= 0.25 - ROBOT_RADIUS + 0.002,
        "no penetration: x = {}",
        r.position.x
    );
    assert!(
        r.position.x > 0.2,
        "it reached the wall: x = {}",
        r.position.x
    );
    assert_eq!(r.collisions, 1, "one contact that lasts is one collision");
}

fn gripper_world(gap: f32) -> swarm_world::World {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    let at = Vec2::new(ROBOT_RADIUS + 0.02 + gap, 0.0);
    b.target(
        "food",
        Placed::new(Shape::Disc { radius: 0.02 }, at, 0.0),
        0.05,
        Rgb { r: 255, g: 0, b: 0 },
        0.06,
    );
    b.build()
}

fn grip(world: &mut swarm_world::World, action: GripperAction) {
    let mut cmd = ActuatorCommand::idle(0, 0);
    cmd.gripper = action;
    world.act_and_step(&[cmd], &[true]);
}

#[test]
fn gripper_picks_a_target_at_a_gap_of_7_mm_but_not_8_mm() {
    let mut near = gripper_world(0.0069);
    grip(&mut near, GripperAction::Pick);
    assert_eq!(
        near.arena.targets[0].state,
        TargetState::Carried(RobotId(0))
    );
    assert!(matches!(
        near.arena.gripper_events[..],
        [GripperEvent::Picked { .. }]
    ));
    assert_eq!(frames(&mut near)[0].gripper_holding, 1);
    assert_eq!(
        frames(&mut near)[0].camera_len,
        0,
        "a carried target is out of the arena"
    );

    let mut far = gripper_world(0.008);
    grip(&mut far, GripperAction::Pick);
    assert_eq!(far.arena.targets[0].state, TargetState::InArena);
    assert_eq!(frames(&mut far)[0].gripper_holding, 0);
}

#[test]
fn carried_target_rides_on_the_robot_and_drops_in_front_of_it() {
    let mut world = gripper_world(0.003);
    grip(&mut world, GripperAction::Pick);
    drive(&mut world, 20, wheels(-10.0, -10.0));
    let robot = world.arena.robots[0].position;
    assert_eq!(
        world.arena.targets[0].placed.position, robot,
        "the target rides on the robot"
    );
    grip(&mut world, GripperAction::Drop);
    let t = &world.arena.targets[0];
    assert_eq!(t.state, TargetState::InArena);
    assert!(
        (t.placed.gap_to_disc(robot, ROBOT_RADIUS) - 0.001).abs() < 1e-4,
        "dropped touching the front"
    );
    assert_eq!(world.arena.robots[0].carrying, None);
}

#[test]
fn dead_robot_holds_still_with_its_led_off_and_reports_not_alive() {
    let mut b = builder();
    let r = b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    let mut world = b.build();
    let mut lit = wheels(10.0, 10.0);
    lit.led = Rgb { r: 0, g: 0, b: 255 };
    world.act_and_step(&[lit], &[true]);
    world.set_alive(r, false);
    let before = world.arena.robots[0].position;
    drive(&mut world, 10, lit);
    assert_eq!(world.arena.robots[0].position, before);
    assert_eq!(world.arena.robots[0].led, Rgb::OFF);
    assert_eq!(frames(&mut world)[0].alive, 0);
}

/// Robot 0 at the origin facing +x, robot 1 (dead) 9 cm ahead of it, with dead bodies `dead_bodies`.
fn dead_robot_ahead(dead_bodies: DeadBodies) -> swarm_world::World {
    let mut b = builder();
    b.robot("r0", "c", Vec2::ZERO, 0.0, Devices::ALL);
    let dead = b.robot("r1", "c", Vec2::new(0.09, 0.0), 0.0, Devices::ALL);
    let mut world = b.build();
    world.set_dead_bodies(dead_bodies);
    world.set_alive(dead, false);
    world
}

#[test]
fn inert_dead_body_is_seen_and_pushed_aside() {
    let mut world = dead_robot_ahead(DeadBodies::Inert);
    assert!(frames(&mut world)[0].proximity[0] > 0.0, "the body is seen");
    drive(&mut world, 40, wheels(10.0, 10.0));
    assert_eq!(world.arena.robots[0].collisions, 1);
    assert!(
        world.arena.robots[1].position.x > 0.1,
        "the body was pushed: {}",
        world.arena.robots[1].position.x
    );
}

#[test]
fn removed_dead_body_is_neither_seen_nor_hit_and_comes_back_with_its_robot() {
    let mut world = dead_robot_ahead(DeadBodies::Removed);
    assert!(world.arena.robots[1].removed);
    assert_eq!(
        frames(&mut world)[0].proximity_readings(),
        [0.0; 8],
        "nothing seen"
    );
    drive(&mut world, 40, wheels(10.0, 10.0));
    assert!(
        world.arena.robots[0].position.x > 0.09 + 2.0 * ROBOT_RADIUS,
        "drove through where the body was: {}",
        world.arena.robots[0].position.x
    );
    assert_eq!(world.arena.robots[0].collisions, 0);
    assert_eq!(world.arena.robots[1].position, Vec2::new(0.09, 0.0));

    world.set_alive(RobotId(1), true);
    assert!(!world.arena.robots[1].removed);
    let backwards = [wheels(-10.0, -10.0), wheels(0.0, 0.0)];
    for _ in 0..40 {
        world.act_and_step(&backwards, &[true, false]);
    }
    assert_eq!(
        world.arena.robots[0].collisions, 1,
        "backing up, robot 0 hits the restarted robot"
    );
    assert!(world.arena.robots[1].position.x < 0.08);
}

#[test]
fn robot_without_a_command_holds_still() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    let mut world = b.build();
    world.act_and_step(&[wheels(10.0, 10.0)], &[false]);
    assert_eq!(world.arena.robots[0].position, Vec2::ZERO);
}

#[test]
fn robot_pushes_a_movable_box_ahead_of_it() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    let crate_box = Placed::new(
        Shape::Rect {
            half: Vec2::splat(0.05),
        },
        Vec2::new(0.1, 0.0),
        0.0,
    );
    b.obstacle(
        "crate",
        crate_box,
        0.1,
        swarm_world::physics::Motion::Movable { mass: 0.05 },
    );
    let mut world = b.build();
    drive(&mut world, 40, wheels(12.8, 12.8));
    let pushed = world.arena.obstacles[0].placed.position;
    let robot = world.arena.robots[0].position;
    assert!(pushed.x > 0.2, "the box moved ahead: {pushed:?}");
    assert!(
        pushed.x - robot.x >= ROBOT_RADIUS + 0.05 - 0.002,
        "and stays in front of the robot"
    );
    assert!(world.arena.robots[0].collisions >= 1);
}
