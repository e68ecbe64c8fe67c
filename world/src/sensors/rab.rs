//! The range-and-bearing receiver: messages broadcast in the previous tick by other robots whose emitter range
//! reaches this robot and whose line of sight is not cut by a body taller than the receiver's turret. Range is
//! reported in cm (an e-puck: minus two e-puck radii, the IRIDIA convention; a foot-bot: centre to centre, as
//! ARGoS does) and bearing in the receiver's frame; each message may be lost with the receiver's
//! `loss_probability`. Nearest first, at most `swarm_contract::messages::MAX_RAB_MESSAGES`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::{RabMessage, SensorFrame};

use crate::devices::RabOptions;
use crate::geometry::wrap_angle;
use crate::media::rab::RabMedium;
use crate::scene::{BodyRef, Scene};
use crate::sensors::Observer;
use crate::sensors::insert_nearest;

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
        body,
    } = observer;
    let turret = body.rab_height;
    let surfaces_cm = if body.rab_range_between_surfaces {
        2.0 * body.radius * 100.0
    } else {
        0.0
    };
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
            turret,
            msg.position,
            turret,
            [Some(BodyRef::Robot(me)), Some(BodyRef::Robot(msg.sender))],
            turret + f32::EPSILON,
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
            range_cm: d * 100.0 - surfaces_cm,
            bearing: wrap_angle(rel.y.atan2(rel.x) - heading),
        };
        insert_nearest(&mut frame.rab, &mut len, received, |m| m.range_cm);
    });
    frame.rab_len = len as u8;
}
