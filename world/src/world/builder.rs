//! [`WorldBuilder`]: a world assembled from explicit entities, as the configuration loader, tests and benches
//! build it.

use swarm_contract::bodies::{BodyModel, CameraView, EPUCK};
use swarm_contract::config::MessagesMedium;
use swarm_contract::config::faults::DeadBodies;
use swarm_contract::messages::PHEROMONE_CHANNELS;

use crate::arena::Arena;
use crate::devices::Devices;
use crate::entities::{
    FloorRegion, Light, LightId, Obstacle, ObstacleId, Robot, RobotId, Target, TargetId,
    TargetState,
};
use crate::geometry::{Placed, Vec2};
use crate::gripper::GripperState;
use crate::loop_functions::{LoopFunctions, default::DefaultLoopFunctions};
use crate::media::led::LedMedium;
use crate::media::mail::MailMedium;
use crate::media::pheromone::{ChannelRates, PheromoneField};
use crate::media::rab::RabMedium;
use crate::physics::{Motion, Physics};
use crate::rng::RobotStreams;
use crate::scene::Scene;
use crate::sensors::camera;
use crate::sensors::distance_scanner::ScannerState;

use super::{Coordinator, DEFAULT_RAB_RANGE, TAG_OBSTACLE, TAG_ROBOT, TAG_TARGET, World};

/// Assembles a [`World`] from explicit entities.
pub struct WorldBuilder {
    arena: Arena,
    seed: u64,
    loop_functions: Box<dyn LoopFunctions>,
    mail: Option<MailMedium>,
    coordinators: Vec<Coordinator>,
}

impl WorldBuilder {
    /// An empty arena `min..max` stepping `ticks_per_second` times per simulated second, for the run `seed`.
    pub fn new(min: Vec2, max: Vec2, ticks_per_second: u32, seed: u64) -> Self {
        let ticks_per_second = ticks_per_second.max(1);
        Self {
            arena: Arena {
                robots: Vec::new(),
                obstacles: Vec::new(),
                targets: Vec::new(),
                lights: Vec::new(),
                floor: Vec::new(),
                // Memory for pheromone only when a pheromone medium asks for it (`WorldBuilder::pheromone`).
                pheromone: PheromoneField::off(min),
                min,
                max,
                tick: 0,
                ticks_per_second,
                gripper_events: Vec::new(),
                gripping_robots: Vec::new(),
                liftable: Vec::new(),
                physics: Physics::new(1.0 / ticks_per_second as f32),
            },
            seed,
            loop_functions: Box::new(DefaultLoopFunctions),
            mail: None,
            coordinators: Vec::new(),
        }
    }

    /// Adds an e-puck at `position` facing `heading` radians.
    pub fn robot(
        &mut self,
        name: &str,
        controller: &str,
        position: Vec2,
        heading: f32,
        devices: Devices,
    ) -> RobotId {
        self.robot_with_body(EPUCK, name, controller, position, heading, devices)
    }

    /// Adds a robot with `body` at `position` facing `heading` radians.
    pub fn robot_with_body(
        &mut self,
        body: BodyModel,
        name: &str,
        controller: &str,
        position: Vec2,
        heading: f32,
        devices: Devices,
    ) -> RobotId {
        let id = RobotId(self.arena.robots.len() as u32);
        let handles = self.arena.physics.add_robot(
            body.radius,
            body.mass,
            position,
            heading,
            TAG_ROBOT | u128::from(id.0),
        );
        if devices.gripper.is_some() {
            self.arena.gripping_robots.push(id);
            // A hundred times the disc's own inertia: what it holds turns with its turret, not its base.
            let inertia = 0.5 * body.mass * body.radius * body.radius;
            self.arena
                .physics
                .hold_rotation(handles.body, 100.0 * inertia);
        }
        self.arena.robots.push(Robot {
            name: name.to_owned(),
            body,
            controller: controller.to_owned(),
            handles,
            position,
            heading,
            led: swarm_contract::messages::Rgb::OFF,
            beacon: swarm_contract::messages::Rgb::OFF,
            alive: true,
            removed: false,
            present: true,
            wheels: [0.0; 2],
            carrying: None,
            gripper: GripperState::default(),
            scanner: ScannerState::default(),
            holds_item: false,
            collisions: 0,
            rab_range: body.rab_range,
            devices,
            rng: RobotStreams::new(self.seed, id.0),
        });
        id
    }

    /// Sets the half-aperture in radians of a robot's omnidirectional camera (the foot-bot's
    /// `omnidirectional_camera_aperture`).
    pub fn camera_aperture(&mut self, robot: RobotId, aperture: f32) {
        if let Some(r) = self.arena.robots.get_mut(robot.index()) {
            r.body.camera_view = CameraView::Aperture(aperture);
        }
    }

    /// Sets a robot's range-and-bearing emitter range in metres.
    pub fn rab_range(&mut self, robot: RobotId, range: f32) {
        if let Some(r) = self.arena.robots.get_mut(robot.index()) {
            r.rab_range = range;
        }
    }

    /// Adds a wall, box or cylinder.
    pub fn obstacle(
        &mut self,
        name: &str,
        placed: Placed,
        height: f32,
        motion: Motion,
    ) -> ObstacleId {
        let id = ObstacleId(self.arena.obstacles.len() as u32);
        let tag = TAG_OBSTACLE | u128::from(id.0);
        let handles = self.arena.physics.add(
            placed.shape,
            placed.position,
            placed.angle(),
            motion,
            tag,
            false,
        );
        self.arena.obstacles.push(Obstacle {
            name: name.to_owned(),
            placed,
            height,
            motion,
            lift_by: None,
            lifted: false,
            handles,
        });
        id
    }

    /// Lets `robots` grippers holding a movable obstacle at once lift it off the ground (see `gripper`).
    pub fn lift_by(&mut self, obstacle: ObstacleId, robots: u32) {
        if let Some(o) = self.arena.obstacles.get_mut(obstacle.index()) {
            o.lift_by = Some(robots.max(1));
            self.arena.liftable.push(obstacle);
        }
    }

    /// Adds a target: a fixed passive body with an LED at `led_height`.
    pub fn target(
        &mut self,
        name: &str,
        placed: Placed,
        height: f32,
        led: swarm_contract::messages::Rgb,
        led_height: f32,
    ) -> TargetId {
        let id = TargetId(self.arena.targets.len() as u32);
        let tag = TAG_TARGET | u128::from(id.0);
        let handles = self.arena.physics.add(
            placed.shape,
            placed.position,
            placed.angle(),
            Motion::Fixed,
            tag,
            false,
        );
        self.arena.targets.push(Target {
            name: name.to_owned(),
            placed,
            height,
            led,
            led_height,
            state: TargetState::InArena,
            handles,
        });
        id
    }

    /// Adds a light source.
    pub fn light(&mut self, light: Light) -> LightId {
        self.arena.lights.push(light);
        LightId(self.arena.lights.len() as u32 - 1)
    }

    /// Adds a floor region (drawn over earlier ones).
    pub fn floor_region(&mut self, region: FloorRegion) {
        self.arena.floor.push(region);
    }

    /// Replaces the pheromone field with one of `cell`-metre cells and the given per-channel rates.
    pub fn pheromone(&mut self, cell: f32, rates: [ChannelRates; PHEROMONE_CHANNELS]) {
        self.arena.pheromone = PheromoneField::new(self.arena.min, self.arena.max, cell, rates);
    }

    /// Gives the world a messages medium (`<messages>`): addressed messages between the run's participants.
    pub fn messages(&mut self, medium: &MessagesMedium) {
        self.mail = Some(MailMedium::new(medium, self.seed));
    }

    /// Adds a coordinator: participant `robots + k` of the run for the k-th one added.
    pub fn coordinator(&mut self, id: &str, controller: &str) {
        self.coordinators.push(Coordinator {
            id: id.to_owned(),
            controller: controller.to_owned(),
        });
    }

    /// Sets the loop functions (the default ones record basic metrics only).
    pub fn loop_functions(&mut self, loop_functions: Box<dyn LoopFunctions>) {
        self.loop_functions = loop_functions;
    }

    /// The finished world, with its media indexed for the first tick.
    pub fn build(self) -> World {
        let (min, max) = (self.arena.min, self.arena.max);
        let mut world = World {
            scene: Scene::new(min, max),
            leds: LedMedium::new(min, max, camera::LED_CELL),
            rab: RabMedium::new(min, max, DEFAULT_RAB_RANGE),
            arena: self.arena,
            loop_functions: self.loop_functions,
            scratch: Vec::with_capacity(64),
            max_ticks: None,
            dead_bodies: DeadBodies::Inert,
            pending_gripper_events: Vec::new(),
            mail: self.mail,
            participants: Vec::new(),
            coordinators: self.coordinators,
            letters: Vec::new(),
            to_world: Vec::new(),
        };
        world.update_media();
        world
    }
}
