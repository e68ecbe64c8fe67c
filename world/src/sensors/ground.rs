//! The ground sensors: the floor's grey level (1 white, 0 black) under the points the body places them at
//! (e-puck: three in front of the wheel axis, index 0 on the left; foot-bot: the four motor-ground sensors).

use rand_chacha::ChaCha8Rng;

use crate::geometry::Vec2;
use crate::sensors::Observer;
use crate::sensors::noise;

/// Fills `out` (one entry per ground sensor of the observer's body) with the grey levels under the sensors;
/// `floor` gives the grey level at an arena point.
pub fn sense(
    observer: Observer,
    floor: impl Fn(Vec2) -> f32,
    noise_level: f32,
    rng: &mut ChaCha8Rng,
    out: &mut [f32],
) {
    for (value, &[x, y]) in out.iter_mut().zip(observer.body.ground_offsets) {
        *value = floor(observer.to_arena(Vec2::new(x, y))).clamp(0.0, 1.0);
    }
    noise::uniform(noise_level, rng, out);
}
