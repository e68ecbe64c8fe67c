//! Which sensors and actuators a robot's controller declares, with their options.
//!
//! The world computes only the sensors a controller declares (ARGoS does the same); the fields of the frame that
//! belong to undeclared sensors keep their empty values. Built from the `<controllers>` section of the config.

use crate::actuators::GRIPPER_REACH;

/// Options of the `epuck_proximity` sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProximityOptions {
    /// Additive uniform noise bound `noise_level` (docs/epuck-and-world.md section 2).
    pub noise_level: f32,
    /// Additive Gaussian noise standard deviation `noise_std_dev` (the aggregation sanity test).
    pub noise_std_dev: f32,
    /// Cast the rays at ARGoS' uniform ring `11.25 deg + 45 deg * i` instead of the physical angles.
    pub argos_uniform_ring: bool,
}

/// Options of the range-and-bearing device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RabOptions {
    /// Payload size in bytes (1 to 4).
    pub data_size: u8,
    /// Probability that a message is lost on its way to one receiver.
    pub loss_probability: f32,
}

/// Options of the omnidirectional camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraOptions {
    /// Gaussian noise on the blob's relative position, in metres.
    pub noise_std_dev: f32,
}

/// Options of the range-finder ring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RangeFinderOptions {
    /// Number of rays, evenly spread from the heading counter-clockwise.
    pub rays: u8,
    /// Reach of each ray from the body centre, in metres.
    pub range: f32,
    /// Gaussian noise standard deviation on each hit distance, in metres.
    pub noise_std_dev: f32,
}

/// Options of the physical gripper (`footbot_gripper`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GripperOptions {
    /// Largest force in newtons a grip holds before it is lost.
    pub max_force: f32,
}

/// The devices of one robot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Devices {
    /// Proximity sensors.
    pub proximity: Option<ProximityOptions>,
    /// Light sensors, with their uniform noise level.
    pub light: Option<f32>,
    /// Ground sensors, with their uniform noise level.
    pub ground: Option<f32>,
    /// Omnidirectional camera.
    pub camera: Option<CameraOptions>,
    /// Range-finder ring.
    pub range_finder: Option<RangeFinderOptions>,
    /// Physical gripper.
    pub gripper: Option<GripperOptions>,
    /// The foot-bot's distance scanner (its readings; the actuator sets its mode).
    pub distance_scanner: bool,
    /// Range-and-bearing sensor and actuator.
    pub rab: Option<RabOptions>,
    /// Multiplicative Gaussian wheel noise `noise_std_dev` (0 = none).
    pub wheel_noise_std_dev: f32,
    /// Largest edge-to-edge gap in metres at which the virtual gripper picks a target (`pickup_gap`).
    pub gripper_reach: f32,
}

impl Devices {
    /// Every sensor on, without noise (tests and benches that place robots by hand).
    pub const ALL: Devices = Devices {
        proximity: Some(ProximityOptions {
            noise_level: 0.0,
            noise_std_dev: 0.0,
            argos_uniform_ring: false,
        }),
        light: Some(0.0),
        ground: Some(0.0),
        camera: Some(CameraOptions { noise_std_dev: 0.0 }),
        range_finder: None,
        gripper: None,
        distance_scanner: false,
        rab: Some(RabOptions {
            data_size: 2,
            loss_probability: 0.0,
        }),
        wheel_noise_std_dev: 0.0,
        gripper_reach: GRIPPER_REACH,
    };

    /// Only wheels and proximity sensors, as in the thesis' obstacle-avoidance configuration.
    pub const PROXIMITY_ONLY: Devices = Devices {
        proximity: Some(ProximityOptions {
            noise_level: 0.0,
            noise_std_dev: 0.0,
            argos_uniform_ring: false,
        }),
        light: None,
        ground: None,
        camera: None,
        range_finder: None,
        gripper: None,
        distance_scanner: false,
        rab: None,
        wheel_noise_std_dev: 0.0,
        gripper_reach: GRIPPER_REACH,
    };
}
