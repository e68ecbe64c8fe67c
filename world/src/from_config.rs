//! Building a world from a parsed `.argos` experiment: arena bounds, floor, hand-placed entities and
//! `<distribute>` blocks in file order, controllers' devices, media and loop functions.
//!
//! Mapping of entities: `<box>` and `<cylinder>` are obstacles (walls are simply boxes), unless they carry
//! `<leds>`, in which case they are targets (ARGoS' passive objects with an LED; one LED each); `<target>` is a
//! target; `<e-puck>`, `<foot-bot>` and `<disc-robot>` robots; `<light>` a light. Every failure is a
//! [`WorldError`] naming `file:line:column`.

use swarm_contract::bodies::RobotKind;
use swarm_contract::config::{
    self, Controller, Device, DeviceKind, Entity, Experiment, FloorSource, Location, PlacedEntity,
};
use swarm_contract::messages::{MAX_RANGE_FINDER_RANGE, MAX_RANGE_RAYS, PHEROMONE_CHANNELS, Rgb};

use crate::actuators::GRIPPER_REACH;
use crate::devices::{
    CameraOptions, Devices, GripperOptions, ProximityOptions, RabOptions, RangeFinderOptions,
};
use crate::distribute::{self, outline};
use crate::entities::{FloorRegion, Light};
use crate::error::WorldError;
use crate::geometry::{Placed, Vec2};
use crate::gripper::DEFAULT_MAX_FORCE;
use crate::loop_functions::{LoopFunctionsParams, LoopFunctionsRegistry};
use crate::media::pheromone::ChannelRates;
use crate::physics::Motion;
use crate::rng::{Purpose, stream};
use crate::world::{World, WorldBuilder};

/// `path:line:column` of a location in the experiment's file.
pub fn locate(exp: &Experiment, location: Location) -> String {
    format!("{}:{}", exp.path.display(), location)
}

/// Most cells of a pheromone grid (per channel): every channel holds two `f32` grids, so this bounds the field
/// at 4 x 2 x 4 x 4 Mi bytes = 128 MiB.
pub const MAX_PHEROMONE_CELLS: u64 = 4 * 1024 * 1024;

fn invalid(exp: &Experiment, location: Location, message: impl Into<String>) -> WorldError {
    WorldError::Invalid {
        location: locate(exp, location),
        message: message.into(),
    }
}

/// Rays of a `range_finder` that does not say (paper A's ring: one every 18 degrees).
pub const DEFAULT_RANGE_RAYS: usize = 20;
/// Reach in metres of a `range_finder` that does not say.
pub const DEFAULT_RANGE_FINDER_RANGE: f64 = 1.0;

/// ITU-R 601 luma of a colour as a grey level in [0, 1] (what ARGoS' ground sensors read).
pub fn grey_level(c: Rgb) -> f32 {
    (0.299 * f32::from(c.r) + 0.587 * f32::from(c.g) + 0.114 * f32::from(c.b)) / 255.0
}

/// Attribute `name` of device `d` as a number, if given.
fn device_number(exp: &Experiment, d: &Device, name: &str) -> Result<Option<f64>, WorldError> {
    d.attributes
        .parse::<f64>(name)
        .map_err(|e| invalid(exp, e.location, e.message))
}

/// The devices a controller declares, for a robot of `kind` (whose body bounds the range-and-bearing payload).
pub fn devices(exp: &Experiment, c: &Controller, kind: RobotKind) -> Result<Devices, WorldError> {
    let max_payload = kind.body().rab_data_size;
    let proximity = match c.sensor(DeviceKind::Proximity) {
        None => None,
        Some(d) => {
            let ring = d
                .attributes
                .parse::<bool>("argos_uniform_ring")
                .map_err(|e| invalid(exp, e.location, e.message))?
                .unwrap_or(false);
            Some(ProximityOptions {
                noise_level: d.noise_level as f32,
                noise_std_dev: d.noise_std_dev as f32,
                argos_uniform_ring: ring,
            })
        }
    };
    let rab_device = c
        .sensor(DeviceKind::RangeAndBearing)
        .or(c.actuator(DeviceKind::RangeAndBearing));
    let rab = match rab_device {
        None => None,
        Some(d) => {
            let attr = |name: &str| device_number(exp, d, name);
            let data_size = attr("data_size")?.unwrap_or(2.0);
            if !(1.0..=f64::from(max_payload)).contains(&data_size) || data_size.fract() != 0.0 {
                return Err(invalid(
                    exp,
                    d.location,
                    format!(
                        "data_size {data_size} must be 1 to {max_payload} bytes on the {}",
                        kind.tag()
                    ),
                ));
            }
            let loss = attr("loss_probability")?.unwrap_or(0.0);
            if !(0.0..=1.0).contains(&loss) {
                return Err(invalid(
                    exp,
                    d.location,
                    format!("loss_probability {loss} must be in [0, 1]"),
                ));
            }
            Some(RabOptions {
                data_size: data_size as u8,
                loss_probability: loss as f32,
            })
        }
    };
    let range_finder = match c.sensor(DeviceKind::RangeFinder) {
        None => None,
        Some(d) => {
            let attr = |name: &str| device_number(exp, d, name);
            let rays = attr("rays")?.unwrap_or(DEFAULT_RANGE_RAYS as f64);
            if !(1.0..=MAX_RANGE_RAYS as f64).contains(&rays) || rays.fract() != 0.0 {
                return Err(invalid(
                    exp,
                    d.location,
                    format!("rays {rays} must be a whole number from 1 to {MAX_RANGE_RAYS}"),
                ));
            }
            let range = attr("range")?.unwrap_or(DEFAULT_RANGE_FINDER_RANGE);
            if !(range > 0.0 && range <= MAX_RANGE_FINDER_RANGE) {
                return Err(invalid(
                    exp,
                    d.location,
                    format!("range {range} must be above 0 and at most {MAX_RANGE_FINDER_RANGE} m"),
                ));
            }
            Some(RangeFinderOptions {
                rays: rays as u8,
                range: range as f32,
                noise_std_dev: d.noise_std_dev as f32,
            })
        }
    };
    let distance_scanner = c.sensor(DeviceKind::DistanceScanner).is_some();
    if let (true, Some(rf)) = (distance_scanner, c.sensor(DeviceKind::RangeFinder)) {
        return Err(invalid(
            exp,
            rf.location,
            format!(
                "controller '{}' declares both 'range_finder' and 'footbot_distance_scanner': both report in the frame's ranges",
                c.id
            ),
        ));
    }
    let gripper = match c.actuator(DeviceKind::Gripper) {
        None => None,
        Some(d) => {
            if let Some(virtual_gripper) = c.actuator(DeviceKind::VirtualGripper) {
                return Err(invalid(
                    exp,
                    virtual_gripper.location,
                    format!(
                        "controller '{}' declares both 'virtual_gripper' and 'footbot_gripper' (at {}); a robot has one gripper",
                        c.id, d.location
                    ),
                ));
            }
            let max_force =
                device_number(exp, d, "max_force")?.unwrap_or(f64::from(DEFAULT_MAX_FORCE));
            if !(max_force > 0.0 && max_force.is_finite()) {
                return Err(invalid(
                    exp,
                    d.location,
                    format!("max_force {max_force} must be a force above 0 N"),
                ));
            }
            Some(GripperOptions {
                max_force: max_force as f32,
            })
        }
    };
    let gripper_reach = match c.actuator(DeviceKind::VirtualGripper) {
        None => GRIPPER_REACH,
        Some(d) => device_number(exp, d, "pickup_gap")?.map_or(GRIPPER_REACH, |g| g as f32),
    };
    Ok(Devices {
        proximity,
        light: c.sensor(DeviceKind::Light).map(|d| d.noise_level as f32),
        ground: c.sensor(DeviceKind::Ground).map(|d| d.noise_level as f32),
        camera: c
            .sensor(DeviceKind::OmnidirectionalCamera)
            .map(|d| CameraOptions {
                noise_std_dev: d.noise_std_dev as f32,
            }),
        range_finder,
        gripper,
        distance_scanner,
        rab,
        wheel_noise_std_dev: c
            .actuator(DeviceKind::Wheels)
            .map_or(0.0, |d| d.noise_std_dev as f32),
        gripper_reach,
    })
}

/// The `<loop_functions>` element flattened for the factories: the element's own attributes by name, and each
/// child's as `child.attribute`; `seed` is the run's.
pub fn loop_functions_params(
    exp: &Experiment,
    lf: &config::LoopFunctions,
    seed: u64,
) -> LoopFunctionsParams {
    let mut attributes = std::collections::BTreeMap::new();
    for (k, a) in &lf.params.attributes {
        attributes.insert(k.clone(), a.value.clone());
    }
    for child in &lf.params.children {
        for (k, a) in &child.attributes {
            attributes.insert(format!("{}.{}", child.name, k), a.value.clone());
        }
    }
    LoopFunctionsParams {
        label: lf.label.clone(),
        location: locate(exp, lf.location),
        attributes,
        children: lf.params.children.iter().map(|c| c.name.clone()).collect(),
        seed,
    }
}

/// Builds the world of `exp` for the run `seed`, with loop functions from `registry`.
pub fn build(
    exp: &Experiment,
    seed: u64,
    registry: &LoopFunctionsRegistry,
) -> Result<World, WorldError> {
    let a = &exp.arena;
    let (c, half) = (
        Vec2::new(a.center.x as f32, a.center.y as f32),
        Vec2::new(a.size.x as f32, a.size.y as f32) / 2.0,
    );
    if half.x <= 0.0 || half.y <= 0.0 {
        return Err(invalid(
            exp,
            a.location,
            format!("arena size {} must be positive in x and y", a.size),
        ));
    }
    let mut b = WorldBuilder::new(c - half, c + half, exp.framework.ticks_per_second, seed);
    if let Some(floor) = &a.floor {
        match &floor.source {
            FloorSource::LoopFunctions => {}
            FloorSource::Image { path } => {
                return Err(invalid(
                    exp,
                    floor.location,
                    format!(
                        "floor source=\"image\" ('{path}') is not supported; use source=\"regions\" or \"loop_functions\""
                    ),
                ));
            }
            FloorSource::Regions {
                background,
                regions,
            } => {
                if *background
                    != (Rgb {
                        r: 255,
                        g: 255,
                        b: 255,
                    })
                {
                    b.floor_region(FloorRegion {
                        min: c - half,
                        max: c + half,
                        grey: grey_level(*background),
                    });
                }
                for r in regions {
                    b.floor_region(FloorRegion {
                        min: Vec2::new(r.min.x as f32, r.min.y as f32),
                        max: Vec2::new(r.max.x as f32, r.max.y as f32),
                        grey: grey_level(r.color),
                    });
                }
            }
        }
    }
    if let Some(p) = &exp.media.pheromone {
        if p.channels.len() > PHEROMONE_CHANNELS {
            return Err(invalid(
                exp,
                p.location,
                format!("at most {PHEROMONE_CHANNELS} pheromone channels are supported"),
            ));
        }
        let mut rates = [ChannelRates {
            evaporation: 0.0,
            diffusion: 0.0,
        }; PHEROMONE_CHANNELS];
        for (r, ch) in rates.iter_mut().zip(&p.channels) {
            *r = ChannelRates {
                evaporation: ch.evaporation as f32,
                diffusion: ch.diffusion as f32,
            };
        }
        let size = exp.arena.size;
        let cells = (size.x / p.cell_size).ceil() * (size.y / p.cell_size).ceil();
        if cells > MAX_PHEROMONE_CELLS as f64 {
            return Err(invalid(
                exp,
                p.location,
                format!(
                    "the pheromone grid would have {cells:.0} cells of {} m over the arena; at most \
                     {MAX_PHEROMONE_CELLS}: use a larger cell_size",
                    p.cell_size
                ),
            ));
        }
        b.pheromone(p.cell_size as f32, rates);
    }
    if let Some(medium) = &exp.media.messages {
        b.messages(medium);
    }
    for coordinator in &exp.coordinators {
        b.coordinator(&coordinator.id, &coordinator.controller);
    }

    let mut occupied: Vec<Placed> = Vec::new();
    let mut rng = stream(seed, Purpose::Placement, 0);
    for item in a.items() {
        match item {
            config::ArenaItem::Placed(PlacedEntity { pose, entity }) => {
                let position = Vec2::new(pose.position.x as f32, pose.position.y as f32);
                let yaw = pose.orientation.yaw_radians() as f32;
                occupied.extend(outline(entity, position, yaw));
                add_entity(exp, &mut b, entity, position, yaw, pose.position.z as f32)?;
            }
            config::ArenaItem::Distribute(d) => {
                let placements =
                    distribute::place(d, &mut occupied, &mut rng, &locate(exp, d.location))?;
                for p in placements {
                    let entity = d.template.with_id(p.id);
                    add_entity(exp, &mut b, &entity, p.position, p.yaw, 0.0)?;
                }
            }
        }
    }
    let params = exp
        .loop_functions
        .as_ref()
        .map(|lf| loop_functions_params(exp, lf, seed));
    b.loop_functions(registry.create(params.as_ref())?);
    let mut world = b.build();
    world.place_by_loop_functions()?;
    world.set_max_ticks(exp.framework.max_ticks());
    // Robots that join later wait outside the arena; they keep the pose they were given to join at. When they
    // join is the world process's business (its arrivals).
    for robot in exp.arena.robots() {
        if robot.entity.arrival != config::Arrival::Start {
            world.park(crate::entities::RobotId(robot.index));
        }
    }
    Ok(world)
}

fn motion(
    exp: &Experiment,
    movable: bool,
    mass: Option<f64>,
    location: Location,
) -> Result<Motion, WorldError> {
    match (movable, mass) {
        (false, _) => Ok(Motion::Fixed),
        (true, Some(m)) if m > 0.0 => Ok(Motion::Movable { mass: m as f32 }),
        (true, _) => Err(invalid(
            exp,
            location,
            "a movable entity needs a positive mass",
        )),
    }
}

fn add_entity(
    exp: &Experiment,
    b: &mut WorldBuilder,
    entity: &Entity,
    position: Vec2,
    yaw: f32,
    z: f32,
) -> Result<(), WorldError> {
    let Some(placed) = outline(entity, position, yaw) else {
        if let Entity::Light(l) = entity {
            b.light(Light {
                name: l.id.clone(),
                position,
                height: z,
                intensity: l.intensity as f32,
                color: l.color,
            });
        }
        return Ok(());
    };
    match entity {
        Entity::Robot(e) => {
            let controller = exp.controller(&e.controller).ok_or_else(|| {
                invalid(
                    exp,
                    e.location,
                    format!(
                        "{} '{}' uses undeclared controller '{}'",
                        e.kind.tag(),
                        e.id,
                        e.controller
                    ),
                )
            })?;
            let mut devices = devices(exp, controller, e.kind)?;
            if let (Some(rab), Some(size)) = (devices.rab.as_mut(), e.rab_data_size) {
                let max = u32::from(e.kind.body().rab_data_size);
                if !(1..=max).contains(&size) {
                    return Err(invalid(
                        exp,
                        e.location,
                        format!("rab_data_size {size} must be 1 to {max} bytes"),
                    ));
                }
                rab.data_size = size as u8;
            }
            if let (Some(rf), Some(range)) = (devices.range_finder.as_mut(), e.range_finder_range) {
                rf.range = range as f32;
            }
            let id = b.robot_with_body(e.body(), &e.id, &e.controller, position, yaw, devices);
            if let Some(range) = e.rab_range {
                b.rab_range(id, range as f32);
            }
            if let Some(aperture) = e.camera_aperture_deg {
                b.camera_aperture(id, (aperture as f32).to_radians());
            }
        }
        Entity::Box(x) => add_passive(
            exp,
            b,
            Passive {
                id: &x.id,
                placed,
                height: x.size.z as f32,
                movable: x.movable,
                mass: x.mass,
                lift_by: x.lift_by,
                leds: x.leds.as_ref(),
                location: x.location,
            },
        )?,
        Entity::Cylinder(x) => add_passive(
            exp,
            b,
            Passive {
                id: &x.id,
                placed,
                height: x.height as f32,
                movable: x.movable,
                mass: x.mass,
                lift_by: x.lift_by,
                leds: x.leds.as_ref(),
                location: x.location,
            },
        )?,
        Entity::Target(t) => {
            b.target(&t.id, placed, t.height as f32, t.color, t.led_height as f32);
        }
        Entity::Light(_) => {}
    }
    Ok(())
}

/// A box or cylinder as `add_passive` needs it.
struct Passive<'a> {
    id: &'a str,
    placed: Placed,
    height: f32,
    movable: bool,
    mass: Option<f64>,
    lift_by: Option<u32>,
    leds: Option<&'a config::LedGroup>,
    location: Location,
}

/// Adds a box or cylinder: an obstacle (liftable if it says so), or a target when it carries an LED.
fn add_passive(exp: &Experiment, b: &mut WorldBuilder, p: Passive) -> Result<(), WorldError> {
    let Passive {
        id,
        placed,
        height,
        movable,
        mass,
        lift_by,
        leds,
        location,
    } = p;
    let motion = motion(exp, movable, mass, location)?;
    match leds {
        None => {
            let obstacle = b.obstacle(id, placed, height, motion);
            if let Some(robots) = lift_by {
                b.lift_by(obstacle, robots);
            }
        }
        Some(group) => {
            let [led] = group.leds.as_slice() else {
                return Err(invalid(
                    exp,
                    group.location,
                    format!(
                        "'{id}' has {} LEDs; a target carries exactly one",
                        group.leds.len()
                    ),
                ));
            };
            if movable {
                return Err(invalid(
                    exp,
                    location,
                    format!(
                        "'{id}' carries an LED, so it is a target, and targets cannot be movable"
                    ),
                ));
            }
            b.target(id, placed, height, led.color, led.offset.z as f32);
        }
    }
    Ok(())
}
