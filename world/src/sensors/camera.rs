//! The omnidirectional camera: the lit LEDs within 0.35 m, lower than the camera, not the robot's own and not
//! hidden behind a body; reported nearest first as colour, bearing and distance in cm, at most
//! `swarm_contract::messages::MAX_CAMERA_BLOBS` of them.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use swarm_contract::messages::{CameraBlob, SensorFrame};

use crate::devices::CameraOptions;
use crate::geometry::{Vec2, wrap_angle};
use crate::media::led::LedMedium;
use crate::scene::{BodyRef, Scene};
use crate::sensors::Observer;
use crate::sensors::insert_nearest;

/// Radius of the ground disc the camera sees, in metres.
pub const CAMERA_RANGE: f32 = 0.35;
/// Height of the camera above the ground in metres; only LEDs below it are seen.
pub const CAMERA_HEIGHT: f32 = 0.122;

/// Fills the camera part of `frame` for robot `me` at `position`/`heading`.
pub fn sense(
    scene: &Scene,
    leds: &LedMedium,
    observer: Observer,
    options: &CameraOptions,
    rng: &mut ChaCha8Rng,
    frame: &mut SensorFrame,
) {
    let Observer {
        me,
        position,
        heading,
    } = observer;
    let mut len = 0usize;
    let noise = (options.noise_std_dev > 0.0)
        .then(|| Normal::new(0.0f32, options.noise_std_dev).ok())
        .flatten();
    leds.near(position, CAMERA_RANGE, |led| {
        if led.owner == Some(BodyRef::Robot(me)) || led.height >= CAMERA_HEIGHT {
            return;
        }
        let mut rel = led.position - position;
        let d = rel.length();
        if d > CAMERA_RANGE
            || scene.blocked(
                position,
                CAMERA_HEIGHT,
                led.position,
                led.height,
                [Some(BodyRef::Robot(me)), led.owner],
                0.0,
            )
        {
            return;
        }
        if let Some(normal) = &noise {
            rel += Vec2::new(normal.sample(rng), normal.sample(rng));
        }
        let blob = CameraBlob {
            color: led.color,
            bearing: wrap_angle(rel.y.atan2(rel.x) - heading),
            distance_cm: rel.length() * 100.0,
        };
        insert_nearest(&mut frame.camera, &mut len, blob, |b| b.distance_cm);
    });
    frame.camera_len = len as u8;
}
