//! The device registry: the sensor and actuator names configurations use, mapped to [`DeviceKind`].
//!
//! Names are registry keys (as in ARGoS): the `.argos` element name finds the entry here. Both e-puck plug-ins'
//! names are accepted (docs/epuck-and-world.md section 4.2), the foot-bot's (`footbot_proximity`, `footbot_light`,
//! `footbot_motor_ground`, `footbot_distance_scanner`, `footbot_gripper`, `footbot_turret`), plus ours: `range_finder`, `virtual_gripper`, `pheromone` and `pheromone_deposit`. A robot-specific
//! name (`epuck_*`, `footbot_*`) is refused on a robot of another kind.

use super::model::{DeviceKind, DeviceRole};
use crate::bodies::RobotKind;

/// Which kind of medium a device must name in its `medium` attribute.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MediumKind {
    /// An `<led>` medium.
    Led,
    /// A `<range_and_bearing>` medium.
    RangeAndBearing,
    /// A `<pheromone>` field.
    Pheromone,
}

impl MediumKind {
    /// The element that declares such a medium.
    pub(crate) fn tag(self) -> &'static str {
        match self {
            MediumKind::Led => "led",
            MediumKind::RangeAndBearing => "range_and_bearing",
            MediumKind::Pheromone => "pheromone",
        }
    }
}

/// One registered device name.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Entry {
    /// The element name.
    pub name: &'static str,
    /// Sensor or actuator.
    pub role: DeviceRole,
    /// What it is.
    pub kind: DeviceKind,
    /// The medium it requires, if any (then `medium` is mandatory).
    pub medium: Option<MediumKind>,
    /// Attributes beyond `implementation`, `noise_level`, `noise_std_dev` and `medium` that this device reads.
    pub attributes: &'static [&'static str],
    /// The only robot this device exists on (`epuck_*`, `footbot_*`), or `None` for a generic device.
    pub body: Option<RobotKind>,
}

use DeviceKind as K;
use DeviceRole::{Actuator as A, Sensor as S};

const RAB_ATTRIBUTES: &[&str] = &[
    "data_size",
    "range",
    "real_range_noise",
    "max_packets",
    "loss_probability",
];

/// Every device name the runtime implements.
pub(crate) const DEVICES: &[Entry] = &[
    Entry {
        name: "epuck_wheels",
        role: A,
        kind: K::Wheels,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "differential_steering",
        role: A,
        kind: K::Wheels,
        medium: None,
        attributes: &[],
        body: None,
    },
    Entry {
        name: "epuck_base_leds",
        role: A,
        kind: K::Leds,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "epuck_rgb_leds",
        role: A,
        kind: K::Leds,
        medium: Some(MediumKind::Led),
        attributes: &[],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "leds",
        role: A,
        kind: K::Leds,
        medium: Some(MediumKind::Led),
        attributes: &[],
        body: None,
    },
    Entry {
        name: "epuck_proximity",
        role: S,
        kind: K::Proximity,
        medium: None,
        attributes: &["argos_uniform_ring"],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "proximity",
        role: S,
        kind: K::Proximity,
        medium: None,
        attributes: &["argos_uniform_ring"],
        body: None,
    },
    Entry {
        name: "epuck_light",
        role: S,
        kind: K::Light,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "light",
        role: S,
        kind: K::Light,
        medium: None,
        attributes: &[],
        body: None,
    },
    Entry {
        name: "epuck_ground",
        role: S,
        kind: K::Ground,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "ground",
        role: S,
        kind: K::Ground,
        medium: None,
        attributes: &[],
        body: None,
    },
    Entry {
        name: "epuck_omnidirectional_camera",
        role: S,
        kind: K::OmnidirectionalCamera,
        medium: Some(MediumKind::Led),
        attributes: &["range"],
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "colored_blob_omnidirectional_camera",
        role: S,
        kind: K::OmnidirectionalCamera,
        medium: Some(MediumKind::Led),
        attributes: &["range"],
        body: None,
    },
    Entry {
        name: "epuck_range_and_bearing",
        role: S,
        kind: K::RangeAndBearing,
        medium: Some(MediumKind::RangeAndBearing),
        attributes: RAB_ATTRIBUTES,
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "range_and_bearing",
        role: S,
        kind: K::RangeAndBearing,
        medium: Some(MediumKind::RangeAndBearing),
        attributes: RAB_ATTRIBUTES,
        body: None,
    },
    Entry {
        name: "epuck_range_and_bearing",
        role: A,
        kind: K::RangeAndBearing,
        medium: Some(MediumKind::RangeAndBearing),
        attributes: RAB_ATTRIBUTES,
        body: Some(RobotKind::EPuck),
    },
    Entry {
        name: "range_and_bearing",
        role: A,
        kind: K::RangeAndBearing,
        medium: Some(MediumKind::RangeAndBearing),
        attributes: RAB_ATTRIBUTES,
        body: None,
    },
    Entry {
        name: "footbot_proximity",
        role: S,
        kind: K::Proximity,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_light",
        role: S,
        kind: K::Light,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_motor_ground",
        role: S,
        kind: K::Ground,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_gripper",
        role: A,
        kind: K::Gripper,
        medium: None,
        attributes: &["max_force"],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_distance_scanner",
        role: S,
        kind: K::DistanceScanner,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_distance_scanner",
        role: A,
        kind: K::DistanceScanner,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "footbot_turret",
        role: A,
        kind: K::Turret,
        medium: None,
        attributes: &[],
        body: Some(RobotKind::FootBot),
    },
    Entry {
        name: "range_finder",
        role: S,
        kind: K::RangeFinder,
        medium: None,
        attributes: &["rays", "range"],
        body: None,
    },
    Entry {
        name: "positioning",
        role: S,
        kind: K::Positioning,
        medium: None,
        attributes: &[],
        body: None,
    },
    Entry {
        name: "virtual_gripper",
        role: S,
        kind: K::VirtualGripper,
        medium: None,
        attributes: &[],
        body: None,
    },
    Entry {
        name: "virtual_gripper",
        role: A,
        kind: K::VirtualGripper,
        medium: None,
        attributes: &["pickup_gap"],
        body: None,
    },
    Entry {
        name: "pheromone",
        role: S,
        kind: K::Pheromone,
        medium: Some(MediumKind::Pheromone),
        attributes: &["channels"],
        body: None,
    },
    Entry {
        name: "pheromone_deposit",
        role: A,
        kind: K::PheromoneDeposit,
        medium: Some(MediumKind::Pheromone),
        attributes: &["channels"],
        body: None,
    },
];

/// Looks a device up by the name a configuration uses.
pub(crate) fn lookup(role: DeviceRole, name: &str) -> Option<&'static Entry> {
    DEVICES.iter().find(|e| e.role == role && e.name == name)
}

/// All names registered for a role.
pub(crate) fn names(role: DeviceRole) -> impl Iterator<Item = &'static str> {
    DEVICES
        .iter()
        .filter(move |e| e.role == role)
        .map(|e| e.name)
}

/// The section a role's devices are declared in.
pub(crate) fn section(role: DeviceRole) -> &'static str {
    match role {
        DeviceRole::Sensor => "sensors",
        DeviceRole::Actuator => "actuators",
    }
}

/// Singular noun for a role.
pub(crate) fn noun(role: DeviceRole) -> &'static str {
    match role {
        DeviceRole::Sensor => "sensor",
        DeviceRole::Actuator => "actuator",
    }
}
