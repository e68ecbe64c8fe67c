//! `<arena>`: entities (box, cylinder, e-puck, foot-bot, our disc robot and target, light); the floor is parsed in
//! `floor.rs`, `<distribute>` blocks in `distribute.rs`.

use super::{Ctx, MediumRef};
use crate::bodies::RobotKind;
use crate::config::faults::At;
use crate::config::model::{
    Arena, Arrival, BoxEntity, CylinderEntity, DiscShape, Element, Entity, Euler, Floor, Led,
    LedGroup, LightEntity, PlacedEntity, Pose, RobotEntity, TargetEntity, Vec3,
};
use crate::config::registry::MediumKind;
use crate::config::suggest::did_you_mean;
use crate::messages::{MAX_RANGE_FINDER_RANGE, Rgb};

/// The entities the arena places, by element name (by hand or in a `<distribute>`).
pub(super) const ENTITIES: &[&str] = &[
    "box",
    "cylinder",
    "e-puck",
    "foot-bot",
    "disc-robot",
    "light",
    "target",
];
const ARENA_CHILDREN: &[&str] = &[
    "box",
    "cylinder",
    "e-puck",
    "foot-bot",
    "disc-robot",
    "light",
    "target",
    "floor",
    "distribute",
];
/// ARGoS entities we recognise but do not simulate.
const UNSUPPORTED_ENTITIES: &[&str] = &[
    "eye-bot",
    "spiri",
    "kheperaiv",
    "pi-puck",
    "builderbot",
    "drone",
    "prototype",
    "block",
];
/// Height of the e-puck omnidirectional camera (docs/epuck-and-world.md 1.5): LEDs at or above it are never seen.
/// `bodies::EPUCK.camera_height` as written in messages (the `f32` would print as 0.12200000137...).
const CAMERA_HEIGHT: f64 = 0.122;
const _: () = assert!(CAMERA_HEIGHT as f32 == crate::bodies::EPUCK.camera_height);
/// Default LED height of a `<target>` (docs/tasks.md 4.9: a red LED at 0.06 m).
const TARGET_LED_HEIGHT: f64 = 0.06;

/// Longest arena side accepted, in metres: far beyond any swarm experiment, and small enough that positions keep
/// millimetre precision in the physics engine's 32-bit floats.
pub const MAX_ARENA_SIDE: f64 = 10_000.0;

/// Parses `<arena size center>`.
pub(super) fn arena(ctx: &mut Ctx, el: &Element) -> Option<Arena> {
    ctx.unknown_attributes(el, &["size", "center", "positional_grid_size"]);
    if let Some(grid) = el.attributes.get("positional_grid_size") {
        ctx.warn(
            grid.location,
            "'positional_grid_size' is ignored: the world indexes space itself",
            None,
        );
    }
    let size: Option<Vec3> = ctx.required(el, "size");
    let side_ok = |v: f64| v.is_finite() && v > 0.0 && v <= MAX_ARENA_SIDE;
    if let Some(s) = size
        && !(side_ok(s.x) && side_ok(s.y))
    {
        let at = el
            .attributes
            .get("size")
            .map_or(el.location, |a| a.location);
        ctx.error(
            at,
            format!(
                "arena 'size' must be positive and at most {MAX_ARENA_SIDE} m in x and y, got {s}"
            ),
            None,
        );
    }
    let center: Vec3 = ctx.attr(el, "center").unwrap_or_default();
    let mut floor: Option<Floor> = None;
    let mut entities = Vec::new();
    let mut distributions = Vec::new();
    for child in &el.children {
        match child.name.as_str() {
            "floor" => {
                if let Some(first) = &floor {
                    ctx.duplicate(child, &el.name, first.location);
                    continue;
                }
                floor = super::floor::parse_floor(ctx, child);
            }
            "distribute" => distributions.extend(super::distribute::distribute(ctx, child)),
            name if ENTITIES.contains(&name) => entities.extend(placed(ctx, child)),
            name if UNSUPPORTED_ENTITIES.contains(&name) => {
                ctx.error(
                    child.location,
                    format!("entity <{name}> is not supported: the world simulates e-pucks, foot-bots and <disc-robot>s"),
                    None,
                );
            }
            _ => ctx.unknown_element(child, &el.name, ARENA_CHILDREN),
        }
    }
    Some(Arena {
        size: size?,
        center,
        floor,
        entities,
        distributions,
        location: el.location,
    })
}

/// A hand-placed entity: its pose comes from `<body>` (lights: their own attributes).
fn placed(ctx: &mut Ctx, el: &Element) -> Option<PlacedEntity> {
    let (pose, entity) = entity(ctx, el, true);
    Some(PlacedEntity {
        pose: pose?,
        entity: entity?,
    })
}

/// Parses an entity. Hand-placed entities need a pose; distribution templates must not have one.
pub(super) fn entity(ctx: &mut Ctx, el: &Element, placed: bool) -> (Option<Pose>, Option<Entity>) {
    let mut pose = None;
    let entity = match el.name.as_str() {
        "light" => {
            pose = light_pose(ctx, el, placed);
            light(ctx, el).map(Entity::Light)
        }
        name => {
            let children: &[&str] = match name {
                "box" | "cylinder" => &["body", "leds"],
                "e-puck" | "foot-bot" | "disc-robot" => &["body", "controller"],
                _ => &["body"],
            };
            let mut body: Option<&Element> = None;
            for child in &el.children {
                if !children.contains(&child.name.as_str()) {
                    ctx.unknown_element(child, &el.name, children);
                } else if child.name == "body" {
                    match body {
                        Some(first) => ctx.duplicate(child, &el.name, first.location),
                        None => body = Some(child),
                    }
                }
            }
            match (body, placed) {
                (Some(b), true) => pose = parse_body(ctx, b),
                (None, true) => ctx.error(
                    el.location,
                    format!("<{name}> placed by hand needs a <body position=\"x,y,z\" orientation=\"z,y,x\"/>"),
                    None,
                ),
                (Some(b), false) => ctx.error(
                    b.location,
                    format!("<body> is not allowed in a <distribute> template: <position> and <orientation> place each <{name}>"),
                    None,
                ),
                (None, false) => {}
            }
            match name {
                "box" => box_entity(ctx, el).map(Entity::Box),
                "cylinder" => cylinder(ctx, el).map(Entity::Cylinder),
                robot if RobotKind::from_tag(robot).is_some() => {
                    robot_entity(ctx, el).map(Entity::Robot)
                }
                _ => target(ctx, el).map(Entity::Target),
            }
        }
    };
    (pose, entity)
}

fn parse_body(ctx: &mut Ctx, el: &Element) -> Option<Pose> {
    ctx.unknown_attributes(el, &["position", "orientation"]);
    for child in &el.children {
        ctx.unknown_element(child, &el.name, &[]);
    }
    let position: Vec3 = ctx.required(el, "position")?;
    let orientation: Euler = ctx.attr(el, "orientation").unwrap_or_default();
    Some(Pose {
        position,
        orientation,
    })
}

/// `movable` (default false) and `mass`, which a movable entity must have.
/// Most robots a `lift_by` may ask for.
const MAX_LIFT_BY: f64 = 64.0;

/// `movable`, `mass` and `lift_by` of a box or cylinder.
struct Mobility {
    movable: bool,
    mass: Option<f64>,
    lift_by: Option<u32>,
}

/// `movable` (default false), `mass` (which a movable entity must have) and `lift_by` (ours: how many robots'
/// grippers lift it; only on a movable entity).
fn mobility(ctx: &mut Ctx, el: &Element) -> Option<Mobility> {
    let lift_by = match el.attributes.get("lift_by") {
        None => Some(None),
        Some(_) => ctx.attr::<u32>(el, "lift_by").and_then(|n| {
            ctx.in_range(el, "lift_by", f64::from(n), 1.0, Some(MAX_LIFT_BY))
                .then_some(Some(n))
        }),
    };
    let (movable, mass) = movable_mass(ctx, el)?;
    let lift_by = lift_by?;
    if let (false, Some(_)) = (movable, lift_by) {
        let at = el
            .attributes
            .get("lift_by")
            .map_or(el.location, |a| a.location);
        ctx.error(
            at,
            format!(
                "'lift_by' needs a movable <{}> (movable=\"true\" and a mass)",
                el.name
            ),
            None,
        );
        return None;
    }
    Some(Mobility {
        movable,
        mass,
        lift_by,
    })
}

fn movable_mass(ctx: &mut Ctx, el: &Element) -> Option<(bool, Option<f64>)> {
    let movable: bool = ctx.attr(el, "movable").unwrap_or(false);
    if !movable {
        if let Some(mass) = el.attributes.get("mass") {
            ctx.warn(
                mass.location,
                format!("'mass' is ignored: this <{}> is not movable", el.name),
                None,
            );
        }
        return Some((false, None));
    }
    if !el.attributes.contains_key("mass") {
        ctx.error(
            el.location,
            format!("a movable <{}> needs a 'mass' (kg)", el.name),
            None,
        );
        return None;
    }
    ctx.positive(el, "mass").map(|m| (true, Some(m)))
}

fn box_entity(ctx: &mut Ctx, el: &Element) -> Option<BoxEntity> {
    ctx.unknown_attributes(el, &["id", "size", "movable", "mass", "lift_by"]);
    let id: Option<String> = ctx.required(el, "id");
    let size: Option<Vec3> = ctx.required(el, "size");
    let size = size.filter(|s| {
        let ok = s.x > 0.0 && s.y > 0.0 && s.z > 0.0;
        if !ok {
            let at = el
                .attributes
                .get("size")
                .map_or(el.location, |a| a.location);
            ctx.error(
                at,
                format!("box 'size' must be positive in every component, got {s}"),
                None,
            );
        }
        ok
    });
    let mobility = mobility(ctx, el);
    let leds = led_group(ctx, el);
    let Mobility {
        movable,
        mass,
        lift_by,
    } = mobility?;
    Some(BoxEntity {
        id: id?,
        size: size?,
        movable,
        mass,
        lift_by,
        leds: leds?,
        location: el.location,
    })
}

fn cylinder(ctx: &mut Ctx, el: &Element) -> Option<CylinderEntity> {
    ctx.unknown_attributes(
        el,
        &["id", "radius", "height", "movable", "mass", "lift_by"],
    );
    let id: Option<String> = ctx.required(el, "id");
    let radius = ctx.positive(el, "radius");
    let height = ctx.positive(el, "height");
    let mobility = mobility(ctx, el);
    let leds = led_group(ctx, el);
    let Mobility {
        movable,
        mass,
        lift_by,
    } = mobility?;
    Some(CylinderEntity {
        id: id?,
        radius: radius?,
        height: height?,
        movable,
        mass,
        lift_by,
        leds: leds?,
        location: el.location,
    })
}

/// The optional `<leds medium>` child: `Some(None)` when absent, `None` on error.
fn led_group(ctx: &mut Ctx, parent: &Element) -> Option<Option<LedGroup>> {
    let mut groups = parent.children.iter().filter(|c| c.name == "leds");
    let Some(el) = groups.next() else {
        return Some(None);
    };
    if let Some(second) = groups.next() {
        ctx.duplicate(second, &parent.name, el.location);
        return None;
    }
    ctx.unknown_attributes(el, &["medium"]);
    let medium = medium_ref(
        ctx,
        el,
        MediumKind::Led,
        format!("<leds> of <{}>", parent.name),
    );
    let mut leds = Vec::new();
    let (children, mut ok) = ctx.children_named(el, "led");
    for child in children {
        ctx.unknown_attributes(child, &["offset", "anchor", "color"]);
        let offset: Option<Vec3> = ctx.required(child, "offset");
        let anchor: String = ctx
            .attr(child, "anchor")
            .unwrap_or_else(|| "origin".to_string());
        let color: Option<Rgb> = ctx.required(child, "color");
        match (offset, color) {
            (Some(offset), Some(color)) => leds.push(Led {
                offset,
                anchor,
                color,
                location: child.location,
            }),
            _ => ok = false,
        }
    }
    ok.then_some(())?;
    Some(Some(LedGroup {
        medium: medium?,
        leds,
        location: el.location,
    }))
}

/// Reads a mandatory `medium` attribute and queues it for checking against `<media>`.
fn medium_ref(ctx: &mut Ctx, el: &Element, kind: MediumKind, user: String) -> Option<String> {
    let id: String = ctx.required(el, "medium")?;
    let location = el
        .attributes
        .get("medium")
        .map_or(el.location, |a| a.location);
    ctx.medium_refs.push(MediumRef {
        id: id.clone(),
        kind,
        location,
        user,
    });
    Some(id)
}

/// Foot-bot attributes ARGoS reads for devices the world does not simulate: accepted with a warning.
const IGNORED_FOOTBOT_ATTRIBUTES: &[&str] = &[
    "perspective_camera_front",
    "perspective_camera_aperture",
    "perspective_camera_focal_length",
    "perspective_camera_range",
];

/// The `<disc-robot>` body attributes, each above 0 and at most the bound given (far beyond any robot, and small
/// enough to keep the physics engine's 32-bit numbers meaningful).
const DISC_ATTRIBUTES: &[(&str, f64)] = &[
    ("radius", 10.0),
    ("height", 10.0),
    ("mass", 10_000.0),
    ("wheel_base", 20.0),
    ("max_speed", 100.0),
    ("max_turn_rate", 1_000.0),
];

/// An optional attribute that must be above 0 and at most `max`: `Some(None)` when absent, `None` when it is bad
/// (reported).
fn positive_at_most(ctx: &mut Ctx, el: &Element, name: &str, max: f64) -> Option<Option<f64>> {
    if !el.attributes.contains_key(name) {
        return Some(None);
    }
    let value = ctx.positive(el, name)?;
    ctx.in_range(el, name, value, 0.0, Some(max))
        .then_some(Some(value))
}

/// `<e-puck>`, `<foot-bot>` or `<disc-robot>`: id, range-and-bearing options, the foot-bot's camera aperture, the
/// disc robot's body, `<controller>`.
fn robot_entity(ctx: &mut Ctx, el: &Element) -> Option<RobotEntity> {
    let kind = RobotKind::from_tag(&el.name)?;
    let body = kind.body();
    let mut known = vec![
        "id",
        "rab_range",
        "rab_data_size",
        "range_finder_range",
        "join_tick",
        "join_time",
        "spare",
    ];
    let mut shape = DiscShape::default();
    let mut shape_ok = true;
    if kind == RobotKind::Disc {
        known.extend(DISC_ATTRIBUTES.iter().map(|(name, _)| *name));
        for (&(name, max), field) in DISC_ATTRIBUTES.iter().zip([
            &mut shape.radius,
            &mut shape.height,
            &mut shape.mass,
            &mut shape.wheel_base,
            &mut shape.max_speed,
            &mut shape.max_turn_rate,
        ]) {
            match positive_at_most(ctx, el, name, max) {
                Some(value) => *field = value,
                None => shape_ok = false,
            }
        }
    }
    if kind == RobotKind::FootBot {
        known.push("omnidirectional_camera_aperture");
        known.extend_from_slice(IGNORED_FOOTBOT_ATTRIBUTES);
        for name in IGNORED_FOOTBOT_ATTRIBUTES {
            if let Some(a) = el.attributes.get(*name) {
                ctx.warn(
                    a.location,
                    format!("'{name}' is ignored: the world simulates no perspective camera"),
                    None,
                );
            }
        }
    }
    ctx.unknown_attributes(el, &known);
    let id: Option<String> = ctx.required(el, "id");
    let rab_range: Option<f64> = ctx.attr(el, "rab_range");
    let rab_range_ok = rab_range.is_none_or(|r| ctx.in_range(el, "rab_range", r, 0.0, None));
    let rab_data_size: Option<u32> = ctx.attr(el, "rab_data_size");
    let rab_data_size_ok = rab_data_size.is_none_or(|d| {
        let max = f64::from(body.rab_data_size);
        ctx.in_range(el, "rab_data_size", f64::from(d), 1.0, Some(max))
    });
    let range_finder_range =
        positive_at_most(ctx, el, "range_finder_range", MAX_RANGE_FINDER_RANGE);
    let range_finder_ok = range_finder_range.is_some();
    let camera_aperture_deg: Option<f64> = ctx.attr(el, "omnidirectional_camera_aperture");
    let aperture_ok = camera_aperture_deg
        .is_none_or(|a| ctx.in_range(el, "omnidirectional_camera_aperture", a, 0.0, Some(89.0)));
    let controller = controller_ref(ctx, el);
    let arrival = arrival(ctx, el);
    (rab_range_ok && rab_data_size_ok && aperture_ok && shape_ok && range_finder_ok)
        .then_some(())?;
    Some(RobotEntity {
        kind,
        id: id?,
        controller: controller?,
        rab_range,
        rab_data_size,
        camera_aperture_deg,
        range_finder_range: range_finder_range.flatten(),
        shape,
        arrival: arrival?,
        location: el.location,
    })
}

/// `join_tick="T"` (T >= 1), `join_time="S"` (S > 0) or `spare="true"`: at most one; none is the start.
fn arrival(ctx: &mut Ctx, el: &Element) -> Option<Arrival> {
    let given: Vec<&str> = ["join_tick", "join_time", "spare"]
        .into_iter()
        .filter(|name| el.attributes.contains_key(*name))
        .collect();
    match given.as_slice() {
        [] => Some(Arrival::Start),
        ["join_tick"] => {
            let tick: u64 = ctx.attr(el, "join_tick")?;
            ctx.in_range(el, "join_tick", tick as f64, 1.0, None)
                .then_some(Arrival::At(At::Tick(tick)))
        }
        ["join_time"] => {
            let seconds = ctx.positive(el, "join_time")?;
            Some(Arrival::At(At::Seconds(seconds)))
        }
        ["spare"] => match ctx.attr::<bool>(el, "spare")? {
            true => Some(Arrival::Spare),
            false => Some(Arrival::Start),
        },
        _ => {
            ctx.error(
                el.location,
                format!(
                    "<{}> gives {}; give at most one of join_tick, join_time and spare",
                    el.name,
                    given.join(" and ")
                ),
                None,
            );
            None
        }
    }
}

/// The one `<controller config="id"/>` child of a robot or coordinator element: the controller's id.
pub(super) fn controller_ref(ctx: &mut Ctx, el: &Element) -> Option<String> {
    let mut controllers = el.children.iter().filter(|c| c.name == "controller");
    match (controllers.next(), controllers.next()) {
        (Some(c), None) => {
            ctx.unknown_attributes(c, &["config"]);
            ctx.required::<String>(c, "config")
        }
        (Some(first), Some(second)) => {
            ctx.duplicate(second, &el.name, first.location);
            None
        }
        (None, _) => {
            ctx.error(
                el.location,
                format!(
                    "<{}> needs a <controller config=\"controller id\"/>",
                    el.name
                ),
                None,
            );
            None
        }
    }
}

fn light_pose(ctx: &mut Ctx, el: &Element, placed: bool) -> Option<Pose> {
    if !placed {
        if let Some(position) = el.attributes.get("position") {
            ctx.error(
                position.location,
                "'position' is not allowed on a <light> template: <distribute> places it",
                None,
            );
        }
        return None;
    }
    let position: Vec3 = ctx.required(el, "position")?;
    let orientation: Euler = ctx.attr(el, "orientation").unwrap_or_default();
    Some(Pose {
        position,
        orientation,
    })
}

fn light(ctx: &mut Ctx, el: &Element) -> Option<LightEntity> {
    ctx.unknown_attributes(
        el,
        &[
            "id",
            "position",
            "orientation",
            "color",
            "intensity",
            "medium",
        ],
    );
    for child in &el.children {
        ctx.unknown_element(child, &el.name, &[]);
    }
    let id: Option<String> = ctx.required(el, "id");
    let color: Option<Rgb> = color(ctx, el, None);
    let intensity = ctx.positive(el, "intensity");
    let medium = medium_ref(ctx, el, MediumKind::Led, "<light>".to_string());
    Some(LightEntity {
        id: id?,
        color: color?,
        intensity: intensity?,
        medium: medium?,
        location: el.location,
    })
}

/// A `color` attribute (mandatory unless a default is given), with a did-you-mean hint for colour names.
pub(super) fn color(ctx: &mut Ctx, el: &Element, default: Option<Rgb>) -> Option<Rgb> {
    use crate::config::values::{Value, color_names};
    let Some(attribute) = el.attributes.get("color") else {
        if default.is_none() {
            ctx.error(
                el.location,
                format!("<{}> is missing the attribute 'color'", el.name),
                None,
            );
        }
        return default;
    };
    match Rgb::parse_value(&attribute.value) {
        Ok(rgb) => Some(rgb),
        Err(reason) => {
            let hint = did_you_mean(attribute.value.trim(), color_names());
            ctx.error(
                attribute.location,
                format!("invalid 'color' in <{}>: {reason}", el.name),
                hint,
            );
            None
        }
    }
}

fn target(ctx: &mut Ctx, el: &Element) -> Option<TargetEntity> {
    ctx.unknown_attributes(
        el,
        &["id", "radius", "height", "color", "led_height", "medium"],
    );
    let id: Option<String> = ctx.required(el, "id");
    let radius = ctx.positive(el, "radius");
    let height = ctx.positive(el, "height");
    let color = color(ctx, el, Some(Rgb { r: 255, g: 0, b: 0 }));
    let led_height: f64 = ctx.attr(el, "led_height").unwrap_or(TARGET_LED_HEIGHT);
    let led_ok = ctx.in_range(el, "led_height", led_height, 0.0, None);
    if led_height >= CAMERA_HEIGHT {
        let at = el
            .attributes
            .get("led_height")
            .map_or(el.location, |a| a.location);
        ctx.warn(
            at,
            format!("target LED at {led_height} m is not below the e-puck camera ({CAMERA_HEIGHT} m): cameras will not see it"),
            None,
        );
    }
    let medium = medium_ref(ctx, el, MediumKind::Led, "<target>".to_string());
    led_ok.then_some(())?;
    Some(TargetEntity {
        id: id?,
        radius: radius?,
        height: height?,
        color: color?,
        led_height,
        medium: medium?,
        location: el.location,
    })
}

/// How messages name an entity, e.g. `<e-puck> 'ep0'`.
pub(super) fn describe(entity: &Entity) -> String {
    format!("<{}> '{}'", entity.tag(), entity.id())
}
