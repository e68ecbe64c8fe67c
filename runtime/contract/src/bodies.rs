//! The robot bodies the platform simulates: their shape, wheels and where their sensors sit.
//!
//! Both sides of the frame need these numbers: the world casts the rays and fills the readings, and a controller
//! that combines readings (e.g. sums the proximity vectors as ARGoS' foot-bot examples do) needs each sensor's
//! angle. A [`BodyModel`] is plain data; the sensor models themselves live in the world.
//!
//! The e-puck follows the IRIDIA model (docs/epuck-and-world.md). The foot-bot follows the numbers ARGoS gives
//! its foot-bot (docs/robots.md): a 0.085 m disc, wheels 0.14 m apart, 24 proximity and 24 light sensors on one
//! ring starting 7.5 degrees left of the heading, four motor-ground sensors under the wheel axis. The disc robot
//! is a configurable differential-drive body for the related methods' robots, by default TurtleBot3-like
//! (radius 0.105 m, 0.22 m/s, 2.84 rad/s); it senses with a range-finder ring, not with IR rings.

use crate::messages::{MAX_GROUND_SENSORS, MAX_LIGHT_SENSORS, MAX_PROXIMITY_SENSORS};

/// Which robot a body is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RobotKind {
    /// The e-puck (IRIDIA model), `<e-puck>`.
    EPuck,
    /// ARGoS' foot-bot, `<foot-bot>`.
    FootBot,
    /// A configurable differential-drive disc, `<disc-robot>` (defaults: [`DISC`]).
    Disc,
}

impl RobotKind {
    /// Every kind, in configuration-element order.
    pub const ALL: [RobotKind; 3] = [RobotKind::EPuck, RobotKind::FootBot, RobotKind::Disc];

    /// The configuration element that places such a robot.
    pub fn tag(self) -> &'static str {
        match self {
            RobotKind::EPuck => "e-puck",
            RobotKind::FootBot => "foot-bot",
            RobotKind::Disc => "disc-robot",
        }
    }

    /// The kind whose element is `tag`.
    pub fn from_tag(tag: &str) -> Option<RobotKind> {
        Self::ALL.into_iter().find(|k| k.tag() == tag)
    }

    /// The body of this kind (for the disc robot: its defaults, which a configuration may change).
    pub fn body(self) -> &'static BodyModel {
        match self {
            RobotKind::EPuck => &EPUCK,
            RobotKind::FootBot => &FOOTBOT,
            RobotKind::Disc => &DISC,
        }
    }
}

/// How a proximity sensor turns the distance to the nearest body on its ray into a reading in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProximityCurve {
    /// IRIDIA's e-puck calibration `298.701 d^2 - 36.8961 d + 1.08212`, clamped to [0, 1].
    Iridia,
    /// The foot-bot's: 1 closer than 0.009889556 m, else `0.0100527 / (d + 0.000163144)` (0.1 at the range end).
    FootBot,
}

/// What part of the ground plane the omnidirectional camera sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CameraView {
    /// A disc of this radius in metres around the robot, whatever the LED's height (the e-puck model).
    Disc(f32),
    /// A cone pointing down from the camera with this half-aperture in radians: an LED at height `h` is seen up
    /// to `(camera height - h) * tan(aperture)` away (the foot-bot's mirror camera, 70 degrees by default).
    Aperture(f32),
}

/// A robot body: geometry, wheels and sensor placement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyModel {
    /// Which robot this is.
    pub kind: RobotKind,
    /// Body radius in metres (a disc seen from above).
    pub radius: f32,
    /// Body height in metres; a taller body occludes what passes below its top.
    pub height: f32,
    /// Mass in kg (what a pushed robot weighs in the physics engine).
    pub mass: f32,
    /// Distance between the wheel contact points in metres.
    pub inter_wheel_distance: f32,
    /// Largest wheel speed in cm/s; wheel commands beyond it are clamped, and so are velocity commands' forward
    /// speeds.
    pub max_wheel_speed_cm_s: f32,
    /// Largest turn rate in rad/s of a velocity command (turning on the spot at full wheel speed is
    /// `2 max_wheel_speed / inter_wheel_distance`).
    pub max_turn_rate: f32,
    /// Height of the LEDs the cameras of other robots see, in metres.
    pub led_height: f32,
    /// Height of the beacon LED in metres, for a body that has one (the foot-bot's turret beacon).
    pub beacon_height: Option<f32>,
    /// Proximity sensor angles in degrees, counter-clockwise from the heading, in reading order.
    pub proximity_angles_deg: &'static [f32],
    /// Distance of a proximity ray's start from the body centre, in metres.
    pub proximity_mount_radius: f32,
    /// Reach of a proximity ray from its start, in metres.
    pub proximity_range: f32,
    /// How a proximity distance becomes a reading.
    pub proximity_curve: ProximityCurve,
    /// Light sensor angles in degrees, counter-clockwise from the heading, in reading order.
    pub light_angles_deg: &'static [f32],
    /// Height from which the light sensors measure the distance to a light and test occlusion, in metres.
    pub light_height: f32,
    /// Ground sensor positions in the robot frame (x forward, y left), in metres, in reading order.
    pub ground_offsets: &'static [[f32; 2]],
    /// Height of the omnidirectional camera in metres; only LEDs below it are seen.
    pub camera_height: f32,
    /// What the camera sees.
    pub camera_view: CameraView,
    /// Height of the range-and-bearing emitter and receiver in metres.
    pub rab_height: f32,
    /// Default range of the range-and-bearing emitter in metres.
    pub rab_range: f32,
    /// Default and largest range-and-bearing payload in bytes.
    pub rab_data_size: u8,
    /// Whether received ranges are reported from body surface to body surface (the IRIDIA e-puck convention)
    /// rather than from centre to centre (ARGoS' generic range-and-bearing sensor).
    pub rab_range_between_surfaces: bool,
}

impl BodyModel {
    /// Largest distance from the body centre at which a proximity ray can touch something.
    pub fn proximity_reach(&self) -> f32 {
        self.proximity_mount_radius + self.proximity_range
    }

    /// How far away, on the ground plane, the camera sees an LED at `led_height` (0 when it cannot see it).
    pub fn camera_range(&self, led_height: f32) -> f32 {
        if led_height >= self.camera_height {
            return 0.0;
        }
        match self.camera_view {
            CameraView::Disc(radius) => radius,
            CameraView::Aperture(aperture) => (self.camera_height - led_height) * aperture.tan(),
        }
    }

    /// The farthest the camera sees anything (an LED on the ground).
    pub fn camera_reach(&self) -> f32 {
        self.camera_range(0.0)
    }
}

/// Angles `start + step * i` in degrees for `i` in `0..N`.
const fn ring<const N: usize>(start: f32, step: f32) -> [f32; N] {
    let mut angles = [0.0; N];
    let mut i = 0;
    while i < N {
        angles[i] = start + step * i as f32;
        i += 1;
    }
    angles
}

/// The e-puck's proximity (and light) sensor angles: the real robot's physical layout, so 0 and 7 are the
/// symmetric front pair.
pub const EPUCK_SENSOR_ANGLES_DEG: [f32; 8] = [17.0, 50.0, 90.0, 150.0, 210.0, 270.0, 310.0, 343.0];
/// ARGoS' uniform e-puck ring `11.25 + 45 i` degrees, chosen by the proximity sensor's `argos_uniform_ring`.
pub const EPUCK_UNIFORM_RING_DEG: [f32; 8] = ring(11.25, 45.0);
/// The foot-bot's 24 proximity and light sensors: `7.5 + 15 i` degrees.
pub const FOOTBOT_SENSOR_ANGLES_DEG: [f32; 24] = ring(7.5, 15.0);

/// The e-puck (IRIDIA model, docs/epuck-and-world.md).
pub const EPUCK: BodyModel = BodyModel {
    kind: RobotKind::EPuck,
    radius: 0.035,
    height: 0.076,
    mass: 0.2,
    inter_wheel_distance: 0.053,
    max_wheel_speed_cm_s: 12.8,
    max_turn_rate: 2.0 * 0.128 / 0.053,
    led_height: 0.086,
    beacon_height: None,
    proximity_angles_deg: &EPUCK_SENSOR_ANGLES_DEG,
    proximity_mount_radius: 0.035,
    proximity_range: 0.05,
    proximity_curve: ProximityCurve::Iridia,
    light_angles_deg: &EPUCK_SENSOR_ANGLES_DEG,
    light_height: 0.032,
    ground_offsets: &[[0.03, 0.009], [0.03, 0.0], [0.03, -0.009]],
    camera_height: 0.122,
    camera_view: CameraView::Disc(0.35),
    rab_height: 0.076,
    rab_range: 0.8,
    rab_data_size: 4,
    rab_range_between_surfaces: true,
};

/// ARGoS' foot-bot (docs/robots.md).
pub const FOOTBOT: BodyModel = BodyModel {
    kind: RobotKind::FootBot,
    radius: 0.085_036_76,
    height: 0.146_899_73,
    mass: 1.6,
    inter_wheel_distance: 0.14,
    max_wheel_speed_cm_s: 30.0,
    max_turn_rate: 2.0 * 0.3 / 0.14,
    led_height: 0.085,
    beacon_height: Some(0.174_249_73),
    proximity_angles_deg: &FOOTBOT_SENSOR_ANGLES_DEG,
    proximity_mount_radius: 0.085_036_76,
    proximity_range: 0.1,
    proximity_curve: ProximityCurve::FootBot,
    light_angles_deg: &FOOTBOT_SENSOR_ANGLES_DEG,
    light_height: 0.0,
    ground_offsets: &[
        [0.063, 0.0116],
        [-0.063, 0.0116],
        [-0.063, -0.0116],
        [0.063, -0.0116],
    ],
    camera_height: 0.288_699_73,
    camera_view: CameraView::Aperture(70.0f32.to_radians()),
    rab_height: 0.1,
    rab_range: 3.0,
    rab_data_size: 4,
    rab_range_between_surfaces: false,
};

/// The disc robot's defaults: a TurtleBot3 Burger-like body (radius 0.105 m, 0.192 m tall, 1 kg, wheels 0.16 m
/// apart, 0.22 m/s, 2.84 rad/s). No IR rings, ground sensors or camera; an LED on top; range-and-bearing as
/// ARGoS' generic device (3 m, 4 bytes, centre-to-centre ranges). It senses with `range_finder`.
pub const DISC: BodyModel = BodyModel {
    kind: RobotKind::Disc,
    radius: 0.105,
    height: 0.192,
    mass: 1.0,
    inter_wheel_distance: 0.16,
    max_wheel_speed_cm_s: 22.0,
    max_turn_rate: 2.84,
    led_height: 0.192,
    beacon_height: None,
    proximity_angles_deg: &[],
    proximity_mount_radius: 0.105,
    proximity_range: 0.0,
    proximity_curve: ProximityCurve::FootBot,
    light_angles_deg: &[],
    light_height: 0.0,
    ground_offsets: &[],
    camera_height: 0.0,
    camera_view: CameraView::Disc(0.0),
    rab_height: 0.192,
    rab_range: 3.0,
    rab_data_size: 4,
    rab_range_between_surfaces: false,
};

const _: () = {
    assert!(EPUCK.proximity_angles_deg.len() <= MAX_PROXIMITY_SENSORS);
    assert!(FOOTBOT.proximity_angles_deg.len() <= MAX_PROXIMITY_SENSORS);
    assert!(EPUCK.light_angles_deg.len() <= MAX_LIGHT_SENSORS);
    assert!(FOOTBOT.light_angles_deg.len() <= MAX_LIGHT_SENSORS);
    assert!(EPUCK.ground_offsets.len() <= MAX_GROUND_SENSORS);
    assert!(FOOTBOT.ground_offsets.len() <= MAX_GROUND_SENSORS);
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footbot_ring_is_uniform_from_seven_and_a_half_degrees() {
        assert_eq!(FOOTBOT_SENSOR_ANGLES_DEG[0], 7.5);
        assert_eq!(FOOTBOT_SENSOR_ANGLES_DEG[23], 352.5);
        assert_eq!(EPUCK_UNIFORM_RING_DEG[7], 326.25);
    }

    #[test]
    fn kinds_round_trip_through_their_tags() {
        for kind in RobotKind::ALL {
            assert_eq!(RobotKind::from_tag(kind.tag()), Some(kind));
            assert_eq!(kind.body().kind, kind);
        }
        assert_eq!(RobotKind::from_tag("eye-bot"), None);
    }

    #[test]
    fn footbot_camera_sees_led_rings_farther_than_the_epuck_camera() {
        let ring = FOOTBOT.camera_range(FOOTBOT.led_height);
        assert!((ring - (0.288_699_73 - 0.085) * 70.0f32.to_radians().tan()).abs() < 1e-6);
        assert_eq!(EPUCK.camera_range(0.0), 0.35);
        assert_eq!(EPUCK.camera_range(0.2), 0.0);
    }
}
