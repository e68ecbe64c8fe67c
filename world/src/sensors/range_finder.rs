//! The range-finder ring: `rays` rays from the body centre, evenly spread counter-clockwise from the heading,
//! each reporting the distance from the centre to the nearest other body it meets within `range`, or infinity.
//! It sees every body (robots, obstacles, targets lying in the arena) whatever its height, as a planar lidar
//! mounted above the tallest robot would not; see docs/robots.md.

use rand_chacha::ChaCha8Rng;
use rand_distr::Distribution;

use crate::devices::RangeFinderOptions;
use crate::geometry::{Vec2, unit};
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
    scene.nearby(position, range, me, scratch);
    // A long range spans many grid cells, so the same body comes back many times; each ray would test it again.
    scratch.sort_unstable();
    scratch.dedup();
    let noise = super::noise::normal(options.noise_std_dev);
    let step = std::f32::consts::TAU / out.len().max(1) as f32;
    for (i, value) in out.iter_mut().enumerate() {
        let dir: Vec2 = unit(heading + step * i as f32);
        let nearest = scene.nearest_hit(scratch, position, dir, range);
        *value = match (&noise, nearest.is_finite()) {
            (Some(normal), true) => (nearest + normal.sample(rng)).clamp(0.0, range),
            _ => nearest,
        };
    }
}
