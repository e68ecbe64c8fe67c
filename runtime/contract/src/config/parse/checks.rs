//! Checks across sections, run once everything is read: media references, controller references, entity ids
//! (including the ids `<distribute>` generates: base id + index, no separator) and positions inside the arena.

use std::collections::{HashMap, HashSet};

use super::Ctx;
use super::arena::describe;
use crate::config::model::{Arena, Distribute, Entity, Experiment, Location, PositionMethod, Vec3};
use crate::config::registry::MediumKind;
use crate::config::suggest::did_you_mean;

/// Runs every cross-section check.
pub(super) fn run(ctx: &mut Ctx, experiment: &Experiment) {
    media_references(ctx, experiment);
    controller_references(ctx, experiment);
    unique_ids(ctx, experiment);
    coordinator_references(ctx, experiment);
    inside_arena(ctx, &experiment.arena);
}

/// Tolerance for positions written exactly on the arena's edge (e.g. walls centred on it).
const EDGE_TOLERANCE: f64 = 1e-9;

/// Hand-placed positions and bounded position generators lie within the arena's x-y rectangle (edges included;
/// Gaussian generators are unbounded and left to the world).
fn inside_arena(ctx: &mut Ctx, arena: &Arena) {
    let (half_x, half_y) = (arena.size.x / 2.0, arena.size.y / 2.0);
    let (lo_x, hi_x) = (arena.center.x - half_x, arena.center.x + half_x);
    let (lo_y, hi_y) = (arena.center.y - half_y, arena.center.y + half_y);
    let inside = |p: Vec3| {
        p.x >= lo_x - EDGE_TOLERANCE
            && p.x <= hi_x + EDGE_TOLERANCE
            && p.y >= lo_y - EDGE_TOLERANCE
            && p.y <= hi_y + EDGE_TOLERANCE
    };
    let bounds = format!("the arena spans x {lo_x}..{hi_x}, y {lo_y}..{hi_y}");
    for p in &arena.entities {
        if !inside(p.pose.position) {
            ctx.error(
                p.entity.location(),
                format!(
                    "{} at {} is outside the arena",
                    describe(&p.entity),
                    p.pose.position
                ),
                Some(bounds.clone()),
            );
        }
    }
    for d in &arena.distributions {
        let corners = match &d.position {
            PositionMethod::Uniform { min, max } => Some((*min, *max)),
            PositionMethod::Constant { values } => Some((*values, *values)),
            PositionMethod::Grid {
                center,
                distances,
                layout,
            } => {
                let reach = |n: u32, step: f64| f64::from(n.saturating_sub(1)) * step.abs() / 2.0;
                let (rx, ry) = (reach(layout[0], distances.x), reach(layout[1], distances.y));
                Some((
                    Vec3::new(center.x - rx, center.y - ry, center.z),
                    Vec3::new(center.x + rx, center.y + ry, center.z),
                ))
            }
            PositionMethod::Gaussian { .. } => None,
        };
        if let Some((low, high)) = corners
            && !(inside(low) && inside(high))
        {
            ctx.error(
                d.position_location,
                format!("<distribute> positions from {low} to {high} reach outside the arena"),
                Some(bounds.clone()),
            );
        }
    }
}

fn media_references(ctx: &mut Ctx, experiment: &Experiment) {
    let media = &experiment.media;
    let declared = |kind: MediumKind| -> Option<&str> {
        match kind {
            MediumKind::Led => media.leds.as_ref().map(|m| m.id.as_str()),
            MediumKind::RangeAndBearing => media.range_and_bearing.as_ref().map(|m| m.id.as_str()),
            MediumKind::Pheromone => media.pheromone.as_ref().map(|m| m.id.as_str()),
        }
    };
    let references = std::mem::take(&mut ctx.medium_refs);
    for r in &references {
        let wanted = declared(r.kind);
        if wanted == Some(r.id.as_str()) {
            continue;
        }
        let other = [
            MediumKind::Led,
            MediumKind::RangeAndBearing,
            MediumKind::Pheromone,
        ]
        .into_iter()
        .find(|&k| k != r.kind && declared(k) == Some(r.id.as_str()));
        match (other, wanted) {
            (Some(k), _) => ctx.error(
                r.location,
                format!(
                    "{} uses medium '{}', which is a <{}> medium; it needs a <{}> medium",
                    r.user,
                    r.id,
                    k.tag(),
                    r.kind.tag()
                ),
                None,
            ),
            (None, Some(existing)) => ctx.error(
                r.location,
                format!(
                    "{} uses medium '{}', which <media> does not declare",
                    r.user, r.id
                ),
                did_you_mean(&r.id, [existing])
                    .or_else(|| Some(format!("the <{}> medium is '{existing}'", r.kind.tag()))),
            ),
            (None, None) => ctx.error(
                r.location,
                format!(
                    "{} uses medium '{}', which <media> does not declare",
                    r.user, r.id
                ),
                Some(format!(
                    "add <{} id=\"{}\"/> to <media>",
                    r.kind.tag(),
                    r.id
                )),
            ),
        }
    }
}

/// Every robot's controller is declared, and declares no device that exists only on another robot (e.g.
/// `footbot_proximity` for an e-puck). Reported once per controller and robot kind.
fn controller_references(ctx: &mut Ctx, experiment: &Experiment) {
    let robots = experiment
        .arena
        .entities
        .iter()
        .map(|p| &p.entity)
        .chain(experiment.arena.distributions.iter().map(|d| &d.template));
    let mut checked = HashSet::new();
    for entity in robots {
        let Entity::Robot(robot) = entity else {
            continue;
        };
        let Some(controller) = experiment.controller(&robot.controller) else {
            let hint = did_you_mean(
                &robot.controller,
                experiment.controllers.iter().map(|c| c.id.as_str()),
            );
            ctx.error(
                robot.location,
                format!(
                    "<{}> '{}' refers to controller '{}', which <controllers> does not declare",
                    robot.kind.tag(),
                    robot.id,
                    robot.controller
                ),
                hint,
            );
            continue;
        };
        if !checked.insert((controller.id.as_str(), robot.kind)) {
            continue;
        }
        let foreign = controller
            .sensors
            .iter()
            .chain(&controller.actuators)
            .filter_map(|d| {
                d.body
                    .filter(|&body| body != robot.kind)
                    .map(|body| (d, body))
            });
        for (device, body) in foreign {
            ctx.error(
                device.location,
                format!(
                    "'{}' exists only on the {}, but <{}> '{}' at {} uses controller '{}'",
                    device.name,
                    body.tag(),
                    robot.kind.tag(),
                    robot.id,
                    robot.location,
                    controller.id
                ),
                Some("use the generic name (e.g. proximity, light, ground) or a controller for this robot".into()),
            );
        }
    }
}

/// Every coordinator's controller is declared, and no coordinator shares a robot's id.
fn coordinator_references(ctx: &mut Ctx, experiment: &Experiment) {
    if experiment.coordinators.is_empty() {
        return;
    }
    let robot_ids: HashSet<String> = experiment
        .arena
        .robots()
        .into_iter()
        .map(|r| r.id)
        .collect();
    for coordinator in &experiment.coordinators {
        if experiment.controller(&coordinator.controller).is_none() {
            let hint = did_you_mean(
                &coordinator.controller,
                experiment.controllers.iter().map(|c| c.id.as_str()),
            );
            ctx.error(
                coordinator.location,
                format!(
                    "<coordinator> '{}' refers to controller '{}', which <controllers> does not declare",
                    coordinator.id, coordinator.controller
                ),
                hint,
            );
        }
        if robot_ids.contains(&coordinator.id) {
            ctx.error(
                coordinator.location,
                format!(
                    "duplicate id '{}': a robot of the arena already uses it",
                    coordinator.id
                ),
                None,
            );
        }
    }
}

/// Entity ids are unique across hand-placed entities and every id a distribution generates.
fn unique_ids(ctx: &mut Ctx, experiment: &Experiment) {
    let mut placed: HashMap<&str, &Entity> = HashMap::new();
    for p in &experiment.arena.entities {
        let id = p.entity.id();
        if let Some(first) = placed.get(id) {
            ctx.error(
                p.entity.location(),
                format!(
                    "duplicate id '{id}': {} at {} already uses it",
                    describe(first),
                    first.location()
                ),
                None,
            );
        } else {
            placed.insert(id, &p.entity);
        }
    }
    let distributions = &experiment.arena.distributions;
    for (i, d) in distributions.iter().enumerate() {
        for p in &experiment.arena.entities {
            if let Some(index) = generated_index(d, p.entity.id()) {
                report_generated(ctx, d, index, p.entity.location(), &describe(&p.entity));
            }
        }
        for earlier in &distributions[..i] {
            if let Some(id) = first_shared_id(earlier, d) {
                ctx.error(
                    d.entity_location,
                    format!(
                        "<distribute> generates id '{id}', which the <distribute> at {} also generates",
                        earlier.location
                    ),
                    Some("give the templates different ids or non-overlapping base_num ranges".to_string()),
                );
            }
        }
    }
}

fn report_generated(ctx: &mut Ctx, d: &Distribute, index: u64, at: Location, what: &str) {
    ctx.error(
        at,
        format!("duplicate id '{}{index}': {what} clashes with the ids generated by the <distribute> at {}", d.template.id(), d.location),
        None,
    );
}

/// The range of indices `[first, last]` a distribution generates.
fn range(d: &Distribute) -> Option<(u64, u64)> {
    let first = u64::from(d.base_num);
    (d.quantity > 0).then(|| (first, first + u64::from(d.quantity) - 1))
}

/// The index `n` if `id` is `base` + `n` for an `n` this distribution generates.
fn generated_index(d: &Distribute, id: &str) -> Option<u64> {
    let digits = id.strip_prefix(d.template.id())?;
    let n = canonical_number(digits)?;
    let (lo, hi) = range(d)?;
    (lo..=hi).contains(&n).then_some(n)
}

/// `digits` as a number if it is how a number prints (no sign, no leading zero).
fn canonical_number(digits: &str) -> Option<u64> {
    let canonical = !digits.is_empty()
        && digits.bytes().all(|b| b.is_ascii_digit())
        && (digits == "0" || !digits.starts_with('0'));
    canonical.then(|| digits.parse().ok()).flatten()
}

/// An id both distributions generate, if any. Ids are `base` + number, so they can only meet when one base is
/// the other followed by digits; then the longer base's numbers, per digit count, form one contiguous run of the
/// shorter base's numbers.
fn first_shared_id(a: &Distribute, b: &Distribute) -> Option<String> {
    let (short, long) = if a.template.id().len() <= b.template.id().len() {
        (a, b)
    } else {
        (b, a)
    };
    let rest = long.template.id().strip_prefix(short.template.id())?;
    let (short_lo, short_hi) = range(short)?;
    let (long_lo, long_hi) = range(long)?;
    if rest.is_empty() {
        let lo = short_lo.max(long_lo);
        return (lo <= short_hi.min(long_hi)).then(|| format!("{}{lo}", short.template.id()));
    }
    let prefix = u128::from(canonical_number(rest)?);
    // long id = short base + rest + n = short base + (prefix * 10^digits(n) + n).
    for digits in 1..=20u32 {
        let scale = 10u128.pow(digits);
        let smallest = if digits == 1 { 0 } else { scale / 10 };
        let lo = u128::from(long_lo).max(smallest);
        let hi = u128::from(long_hi).min(scale - 1);
        if lo > hi {
            continue;
        }
        let (run_lo, run_hi) = (prefix * scale + lo, prefix * scale + hi);
        let meet_lo = run_lo.max(u128::from(short_lo));
        if meet_lo <= run_hi.min(u128::from(short_hi)) {
            return Some(format!("{}{meet_lo}", short.template.id()));
        }
    }
    None
}
