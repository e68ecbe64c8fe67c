//! The proximity sensors: IR rays from the body's sensor ring, each read through its body's calibration curve.
//!
//! The body (`swarm_contract::bodies`) says where the rays start, which way they point and how far they reach:
//! the e-puck's eight rays start on its edge at the real robot's physical angles (17, 50, 90, 150, 210, 270, 310,
//! 343 degrees, so 0 and 7 are the symmetric front pair) and reach 5 cm; `argos_uniform_ring` casts them at
//! ARGoS' `11.25 + 45 i` degrees instead. The foot-bot's 24 rays start on its edge at `7.5 + 15 i` degrees and
//! reach 10 cm. A ray cannot tell robots, obstacles and targets apart.

use std::sync::LazyLock;

use rand_chacha::ChaCha8Rng;
use swarm_contract::bodies::{
    BodyModel, EPUCK_SENSOR_ANGLES_DEG, EPUCK_UNIFORM_RING_DEG, FOOTBOT_SENSOR_ANGLES_DEG,
    ProximityCurve, RobotKind,
};

use crate::devices::ProximityOptions;
use crate::geometry::{Vec2, unit};
use crate::scene::Scene;
use crate::sensors::Observer;
use crate::sensors::noise;

/// The IRIDIA e-puck calibration: the reading for an object `d` metres from the ray start,
/// `298.701 d^2 - 36.8961 d + 1.08212` clamped to [0, 1] within the 5 cm range, 0 beyond.
pub fn iridia_curve(d: f32) -> f32 {
    if d > swarm_contract::bodies::EPUCK.proximity_range {
        return 0.0;
    }
    (298.701 * d * d - 36.8961 * d + 1.08212).clamp(0.0, 1.0)
}

/// The foot-bot's calibration: 1 closer than 0.009889556 m, else `0.0100527 / (d + 0.000163144)` within the
/// 10 cm range, 0 beyond.
pub fn footbot_curve(d: f32) -> f32 {
    if d > swarm_contract::bodies::FOOTBOT.proximity_range {
        0.0
    } else if d < 0.009_889_556 {
        1.0
    } else {
        0.010_052_7 / (d + 0.000_163_144)
    }
}

/// The reading of a body's sensor whose ray meets something `d` metres from its start.
pub fn reading(curve: ProximityCurve, d: f32) -> f32 {
    match curve {
        ProximityCurve::Iridia => iridia_curve(d),
        ProximityCurve::FootBot => footbot_curve(d),
    }
}

/// Unit vectors of a body's ray directions in the robot frame (computed once per layout).
fn sensor_directions(body: &BodyModel, argos_uniform_ring: bool) -> &'static [Vec2] {
    static TABLES: LazyLock<[Vec<Vec2>; 3]> = LazyLock::new(|| {
        let table = |angles: &[f32]| angles.iter().map(|a| unit(a.to_radians())).collect();
        [
            table(&EPUCK_SENSOR_ANGLES_DEG),
            table(&EPUCK_UNIFORM_RING_DEG),
            table(&FOOTBOT_SENSOR_ANGLES_DEG),
        ]
    });
    match (body.kind, argos_uniform_ring) {
        (RobotKind::EPuck, false) => &TABLES[0],
        (RobotKind::EPuck, true) => &TABLES[1],
        (RobotKind::FootBot, _) => &TABLES[2],
        (RobotKind::Disc, _) => &[],
    }
}

/// Fills `out` (one entry per proximity sensor of the observer's body) with the readings of the robot with scene
/// index `me`. `scratch` receives the gathered nearby bodies (kept by the caller so that sensing does not
/// allocate).
pub fn sense(
    scene: &Scene,
    observer: Observer,
    options: &ProximityOptions,
    rng: &mut ChaCha8Rng,
    scratch: &mut Vec<u32>,
    out: &mut [f32],
) {
    let Observer {
        me,
        position,
        heading,
        body,
    } = observer;
    scene.nearby(position, body.proximity_reach(), me, scratch);
    let (s, c) = heading.sin_cos();
    for (value, local) in out
        .iter_mut()
        .zip(sensor_directions(body, options.argos_uniform_ring))
    {
        let dir = Vec2::new(c * local.x - s * local.y, s * local.x + c * local.y);
        let origin = position + dir * body.proximity_mount_radius;
        let nearest = scene.nearest_hit(scratch, origin, dir, body.proximity_range);
        *value = if nearest.is_finite() {
            reading(body.proximity_curve, nearest)
        } else {
            0.0
        };
    }
    noise::uniform(options.noise_level, rng, out);
    noise::gaussian(options.noise_std_dev, rng, out);
}
