//! The range-finder ring: `rays` rays from the body centre, evenly spread counter-clockwise from the heading,
//! each reporting the distance from the centre to the nearest other body it meets within `range`, or infinity.
//! It sees every body (robots, obstacles, targets lying in the arena) whatever its height, as a planar lidar
//! mounted above the tallest robot would not; see docs/robots.md.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::devices::RangeFinderOptions;
use crate::geometry::{Aabb, Vec2, unit};
use crate::scene::Scene;
use crate::sensors::Observer;

/// Fills `out` (one entry per ray) with the readings of robot `me`. `scratch` receives the gathered nearby
/// bodies.
pub fn sense(
    scene: &Scene,
    observer: Observer,
    options: &RangeFinderOptions,
    rng: &mut ChaCha8Rng,
    scratch: &mut Vec<u32>,
    out: &mut [f32],
) {
    let Observer {
        me,
        position,
        heading,
        ..
    } = observer;
    let range = options.range;
    scene.gather(&Aabb::around(position, range), scratch);
    scratch.sort_unstable();
    scratch.dedup();
    scratch.retain(|&i| i != me && scene.shapes[i as usize].signed_distance(position) <= range);
    let noise = (options.noise_std_dev > 0.0)
        .then(|| Normal::new(0.0f32, options.noise_std_dev).ok())
        .flatten();
    let step = std::f32::consts::TAU / out.len().max(1) as f32;
    for (i, value) in out.iter_mut().enumerate() {
        let dir: Vec2 = unit(heading + step * i as f32);
        let nearest = scratch
            .iter()
            .filter_map(|&b| scene.shapes[b as usize].ray_hit(position, dir, range))
            .fold(f32::INFINITY, f32::min);
        *value = match (&noise, nearest.is_finite()) {
            (Some(normal), true) => (nearest + normal.sample(rng)).clamp(0.0, range),
            _ => nearest,
        };
    }
}
