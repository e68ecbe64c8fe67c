//! The world and its tick, in ARGoS order: sense (every robot's frame), control (outside, in the agents), act,
//! physics, media, loop functions.
//!
//! [`WorldBuilder`] assembles a world from explicit entities (tests, benches and the configuration loader all go
//! through it). A tick touches only preallocated buffers: [`World::sense`] allocates nothing once warmed up, and
//! [`World::act_and_step`] only reuses buffers around the rapier2d step (which allocates a few small buffers of its
//! own per step).

mod builder;

use swarm_contract::config::Experiment;
use swarm_contract::config::faults::DeadBodies;
use swarm_contract::mail::{Mail, Mailbox};
use swarm_contract::messages::{ActuatorCommand, PHEROMONE_CHANNELS, SensorFrame};

use crate::actuators;
use crate::arena::{Arena, GripperEvent, ReleaseCause};
use crate::entities::{RobotId, floor_grey};
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::{LoopFunctions, LoopFunctionsRegistry};
use crate::media::led::LedMedium;
use crate::media::mail::{MailMedium, MessageRecord, Participant};
use crate::media::rab::RabMedium;
use crate::physics::Motion;
use crate::scene::Scene;
use crate::sensors::{
    Observer, camera, distance_scanner, ground, light, proximity, rab, range_finder,
};
pub use builder::WorldBuilder;

/// Default range of an e-puck's range-and-bearing emitter in metres (each body has its own).
pub const DEFAULT_RAB_RANGE: f32 = swarm_contract::bodies::EPUCK.rab_range;
/// Default pheromone cell side in metres (docs/tasks.md 5.2).
pub const DEFAULT_PHEROMONE_CELL: f32 = 0.05;

/// Tags in physics user data: the kind in the high word, the index in the low word.
const TAG_ROBOT: u128 = 1 << 32;
const TAG_OBSTACLE: u128 = 2 << 32;
const TAG_TARGET: u128 = 3 << 32;

/// A participant of the run without a body (`<coordinator>`): it takes part in the lockstep and talks through the
/// messages medium, but the world simulates nothing of it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Coordinator {
    /// Its id.
    pub id: String,
    /// Its controller's id.
    pub controller: String,
}

/// A running world.
pub struct World {
    /// The arena state.
    pub arena: Arena,
    scene: Scene,
    leds: LedMedium,
    rab: RabMedium,
    loop_functions: Box<dyn LoopFunctions>,
    scratch: Vec<u32>,
    max_ticks: Option<u64>,
    dead_bodies: DeadBodies,
    /// Gripper events that happened between ticks (a robot killed by a fault), reported with the next tick's.
    pending_gripper_events: Vec<GripperEvent>,
    /// The messages medium, if the run has one.
    mail: Option<MailMedium>,
    /// Every participant's state for the messages medium, refilled each tick.
    participants: Vec<Participant>,
    /// The participants after the robots, which have no body.
    coordinators: Vec<Coordinator>,
    /// What the loop functions send this tick, refilled each tick.
    letters: Vec<Mail>,
    /// What the participants sent the world this tick (for its loop functions).
    to_world: Vec<Mail>,
}

impl World {
    /// Builds the world of a parsed experiment for the run `seed`, with the built-in loop functions.
    pub fn new(experiment: &Experiment, seed: u64) -> Result<World, WorldError> {
        Self::with_registry(experiment, seed, &LoopFunctionsRegistry::default())
    }

    /// Builds the world of a parsed experiment for the run `seed`, with loop functions from `registry`.
    pub fn with_registry(
        experiment: &Experiment,
        seed: u64,
        registry: &LoopFunctionsRegistry,
    ) -> Result<World, WorldError> {
        crate::from_config::build(experiment, seed, registry)
    }

    /// Number of robots.
    pub fn robot_count(&self) -> usize {
        self.arena.robots.len()
    }

    /// Ticks completed.
    pub fn tick(&self) -> u64 {
        self.arena.tick
    }

    /// Stops the experiment after `ticks` ticks (`None`: only the loop functions stop it).
    pub fn set_max_ticks(&mut self, ticks: Option<u64>) {
        self.max_ticks = ticks;
    }

    /// The tick limit (`None`: only the loop functions stop the experiment).
    pub fn max_ticks(&self) -> Option<u64> {
        self.max_ticks
    }

    /// Whether the experiment is over: the tick limit is reached or the loop functions say so.
    pub fn is_finished(&self) -> bool {
        self.max_ticks.is_some_and(|m| self.arena.tick >= m)
            || self.loop_functions.is_finished(&self.arena)
    }

    /// The run's coordinators: participants `robot_count()..` in order.
    pub fn coordinators(&self) -> &[Coordinator] {
        &self.coordinators
    }

    /// Number of participants: the robots, then the coordinators.
    pub fn participant_count(&self) -> usize {
        self.arena.robots.len() + self.coordinators.len()
    }

    /// Whether the run has a messages medium.
    pub fn has_mail(&self) -> bool {
        self.mail.is_some()
    }

    /// Decides the fate of the messages sent in `tick` (`outboxes`, one per sender in participant order) by the
    /// messages medium: `inboxes` (one per participant: the robots, then the participants without a body such
    /// as coordinators) get what each receives in the next tick, `records` every decision. `up` says per
    /// participant whether it takes part; a robot must also be alive in the world. Without a medium nothing is
    /// delivered or recorded.
    pub fn route_mail(
        &mut self,
        tick: u64,
        outboxes: &[Mailbox],
        up: &[bool],
        inboxes: &mut [Mailbox],
        records: &mut Vec<MessageRecord>,
    ) {
        let Some(mail) = &mut self.mail else {
            return;
        };
        let robots = &self.arena.robots;
        self.participants.clear();
        self.participants.extend(up.iter().enumerate().map(
            |(index, &up)| match robots.get(index) {
                Some(robot) => Participant {
                    up: up && robot.alive,
                    position: Some(robot.position),
                },
                None => Participant { up, position: None },
            },
        ));
        mail.route(
            tick,
            outboxes,
            &self.participants,
            inboxes,
            &mut self.to_world,
            records,
        );
        self.loop_functions.read_mail(&self.arena, &self.to_world);
        self.letters.clear();
        self.loop_functions
            .post_mail(&self.arena, &mut self.letters);
        mail.post_letters(tick, &self.letters, &self.participants, inboxes, records);
    }

    /// Lets the loop functions move robots to where the task wants them before the first tick.
    pub fn place_by_loop_functions(&mut self) -> Result<(), WorldError> {
        self.loop_functions.place(&mut self.arena)?;
        self.index_bodies();
        Ok(())
    }

    /// The task metrics of the loop functions.
    pub fn metrics(&self) -> serde_json::Value {
        self.loop_functions.metrics(&self.arena)
    }

    /// The file name, in the run folder, of the loop functions' own per-tick output, if they keep one.
    pub fn loop_output_name(&self) -> Option<&str> {
        self.loop_functions.output_name()
    }

    /// Moves the loop functions' output produced since the last call to the end of `out`.
    pub fn drain_loop_output(&mut self, out: &mut Vec<u8>) {
        self.loop_functions.drain_output(out);
    }

    /// Grey level of the floor at `p` as the ground sensors read it (loop functions first, then floor regions).
    pub fn floor_at(&self, p: Vec2) -> f32 {
        self.loop_functions
            .floor_color(p)
            .unwrap_or_else(|| floor_grey(&self.arena.floor, p))
    }

    /// Sets what becomes of the bodies of robots that die from now on (default: they stay, inert).
    pub fn set_dead_bodies(&mut self, dead_bodies: DeadBodies) {
        self.dead_bodies = dead_bodies;
    }

    /// Marks a robot alive or dead. A dead robot never acts and its LED is off; its body stays as an inert
    /// obstacle or, with [`DeadBodies::Removed`], leaves the arena until the robot is alive again.
    pub fn set_alive(&mut self, robot: RobotId, alive: bool) {
        if !alive {
            // A dead robot's gripper opens; the event belongs to the coming tick's record.
            let before = self.arena.gripper_events.len();
            crate::gripper::release(&mut self.arena, robot, ReleaseCause::Died);
            self.pending_gripper_events
                .extend(self.arena.gripper_events.drain(before..));
        }
        let Some(r) = self
            .arena
            .robots
            .get_mut(robot.index())
            .filter(|r| r.present)
        else {
            return;
        };
        r.alive = alive;
        if !alive {
            r.led = swarm_contract::messages::Rgb::OFF;
            r.beacon = swarm_contract::messages::Rgb::OFF;
            r.wheels = [0.0; 2];
            self.arena.physics.drive(r.handles.body, 0.0, 0.0);
        }
        let removed = !alive && self.dead_bodies == DeadBodies::Removed;
        if r.removed != removed {
            r.removed = removed;
            self.arena.physics.set_enabled(r.handles, !removed);
        }
        // The next frames must already see the arena without (or with) the body, and its LEDs off (or on).
        self.index_bodies();
    }

    /// Rebuilds the scene's and the LED medium's indexes from the arena's bodies.
    fn index_bodies(&mut self) {
        self.scene.rebuild(
            &self.arena.robots,
            &self.arena.obstacles,
            &self.arena.targets,
        );
        self.leds
            .rebuild(&self.arena.robots, &self.arena.targets, &self.arena.lights);
    }

    /// Takes `robot` out of the arena: it is not in the run (before it joins, or after it left). Its body
    /// collides with nothing, no sensor sees it, and its gripper lets go.
    pub fn park(&mut self, robot: RobotId) {
        self.set_alive(robot, false);
        let Some(r) = self.arena.robots.get_mut(robot.index()) else {
            return;
        };
        r.present = false;
        r.removed = true;
        self.arena.physics.set_enabled(r.handles, false);
        self.index_bodies();
    }

    /// Brings the absent `robot` into the arena at `wanted` (position and heading; default: the pose the
    /// configuration gave it), or at the nearest free pose (see `arrivals`); returns where it is.
    pub fn join(
        &mut self,
        robot: RobotId,
        wanted: Option<(Vec2, f32)>,
    ) -> Result<(Vec2, f32), crate::arrivals::PlaceRefused> {
        let refused = |why: &str| Err(crate::arrivals::PlaceRefused(why.to_owned()));
        let Some(r) = self.arena.robots.get(robot.index()) else {
            return refused("no such robot");
        };
        if r.present {
            return refused("it is in the arena already");
        }
        let (position, heading) = wanted.unwrap_or((r.position, r.heading));
        let pose =
            crate::arrivals::free_pose(&self.arena, robot, position, heading, r.body.radius)?;
        let r = &mut self.arena.robots[robot.index()];
        r.present = true;
        r.removed = false;
        r.position = pose.0;
        r.heading = pose.1;
        r.wheels = [0.0; 2];
        self.arena.physics.teleport(r.handles.body, pose.0, pose.1);
        self.arena.physics.set_enabled(r.handles, true);
        self.set_alive(robot, true);
        Ok(pose)
    }

    /// Fills every robot's frame for the coming tick (`frames[i]` for robot i; extra frames are left alone).
    pub fn sense(&mut self, frames: &mut [SensorFrame]) {
        self.sense_robots(0, frames);
    }

    /// Fills the frames of robots `first..` for the coming tick (`frames[i]` for robot `first + i`; frames
    /// past the last robot are left alone). A robot's frame depends on the world's state and its own sensor
    /// noise streams only, so sensing the robots in parts, in any order, gives the frames [`World::sense`]
    /// gives.
    pub fn sense_robots(&mut self, first: usize, frames: &mut [SensorFrame]) {
        let tick = self.arena.tick + 1;
        let arena = &mut self.arena;
        let floor = |p: Vec2| {
            self.loop_functions
                .floor_color(p)
                .unwrap_or_else(|| floor_grey(&arena.floor, p))
        };
        let robots = arena.robots.iter_mut().skip(first);
        for (me, (robot, frame)) in (first as u32..).zip(robots.zip(frames.iter_mut())) {
            if !robot.alive {
                // A dead robot senses nothing; its frame only says so.
                *frame = SensorFrame::empty(me);
                frame.alive = 0;
            }
            frame.tick = tick;
            frame.robot = me;
            frame.gripper_holding = match robot.gripper.holding {
                Some(grip) if arena.obstacles[grip.obstacle.index()].lifted => 2,
                Some(_) => 1,
                None => u8::from(robot.carrying.is_some() || robot.holds_item),
            };
            frame.held_object = robot.gripper.holding.map_or(0, |g| g.obstacle.0 + 1);
            frame.position = [robot.position.x, robot.position.y];
            frame.heading = robot.heading;
            if !robot.alive {
                continue;
            }
            frame.alive = 1;
            frame.camera_len = 0;
            frame.rab_len = 0;
            let (pos, heading, body) = (robot.position, robot.heading, &robot.body);
            let observer = Observer {
                me,
                position: pos,
                heading,
                body,
            };
            let devices = robot.devices;
            if let Some(opts) = &devices.proximity {
                let n = body.proximity_angles_deg.len();
                frame.proximity_len = n as u8;
                proximity::sense(
                    &self.scene,
                    observer,
                    opts,
                    &mut robot.rng.proximity,
                    &mut self.scratch,
                    &mut frame.proximity[..n],
                );
            }
            if let Some(level) = devices.light {
                let n = body.light_angles_deg.len();
                frame.light_len = n as u8;
                light::sense(
                    &self.scene,
                    &arena.lights,
                    observer,
                    level,
                    &mut robot.rng.light,
                    &mut frame.light[..n],
                );
            }
            if let Some(level) = devices.ground {
                let n = body.ground_offsets.len();
                frame.ground_len = n as u8;
                ground::sense(
                    observer,
                    floor,
                    level,
                    &mut robot.rng.ground,
                    &mut frame.ground[..n],
                );
            }
            if let Some(opts) = &devices.range_finder {
                let n = usize::from(opts.rays);
                frame.ranges_len = opts.rays;
                range_finder::sense(
                    &self.scene,
                    observer,
                    opts,
                    &mut robot.rng.range_finder,
                    &mut self.scratch,
                    &mut frame.ranges[..n],
                );
            }
            if devices.distance_scanner {
                distance_scanner::sense(
                    &self.scene,
                    observer,
                    &mut robot.scanner,
                    &mut self.scratch,
                    frame,
                );
            }
            if let Some(opts) = &devices.camera {
                camera::sense(
                    &self.scene,
                    &self.leds,
                    observer,
                    opts,
                    &mut robot.rng.camera,
                    frame,
                );
            }
            if let Some(opts) = &devices.rab {
                rab::sense(
                    &self.scene,
                    &self.rab,
                    observer,
                    opts,
                    &mut robot.rng.rab,
                    frame,
                );
            }
            let (s, c) = heading.sin_cos();
            for ch in 0..PHEROMONE_CHANNELS {
                frame.pheromone[ch] = arena.pheromone.concentration(ch, pos);
                let g = arena.pheromone.gradient(ch, pos);
                frame.pheromone_gradient[ch] = [c * g.x + s * g.y, -s * g.x + c * g.y];
            }
        }
    }

    /// Applies this tick's commands (robots without one, and dead robots, hold still), then steps physics, media
    /// and the loop functions. `commands[i]` and `has_command[i]` belong to robot i.
    pub fn act_and_step(&mut self, commands: &[ActuatorCommand], has_command: &[bool]) {
        self.arena.tick += 1;
        self.arena.gripper_events.clear();
        self.arena
            .gripper_events
            .append(&mut self.pending_gripper_events);
        self.loop_functions.pre_step(&mut self.arena);
        self.rab.clear();
        for i in 0..self.arena.robots.len() {
            let cmd = commands
                .get(i)
                .filter(|_| has_command.get(i).copied().unwrap_or(false));
            actuators::apply(&mut self.arena, &mut self.rab, RobotId(i as u32), cmd);
        }
        self.step_physics();
        self.update_media();
        self.loop_functions
            .post_step(&mut self.arena, commands, has_command);
    }

    fn step_physics(&mut self) {
        let arena = &mut self.arena;
        for &(a, b) in arena.physics.step() {
            for tag in [a, b] {
                if tag >> 32 == TAG_ROBOT >> 32
                    && let Some(r) = arena.robots.get_mut((tag & 0xffff_ffff) as usize)
                {
                    r.collisions += 1;
                }
            }
        }
        for r in &mut arena.robots {
            (r.position, r.heading) = arena.physics.pose(r.handles.body);
        }
        crate::gripper::update(arena);
        for o in arena
            .obstacles
            .iter_mut()
            .filter(|o| matches!(o.motion, Motion::Movable { .. }))
        {
            let (position, angle) = arena.physics.pose(o.handles.body);
            o.placed.set_pose(position, angle);
        }
        actuators::carry(arena);
    }

    fn update_media(&mut self) {
        self.index_bodies();
        self.rab.commit(&self.arena.robots);
        self.arena.pheromone.step();
    }

    /// Runs `ticks` ticks with an in-process controller called once per live robot per tick (tests and benches).
    /// Each robot's command persists between ticks, like a real actuator's last setting.
    pub fn run_in_process(
        &mut self,
        ticks: u64,
        mut controller: impl FnMut(&SensorFrame, &mut ActuatorCommand),
    ) {
        let n = self.robot_count();
        let mut frames: Vec<SensorFrame> = (0..n as u32).map(SensorFrame::empty).collect();
        let mut commands: Vec<ActuatorCommand> =
            (0..n as u32).map(|r| ActuatorCommand::idle(r, 0)).collect();
        let mut has_command = vec![false; n];
        for _ in 0..ticks {
            self.sense(&mut frames);
            for ((frame, cmd), has) in frames
                .iter()
                .zip(commands.iter_mut())
                .zip(has_command.iter_mut())
            {
                *has = frame.alive != 0;
                if *has {
                    cmd.tick = frame.tick;
                    controller(frame, cmd);
                }
            }
            self.act_and_step(&commands, &has_command);
        }
    }
}
