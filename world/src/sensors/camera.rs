//! The omnidirectional camera: the lit LEDs in view, lower than the camera, not the robot's own and not hidden
//! behind a body; reported nearest first as colour, bearing and distance in cm, at most
//! `swarm_contract::messages::MAX_CAMERA_BLOBS` of them. What is in view depends on the body: the e-puck sees
//! LEDs within 0.35 m, the foot-bot those inside its camera's cone (`swarm_contract::bodies::CameraView`).

use rand_chacha::ChaCha8Rng;
use rand_distr::Distribution;
use swarm_contract::messages::{CameraBlob, SensorFrame};

use crate::devices::CameraOptions;
use crate::geometry::{Vec2, wrap_angle};
use crate::media::led::LedMedium;
use crate::scene::{BodyRef, Scene};
use crate::sensors::Observer;
use crate::sensors::insert_nearest;

/// Side of the LED medium's grid cells in metres: the e-puck camera's range, so its query touches at most four.
pub const LED_CELL: f32 = 0.35;

/// Fills the camera part of `frame` for robot `me`.
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
        body,
    } = observer;
    let camera_height = body.camera_height;
    let mut len = 0usize;
    let noise = super::noise::normal(options.noise_std_dev);
    leds.near(position, body.camera_reach(), |led| {
        if led.owner == Some(BodyRef::Robot(me)) || led.height >= camera_height {
            return;
        }
        let mut rel = led.position - position;
        let d = rel.length();
        if d > body.camera_range(led.height)
            || scene.blocked(
                position,
                camera_height,
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
