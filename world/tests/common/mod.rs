//! Helpers shared by the integration tests: a small arena with hand-placed entities, and the thesis example.

#![allow(dead_code)]

pub mod config;

use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_world::WorldBuilder;
use swarm_world::geometry::{Placed, Shape, Vec2};
use swarm_world::physics::Motion;

/// Ticks per second of the test worlds (the thesis' 20).
pub const TPS: u32 = 20;

/// A 4 x 4 m arena without walls, seed 1.
pub fn builder() -> WorldBuilder {
    WorldBuilder::new(Vec2::splat(-2.0), Vec2::splat(2.0), TPS, 1)
}

/// A fixed box of `size` (x, y) at `position`, 0.4 m tall.
pub fn wall(b: &mut WorldBuilder, position: Vec2, size: Vec2) {
    b.obstacle(
        "wall",
        Placed::new(Shape::Rect { half: size / 2.0 }, position, 0.0),
        0.4,
        Motion::Fixed,
    );
}

/// Every robot's frame after one `sense`.
pub fn frames(world: &mut swarm_world::World) -> Vec<SensorFrame> {
    let mut frames: Vec<SensorFrame> = (0..world.robot_count() as u32)
        .map(SensorFrame::empty)
        .collect();
    world.sense(&mut frames);
    frames
}

/// Steps `ticks` ticks with every robot commanded `command` (its robot field is set per robot).
pub fn drive(world: &mut swarm_world::World, ticks: u64, command: ActuatorCommand) {
    let n = world.robot_count();
    let commands: Vec<ActuatorCommand> = (0..n as u32)
        .map(|r| {
            let mut c = command;
            c.robot = r;
            c
        })
        .collect();
    let has = vec![true; n];
    for _ in 0..ticks {
        world.act_and_step(&commands, &has);
    }
}

/// A command with the given wheel speeds in cm/s and nothing else.
pub fn wheels(left: f32, right: f32) -> ActuatorCommand {
    let mut c = ActuatorCommand::idle(0, 0);
    c.wheels = [left, right];
    c
}
