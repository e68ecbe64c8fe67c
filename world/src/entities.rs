//! The typed sets of things in the arena: robots, obstacles, targets, lights and floor regions.
//!
//! Each set is a plain `Vec` addressed by a typed index handle (rapier-style arenas without removal: entities
//! that leave the arena change state instead of disappearing, so handles stay valid for the whole run). Systems
//! (sensors, actuators, media, loop functions) are functions over these sets; no entity points at another.

use swarm_contract::bodies::{BodyModel, EPUCK};
use swarm_contract::messages::Rgb;

use crate::devices::Devices;
use crate::geometry::{Placed, Shape, Vec2};
use crate::gripper::GripperState;
use crate::physics::{BodyHandles, Motion};
use crate::rng::RobotStreams;
use crate::sensors::distance_scanner::ScannerState;

/// e-puck body radius in metres (docs/epuck-and-world.md 1.1); other bodies are in `swarm_contract::bodies`.
pub const ROBOT_RADIUS: f32 = EPUCK.radius;

macro_rules! handle {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(pub u32);

        impl $name {
            /// The index into its set.
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}

handle!(
    /// Index of a robot; equal to `SensorFrame::robot` and to the robot's place in the run.
    RobotId
);
handle!(
    /// Index of an obstacle (wall, box, cylinder).
    ObstacleId
);
handle!(
    /// Index of a target (a passive object with an LED that the gripper can carry).
    TargetId
);
handle!(
    /// Index of a light source.
    LightId
);

/// One robot.
#[derive(Debug)]
pub struct Robot {
    /// The id from the configuration (`fb0`, `ep12`, ...).
    pub name: String,
    /// Its body: shape, wheels and sensor placement (with the configuration's changes: a disc robot's
    /// attributes, a foot-bot's camera aperture).
    pub body: BodyModel,
    /// The controller id the configuration assigns.
    pub controller: String,
    /// Physics handles.
    pub handles: BodyHandles,
    /// Position of the point between the wheels, after the last physics step.
    pub position: Vec2,
    /// Heading in radians, counter-clockwise from +X.
    pub heading: f32,
    /// LED colour (off when dead).
    pub led: Rgb,
    /// Beacon LED colour, for a body with a beacon (off when dead).
    pub beacon: Rgb,
    /// Whether the robot is alive; a dead robot is an inert obstacle (or removed).
    pub alive: bool,
    /// Whether its dead body has left the arena (`<faults dead_bodies="removed">`), or the robot is not in the
    /// arena at all (see `present`): it collides with nothing and no sensor sees it.
    pub removed: bool,
    /// Whether the robot is in the run: false before it joins (`join_tick`, `join_time`, `spare`) and after it
    /// left (`swarm ctl remove`). An absent robot is removed and not alive, whatever the faults do.
    pub present: bool,
    /// Wheel speeds applied in the last tick, in cm/s, after clamping and noise.
    pub wheels: [f32; 2],
    /// The target the virtual gripper carries.
    pub carrying: Option<TargetId>,
    /// The physical gripper and turret (used when the controller declares `footbot_gripper`).
    pub gripper: GripperState,
    /// The distance scanner's mode and turret angle.
    pub scanner: ScannerState,
    /// Whether the loop functions gave it an item that is no body in the arena (ARGoS' foraging example's
    /// food); the frame's `gripper_holding` reports it like a carried target.
    pub holds_item: bool,
    /// Contacts with any body that started since the run began.
    pub collisions: u64,
    /// Range of the robot's range-and-bearing emitter in metres.
    pub rab_range: f32,
    /// The sensors and actuators its controller declares.
    pub devices: Devices,
    /// Its random streams.
    pub rng: RobotStreams,
}

/// A wall, box or cylinder.
#[derive(Debug)]
pub struct Obstacle {
    /// The id from the configuration.
    pub name: String,
    /// Outline and current pose.
    pub placed: Placed,
    /// Height in metres.
    pub height: f32,
    /// Fixed or movable.
    pub motion: Motion,
    /// How many robots' grippers lift it off the ground (`lift_by`), if it can be lifted.
    pub lift_by: Option<u32>,
    /// Whether it is lifted now: held by at least `lift_by` grippers, it slides without ground friction.
    pub lifted: bool,
    /// Physics handles.
    pub handles: BodyHandles,
}

/// Where a target is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetState {
    /// Lying in the arena, a body that robots sense and bump into.
    InArena,
    /// Riding on a robot's virtual gripper, out of the arena.
    Carried(RobotId),
    /// Taken out of the run (e.g. delivered home) by the loop functions.
    Removed,
}

/// A passive object carrying an LED (foraging food).
#[derive(Debug)]
pub struct Target {
    /// The id from the configuration.
    pub name: String,
    /// Outline and pose (the pose of the carrier while carried).
    pub placed: Placed,
    /// Body height in metres.
    pub height: f32,
    /// LED colour.
    pub led: Rgb,
    /// LED height above the ground in metres.
    pub led_height: f32,
    /// Where it is.
    pub state: TargetState,
    /// Physics handles (the collider is disabled while the target is not in the arena).
    pub handles: BodyHandles,
}

impl Target {
    /// The target's radius as the gripper sees it (bounding radius for boxes).
    pub fn radius(&self) -> f32 {
        match self.placed.shape {
            Shape::Disc { radius } => radius,
            Shape::Rect { half } => half.length(),
        }
    }
}

/// A light source (read by the light sensors).
#[derive(Debug, Clone)]
pub struct Light {
    /// The id from the configuration.
    pub name: String,
    /// Position on the ground plane.
    pub position: Vec2,
    /// Height above the ground in metres.
    pub height: f32,
    /// Intensity (the IRIDIA light model's scale in metres).
    pub intensity: f32,
    /// Colour; a light that is off does not shine.
    pub color: Rgb,
}

/// A rectangle of floor with a grey level (1 white, 0 black), read by the ground sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorRegion {
    /// Lower corner.
    pub min: Vec2,
    /// Upper corner.
    pub max: Vec2,
    /// Grey level in [0, 1].
    pub grey: f32,
}

impl FloorRegion {
    /// Whether `p` lies in the region (edges included).
    pub fn contains(&self, p: Vec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }
}

/// Grey level at `p` of the floor made of `regions` (later regions drawn over earlier ones; white elsewhere).
pub fn floor_grey(regions: &[FloorRegion], p: Vec2) -> f32 {
    regions
        .iter()
        .rev()
        .find(|r| r.contains(p))
        .map_or(1.0, |r| r.grey)
}
