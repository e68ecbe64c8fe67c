//! `<distribute>` exactly as ARGoS does it (docs/epuck-and-world.md 4.4): ids are the base id followed by the index
//! (from `base_num`, no separator); each entity's pose is drawn from the position and orientation generators and
//! redrawn while its body collides with anything placed before it, at most `max_trials` times; bodiless entities
//! are never checked; a grid takes the lattice points in order and fails on a collision.
//!
//! This module only draws poses and checks them; turning entities into world objects is `from_config`'s job.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use swarm_contract::config::{Distribute, Entity, Euler, OrientationMethod, PositionMethod, Vec3};

use crate::error::WorldError;
use crate::geometry::{Placed, Shape, Vec2};

/// The outline of an entity at a pose, or `None` for bodiless entities (lights).
pub fn outline(entity: &Entity, position: Vec2, yaw: f32) -> Option<Placed> {
    let shape = match entity {
        Entity::Box(b) => Shape::Rect {
            half: Vec2::new(b.size.x as f32 / 2.0, b.size.y as f32 / 2.0),
        },
        Entity::Cylinder(c) => Shape::Disc {
            radius: c.radius as f32,
        },
        Entity::Robot(r) => Shape::Disc {
            radius: r.body().radius,
        },
        Entity::Target(t) => Shape::Disc {
            radius: t.radius as f32,
        },
        Entity::Light(_) => return None,
    };
    Some(Placed::new(shape, position, yaw))
}

fn uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    if hi > lo {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

fn gaussian(rng: &mut ChaCha8Rng, mean: f64, std_dev: f64) -> f64 {
    match Normal::new(mean, std_dev) {
        Ok(n) if std_dev > 0.0 => n.sample(rng),
        _ => mean,
    }
}

/// Draws one position (x, y; z is ignored in 2-D) for copy `index`.
fn draw_position(method: &PositionMethod, index: u32, rng: &mut ChaCha8Rng) -> Vec2 {
    let v = match method {
        PositionMethod::Uniform { min, max } => Vec3::new(
            uniform(rng, min.x, max.x),
            uniform(rng, min.y, max.y),
            uniform(rng, min.z, max.z),
        ),
        PositionMethod::Gaussian { mean, std_dev } => Vec3::new(
            gaussian(rng, mean.x, std_dev.x),
            gaussian(rng, mean.y, std_dev.y),
            gaussian(rng, mean.z, std_dev.z),
        ),
        PositionMethod::Constant { values } => *values,
        PositionMethod::Grid {
            center,
            distances,
            layout,
        } => {
            let [nx, ny, _] = layout.map(|n| n.max(1));
            let (ix, iy) = (index % nx, (index / nx) % ny);
            let offset = |i: u32, n: u32, d: f64| (f64::from(i) - f64::from(n - 1) / 2.0) * d;
            Vec3::new(
                center.x + offset(ix, nx, distances.x),
                center.y + offset(iy, ny, distances.y),
                center.z,
            )
        }
    };
    Vec2::new(v.x as f32, v.y as f32)
}

/// Draws one heading in radians (the Z Euler angle).
fn draw_yaw(method: &OrientationMethod, rng: &mut ChaCha8Rng) -> f32 {
    let z_deg = match method {
        OrientationMethod::Uniform { min, max } => {
            let z = uniform(rng, min.z_deg, max.z_deg);
            // Y and X are drawn too, so that the stream advances as ARGoS' three-angle generator does.
            uniform(rng, min.y_deg, max.y_deg);
            uniform(rng, min.x_deg, max.x_deg);
            z
        }
        OrientationMethod::Gaussian { mean, std_dev } => {
            let z = gaussian(rng, mean.z_deg, std_dev.z_deg);
            gaussian(rng, mean.y_deg, std_dev.y_deg);
            gaussian(rng, mean.x_deg, std_dev.x_deg);
            z
        }
        OrientationMethod::Constant { values } => values.z_deg,
    };
    Euler {
        z_deg,
        y_deg: 0.0,
        x_deg: 0.0,
    }
    .yaw_radians() as f32
}

/// One placed copy of a distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The copy's id (`base id` + index).
    pub id: String,
    /// Its position.
    pub position: Vec2,
    /// Its heading in radians.
    pub yaw: f32,
}

/// Places every copy of `dist`, checking bodies against `occupied` (which grows with each placed body).
/// `location` is the `path:line:column` of the `<distribute>` for errors.
pub fn place(
    dist: &Distribute,
    occupied: &mut Vec<Placed>,
    rng: &mut ChaCha8Rng,
    location: &str,
) -> Result<Vec<Placement>, WorldError> {
    if let PositionMethod::Grid { layout, .. } = &dist.position {
        let room = layout.iter().map(|&n| n as usize).product::<usize>();
        if dist.quantity as usize > room {
            return Err(WorldError::GridTooSmall {
                location: location.to_owned(),
                layout: format!("{},{},{}", layout[0], layout[1], layout[2]),
                room,
                quantity: dist.quantity as usize,
            });
        }
    }
    let is_grid = matches!(dist.position, PositionMethod::Grid { .. });
    let mut placed = Vec::with_capacity(dist.quantity as usize);
    for index in 0..dist.quantity {
        let id = dist.entity_id(index);
        let mut trials = 0u32;
        loop {
            let position = draw_position(&dist.position, index, rng);
            let yaw = draw_yaw(&dist.orientation, rng);
            let body = outline(&dist.template, position, yaw);
            let free = body.is_none_or(|b| !occupied.iter().any(|o| o.overlaps(&b)));
            if free {
                occupied.extend(body);
                placed.push(Placement { id, position, yaw });
                break;
            }
            if is_grid {
                return Err(WorldError::GridCollision {
                    location: location.to_owned(),
                    id,
                    x: position.x,
                    y: position.y,
                    placed: index as usize,
                    quantity: dist.quantity as usize,
                });
            }
            trials += 1;
            if trials > dist.max_trials {
                return Err(WorldError::Placement {
                    location: location.to_owned(),
                    base: dist.template.id().to_owned(),
                    id,
                    placed: index as usize,
                    quantity: dist.quantity as usize,
                    max_trials: dist.max_trials,
                });
            }
        }
    }
    Ok(placed)
}
