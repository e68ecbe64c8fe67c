//! Profile `aggregation` (docs/tasks.md section 1): Gauci et al.'s "aggregation without computation" with the
//! thesis' proximity-only binary sensor, for the models in `configs/aggregation/models`.
//!
//! Events and procedures (v = `velocity` in cm/s, default 12.8; wheels are (left, right)):
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `s0` | u | I = 0: max(p0, p7) <= `theta_i` (default 0.1) |
//! | `s1` | u | I = 1: max(p0, p7) > `theta_i` |
//! | `v0` | c | wheels (-0.7 v, -v): circle backwards, clockwise |
//! | `v1` | c | wheels (v, -v): rotate clockwise on the spot |
//!
//! Exactly one of `s0`, `s1` occurs in every tick. `theta_i` must lie above the proximity noise floor (docs/tasks.md:
//! 0.1 for sigma <= 0.03, about 0.5 for sigma = 0.3). Speeds persist until the next action, so the models'
//! alternation spec (E3) only removes redundant commands.

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default wheel speed scale in cm/s (v_max of docs/tasks.md section 0).
pub const DEFAULT_VELOCITY: f32 = 12.8;
/// Default threshold of the binary sensor on the front proximity pair (docs/tasks.md section 1, sigma <= 0.03).
pub const DEFAULT_THETA_I: f32 = 0.1;
/// Normalised wheel speeds (left, right) while nothing is seen (I = 0).
pub const SPEEDS_I0: [f32; 2] = [-0.7, -1.0];
/// Normalised wheel speeds (left, right) while something is seen (I = 1).
pub const SPEEDS_I1: [f32; 2] = [1.0, -1.0];

/// Profile `aggregation`: one robot's parameters (the control law keeps no memory).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aggregation {
    /// Wheel speed scale in cm/s: normalised speeds are multiplied by it.
    pub velocity: f32,
    /// The binary input is 1 when max(p0, p7) exceeds this.
    pub theta_i: f32,
}

impl Aggregation {
    fn sees(&self, frame: &SensorFrame) -> bool {
        frame.proximity[0].max(frame.proximity[7]) > self.theta_i
    }
}

/// `s0`: nothing in the line of sight.
fn s0(s: &Aggregation, frame: &SensorFrame) -> bool {
    !s.sees(frame)
}

/// `s1`: a robot or object in the line of sight.
fn s1(s: &Aggregation, frame: &SensorFrame) -> bool {
    s.sees(frame)
}

/// `v0`: the I = 0 speeds.
fn v0(s: &mut Aggregation, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = SPEEDS_I0.map(|x| x * s.velocity);
}

/// `v1`: the I = 1 speeds.
fn v1(s: &mut Aggregation, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = SPEEDS_I1.map(|x| x * s.velocity);
}

impl Profile for Aggregation {
    const NAME: &'static str = "aggregation";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("s0", Procedure::Check(s0)),
        ("s1", Procedure::Check(s1)),
        ("v0", Procedure::Act(v0)),
        ("v1", Procedure::Act(v1)),
    ];

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
            theta_i: params.unit_f32_or("theta_i", DEFAULT_THETA_I)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::profiles::bind_profile;
    use crate::supervisors;

    fn profile() -> Aggregation {
        Aggregation::from_params(&Params::default()).unwrap()
    }

    fn frame_with(readings: &[(usize, f32)]) -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        for &(i, v) in readings {
            f.proximity[i] = v;
        }
        f
    }

    #[test]
    fn binary_input_is_one_when_a_front_sensor_exceeds_0_1() {
        let p = profile();
        for frame in [frame_with(&[(0, 0.11)]), frame_with(&[(7, 0.11)])] {
            assert!(s1(&p, &frame));
            assert!(!s0(&p, &frame));
        }
    }

    #[test]
    fn binary_input_is_zero_at_exactly_0_1_and_for_side_sensors() {
        let p = profile();
        for frame in [
            frame_with(&[(0, 0.1), (7, 0.1)]),
            frame_with(&[(1, 0.9), (6, 0.9), (3, 0.9)]),
        ] {
            assert!(s0(&p, &frame));
            assert!(!s1(&p, &frame));
        }
    }

    #[test]
    fn theta_i_of_0_5_ignores_noise_of_sigma_0_3_below_it() {
        let p = Aggregation::from_params(&Params::new([("theta_i", "0.5")])).unwrap();
        assert!(s0(&p, &frame_with(&[(0, 0.45)])));
        assert!(s1(&p, &frame_with(&[(0, 0.55)])));
    }

    #[test]
    fn v0_circles_backwards_clockwise_at_minus_0_7_and_minus_1_vmax() {
        let mut c = ActuatorCommand::idle(0, 1);
        v0(&mut profile(), &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [-0.7 * 12.8, -12.8]);
    }

    #[test]
    fn v1_rotates_clockwise_on_the_spot_at_vmax() {
        let mut c = ActuatorCommand::idle(0, 1);
        v1(&mut profile(), &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [12.8, -12.8]);
    }

    #[test]
    fn velocity_scales_the_normalised_speeds() {
        let mut p = Aggregation::from_params(&Params::new([("velocity", "10")])).unwrap();
        let mut c = ActuatorCommand::idle(0, 1);
        v0(&mut p, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [-7.0, -10.0]);
    }

    #[test]
    fn theta_i_outside_the_unit_interval_is_rejected() {
        let err = bind_profile("aggregation", &Params::new([("theta_i", "1.5")]), &[])
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `aggregation`: parameter `theta_i` = 1.5 is out of range: must be in [0, 1]"
        );
    }

    #[test]
    fn aggregation_binds_every_event_of_the_shipped_models() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/aggregation/models");
        let set = supervisors::load(&[models]).unwrap();
        let names: Vec<&str> = set.events.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names.len(), 4, "{names:?}");
        assert!(bind_profile("aggregation", &Params::default(), &set.events).is_ok());
    }

    #[test]
    fn aggregation_fails_on_an_event_it_has_no_callback_for() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/aggregation/models");
        let mut events = supervisors::load(&[models]).unwrap().events;
        events.push(swarm_contract::supervisor_gen::compiled::CompiledEvent {
            name: "v2".to_owned(),
            controllable: true,
        });
        let err = bind_profile("aggregation", &Params::default(), &events)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `aggregation` does not fit the supervisors\n  \
             supervisor events without a callback: `v2` (controllable)"
        );
    }
}
