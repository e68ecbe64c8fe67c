//! Profiles `obstacle_avoidance` (ptSCT models) and `obstacle_avoidance_sct` (plain-SCT models with a timer
//! generator), docs/tasks.md section 3: a random walk that turns away from obstacles.
//!
//! Events and procedures (v = `velocity` in cm/s, default 12.8; wheels are (left, right) in cm/s):
//!
//! | event | kind | procedure | LED |
//! |---|---|---|---|
//! | `saw-obs` | u | max(p0, p7) > `theta_obs` (default 0.1, about 4 cm) | - |
//! | `Go` | c | wheels (v, v) | green |
//! | `turn-left` | c | wheels (0, v): pivot on the left wheel | blue |
//! | `turn-right` | c | wheels (v, 0): pivot on the right wheel | blue |
//! | `turn-inv-obs` | c | away from the brighter front side: max(p0, p1) >= max(p7, p6) -> (v, 0), else (0, v) | red |
//!
//! Turns follow the thesis' style (one wheel stopped; its example turns right with left 2.5 cm/s, right 0) at the
//! full `velocity`, so a turn of the 5-tick lower bound at 20 ticks/s rotates about 34 degrees. Wheel speeds and
//! the LED persist until the next action, as on the robot. The plain-SCT profile adds timer generator 1
//! (`start_timer_1`, `timer_1_lw_5`, `inc_timer_1`, `timer_1_eq_5`, `end_timer_1`; see [`super::timer`]).

use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use super::timer::{self, StepTimer};
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default wheel speed in cm/s (the thesis' `velocity="12.8"`, the e-puck maximum).
pub const DEFAULT_VELOCITY: f32 = 12.8;
/// Default obstacle threshold on the front proximity readings (docs/tasks.md section 3).
pub const DEFAULT_THETA_OBS: f32 = 0.1;
/// Increments of timer generator 1 in the plain-SCT models (the ptSCT models' `Go` lower bound).
pub const SCT_TIMER_TICKS: u16 = 5;

const GREEN: Rgb = Rgb { r: 0, g: 255, b: 0 };
const BLUE: Rgb = Rgb { r: 0, g: 0, b: 255 };
const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };

/// Parameters of the walk shared by both profiles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walker {
    /// Wheel speed in cm/s.
    pub velocity: f32,
    /// `saw-obs` fires when max(p0, p7) exceeds this.
    pub theta_obs: f32,
}

impl Walker {
    /// Reads `velocity` (cm/s, >= 0) and `theta_obs` (in [0, 1]).
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
            theta_obs: params.unit_f32_or("theta_obs", DEFAULT_THETA_OBS)?,
        })
    }
}

impl AsRef<Walker> for Walker {
    fn as_ref(&self) -> &Walker {
        self
    }
}

impl AsMut<Walker> for Walker {
    fn as_mut(&mut self) -> &mut Walker {
        self
    }
}

/// `saw-obs`: an obstacle ahead on the front pair of sensors.
pub fn saw_obs<S: AsRef<Walker>>(s: &S, frame: &SensorFrame) -> bool {
    frame.proximity[0].max(frame.proximity[7]) > s.as_ref().theta_obs
}

/// `Go`: straight ahead.
pub fn go<S: AsMut<Walker>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    let v = s.as_mut().velocity;
    command.wheels = [v, v];
    command.led = GREEN;
}

/// `turn-left`: pivot counter-clockwise on the stopped left wheel.
pub fn turn_left<S: AsMut<Walker>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [0.0, s.as_mut().velocity];
    command.led = BLUE;
}

/// `turn-right`: pivot clockwise on the stopped right wheel.
pub fn turn_right<S: AsMut<Walker>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [s.as_mut().velocity, 0.0];
    command.led = BLUE;
}

/// `turn-inv-obs`: turn away from the front side with the higher reading (left wins ties, as in the ARGoS port).
pub fn turn_inv_obs<S: AsMut<Walker>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    let v = s.as_mut().velocity;
    let p = &frame.proximity;
    let left = p[0].max(p[1]);
    let right = p[7].max(p[6]);
    command.wheels = if left >= right { [v, 0.0] } else { [0.0, v] };
    command.led = RED;
}

/// Profile `obstacle_avoidance`: the ptSCT models' events (lower bounds are enforced by the player).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleAvoidance {
    /// Walk parameters.
    pub walker: Walker,
}

impl AsRef<Walker> for ObstacleAvoidance {
    fn as_ref(&self) -> &Walker {
        &self.walker
    }
}

impl AsMut<Walker> for ObstacleAvoidance {
    fn as_mut(&mut self) -> &mut Walker {
        &mut self.walker
    }
}

impl Profile for ObstacleAvoidance {
    const NAME: &'static str = "obstacle_avoidance";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("saw-obs", Procedure::Check(saw_obs::<Self>)),
        ("Go", Procedure::Act(go::<Self>)),
        ("turn-left", Procedure::Act(turn_left::<Self>)),
        ("turn-right", Procedure::Act(turn_right::<Self>)),
        ("turn-inv-obs", Procedure::Act(turn_inv_obs::<Self>)),
    ];

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            walker: Walker::from_params(params)?,
        })
    }
}

/// Profile `obstacle_avoidance_sct`: the plain-SCT models' events, with timer generator 1 replacing the lower bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObstacleAvoidanceSct {
    /// Walk parameters.
    pub walker: Walker,
    /// Timer generator 1: the wait before `Go` after a turn.
    pub timer: StepTimer,
}

impl AsRef<Walker> for ObstacleAvoidanceSct {
    fn as_ref(&self) -> &Walker {
        &self.walker
    }
}

impl AsMut<Walker> for ObstacleAvoidanceSct {
    fn as_mut(&mut self) -> &mut Walker {
        &mut self.walker
    }
}

impl AsRef<StepTimer> for ObstacleAvoidanceSct {
    fn as_ref(&self) -> &StepTimer {
        &self.timer
    }
}

impl AsMut<StepTimer> for ObstacleAvoidanceSct {
    fn as_mut(&mut self) -> &mut StepTimer {
        &mut self.timer
    }
}

impl Profile for ObstacleAvoidanceSct {
    const NAME: &'static str = "obstacle_avoidance_sct";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("saw-obs", Procedure::Check(saw_obs::<Self>)),
        ("Go", Procedure::Act(go::<Self>)),
        ("turn-left", Procedure::Act(turn_left::<Self>)),
        ("turn-right", Procedure::Act(turn_right::<Self>)),
        ("turn-inv-obs", Procedure::Act(turn_inv_obs::<Self>)),
        ("start_timer_1", Procedure::Act(timer::start::<Self>)),
        ("timer_1_lw_5", Procedure::Check(timer::lower::<Self>)),
        ("inc_timer_1", Procedure::Act(timer::inc::<Self>)),
        ("timer_1_eq_5", Procedure::Check(timer::reached::<Self>)),
        ("end_timer_1", Procedure::Act(timer::end::<Self>)),
    ];

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            walker: Walker::from_params(params)?,
            timer: StepTimer::new(SCT_TIMER_TICKS),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walker() -> Walker {
        Walker::from_params(&Params::default()).unwrap()
    }

    fn frame_with(readings: &[(usize, f32)]) -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        for &(i, v) in readings {
            f.proximity[i] = v;
        }
        f
    }

    #[test]
    fn saw_obs_fires_when_front_sensor_exceeds_0_1() {
        assert!(saw_obs(&walker(), &frame_with(&[(0, 0.11)])));
        assert!(saw_obs(&walker(), &frame_with(&[(7, 0.11)])));
    }

    #[test]
    fn saw_obs_stays_quiet_at_exactly_0_1() {
        assert!(!saw_obs(&walker(), &frame_with(&[(0, 0.1), (7, 0.1)])));
    }

    #[test]
    fn saw_obs_ignores_side_sensors() {
        assert!(!saw_obs(
            &walker(),
            &frame_with(&[(1, 0.9), (2, 0.9), (5, 0.9), (6, 0.9)])
        ));
    }

    #[test]
    fn saw_obs_uses_the_theta_obs_parameter() {
        let w = Walker::from_params(&Params::new([("theta_obs", "0.5")])).unwrap();
        assert!(!saw_obs(&w, &frame_with(&[(0, 0.4)])));
        assert!(saw_obs(&w, &frame_with(&[(0, 0.6)])));
    }

    #[test]
    fn go_drives_both_wheels_at_velocity_and_shows_green() {
        let mut w = walker();
        let mut c = ActuatorCommand::idle(0, 1);
        go(&mut w, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [12.8, 12.8]);
        assert_eq!(c.led, GREEN);
    }

    #[test]
    fn go_uses_the_velocity_parameter() {
        let mut w = Walker::from_params(&Params::new([("velocity", "5")])).unwrap();
        let mut c = ActuatorCommand::idle(0, 1);
        go(&mut w, &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [5.0, 5.0]);
    }

    #[test]
    fn turn_left_stops_the_left_wheel() {
        let mut c = ActuatorCommand::idle(0, 1);
        turn_left(&mut walker(), &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [0.0, 12.8]);
        assert_eq!(c.led, BLUE);
    }

    #[test]
    fn turn_right_stops_the_right_wheel() {
        let mut c = ActuatorCommand::idle(0, 1);
        turn_right(&mut walker(), &SensorFrame::empty(0), &mut c);
        assert_eq!(c.wheels, [12.8, 0.0]);
        assert_eq!(c.led, BLUE);
    }

    #[test]
    fn turn_inv_obs_turns_right_away_from_an_obstacle_on_the_left() {
        let mut c = ActuatorCommand::idle(0, 1);
        turn_inv_obs(&mut walker(), &frame_with(&[(0, 0.6), (7, 0.2)]), &mut c);
        assert_eq!(c.wheels, [12.8, 0.0]);
        assert_eq!(c.led, RED);
    }

    #[test]
    fn turn_inv_obs_turns_left_away_from_an_obstacle_on_the_right() {
        let mut c = ActuatorCommand::idle(0, 1);
        turn_inv_obs(&mut walker(), &frame_with(&[(0, 0.2), (6, 0.7)]), &mut c);
        assert_eq!(c.wheels, [0.0, 12.8]);
    }

    #[test]
    fn turn_inv_obs_turns_right_on_a_head_on_tie() {
        let mut c = ActuatorCommand::idle(0, 1);
        turn_inv_obs(&mut walker(), &frame_with(&[(0, 0.5), (7, 0.5)]), &mut c);
        assert_eq!(c.wheels, [12.8, 0.0]);
    }

    #[test]
    fn sct_profile_timer_waits_five_increments() {
        let mut s = ObstacleAvoidanceSct::from_params(&Params::default()).unwrap();
        let f = SensorFrame::empty(0);
        let mut c = ActuatorCommand::idle(0, 1);
        timer::start(&mut s, &f, &mut c);
        for _ in 0..SCT_TIMER_TICKS {
            assert!(timer::lower(&s, &f));
            timer::inc(&mut s, &f, &mut c);
        }
        assert!(timer::reached(&s, &f));
    }
}
