//! The range-and-bearing receiver: messages broadcast in the previous tick by other robots whose emitter range
//! reaches this robot and whose line of sight is not cut by a body taller than a robot. Range is reported in cm
//! minus two body radii and bearing in the receiver's frame (the IRIDIA convention); each message may be lost
//! with the receiver's `loss_probability`. Nearest first, at most `swarm_contract::messages::MAX_RAB_MESSAGES`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::{RabMessage, SensorFrame};

use crate::devices::RabOptions;
use crate::entities::{ROBOT_HEIGHT, ROBOT_RADIUS};
use crate::geometry::wrap_angle;
use crate::media::rab::RabMedium;
use crate::scene::{BodyRef, Scene};
use crate::sensors::Observer;
use crate::sensors::insert_nearest;

/// Height of the range-and-bearing turret above the ground, in metres.
pub const RAB_HEIGHT: f32 = ROBOT_HEIGHT;

/// Fills the range-and-bearing part of `frame` for robot `me` at `position`/`heading`.
pub fn sense(
    scene: &Scene,
    medium: &RabMedium,
    observer: Observer,
    options: &RabOptions,
    rng: &mut ChaCha8Rng,
    frame: &mut SensorFrame,
) {
    let Observer {
        me,
        position,
        heading,
    } = observer;
    let mut len = 0usize;
    medium.near(position, |msg| {
        if msg.sender == me {
            return;
        }
        let rel = msg.position - position;
        let d = rel.length();
        if d > msg.range {
            return;
        }
        let blocked = scene.blocked(
            position,
            RAB_HEIGHT,
            msg.position,
            RAB_HEIGHT,
            [Some(BodyRef::Robot(me)), Some(BodyRef::Robot(msg.sender))],
            RAB_HEIGHT + f32::EPSILON,
        );
        if blocked
            || (options.loss_probability > 0.0 && rng.random::<f32>() < options.loss_probability)
        {
            return;
        }
        let received = RabMessage {
            sender: msg.sender,
            payload: msg.payload,
            len: msg.len.min(options.data_size),
            range_cm: d * 100.0 - 2.0 * ROBOT_RADIUS * 100.0,
            bearing: wrap_angle(rel.y.atan2(rel.x) - heading),
        };
        insert_nearest(&mut frame.rab, &mut len, received, |m| m.range_cm);
    });
    frame.rab_len = len as u8;
}
