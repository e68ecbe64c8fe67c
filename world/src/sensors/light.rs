//! The light sensors: a ring of sensors (the body's light angles) that read every lit, unoccluded light.
//!
//! For a light at 3-D distance d with intensity I the contribution is `exp(-2 d / I)` when `d / I <= 2.5`,
//! weighted by `1 - 2 delta / pi` for a sensor `delta < 90 deg` from the light's bearing; contributions are summed
//! over lights and clamped to [0, 1]. This is the IRIDIA e-puck model and ARGoS' foot-bot model alike; the bodies
//! differ in their angles and in the height the distance is measured from (the e-puck's IR ring at 3.2 cm, the
//! foot-bot's origin on the ground, as ARGoS does). A light is occluded when a body's top is above the sight
//! line.

use rand_chacha::ChaCha8Rng;

use crate::entities::Light;
use crate::geometry::wrap_angle;
use crate::scene::{BodyRef, Scene};
use crate::sensors::Observer;
use crate::sensors::noise;

/// The unweighted reading of one light at 3-D distance `d`: `exp(-2 d / I)` if `d / I <= 2.5`, else 0.
pub fn intensity_at(d: f32, intensity: f32) -> f32 {
    if intensity <= 0.0 || d / intensity > 2.5 {
        0.0
    } else {
        (-2.0 * d / intensity).exp()
    }
}

/// Fills `out` (one entry per light sensor of the observer's body) with the light readings of robot `me`.
pub fn sense(
    scene: &Scene,
    lights: &[Light],
    observer: Observer,
    noise_level: f32,
    rng: &mut ChaCha8Rng,
    out: &mut [f32],
) {
    let Observer {
        me,
        position,
        heading,
        body,
    } = observer;
    out.fill(0.0);
    let sensor_height = body.light_height;
    for light in lights.iter().filter(|l| l.color.is_on()) {
        let flat = light.position - position;
        let dz = light.height - sensor_height;
        let value = intensity_at((flat.length_squared() + dz * dz).sqrt(), light.intensity);
        if value <= 0.0
            || scene.blocked(
                position,
                sensor_height,
                light.position,
                light.height,
                [Some(BodyRef::Robot(me)), None],
                0.0,
            )
        {
            continue;
        }
        let bearing = flat.y.atan2(flat.x) - heading;
        for (reading, angle) in out.iter_mut().zip(body.light_angles_deg) {
            let delta = wrap_angle(bearing - angle.to_radians()).abs();
            if delta < std::f32::consts::FRAC_PI_2 {
                *reading += value * (1.0 - 2.0 * delta / std::f32::consts::PI);
            }
        }
    }
    out.iter_mut().for_each(|v| *v = v.clamp(0.0, 1.0));
    noise::uniform(noise_level, rng, out);
}
