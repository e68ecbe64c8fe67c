//! Native controller `sensor_probe`: shows three sensor readings on the robot's LEDs, so that the run's records
//! (`trajectory.csv`'s `led_r`, `led_g`, `led_b`) carry them. For checking a body's sensors end to end, and for
//! seeing a reading in a replay.
//!
//! `red`, `green` and `blue` each name a reading as `sensor:index`: `proximity`, `light` and `ground` readings in
//! [0, 1], and `range` readings in metres (capped at 1). The colour channel is the reading times 255, rounded; an
//! index past the sensor's readings shows 0. The robot does not move.

use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;

/// A sensor a channel shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sensor {
    Proximity,
    Light,
    Ground,
    Range,
}

/// One reading: a sensor and an index into its readings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Reading {
    sensor: Sensor,
    index: usize,
}

impl Reading {
    /// `sensor:index`, or `None` for a channel left dark.
    fn parse(params: &Params, name: &str) -> Result<Option<Reading>, ParamError> {
        let Some(raw) = params.get(name) else {
            return Ok(None);
        };
        let malformed = || ParamError::Malformed {
            name: name.to_owned(),
            value: raw.to_owned(),
            expected: "`sensor:index` with sensor proximity, light, ground or range",
        };
        let (sensor, index) = raw.split_once(':').ok_or_else(malformed)?;
        let sensor = match sensor.trim() {
            "proximity" => Sensor::Proximity,
            "light" => Sensor::Light,
            "ground" => Sensor::Ground,
            "range" => Sensor::Range,
            _ => return Err(malformed()),
        };
        let index = index.trim().parse().map_err(|_| malformed())?;
        Ok(Some(Reading { sensor, index }))
    }

    /// The channel value, 0-255.
    fn level(self, frame: &SensorFrame) -> u8 {
        let readings = match self.sensor {
            Sensor::Proximity => frame.proximity_readings(),
            Sensor::Light => frame.light_readings(),
            Sensor::Ground => frame.ground_readings(),
            Sensor::Range => frame.range_readings(),
        };
        let value = readings.get(self.index).copied().unwrap_or(0.0);
        (value.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// The probe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SensorProbe {
    channels: [Option<Reading>; 3],
}

impl SensorProbe {
    /// Registry name.
    pub const NAME: &'static str = "sensor_probe";

    /// Reads `red`, `green` and `blue`.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            channels: [
                Reading::parse(params, "red")?,
                Reading::parse(params, "green")?,
                Reading::parse(params, "blue")?,
            ],
        })
    }
}

impl NativeController for SensorProbe {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let [r, g, b] = self.channels.map(|c| c.map_or(0, |c| c.level(frame)));
        command.wheels = [0.0, 0.0];
        command.led = Rgb { r, g, b };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_show_the_named_readings() {
        let params = Params::new([
            ("red", "proximity:2"),
            ("green", "ground:0"),
            ("blue", "range:1"),
        ]);
        let mut probe = SensorProbe::from_params(&params).unwrap();
        let mut f = SensorFrame::empty(0);
        f.proximity_len = 8;
        f.proximity[2] = 0.5;
        f.ground_len = 3;
        f.ground[0] = 1.0;
        f.ranges_len = 2;
        f.ranges[1] = f32::INFINITY;
        let mut cmd = ActuatorCommand::idle(0, 1);
        probe.step(&f, &mut cmd);
        assert_eq!(
            cmd.led,
            Rgb {
                r: 128,
                g: 255,
                b: 255
            }
        );
    }

    #[test]
    fn a_malformed_channel_names_the_parameter() {
        let params = Params::new([("red", "sonar:1")]);
        let err = SensorProbe::from_params(&params).unwrap_err();
        assert!(err.to_string().contains("`red`"), "{err}");
    }
}
