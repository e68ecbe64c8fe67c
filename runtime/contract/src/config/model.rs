//! The typed model of a parsed `.argos` experiment.
//!
//! Plain data: every value has been parsed and checked by the parser, so the world and the launcher build from it
//! without re-reading XML. Every item carries the [`Location`] of the element it came from (the file path is stored
//! once, in [`Experiment::path`]), so later semantic errors such as a failed placement can still be reported as
//! `file:line:column: message` through [`Experiment::diagnostic`]. Units are SI (metres, seconds) unless a field
//! says otherwise; orientations are kept in degrees as written and converted by accessors.
//!
//! This module must never read files or depend on the world: it is the contract between the parser and its users.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::bodies::{BodyModel, RobotKind};
use crate::messages::Rgb;

use super::diagnostic::Diagnostic;

/// A position in the configuration file: 1-based line and column (in characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Location {
    /// 1-based line number.
    pub line: u32,
    /// 1-based column number, counted in characters.
    pub column: u32,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// A 3-D vector in metres, written `"x,y,z"` in the configuration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vec3 {
    /// X component.
    pub x: f64,
    /// Y component.
    pub y: f64,
    /// Z component (height).
    pub z: f64,
}

impl Vec3 {
    /// Builds a vector from its components.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

impl fmt::Display for Vec3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", self.x, self.y, self.z)
    }
}

/// A 2-D vector in metres, written `"x,y"` in the configuration (used by floor regions).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vec2 {
    /// X component.
    pub x: f64,
    /// Y component.
    pub y: f64,
}

impl fmt::Display for Vec2 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{}", self.x, self.y)
    }
}

/// An orientation as ARGoS writes it: Euler angles in **degrees**, in the order Z, Y, X (`"90,0,0"` is a quarter
/// turn about the vertical axis). Only Z matters in our 2-D world.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Euler {
    /// Rotation about the vertical axis, degrees, counter-clockwise.
    pub z_deg: f64,
    /// Rotation about Y, degrees (ignored in 2-D).
    pub y_deg: f64,
    /// Rotation about X, degrees (ignored in 2-D).
    pub x_deg: f64,
}

impl Euler {
    /// The heading in radians (rotation about the vertical axis), the only angle a 2-D world uses.
    pub fn yaw_radians(&self) -> f64 {
        self.z_deg.to_radians()
    }
}

/// Where an entity stands: the `<body position=".." orientation=".."/>` of an entity (or the `position` and
/// `orientation` attributes of a `<light>`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Pose {
    /// Position in metres; for robots the ground point midway between the wheels.
    pub position: Vec3,
    /// Orientation, Euler Z,Y,X in degrees.
    pub orientation: Euler,
}

/// The root of a parsed experiment (`<argos-configuration>`).
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// The configuration file this experiment was read from; relative paths inside it are relative to its folder.
    pub path: PathBuf,
    /// `<framework>`: threads, length, tick rate, seed.
    pub framework: Framework,
    /// `<controllers>`: the controller types robots refer to, in file order.
    pub controllers: Vec<Controller>,
    /// `<loop_functions>`, if present.
    pub loop_functions: Option<LoopFunctions>,
    /// `<arena>`: size, floor, hand-placed entities and distributions.
    pub arena: Arena,
    /// `<physics_engines>`: the one `dynamics2d` engine the world runs.
    pub physics_engine: PhysicsEngine,
    /// `<media>`: LED, range-and-bearing and pheromone media.
    pub media: Media,
    /// `<coordinators>` (our extension): processes of the run that are not robots, in file order.
    pub coordinators: Vec<Coordinator>,
    /// `<faults>`: the fault schedule and restart rules the configuration itself gives (empty without the
    /// section); a run adds `--fault` texts with [`FaultSchedule::for_run`](super::faults::FaultSchedule::for_run).
    pub faults: super::faults::FaultSchedule,
}

/// `<coordinator id>` with `<controller config>`: a process of the run without a body, e.g. a central store or an
/// allocator. It runs its controller in lockstep with the world like a robot's agent, talks to robots through
/// the `<messages>` medium, and faults apply to it (docs/messages.md).
#[derive(Debug, Clone, PartialEq)]
pub struct Coordinator {
    /// `id`, unique among robots and coordinators.
    pub id: String,
    /// The controller's id in `<controllers>`.
    pub controller: String,
    /// Where the element is.
    pub location: Location,
}

/// A process of a run that takes part in the lockstep: a robot, or a coordinator.
#[derive(Debug, Clone, PartialEq)]
pub struct Participant<'a> {
    /// Its index in the run: the robots first (`Arena::robots` order), then the coordinators in file order.
    pub index: u32,
    /// Its id.
    pub id: String,
    /// Its controller's id.
    pub controller: &'a str,
    /// The robot's element; `None` for a coordinator.
    pub robot: Option<&'a RobotEntity>,
    /// When it enters the run: a coordinator at the start, a robot as its element says.
    pub arrival: Arrival,
    /// Where its element is.
    pub location: Location,
}

impl Experiment {
    /// Every participant of the run in index order: the robots, then the coordinators.
    pub fn participants(&self) -> Vec<Participant<'_>> {
        let robots = self.arena.robots();
        let first_coordinator = robots.len() as u32;
        let robots = robots.into_iter().map(|r| Participant {
            index: r.index,
            id: r.id,
            controller: r.entity.controller.as_str(),
            robot: Some(r.entity),
            arrival: r.entity.arrival,
            location: r.entity.location,
        });
        let coordinators = (first_coordinator..)
            .zip(&self.coordinators)
            .map(|(index, c)| Participant {
                index,
                id: c.id.clone(),
                controller: c.controller.as_str(),
                robot: None,
                arrival: Arrival::Start,
                location: c.location,
            });
        robots.chain(coordinators).collect()
    }

    /// The controller with the given `id`, if declared.
    pub fn controller(&self, id: &str) -> Option<&Controller> {
        self.controllers.iter().find(|c| c.id == id)
    }

    /// The folder that relative paths in this configuration are resolved against.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or_else(|| Path::new(""))
    }

    /// Resolves a path written in the configuration (absolute paths are kept as they are).
    pub fn resolve(&self, written: &str) -> PathBuf {
        self.base_dir().join(written)
    }

    /// A located error or warning about this file, e.g. for a placement failure found by the world.
    pub fn diagnostic(&self, location: Location, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(self.path.clone(), location, message)
    }
}

/// `<framework>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Framework {
    /// `<system threads>`: worker threads requested (0 = the main thread does everything). Informational.
    pub threads: u32,
    /// `<system pin_threads_to_cores>`: whether each robot's agent process is pinned to one CPU by its
    /// chain (ARGoS' attribute, for our processes); true when absent.
    pub pin_agents: bool,
    /// `<system realtime_priority>` (ours): whether the world's ticking thread and the agents run at real-time
    /// priority when the system allows it; true when absent.
    pub realtime_priority: bool,
    /// The run's timeouts and size limits, with `<system>`'s attributes of the same names applied (each process
    /// applies the command line's overrides on top).
    pub limits: crate::limits::Limits,
    /// `<hosts>`: the machines the robots run on; `None` runs every robot on the launcher's machine.
    pub hosts: Option<super::hosts::HostsConfig>,
    /// `<experiment length>` in seconds; 0 means no limit (stop via loop functions).
    pub length_seconds: f64,
    /// `<experiment ticks_per_second>`: control steps per simulated second, always > 0.
    pub ticks_per_second: u32,
    /// `<experiment random_seed>`; `None` when absent or 0, meaning the launcher draws one from the clock (and
    /// prints it).
    pub random_seed: Option<u64>,
    /// Where `<experiment>` is.
    pub location: Location,
}

impl Framework {
    /// The number of ticks the experiment runs, or `None` when unlimited.
    pub fn max_ticks(&self) -> Option<u64> {
        if self.length_seconds > 0.0 {
            Some((self.length_seconds * f64::from(self.ticks_per_second)).round() as u64)
        } else {
            None
        }
    }

    /// Simulated seconds per tick.
    pub fn tick_seconds(&self) -> f64 {
        1.0 / f64::from(self.ticks_per_second)
    }
}

/// One attribute as written, with its location, for free-form sections (`<params>`, loop functions, devices).
#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    /// The attribute's value, unescaped.
    pub value: String,
    /// Where the attribute starts.
    pub location: Location,
}

/// An owned XML element, for the free-form subtrees ARGoS passes unchanged to controllers and loop functions.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Element {
    /// The tag name.
    pub name: String,
    /// Attributes by name (sorted, so iteration is deterministic).
    pub attributes: BTreeMap<String, Attribute>,
    /// Child elements in file order.
    pub children: Vec<Element>,
    /// Concatenated, trimmed text content (empty for most elements).
    pub text: String,
    /// Where the element's start tag is.
    pub location: Location,
}

impl Element {
    /// The raw value of an attribute.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.attributes.get(name).map(|a| a.value.as_str())
    }

    /// Parses an attribute with [`FromStr`]; `Ok(None)` when absent, a [`ValueError`] naming the attribute's
    /// location when malformed. Booleans accept `true`/`false`; numbers use Rust's syntax.
    pub fn parse<T>(&self, name: &str) -> Result<Option<T>, ValueError>
    where
        T: FromStr,
        T::Err: fmt::Display,
    {
        match self.attributes.get(name) {
            None => Ok(None),
            Some(a) => a
                .value
                .trim()
                .parse::<T>()
                .map(Some)
                .map_err(|e| ValueError {
                    location: a.location,
                    message: format!(
                        "invalid value '{}' for '{}' in <{}>: {}",
                        a.value, name, self.name, e
                    ),
                }),
        }
    }

    /// The first child element with the given tag.
    pub fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
}

/// A malformed value found after parsing (e.g. a controller param read by a profile); turn it into a
/// [`Diagnostic`] with [`Experiment::diagnostic`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{location}: {message}")]
pub struct ValueError {
    /// Where the bad value is.
    pub location: Location,
    /// What is wrong.
    pub message: String,
}

/// A controller type under `<controllers>`: what robots referring to its `id` run.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// The element name the controller registered under, e.g. `epuck_obstacle_avoidance_sct_prob_controller`.
    pub tag: String,
    /// `id`, referenced by `<controller config="..">` in robots.
    pub id: String,
    /// `library` as written (ARGoS: a shared object; here informational, may be empty).
    pub library: String,
    /// `<actuators>` children, in file order.
    pub actuators: Vec<Device>,
    /// `<sensors>` children, in file order.
    pub sensors: Vec<Device>,
    /// `<params>`: attributes and subtree, passed unchanged to the agent's profile. See `docs/configuration.md`
    /// for the names our profiles read (`profile`, `supervisors`, `velocity`, ...).
    pub params: Element,
    /// Where the controller element is.
    pub location: Location,
}

impl Controller {
    /// The first sensor of the given kind.
    pub fn sensor(&self, kind: DeviceKind) -> Option<&Device> {
        self.sensors.iter().find(|d| d.kind == kind)
    }

    /// `<params profile>`: the agent profile (the set of operational procedures) named explicitly; when absent
    /// the agent picks the profile registered for [`Controller::tag`].
    pub fn profile(&self) -> Option<&str> {
        self.params.get("profile")
    }

    /// `<params supervisors>`: the comma-separated supervisor files (ptSCT XML models or compiled supervisors) as
    /// written, relative to the configuration file (resolve them with [`Experiment::resolve`]); empty when absent.
    pub fn supervisors(&self) -> Vec<&str> {
        self.params
            .get("supervisors")
            .map(|list| list.split(',').map(str::trim).collect())
            .unwrap_or_default()
    }

    /// The first actuator of the given kind.
    pub fn actuator(&self, kind: DeviceKind) -> Option<&Device> {
        self.actuators.iter().find(|d| d.kind == kind)
    }
}

/// Whether a device is a sensor or an actuator (the same name, e.g. `range_and_bearing`, can be both).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DeviceRole {
    /// Declared under `<sensors>`.
    Sensor,
    /// Declared under `<actuators>`.
    Actuator,
}

/// What a declared device does, independent of which plug-in's name the configuration used
/// (`epuck_proximity` and `proximity` are both [`DeviceKind::Proximity`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DeviceKind {
    /// Wheels: `epuck_wheels`, `differential_steering` (actuator).
    Wheels,
    /// LEDs: `epuck_rgb_leds`, `epuck_base_leds`, `leds` (actuator).
    Leds,
    /// The IR proximity ring (8 on the e-puck, 24 on the foot-bot): `epuck_proximity`, `footbot_proximity`,
    /// `proximity`.
    Proximity,
    /// The light sensors (8 on the e-puck, 24 on the foot-bot): `epuck_light`, `footbot_light`, `light`.
    Light,
    /// The ground sensors (3 on the e-puck, the foot-bot's 4 motor-ground sensors): `epuck_ground`,
    /// `footbot_motor_ground`, `ground`.
    Ground,
    /// The omnidirectional LED-blob camera: `epuck_omnidirectional_camera`, `colored_blob_omnidirectional_camera`.
    OmnidirectionalCamera,
    /// Range-and-bearing: `epuck_range_and_bearing`, `range_and_bearing` (sensor and actuator).
    RangeAndBearing,
    /// A ring of range-finder rays from the body centre (our `range_finder`, sensor; attributes `rays` and
    /// `range`).
    RangeFinder,
    /// Absolute pose: `positioning` (sensor).
    Positioning,
    /// Our virtual gripper (thesis section "gripper"): `virtual_gripper` (sensor: holding state; actuator: grip).
    VirtualGripper,
    /// The foot-bot's physical gripper: `footbot_gripper` (actuator; attribute `max_force`).
    Gripper,
    /// The foot-bot's turret, which aims the gripper: `footbot_turret` (actuator).
    Turret,
    /// The foot-bot's rotating distance scanner: `footbot_distance_scanner` (sensor: readings; actuator: mode).
    DistanceScanner,
    /// Our pheromone field sensor: `pheromone` (sensor).
    Pheromone,
    /// Our pheromone deposit: `pheromone_deposit` (actuator).
    PheromoneDeposit,
}

/// One sensor or actuator declared in a controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Device {
    /// The element name as written, e.g. `epuck_proximity`.
    pub name: String,
    /// What the device is.
    pub kind: DeviceKind,
    /// Sensor or actuator.
    pub role: DeviceRole,
    /// `implementation` (`default`, `rot_z_only`, ...); `default` when absent.
    pub implementation: String,
    /// `noise_level`: additive uniform noise half-width on normalised readings (0 when absent).
    pub noise_level: f64,
    /// `noise_std_dev`: Gaussian noise standard deviation (0 when absent).
    pub noise_std_dev: f64,
    /// `medium`: the id of the medium the device uses, if any (checked against `<media>`).
    pub medium: Option<String>,
    /// The only robot the device exists on (`epuck_*`, `footbot_*` names), or `None` for a generic device.
    pub body: Option<RobotKind>,
    /// All attributes as written, including the typed ones above (e.g. `data_size`, `show_rays`, `range`).
    pub attributes: Element,
    /// Where the device element is.
    pub location: Location,
}

/// `<loop_functions library label>` and its free-form subtree.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopFunctions {
    /// `label`: the loop functions' registry name, e.g. `foraging_loop_functions`.
    pub label: String,
    /// `library` as written (informational).
    pub library: String,
    /// The whole element: attributes and children, passed unchanged to the loop functions.
    pub params: Element,
    /// Where `<loop_functions>` is.
    pub location: Location,
}

/// `<arena>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Arena {
    /// `size`: extent of the arena in metres.
    pub size: Vec3,
    /// `center`: centre of the arena.
    pub center: Vec3,
    /// `<floor>`, if present (absent: uniformly white).
    pub floor: Option<Floor>,
    /// Hand-placed entities, in file order. They are never collision-checked (ARGoS semantics).
    pub entities: Vec<PlacedEntity>,
    /// `<distribute>` blocks, in file order.
    pub distributions: Vec<Distribute>,
    /// Where `<arena>` is.
    pub location: Location,
}

/// One item of the arena in file order, as ARGoS processes them (a distribution only collision-checks against
/// what was placed before it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArenaItem<'a> {
    /// A hand-placed entity.
    Placed(&'a PlacedEntity),
    /// A distribution.
    Distribute(&'a Distribute),
}

impl Arena {
    /// Hand-placed entities and distributions merged back into file order.
    pub fn items(&self) -> Vec<ArenaItem<'_>> {
        let mut items: Vec<(Location, ArenaItem<'_>)> = self
            .entities
            .iter()
            .map(|e| (e.entity.location(), ArenaItem::Placed(e)))
            .chain(
                self.distributions
                    .iter()
                    .map(|d| (d.location, ArenaItem::Distribute(d))),
            )
            .collect();
        items.sort_by_key(|(loc, _)| *loc);
        items.into_iter().map(|(_, item)| item).collect()
    }
}

/// One robot of the experiment, as [`Arena::robots`] lists them.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot<'a> {
    /// Position in the canonical order, from 0: the robot's slot for every process of a run.
    pub index: u32,
    /// The robot's id (a distribution's robots are `base id` + index, e.g. `fb0`).
    pub id: String,
    /// The robot's element, `<e-puck>` or `<foot-bot>` (for distributed robots: the template).
    pub entity: &'a RobotEntity,
}

impl Arena {
    /// Every robot in the canonical order that the launcher, the world and the agents share: arena items in file
    /// order, each distribution expanded in index order. Robot `index` values are 0, 1, 2, ...
    pub fn robots(&self) -> Vec<Robot<'_>> {
        let mut robots = Vec::new();
        for item in self.items() {
            match item {
                ArenaItem::Placed(PlacedEntity {
                    entity: Entity::Robot(robot),
                    ..
                }) => {
                    robots.push((robot.id.clone(), robot));
                }
                ArenaItem::Distribute(d) => {
                    if let Entity::Robot(robot) = &d.template {
                        robots.extend((0..d.quantity).map(|i| (d.entity_id(i), robot)));
                    }
                }
                ArenaItem::Placed(_) => {}
            }
        }
        robots
            .into_iter()
            .zip(0u32..)
            .map(|((id, entity), index)| Robot { index, id, entity })
            .collect()
    }
}

/// A hand-placed entity with its pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PlacedEntity {
    /// From `<body>` (or, for lights, the `position`/`orientation` attributes).
    pub pose: Pose,
    /// The entity.
    pub entity: Entity,
}

/// An arena entity without its pose (the pose is in [`PlacedEntity`] or drawn by a [`Distribute`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Entity {
    /// `<box>`.
    Box(BoxEntity),
    /// `<cylinder>`.
    Cylinder(CylinderEntity),
    /// A robot: `<e-puck>`, `<foot-bot>` or `<disc-robot>`.
    Robot(RobotEntity),
    /// `<light>`.
    Light(LightEntity),
    /// `<target>` (our extension): a foraging target the virtual gripper can pick up.
    Target(TargetEntity),
}

impl Entity {
    /// The entity's id (for a distribution template: the base id).
    pub fn id(&self) -> &str {
        match self {
            Entity::Box(e) => &e.id,
            Entity::Cylinder(e) => &e.id,
            Entity::Robot(e) => &e.id,
            Entity::Light(e) => &e.id,
            Entity::Target(e) => &e.id,
        }
    }

    /// Where the entity's element is.
    pub fn location(&self) -> Location {
        match self {
            Entity::Box(e) => e.location,
            Entity::Cylinder(e) => e.location,
            Entity::Robot(e) => e.location,
            Entity::Light(e) => e.location,
            Entity::Target(e) => e.location,
        }
    }

    /// The XML element name of this entity kind.
    pub fn tag(&self) -> &'static str {
        match self {
            Entity::Box(_) => "box",
            Entity::Cylinder(_) => "cylinder",
            Entity::Robot(e) => e.kind.tag(),
            Entity::Light(_) => "light",
            Entity::Target(_) => "target",
        }
    }

    /// Whether the entity has a physical body (lights do not and are never collision-checked).
    pub fn has_body(&self) -> bool {
        !matches!(self, Entity::Light(_))
    }

    /// A copy with another id, as `<distribute>` makes them (`base id` + index).
    pub fn with_id(&self, id: String) -> Entity {
        let mut copy = self.clone();
        match &mut copy {
            Entity::Box(e) => e.id = id,
            Entity::Cylinder(e) => e.id = id,
            Entity::Robot(e) => e.id = id,
            Entity::Light(e) => e.id = id,
            Entity::Target(e) => e.id = id,
        }
        copy
    }
}

/// `<box id size movable [mass]>`.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxEntity {
    /// Unique id.
    pub id: String,
    /// Extent along x, y, z in metres (before rotation).
    pub size: Vec3,
    /// `movable`: whether robots can push it.
    pub movable: bool,
    /// `mass` in kg; present exactly when `movable` is true.
    pub mass: Option<f64>,
    /// `lift_by` (ours): how many robots' grippers lift it off the ground; only on a movable box.
    pub lift_by: Option<u32>,
    /// `<leds>` on the box, if any.
    pub leds: Option<LedGroup>,
    /// Where the element is.
    pub location: Location,
}

/// `<cylinder id radius height movable [mass]>`.
#[derive(Debug, Clone, PartialEq)]
pub struct CylinderEntity {
    /// Unique id.
    pub id: String,
    /// Radius in metres.
    pub radius: f64,
    /// Height in metres.
    pub height: f64,
    /// `movable`: whether robots can push it.
    pub movable: bool,
    /// `mass` in kg; present exactly when `movable` is true.
    pub mass: Option<f64>,
    /// `lift_by` (ours): how many robots' grippers lift it off the ground; only on a movable cylinder.
    pub lift_by: Option<u32>,
    /// `<leds>` on the cylinder (ARGoS passive objects with LEDs), if any.
    pub leds: Option<LedGroup>,
    /// Where the element is.
    pub location: Location,
}

/// `<leds medium="..">` with its `<led>` children.
#[derive(Debug, Clone, PartialEq)]
pub struct LedGroup {
    /// The LED medium id the LEDs are registered in.
    pub medium: String,
    /// The LEDs.
    pub leds: Vec<Led>,
    /// Where `<leds>` is.
    pub location: Location,
}

/// `<led offset anchor color>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Led {
    /// Offset from the anchor, metres.
    pub offset: Vec3,
    /// `anchor` (ARGoS: `origin` for passive objects).
    pub anchor: String,
    /// Colour (ARGoS names such as `red`, or `r,g,b[,a]`).
    pub color: Rgb,
    /// Where the element is.
    pub location: Location,
}

/// `<e-puck id [rab_range] [rab_data_size]>`, `<foot-bot id [rab_range] [rab_data_size]
/// [omnidirectional_camera_aperture]>` or `<disc-robot id [rab_range] [rab_data_size] [radius] [height] [mass]
/// [wheel_base] [max_speed] [max_turn_rate]>`, each also `[range_finder_range]`, with `<controller config>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotEntity {
    /// Which robot the element places.
    pub kind: RobotKind,
    /// Unique id.
    pub id: String,
    /// The `config` of `<controller>`: the id of a declared controller (checked).
    pub controller: String,
    /// `rab_range` in metres, if given.
    pub rab_range: Option<f64>,
    /// `rab_data_size` in bytes, if given.
    pub rab_data_size: Option<u32>,
    /// `omnidirectional_camera_aperture` in degrees (foot-bot), if given.
    pub camera_aperture_deg: Option<f64>,
    /// `range_finder_range` (ours): this robot's range-finder reach in metres, replacing its controller's.
    pub range_finder_range: Option<f64>,
    /// The disc robot's body attributes (all `None` for the e-puck and the foot-bot, whose bodies are fixed).
    pub shape: DiscShape,
    /// When the robot enters the arena (`join_tick`, `join_time`, `spare`; ours): at the start unless given.
    pub arrival: Arrival,
    /// Where the element is.
    pub location: Location,
}

/// When a robot enters the arena (docs/joins.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Arrival {
    /// At the start of the run.
    #[default]
    Start,
    /// Mid-run, at a tick or time of the schedule (`join_tick`, `join_time`).
    At(super::faults::At),
    /// Only when `swarm ctl spawn` asks for it (`spare="true"`).
    Spare,
}

impl RobotEntity {
    /// The robot's body: its kind's, with the disc robot's attributes applied.
    pub fn body(&self) -> BodyModel {
        let mut body = *self.kind.body();
        let s = &self.shape;
        let set = |field: &mut f32, value: Option<f64>| {
            if let Some(v) = value {
                *field = v as f32;
            }
        };
        set(&mut body.radius, s.radius);
        set(&mut body.proximity_mount_radius, s.radius);
        set(&mut body.height, s.height);
        set(&mut body.led_height, s.height);
        set(&mut body.rab_height, s.height);
        set(&mut body.mass, s.mass);
        set(&mut body.inter_wheel_distance, s.wheel_base);
        set(
            &mut body.max_wheel_speed_cm_s,
            s.max_speed.map(|v| v * 100.0),
        );
        set(&mut body.max_turn_rate, s.max_turn_rate);
        body
    }
}

/// The attributes of a `<disc-robot>` that change its body from the defaults (`bodies::DISC`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DiscShape {
    /// `radius` in metres.
    pub radius: Option<f64>,
    /// `height` in metres.
    pub height: Option<f64>,
    /// `mass` in kg.
    pub mass: Option<f64>,
    /// `wheel_base`: distance between the wheels in metres.
    pub wheel_base: Option<f64>,
    /// `max_speed`: largest wheel and forward speed in m/s.
    pub max_speed: Option<f64>,
    /// `max_turn_rate`: largest turn rate of a velocity command in rad/s.
    pub max_turn_rate: Option<f64>,
}

/// `<light id position orientation color intensity medium>`; its position is the [`PlacedEntity`] pose.
#[derive(Debug, Clone, PartialEq)]
pub struct LightEntity {
    /// Unique id.
    pub id: String,
    /// Colour.
    pub color: Rgb,
    /// `intensity` (IRIDIA light sensor: reading `exp(-2 d / I)`).
    pub intensity: f64,
    /// The LED medium id.
    pub medium: String,
    /// Where the element is.
    pub location: Location,
}

/// `<target id radius height color led_height>` (our extension): a small cylinder the virtual gripper can pick
/// up, carrying one LED at `led_height` that cameras see.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetEntity {
    /// Unique id.
    pub id: String,
    /// Body radius in metres.
    pub radius: f64,
    /// Body height in metres.
    pub height: f64,
    /// LED colour.
    pub color: Rgb,
    /// LED height above the ground in metres (must be below the camera, 0.122 m, to be seen).
    pub led_height: f64,
    /// The LED medium id the LED is registered in.
    pub medium: String,
    /// Where the element is.
    pub location: Location,
}

/// `<floor id source ..>`: the colour field ground sensors read.
#[derive(Debug, Clone, PartialEq)]
pub struct Floor {
    /// `id`.
    pub id: String,
    /// Where the colours come from.
    pub source: FloorSource,
    /// `pixels_per_meter`: resolution of the field.
    pub pixels_per_meter: f64,
    /// Where the element is.
    pub location: Location,
}

/// `<floor source=..>`.
#[derive(Debug, Clone, PartialEq)]
pub enum FloorSource {
    /// `source="loop_functions"`: the loop functions compute the colour of each point.
    LoopFunctions,
    /// `source="image" path=".."`: an image stretched over the arena (path as written, relative to the config).
    Image {
        /// The image path as written.
        path: String,
    },
    /// `source="regions"` (our extension): a background colour with axis-aligned rectangles on top; later
    /// regions paint over earlier ones.
    Regions {
        /// `color`: the background (default white).
        background: Rgb,
        /// `<region>` children in file order.
        regions: Vec<FloorRegion>,
    },
}

/// `<region min="x,y" max="x,y" color>` inside `<floor source="regions">`.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorRegion {
    /// Lower-left corner (min x, min y), metres.
    pub min: Vec2,
    /// Upper-right corner, metres; `min <= max` componentwise (checked).
    pub max: Vec2,
    /// Colour painted inside.
    pub color: Rgb,
    /// Where the element is.
    pub location: Location,
}

/// `<distribute>`: `quantity` copies of a template entity at generated poses.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribute {
    /// `<position method=..>`.
    pub position: PositionMethod,
    /// `<orientation method=..>`.
    pub orientation: OrientationMethod,
    /// `<entity quantity>`: how many copies.
    pub quantity: u32,
    /// `<entity max_trials>`: redraws allowed per entity before the experiment fails.
    pub max_trials: u32,
    /// `<entity base_num>`: index of the first copy (default 0); ids are `template id` + index, no separator.
    pub base_num: u32,
    /// The one entity template inside `<entity>`.
    pub template: Entity,
    /// Where `<distribute>` is.
    pub location: Location,
    /// Where `<position>` is.
    pub position_location: Location,
    /// Where `<orientation>` is.
    pub orientation_location: Location,
    /// Where `<entity>` is.
    pub entity_location: Location,
}

impl Distribute {
    /// The id of the copy with the given index (0-based within this distribution), e.g. `fb0`.
    pub fn entity_id(&self, index: u32) -> String {
        format!(
            "{}{}",
            self.template.id(),
            u64::from(self.base_num) + u64::from(index)
        )
    }
}

/// A position generator of `<distribute>`.
#[derive(Debug, Clone, PartialEq)]
pub enum PositionMethod {
    /// `method="uniform" min max`: each component uniform in [min, max] (min <= max checked).
    Uniform {
        /// Lower corner.
        min: Vec3,
        /// Upper corner.
        max: Vec3,
    },
    /// `method="gaussian" mean std_dev`: each component Gaussian.
    Gaussian {
        /// Mean.
        mean: Vec3,
        /// Standard deviation per component (>= 0 checked).
        std_dev: Vec3,
    },
    /// `method="constant" values`: always the same position.
    Constant {
        /// The position.
        values: Vec3,
    },
    /// `method="grid" center distances layout`: a lattice of `layout` cells spaced `distances`, centred on
    /// `center`, filled in order x first, then y, then z (`quantity <= nx*ny*nz` checked).
    Grid {
        /// Centre of the lattice.
        center: Vec3,
        /// Spacing along x, y, z.
        distances: Vec3,
        /// Number of cells along x, y, z (each >= 1).
        layout: [u32; 3],
    },
}

/// An orientation generator of `<distribute>`; all values Euler Z,Y,X in degrees.
#[derive(Debug, Clone, PartialEq)]
pub enum OrientationMethod {
    /// `method="uniform" min max`.
    Uniform {
        /// Lower bound.
        min: Euler,
        /// Upper bound.
        max: Euler,
    },
    /// `method="gaussian" mean std_dev`.
    Gaussian {
        /// Mean.
        mean: Euler,
        /// Standard deviation per angle.
        std_dev: Euler,
    },
    /// `method="constant" values`.
    Constant {
        /// The orientation.
        values: Euler,
    },
}

/// `<physics_engines>`: the one 2-D engine.
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicsEngine {
    /// `id`.
    pub id: String,
    /// `iterations` (ARGoS dynamics2d solver iterations per step, default 10).
    pub iterations: u32,
    /// Where `<dynamics2d>` is.
    pub location: Location,
}

/// `<media>`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Media {
    /// `<led id>`: the LED medium (LEDs, lights, cameras).
    pub leds: Option<Medium>,
    /// `<range_and_bearing id>`: the RAB medium.
    pub range_and_bearing: Option<Medium>,
    /// `<pheromone id cell_size>` (our extension): the pheromone field.
    pub pheromone: Option<PheromoneField>,
    /// `<messages id ...>` (our extension): addressed messages between the run's participants.
    pub messages: Option<MessagesMedium>,
}

impl Media {
    /// Whether a medium with this id is declared (of any kind).
    pub fn has(&self, id: &str) -> bool {
        self.leds.as_ref().is_some_and(|m| m.id == id)
            || self.range_and_bearing.as_ref().is_some_and(|m| m.id == id)
            || self.pheromone.as_ref().is_some_and(|m| m.id == id)
            || self.messages.as_ref().is_some_and(|m| m.id == id)
    }
}

/// `<messages id range loss max_payload max_per_tick>` (our extension; docs/messages.md): the medium of addressed
/// messages. The world decides each message's fate by these limits and records it.
#[derive(Debug, Clone, PartialEq)]
pub struct MessagesMedium {
    /// `id`.
    pub id: String,
    /// `range`: farthest a message travels between two robots' centres, in metres (absent: any distance).
    pub range: Option<f64>,
    /// `loss`: probability in [0, 1] that a message between two robots is lost (default 0).
    pub loss: f64,
    /// `max_payload`: most payload bytes of one message (default and at most
    /// [`crate::mail::MAIL_PAYLOAD_BYTES`]); a longer message is dropped.
    pub max_payload: u32,
    /// `max_per_tick`: most messages one participant sends per tick (default 8, at most
    /// [`crate::mail::MAILBOX_CAPACITY`]); the later ones are dropped.
    pub max_per_tick: u32,
    /// Where the element is.
    pub location: Location,
}

/// A declared LED or RAB medium.
#[derive(Debug, Clone, PartialEq)]
pub struct Medium {
    /// `id`, referenced by devices' and entities' `medium`.
    pub id: String,
    /// `grid_size` (ARGoS spatial-hash hint), if given.
    pub grid_size: Option<[u32; 3]>,
    /// Where the element is.
    pub location: Location,
}

/// `<pheromone id cell_size>` with `<channel>` children (our extension; docs/tasks.md section 5.2).
#[derive(Debug, Clone, PartialEq)]
pub struct PheromoneField {
    /// `id`, referenced by pheromone devices' `medium`.
    pub id: String,
    /// `cell_size`: side of a grid cell in metres (> 0).
    pub cell_size: f64,
    /// Channels in file order; at most [`crate::messages::PHEROMONE_CHANNELS`].
    pub channels: Vec<PheromoneChannel>,
    /// Where the element is.
    pub location: Location,
}

/// `<channel name evaporation diffusion>`.
#[derive(Debug, Clone, PartialEq)]
pub struct PheromoneChannel {
    /// `name`, e.g. `food` or `home`; unique within the field.
    pub name: String,
    /// `evaporation`: ρ in `τ ← (1 − ρ)·τ` per tick, in [0, 1].
    pub evaporation: f64,
    /// `diffusion`: weight D of the 3×3 blur per tick, in [0, 1] (0 = none).
    pub diffusion: f64,
    /// Where the element is.
    pub location: Location,
}
