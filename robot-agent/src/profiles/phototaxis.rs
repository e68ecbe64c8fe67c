//! Profile `phototaxis`: drive towards the light, for the models in `configs/phototaxis/models` (the example of
//! docs/tutorial.md and docs/controllers.md).
//!
//! Events and procedures (v = `velocity` in cm/s, default 10; wheels are (left, right)):
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `light_left` | u | the left light sensors read more than the right ones by `margin` (default 0.15), or the light is behind |
//! | `light_right` | u | the right light sensors read more than the left ones by `margin` |
//! | `light_ahead` | u | neither: the light is ahead, or no light is seen |
//! | `forward` | c | wheels (v, v) |
//! | `turn_left` | c | wheels (-v/2, v/2): turn on the spot, counter-clockwise |
//! | `turn_right` | c | wheels (v/2, -v/2): turn on the spot, clockwise |
//!
//! Exactly one of the three checks holds in every tick. The light sensors sit at the proximity angles
//! (docs/epuck-and-world.md 1.2 and 1.3): sensors 0-3 on the left (17, 50, 90, 150 degrees counter-clockwise from
//! the heading), 4-7 on the right; 0 and 7 face forward, 3 and 4 backward.

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default wheel speed in cm/s.
pub const DEFAULT_VELOCITY: f32 = 10.0;
/// Default difference between the two sides' light readings that counts as "the light is on that side".
pub const DEFAULT_MARGIN: f32 = 0.15;

/// Profile `phototaxis`: one robot's parameters (the control law keeps no memory; the supervisor remembers where
/// the light was seen last).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phototaxis {
    /// Wheel speed in cm/s.
    pub velocity: f32,
    /// Light difference that decides a side.
    pub margin: f32,
}

/// Where the light is, from one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Ahead,
    Left,
    Right,
}

impl Phototaxis {
    fn side(&self, frame: &SensorFrame) -> Side {
        let l = &frame.light;
        let left = l[0] + l[1] + l[2] + l[3];
        let right = l[4] + l[5] + l[6] + l[7];
        let behind = l[3] + l[4] > l[0] + l[7] + self.margin;
        if left > right + self.margin || (behind && left >= right) {
            Side::Left
        } else if right > left + self.margin || behind {
            Side::Right
        } else {
            Side::Ahead
        }
    }
}

fn light_ahead(s: &Phototaxis, frame: &SensorFrame) -> bool {
    s.side(frame) == Side::Ahead
}

fn light_left(s: &Phototaxis, frame: &SensorFrame) -> bool {
    s.side(frame) == Side::Left
}

fn light_right(s: &Phototaxis, frame: &SensorFrame) -> bool {
    s.side(frame) == Side::Right
}

fn forward(s: &mut Phototaxis, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [s.velocity, s.velocity];
}

fn turn_left(s: &mut Phototaxis, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [-s.velocity / 2.0, s.velocity / 2.0];
}

fn turn_right(s: &mut Phototaxis, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [s.velocity / 2.0, -s.velocity / 2.0];
}

impl Profile for Phototaxis {
    const NAME: &'static str = "phototaxis";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("light_ahead", Procedure::Check(light_ahead)),
        ("light_left", Procedure::Check(light_left)),
        ("light_right", Procedure::Check(light_right)),
        ("forward", Procedure::Act(forward)),
        ("turn_left", Procedure::Act(turn_left)),
        ("turn_right", Procedure::Act(turn_right)),
    ];

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
            margin: params.unit_f32_or("margin", DEFAULT_MARGIN)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::profiles::bind_profile;
    use crate::supervisors;

    fn profile() -> Phototaxis {
        Phototaxis::from_params(&Params::default()).unwrap()
    }

    fn lit(readings: &[(usize, f32)]) -> SensorFrame {
        let mut frame = SensorFrame::empty(0);
        for &(i, v) in readings {
            frame.light[i] = v;
        }
        frame
    }

    #[test]
    fn exactly_one_side_holds_and_it_is_the_lit_one() {
        let p = profile();
        for (frame, side) in [
            (lit(&[]), Side::Ahead),
            (lit(&[(0, 0.5), (7, 0.5)]), Side::Ahead),
            (lit(&[(2, 0.6)]), Side::Left),
            (lit(&[(5, 0.6)]), Side::Right),
            (lit(&[(3, 0.4), (4, 0.4)]), Side::Left),
            (lit(&[(3, 0.3), (4, 0.4)]), Side::Right),
        ] {
            let holds = [
                light_ahead(&p, &frame),
                light_left(&p, &frame),
                light_right(&p, &frame),
            ];
            assert_eq!(holds.iter().filter(|&&h| h).count(), 1, "{:?}", frame.light);
            assert_eq!(p.side(&frame), side, "{:?}", frame.light);
        }
    }

    #[test]
    fn turns_spin_on_the_spot_and_forward_drives_straight() {
        let mut p = profile();
        let mut c = ActuatorCommand::idle(0, 1);
        turn_left(&mut p, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [-5.0, 5.0]);
        turn_right(&mut p, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [5.0, -5.0]);
        forward(&mut p, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [10.0, 10.0]);
    }

    #[test]
    fn phototaxis_binds_every_event_of_the_shipped_models() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/phototaxis/models");
        let set = supervisors::load(&[models]).unwrap();
        assert_eq!(set.events.len(), 6);
        assert!(bind_profile("phototaxis", &Params::default(), &set.events).is_ok());
    }
}
