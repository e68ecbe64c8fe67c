//! The e-puck proximity sensors: eight IR rays from the body edge, read through the IRIDIA calibration curve.
//!
//! Sensor i points at the physical angle of the real e-puck (17, 50, 90, 150, 210, 270, 310, 343 degrees, so
//! sensors 0 and 7 are the symmetric front pair); `argos_uniform_ring` casts at ARGoS' `11.25 + 45 i` degrees
//! instead. A ray starts on the body edge and reaches 5 cm; it cannot tell robots, obstacles and targets apart.

use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::PROXIMITY_SENSORS;

use crate::devices::ProximityOptions;
use crate::entities::ROBOT_RADIUS;
use std::sync::LazyLock;

use crate::geometry::{Aabb, Vec2, unit};
use crate::scene::{PROXIMITY_REACH, Scene};
use crate::sensors::Observer;
use crate::sensors::noise;

/// Reach of a proximity ray beyond the body edge, in metres (IRIDIA model).
pub const PROXIMITY_RANGE: f32 = 0.05;

/// The physical sensor angles in degrees, counter-clockwise from the heading.
pub const PHYSICAL_ANGLES_DEG: [f32; PROXIMITY_SENSORS] =
    [17.0, 50.0, 90.0, 150.0, 210.0, 270.0, 310.0, 343.0];

/// The angle of sensor `i` in radians, on the physical layout or on ARGoS' uniform ring.
pub fn sensor_angle(i: usize, argos_uniform_ring: bool) -> f32 {
    if argos_uniform_ring {
        (11.25 + 45.0 * i as f32).to_radians()
    } else {
        PHYSICAL_ANGLES_DEG[i].to_radians()
    }
}

/// Unit vectors of the sensor directions in the robot frame, for both layouts (computed once).
fn sensor_directions(argos_uniform_ring: bool) -> &'static [Vec2; PROXIMITY_SENSORS] {
    static TABLES: LazyLock<[[Vec2; PROXIMITY_SENSORS]; 2]> = LazyLock::new(|| {
        [false, true].map(|ring| std::array::from_fn(|i| unit(sensor_angle(i, ring))))
    });
    &TABLES[usize::from(argos_uniform_ring)]
}

/// The IRIDIA calibration: the reading for an object `d` metres from the ray start,
/// `298.701 d^2 - 36.8961 d + 1.08212` clamped to [0, 1] within the range, 0 beyond.
pub fn iridia_curve(d: f32) -> f32 {
    if d > PROXIMITY_RANGE {
        return 0.0;
    }
    (298.701 * d * d - 36.8961 * d + 1.08212).clamp(0.0, 1.0)
}

/// Fills `out` with the readings of the robot with scene index `me` at `position`/`heading`.
/// `scratch` receives the gathered nearby bodies (kept by the caller so that sensing does not allocate).
pub fn sense(
    scene: &Scene,
    observer: Observer,
    options: &ProximityOptions,
    rng: &mut ChaCha8Rng,
    scratch: &mut Vec<u32>,
    out: &mut [f32; PROXIMITY_SENSORS],
) {
    let Observer {
        me,
        position,
        heading,
    } = observer;
    scene.gather(&Aabb::around(position, PROXIMITY_REACH), scratch);
    scratch.retain(|&i| {
        i != me && scene.shapes[i as usize].signed_distance(position) <= PROXIMITY_REACH
    });
    let (s, c) = heading.sin_cos();
    for (value, local) in out
        .iter_mut()
        .zip(sensor_directions(options.argos_uniform_ring))
    {
        let dir = Vec2::new(c * local.x - s * local.y, s * local.x + c * local.y);
        let origin = position + dir * ROBOT_RADIUS;
        let nearest = scratch
            .iter()
            .filter_map(|&b| scene.shapes[b as usize].ray_hit(origin, dir, PROXIMITY_RANGE))
            .fold(f32::INFINITY, f32::min);
        *value = if nearest.is_finite() {
            iridia_curve(nearest)
        } else {
            0.0
        };
    }
    noise::uniform(options.noise_level, rng, out);
    noise::gaussian(options.noise_std_dev, rng, out);
}
