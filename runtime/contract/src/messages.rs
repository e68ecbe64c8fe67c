//! The message contract between the world and the robot agents.
//!
//! Both types are fixed-size `#[repr(C)]` plain data so that they travel through iceoryx2 shared memory without
//! serialisation. The world writes one [`SensorFrame`] per robot per tick and reads one [`ActuatorCommand`] per robot
//! per tick. A controller sees nothing of the world except what is in the frame (ARGoS' control-interface wall):
//! if a callback needs something new, it is added here, not passed through a side channel.
//!
//! Capacities are compile-time constants because shared-memory layouts must be identical in every process; they
//! are sized for the largest body (`crate::bodies`: the foot-bot's 24-sensor rings) and the thesis' tasks, and a
//! length field says how many entries a robot's body fills. Any change to a layout must bump [`MESSAGE_VERSION`],
//! which is part of every service name, so processes built from different versions never connect.
//!
//! Across hosts the same types travel bincode-encoded (`Encode`/`Decode`, field by field, little-endian), never
//! as raw memory, so hosts of different architectures interoperate (see `remote::codec`); frames and commands
//! leave out the unused ends of their arrays (`crate::compact_encoding`).

use bincode::{Decode, Encode};
use iceoryx2::prelude::ZeroCopySend;

/// Layout version of [`SensorFrame`] and [`ActuatorCommand`]; part of every service name.
pub const MESSAGE_VERSION: u32 = 10;

/// Most proximity sensors a body has (the foot-bot's 24; the e-puck has 8).
pub const MAX_PROXIMITY_SENSORS: usize = 24;
/// Most light sensors a body has (the foot-bot's 24; the e-puck has 8).
pub const MAX_LIGHT_SENSORS: usize = 24;
/// Most ground sensors a body has (the foot-bot's four motor-ground sensors; the e-puck has 3).
pub const MAX_GROUND_SENSORS: usize = 4;
/// Most rays of a range-finder ring (paper A's robots use 20, 18 degrees apart).
pub const MAX_RANGE_RAYS: usize = 24;
/// Longest range-finder reach a configuration may give, in metres (`<range_finder range>`, `range_finder_range`).
pub const MAX_RANGE_FINDER_RANGE: f64 = 100.0;
/// Most LED blobs the omnidirectional camera reports per tick; further blobs (farthest first) are dropped.
pub const MAX_CAMERA_BLOBS: usize = 16;
/// Most range-and-bearing messages a robot receives per tick; further messages (farthest first) are dropped.
pub const MAX_RAB_MESSAGES: usize = 16;
/// Largest range-and-bearing payload, in bytes (the IRIDIA e-puck's maximum, for every body: each byte here is
/// 16 bytes of every robot's frame in every tick; longer messages between robots are a medium of their own).
pub const RAB_PAYLOAD_BYTES: usize = 4;
/// Number of pheromone channels in the world's field (e.g. trail and home).
pub const PHEROMONE_CHANNELS: usize = 2;
/// Most supervisors one robot may run.
pub const MAX_SUPERVISORS: usize = 16;
/// Most self-loop timer stamps a command can carry (docs/ptsct.md section 3).
pub const MAX_FIRED_STAMPS: usize = 32;
/// Most events one robot can fire in one tick (uncontrollable ones plus at most one controllable).
pub const MAX_EVENTS_PER_TICK: usize = 16;

/// An RGB colour, as LEDs show it and cameras see it. All zero means off.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub struct Rgb {
    /// Red, 0-255.
    pub r: u8,
    /// Green, 0-255.
    pub g: u8,
    /// Blue, 0-255.
    pub b: u8,
}

impl Rgb {
    /// LEDs off.
    pub const OFF: Rgb = Rgb { r: 0, g: 0, b: 0 };

    /// Whether the LED is lit.
    pub fn is_on(self) -> bool {
        self != Self::OFF
    }
}

/// One LED blob seen by the omnidirectional camera.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub struct CameraBlob {
    /// Colour of the LED.
    pub color: Rgb,
    /// Bearing in radians in the robot frame, in [-pi, pi], counter-clockwise from the heading.
    pub bearing: f32,
    /// Distance from the robot centre in cm (the IRIDIA convention).
    pub distance_cm: f32,
}

/// One range-and-bearing message received this tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub struct RabMessage {
    /// Index of the sending robot in the run.
    pub sender: u32,
    /// Payload; only the first `len` bytes are meaningful.
    pub payload: [u8; RAB_PAYLOAD_BYTES],
    /// Number of meaningful payload bytes.
    pub len: u8,
    /// Range in cm minus two body radii (the IRIDIA convention).
    pub range_cm: f32,
    /// Bearing in radians in the receiver's frame, in [-pi, pi].
    pub bearing: f32,
}

/// Everything one robot senses in one tick. Written by the world, read by the robot's agent.
// Encode and Decode: crate::compact_encoding.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
pub struct SensorFrame {
    /// Tick this frame belongs to (1 for the first tick).
    pub tick: u64,
    /// Index of the robot in the run (0..N).
    pub robot: u32,
    /// What the physical gripper holds: 1 + the object's index among the arena's boxes and cylinders in
    /// configuration order (`summary.json`'s `movable_objects` give each one's `index`); 0 when it holds nothing.
    pub held_object: u32,
    /// Non-zero while the robot is alive in the world.
    pub alive: u8,
    /// Non-zero while the robot holds something: 1 a target of the virtual gripper, an object of the physical
    /// gripper or an item the loop functions gave it; 2 an object of the physical gripper that is lifted.
    pub gripper_holding: u8,
    /// Number of valid entries in `proximity` (the body's sensor count; 0 when the sensor is not declared).
    pub proximity_len: u8,
    /// Number of valid entries in `light`.
    pub light_len: u8,
    /// Number of valid entries in `ground`.
    pub ground_len: u8,
    /// Number of valid entries in `ranges` (the range finder's ray count; 0 when it is not declared).
    pub ranges_len: u8,
    /// Number of valid entries in `camera`.
    pub camera_len: u8,
    /// Number of valid entries in `rab`.
    pub rab_len: u8,
    /// Number of messages waiting in the robot's inbox this tick (`crate::mail`; 0: the agent need not look).
    pub inbox_len: u8,
    /// Proximity readings in [0, 1] (0 nothing, 1 touching), sensor i at the body's i-th proximity angle
    /// (`crate::bodies::BodyModel::proximity_angles_deg`).
    pub proximity: [f32; MAX_PROXIMITY_SENSORS],
    /// Light readings in [0, 1], sensor i at the body's i-th light angle.
    pub light: [f32; MAX_LIGHT_SENSORS],
    /// Ground readings in [0, 1] (1 white, 0 black), in the body's ground-sensor order (e-puck: index 0 is the
    /// left sensor).
    pub ground: [f32; MAX_GROUND_SENSORS],
    /// Range-finder readings: metres from the body centre to the nearest body along ray i (ray i at
    /// `360 i / ranges_len` degrees counter-clockwise from the heading), or infinity when nothing is within range.
    /// The foot-bot's distance scanner fills them instead: see `scan_start`.
    pub ranges: [f32; MAX_RANGE_RAYS],
    /// For the foot-bot's distance scanner: the angle in radians (from the heading) of its first ray's first
    /// reading. Its four rays point `scan_start + k pi/2` (k = 0..3; rays 0 and 2 short-range, 1 and 3
    /// long-range); `ranges` holds them ray by ray, each ray `ranges_len / 4` readings spread over `scan_span`
    /// radians (the turn since the last tick; 0 when it does not rotate). A reading is metres from the body
    /// centre, 0 when a body is closer than the ray's minimum distance, infinity when nothing is in reach.
    pub scan_start: f32,
    /// See `scan_start`.
    pub scan_span: f32,
    /// LED blobs seen by the omnidirectional camera, nearest first.
    pub camera: [CameraBlob; MAX_CAMERA_BLOBS],
    /// Range-and-bearing messages received, nearest first.
    pub rab: [RabMessage; MAX_RAB_MESSAGES],
    /// Pheromone concentration at the robot's position, per channel.
    pub pheromone: [f32; PHEROMONE_CHANNELS],
    /// Pheromone gradient (d/dx, d/dy) in the robot frame, per channel.
    pub pheromone_gradient: [[f32; 2]; PHEROMONE_CHANNELS],
    /// Position in metres in the arena frame (the `positioning` sensor; controllers may ignore it).
    pub position: [f32; 2],
    /// Heading in radians, counter-clockwise from +X (the `positioning` sensor).
    pub heading: f32,
}

impl SensorFrame {
    /// An empty frame for `robot`: nothing sensed, alive, all ground sensors on white floor.
    pub fn empty(robot: u32) -> Self {
        Self {
            tick: 0,
            robot,
            held_object: 0,
            alive: 1,
            gripper_holding: 0,
            proximity_len: 0,
            proximity: [0.0; MAX_PROXIMITY_SENSORS],
            light_len: 0,
            light: [0.0; MAX_LIGHT_SENSORS],
            ground_len: 0,
            ground: [1.0; MAX_GROUND_SENSORS],
            ranges_len: 0,
            ranges: [f32::INFINITY; MAX_RANGE_RAYS],
            scan_start: 0.0,
            scan_span: 0.0,
            camera_len: 0,
            camera: [CameraBlob::default(); MAX_CAMERA_BLOBS],
            rab_len: 0,
            rab: [RabMessage::default(); MAX_RAB_MESSAGES],
            inbox_len: 0,
            pheromone: [0.0; PHEROMONE_CHANNELS],
            pheromone_gradient: [[0.0; 2]; PHEROMONE_CHANNELS],
            position: [0.0; 2],
            heading: 0.0,
        }
    }

    /// Fills `frames`, the frames of robots `first..`, for `tick` with `sense(tick, first, frames)`: each
    /// starts as [`SensorFrame::empty`] with the tick, and its `tick` and `robot` are enforced afterwards, so
    /// a sense function can neither misdate a frame nor move it to another robot.
    pub fn sense_into(
        tick: u64,
        first: usize,
        frames: &mut [SensorFrame],
        sense: &mut impl FnMut(u64, usize, &mut [SensorFrame]),
    ) {
        for (robot, frame) in (first as u32..).zip(frames.iter_mut()) {
            *frame = SensorFrame::empty(robot);
            frame.tick = tick;
        }
        sense(tick, first, frames);
        for (robot, frame) in (first as u32..).zip(frames.iter_mut()) {
            frame.tick = tick;
            frame.robot = robot;
        }
    }

    /// The valid proximity readings.
    pub fn proximity_readings(&self) -> &[f32] {
        &self.proximity[..usize::from(self.proximity_len).min(MAX_PROXIMITY_SENSORS)]
    }

    /// The valid light readings.
    pub fn light_readings(&self) -> &[f32] {
        &self.light[..usize::from(self.light_len).min(MAX_LIGHT_SENSORS)]
    }

    /// The valid ground readings.
    pub fn ground_readings(&self) -> &[f32] {
        &self.ground[..usize::from(self.ground_len).min(MAX_GROUND_SENSORS)]
    }

    /// The valid range-finder readings.
    pub fn range_readings(&self) -> &[f32] {
        &self.ranges[..usize::from(self.ranges_len).min(MAX_RANGE_RAYS)]
    }

    /// The valid camera blobs.
    pub fn camera_blobs(&self) -> &[CameraBlob] {
        &self.camera[..usize::from(self.camera_len).min(MAX_CAMERA_BLOBS)]
    }

    /// The valid range-and-bearing messages.
    pub fn rab_messages(&self) -> &[RabMessage] {
        &self.rab[..usize::from(self.rab_len).min(MAX_RAB_MESSAGES)]
    }
}

/// How the wheels are commanded this tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub enum Drive {
    /// Left and right wheel speeds in cm/s (`ActuatorCommand::wheels`), each clamped to the body's limit.
    #[default]
    Wheels = 0,
    /// Forward speed in m/s and turn rate in rad/s (`ActuatorCommand::twist`), each clamped to the body's limit
    /// (as a TurtleBot's `cmd_vel`).
    Twist = 1,
}

/// What the foot-bot's distance scanner does (ARGoS' `Disable`, `SetAngle`/`Enable`, `SetRPM`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub enum Scanner {
    /// Off: no readings.
    #[default]
    Off = 0,
    /// Held at the angle `scanner_setting` (radians from the heading): four readings per tick.
    Angle = 1,
    /// Turning at `scanner_setting` revolutions per minute: 24 readings per tick over the angle swept.
    Speed = 2,
}

/// How the foot-bot's turret moves (ARGoS' turret modes).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub enum Turret {
    /// Turned to `turret` radians from the heading.
    #[default]
    Position = 0,
    /// Turning at `turret` radians per second (0 holds it where it is).
    Speed = 1,
    /// Free: it turns wherever a held object pulls it.
    Passive = 2,
}

/// What the virtual gripper should do this tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub enum GripperAction {
    /// Keep the current state.
    #[default]
    Hold = 0,
    /// Pick up the nearest target within reach (edge-to-edge gap at most 7 mm).
    Pick = 1,
    /// Drop the carried target at the robot's position.
    Drop = 2,
}

/// The tick at which a controllable self-loop last fired in its supervisor's current state (docs/ptsct.md section 3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, Encode, Decode)]
#[repr(C)]
pub struct FiredStamp {
    /// Index of the supervisor in the robot's supervisor set.
    pub supervisor: u8,
    /// Global event id.
    pub event: u8,
    /// Tick of the last firing.
    pub tick: u64,
}

/// The state of a robot's supervisors after a player step: enough to record and to resume them exactly.
// Encode and Decode: crate::compact_encoding.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
pub struct SupervisorSnapshot {
    /// Number of supervisors in use.
    pub count: u8,
    /// Current state of each supervisor.
    pub states: [u16; MAX_SUPERVISORS],
    /// Tick at which each supervisor entered its current state.
    pub entered: [u64; MAX_SUPERVISORS],
    /// Number of valid entries in `fired`.
    pub fired_len: u8,
    /// Self-loop timer stamps of the current states.
    pub fired: [FiredStamp; MAX_FIRED_STAMPS],
}

impl Default for SupervisorSnapshot {
    fn default() -> Self {
        Self {
            count: 0,
            states: [0; MAX_SUPERVISORS],
            entered: [0; MAX_SUPERVISORS],
            fired_len: 0,
            fired: [FiredStamp::default(); MAX_FIRED_STAMPS],
        }
    }
}

/// Everything one robot commands in one tick, plus what it did. Written by the agent, read by the world.
// Encode and Decode: crate::compact_encoding.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
pub struct ActuatorCommand {
    /// Tick this command answers (equal to the frame's tick).
    pub tick: u64,
    /// Index of the robot in the run.
    pub robot: u32,
    /// Which of `wheels` and `twist` drives the robot.
    pub drive: Drive,
    /// Left and right wheel speeds in cm/s (the world clamps them to the robot's limit).
    pub wheels: [f32; 2],
    /// Forward speed in m/s and turn rate in rad/s, counter-clockwise positive (used when `drive` is `Twist`).
    pub twist: [f32; 2],
    /// LED colour (the e-puck's LEDs; the foot-bot's ring of 12, which ARGoS' `SetAllColors` also sets).
    pub led: Rgb,
    /// The foot-bot's beacon LED on its turret (ARGoS' LED 12); ignored by bodies without one.
    pub beacon: Rgb,
    /// Number of range-and-bearing payload bytes to broadcast this tick (0 = send nothing).
    pub rab_len: u8,
    /// Range-and-bearing payload.
    pub rab_payload: [u8; RAB_PAYLOAD_BYTES],
    /// Number of messages the robot put in its outbox this tick (`crate::mail`; 0: the world need not look).
    pub outbox_len: u8,
    /// Gripper action: for the virtual gripper, pick or drop a target; for the foot-bot's physical gripper,
    /// `Pick` locks it (it grips what comes within reach) and `Drop` unlocks it.
    pub gripper: GripperAction,
    /// How the foot-bot's turret moves.
    pub turret_mode: Turret,
    /// The turret's angle in radians, counter-clockwise from the heading (`Turret::Position`: where the gripper
    /// faces), or its speed in radians per second (`Turret::Speed`).
    pub turret: f32,
    /// The foot-bot distance scanner's mode.
    pub scanner: Scanner,
    /// Its angle in radians (`Scanner::Angle`) or speed in revolutions per minute (`Scanner::Speed`).
    pub scanner_setting: f32,
    /// Amount of pheromone to deposit at the robot's position, per channel.
    pub pheromone_deposit: [f32; PHEROMONE_CHANNELS],
    /// Number of valid entries in `events`.
    pub events_len: u8,
    /// Global ids of the events fired this tick, in firing order (for `events.csv`).
    pub events: [u8; MAX_EVENTS_PER_TICK],
    /// Supervisor states and timers after this tick's step.
    pub supervisors: SupervisorSnapshot,
}

impl ActuatorCommand {
    /// Commands forward speed `v` (m/s) and turn rate `w` (rad/s) instead of wheel speeds.
    pub fn set_twist(&mut self, v: f32, w: f32) {
        self.drive = Drive::Twist;
        self.twist = [v, w];
    }

    /// The command of a robot that does nothing: wheels stopped, LEDs off.
    pub fn idle(robot: u32, tick: u64) -> Self {
        Self {
            tick,
            robot,
            drive: Drive::Wheels,
            wheels: [0.0; 2],
            twist: [0.0; 2],
            led: Rgb::OFF,
            beacon: Rgb::OFF,
            rab_len: 0,
            rab_payload: [0; RAB_PAYLOAD_BYTES],
            outbox_len: 0,
            gripper: GripperAction::Hold,
            turret_mode: Turret::Position,
            turret: 0.0,
            scanner: Scanner::Off,
            scanner_setting: 0.0,
            pheromone_deposit: [0.0; PHEROMONE_CHANNELS],
            events_len: 0,
            events: [0; MAX_EVENTS_PER_TICK],
            supervisors: SupervisorSnapshot::default(),
        }
    }

    /// The events fired this tick.
    pub fn fired_events(&self) -> &[u8] {
        &self.events[..usize::from(self.events_len).min(MAX_EVENTS_PER_TICK)]
    }
}
