//! The three e-puck ground sensors: the floor's grey level (1 white, 0 black) under three points in front of the
//! wheel axis, index 0 on the left.

use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::GROUND_SENSORS;

use crate::geometry::Vec2;
use crate::sensors::noise;

/// Sensor positions in the robot frame (x forward, y left), in metres; index 0 is the left sensor.
pub const GROUND_OFFSETS: [Vec2; GROUND_SENSORS] = [
    Vec2::new(0.03, 0.009),
    Vec2::new(0.03, 0.0),
    Vec2::new(0.03, -0.009),
];

/// Fills `out` with the grey levels under the sensors of a robot at `position`/`heading`; `floor` gives the grey
/// level at an arena point.
pub fn sense(
    position: Vec2,
    heading: f32,
    floor: impl Fn(Vec2) -> f32,
    noise_level: f32,
    rng: &mut ChaCha8Rng,
    out: &mut [f32; GROUND_SENSORS],
) {
    let (s, c) = heading.sin_cos();
    for (value, offset) in out.iter_mut().zip(GROUND_OFFSETS) {
        let p = position + Vec2::new(c * offset.x - s * offset.y, s * offset.x + c * offset.y);
        *value = floor(p).clamp(0.0, 1.0);
    }
    noise::uniform(noise_level, rng, out);
}
