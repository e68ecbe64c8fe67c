//! Where a robot that joins a running swarm is placed (docs/joins.md): at the pose it asks for when that is
//! free, else at the nearest free pose on rings around it, else nowhere, with the reason.
//!
//! Free means inside the arena and clear of every wall, box, cylinder, target lying in the arena and robot body
//! in the arena (dead bodies that stay count). The rings are searched in a fixed order, so the same world state
//! gives the same place: joins by schedule are as deterministic as the rest of a lockstep run.

use crate::arena::Arena;
use crate::entities::{RobotId, TargetState};
use crate::geometry::{Vec2, unit};

/// Rings searched around the wanted position; ring k has radius k body diameters and 8 k candidate places.
const RINGS: u32 = 8;

/// Why a robot could not be placed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PlaceRefused(pub String);

/// A free pose for `robot` (radius `radius`) at or near `wanted`, facing `heading`.
pub fn free_pose(
    arena: &Arena,
    robot: RobotId,
    wanted: Vec2,
    heading: f32,
    radius: f32,
) -> Result<(Vec2, f32), PlaceRefused> {
    let first = match blocker(arena, robot, wanted, radius) {
        None => return Ok((wanted, heading)),
        Some(what) => what,
    };
    for ring in 1..=RINGS {
        let distance = 2.0 * radius * ring as f32;
        let places = 8 * ring;
        for k in 0..places {
            let angle = std::f32::consts::TAU * k as f32 / places as f32;
            let at = wanted + unit(angle) * distance;
            if blocker(arena, robot, at, radius).is_none() {
                return Ok((at, heading));
            }
        }
    }
    Err(PlaceRefused(format!(
        "({:.3}, {:.3}) is taken by {first}, and no free place is within {:.2} m of it",
        wanted.x,
        wanted.y,
        2.0 * radius * RINGS as f32
    )))
}

/// What keeps a disc of `radius` at `at` from being placed, if anything.
fn blocker(arena: &Arena, robot: RobotId, at: Vec2, radius: f32) -> Option<String> {
    if at.x - radius < arena.min.x
        || at.y - radius < arena.min.y
        || at.x + radius > arena.max.x
        || at.y + radius > arena.max.y
    {
        return Some("the arena's edge".into());
    }
    if let Some(o) = arena
        .obstacles
        .iter()
        .find(|o| o.placed.gap_to_disc(at, radius) <= 0.0)
    {
        return Some(format!("'{}'", o.name));
    }
    if let Some(t) = arena
        .targets
        .iter()
        .filter(|t| t.state == TargetState::InArena)
        .find(|t| t.placed.gap_to_disc(at, radius) <= 0.0)
    {
        return Some(format!("target '{}'", t.name));
    }
    arena
        .robots
        .iter()
        .enumerate()
        .filter(|&(i, r)| i != robot.index() && r.present && !r.removed)
        .find(|(_, r)| (r.position - at).length() <= r.body.radius + radius)
        .map(|(_, r)| format!("robot '{}'", r.name))
}
