//! Profile `foraging`: the operational procedures of the foraging models (docs/tasks.md 4.3-4.5, 4.11-4.12), one per
//! event of `configs/foraging/models` (G1-G8, E1-E7).
//!
//! The robot's memory holds its phase (tracked by the same events as E6), the tick its search or real rest began
//! (the step and rest thresholds), whether resting is allowed (the resting switch, 4.11) and the gripper requests in
//! flight. Checks are pure functions of that memory and the frame; actions write the command. v = `velocity`.
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `saw-obs` | u | max(p0, p7) > `theta_obs` (default 0.1) |
//! | `saw-home` | u | the largest light reading > `theta_light` (default 0.05) |
//! | `is-in-home` | u | the middle ground reading < `home_ground` (default 0.5: home is black) |
//! | `saw-food` | u | a camera blob of the target colour (`food_color`, default red 255,0,0) |
//! | `is-on-food` | u | the nearest such blob within `food_reach_cm` of the robot centre (default 6.2 cm: robot radius 3.5 + target radius 2 + the thesis' 7 mm gap) |
//! | `have-food` | u | the gripper holds a target |
//! | `pick-ended` / `drop-ended` | u | a tick has passed since `pick-food` / `drop-food` (the world acts on a request in the tick it is made) |
//! | `did-search-expire` | u | resting allowed and ticks since `search-food` >= `search_budget_steps` (default 4000); never when `resting="false"` |
//! | `did-rest-expire` | u | ticks since `Stop` or `continue-rest` >= `rest_ticks` (default 1000) |
//! | `Go`, `rest-wait` | c | wheels (v, v) |
//! | `Stop` | c | wheels (0, 0); the real rest begins |
//! | `turn-left` / `turn-right` | c | pivot at -/+ 0.5 v: wheels (-v/2, v/2) / (v/2, -v/2) |
//! | `turn-inv-obs` | c | pivot away from the front side with the larger reading (max(p0, p1) against max(p7, p6)) |
//! | `turn-to-home` / `turn-inv-home` | c | pivot towards / away from the side of the brightest light sensor (0-3 left, 4-7 right) |
//! | `turn-to-food` | c | pivot towards the nearest target blob, or straight on when it is within 0.15 rad of the heading |
//! | `pick-food` / `drop-food` | c | stop and ask the gripper to pick / drop |
//! | `search-food` | c | search phase begins: budget counter to 0, gripper idle |
//! | `rest` | c | rest phase begins (the walk home) |
//! | `start-search` / `continue-rest` | c | the real rest ends / restarts its `rest_ticks` count |
//! | `inc-food-count`, `lost-food` | c | the pick-up request is over; gripper idle |
//! | other start, end and shadow events | c | nothing: they only move the supervisors |
//!
//! **LED contract with the world.** The LED shows the phase, and the loop functions `foraging_loop_functions`
//! read it for the energy accounting and the resting ratio (docs/tasks.md 4.13-4.14): green [`SEARCH_LED`] from
//! `search-food` (or `start-search`) until `rest`, blue [`RETURN_LED`] from `rest` until the next search or the
//! real rest, white [`REST_LED`] during the real rest (`Stop` until `start-search`). None of them is the target
//! colour, so cameras never take a robot for food (docs/tasks.md 4.2).

use swarm_contract::messages::{ActuatorCommand, GripperAction, Rgb, SensorFrame};

use super::obstacle_avoidance::{DEFAULT_THETA_OBS, DEFAULT_VELOCITY};
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// LED of the search phase.
pub const SEARCH_LED: Rgb = Rgb { r: 0, g: 255, b: 0 };
/// LED of the rest phase while the robot walks home and settles.
pub const RETURN_LED: Rgb = Rgb { r: 0, g: 0, b: 255 };
/// LED of the real rest (E7's resting state).
pub const REST_LED: Rgb = Rgb {
    r: 255,
    g: 255,
    b: 255,
};
/// Default `saw-home` threshold on the largest light reading (docs/tasks.md 4.5).
pub const DEFAULT_THETA_LIGHT: f32 = 0.05;
/// Default `is-in-home` threshold on the middle ground reading (home is black).
pub const DEFAULT_HOME_GROUND: f32 = 0.5;
/// Default distance in cm from the robot centre to a target's LED at which `is-on-food` holds.
pub const DEFAULT_FOOD_REACH_CM: f32 = 6.2;
/// Default search budget in steps (ticks) (docs/tasks.md 4.12).
pub const DEFAULT_SEARCH_BUDGET: u64 = 4000;
/// Default length of a real rest in ticks (docs/tasks.md 4.11).
pub const DEFAULT_REST_TICKS: u64 = 1000;
/// Bearing in radians within which `turn-to-food` drives straight on instead of pivoting.
pub const AIM_TOLERANCE: f32 = 0.15;

/// Where the robot is in E7's cycle, as E6 tracks it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Before the first `search-food`.
    Idle,
    /// From `search-food` until `rest`.
    Search,
    /// From `rest` until the next search or the real rest: walking home and settling.
    Return,
    /// The real rest: from `Stop` until `start-search`.
    Rest,
}

/// One forager's parameters and memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Forager {
    /// Wheel speed v in cm/s.
    pub velocity: f32,
    /// `saw-obs` threshold on the front proximity pair.
    pub theta_obs: f32,
    /// `saw-home` threshold on the largest light reading.
    pub theta_light: f32,
    /// `is-in-home` holds when the middle ground reading is below this.
    pub home_ground: f32,
    /// The LED colour of targets.
    pub food_color: Rgb,
    /// `is-on-food` distance in cm from the robot centre to the target's LED.
    pub food_reach_cm: f32,
    /// The resting switch (docs/tasks.md 4.11): with `false`, `did-search-expire` never holds.
    pub resting: bool,
    /// Search budget in steps (ticks).
    pub search_budget: u64,
    /// Length of one real-rest period in ticks.
    pub rest_ticks: u64,
    phase: Phase,
    phase_started: u64,
    pick_requested: Option<u64>,
    drop_requested: Option<u64>,
}

impl Forager {
    /// Reads the parameters (`velocity`, `theta_obs`, `theta_light`, `home_ground`, `food_color`, `food_reach_cm`,
    /// `resting`, `search_budget_steps`, `rest_ticks`); absent ones take the defaults of docs/tasks.md 4.5 and 4.12.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        Ok(Self {
            velocity: params.non_negative_f32_or("velocity", DEFAULT_VELOCITY)?,
            theta_obs: params.unit_f32_or("theta_obs", DEFAULT_THETA_OBS)?,
            theta_light: params.unit_f32_or("theta_light", DEFAULT_THETA_LIGHT)?,
            home_ground: params.unit_f32_or("home_ground", DEFAULT_HOME_GROUND)?,
            food_color: color_or(params, "food_color", Rgb { r: 255, g: 0, b: 0 })?,
            food_reach_cm: params.non_negative_f32_or("food_reach_cm", DEFAULT_FOOD_REACH_CM)?,
            resting: bool_or(params, "resting", true)?,
            search_budget: params.whole_or("search_budget_steps", DEFAULT_SEARCH_BUDGET)?,
            rest_ticks: params.whole_or("rest_ticks", DEFAULT_REST_TICKS)?,
            phase: Phase::Idle,
            phase_started: 0,
            pick_requested: None,
            drop_requested: None,
        })
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    fn enter(&mut self, phase: Phase, frame: &SensorFrame, command: &mut ActuatorCommand) {
        self.phase = phase;
        self.phase_started = frame.tick;
        command.led = match phase {
            Phase::Idle => Rgb::OFF,
            Phase::Search => SEARCH_LED,
            Phase::Return => RETURN_LED,
            Phase::Rest => REST_LED,
        };
    }

    fn pivot(&self, left: bool, command: &mut ActuatorCommand) {
        let half = 0.5 * self.velocity;
        command.wheels = if left { [-half, half] } else { [half, -half] };
    }

    /// Pivots towards `bearing` (radians, counter-clockwise from the heading), or drives straight on when the
    /// bearing is within [`AIM_TOLERANCE`].
    pub fn steer(&self, bearing: f32, command: &mut ActuatorCommand) {
        if bearing.abs() <= AIM_TOLERANCE {
            command.wheels = [self.velocity; 2];
        } else {
            self.pivot(bearing > 0.0, command);
        }
    }

    /// The nearest blob of the target colour.
    fn nearest_food<'f>(
        &self,
        frame: &'f SensorFrame,
    ) -> Option<&'f swarm_contract::messages::CameraBlob> {
        // Blobs arrive nearest first.
        frame
            .camera_blobs()
            .iter()
            .find(|b| b.color == self.food_color)
    }
}

fn malformed(name: &str, value: &str, expected: &'static str) -> ParamError {
    ParamError::Malformed {
        name: name.to_owned(),
        value: value.to_owned(),
        expected,
    }
}

fn bool_or(params: &Params, name: &str, default: bool) -> Result<bool, ParamError> {
    match params.get(name).map(str::trim) {
        None => Ok(default),
        Some("true") => Ok(true),
        Some("false") => Ok(false),
        Some(other) => Err(malformed(name, other, "`true` or `false`")),
    }
}

fn color_or(params: &Params, name: &str, default: Rgb) -> Result<Rgb, ParamError> {
    let Some(raw) = params.get(name) else {
        return Ok(default);
    };
    let named = match raw.trim() {
        "red" => Some(Rgb { r: 255, g: 0, b: 0 }),
        "green" => Some(SEARCH_LED),
        "blue" => Some(RETURN_LED),
        "yellow" => Some(Rgb {
            r: 255,
            g: 255,
            b: 0,
        }),
        _ => None,
    };
    if let Some(c) = named {
        return Ok(c);
    }
    let parts: Vec<Option<u8>> = raw.split(',').map(|p| p.trim().parse().ok()).collect();
    match parts.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok(Rgb {
            r: *r,
            g: *g,
            b: *b,
        }),
        _ => Err(malformed(
            name,
            raw,
            "a colour: red, green, blue, yellow or r,g,b with 0-255 each",
        )),
    }
}

impl AsRef<Forager> for Forager {
    fn as_ref(&self) -> &Forager {
        self
    }
}

impl AsMut<Forager> for Forager {
    fn as_mut(&mut self) -> &mut Forager {
        self
    }
}

/// `saw-obs`: an obstacle ahead on the front pair.
pub fn saw_obs<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    frame.proximity[0].max(frame.proximity[7]) > s.as_ref().theta_obs
}

/// `saw-home`: the brightest light sensor is above the threshold.
pub fn saw_home<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    frame
        .light_readings()
        .iter()
        .copied()
        .fold(0.0f32, f32::max)
        > s.as_ref().theta_light
}

/// `is-in-home`: the middle ground sensor sees the home floor.
pub fn is_in_home<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    frame.ground[1] < s.as_ref().home_ground
}

/// `saw-food`: a target LED is in view.
pub fn saw_food<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    s.as_ref().nearest_food(frame).is_some()
}

/// `is-on-food`: the nearest target is within the gripper's reach.
pub fn is_on_food<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    let f = s.as_ref();
    f.nearest_food(frame)
        .is_some_and(|b| b.distance_cm <= f.food_reach_cm)
}

/// `have-food`: the gripper holds a target.
pub fn have_food<S: AsRef<Forager>>(_: &S, frame: &SensorFrame) -> bool {
    frame.gripper_holding != 0
}

/// `pick-ended`: the pick-up request was handled by the world.
pub fn pick_ended<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    s.as_ref().pick_requested.is_some_and(|t| frame.tick > t)
}

/// `drop-ended`: the drop request was handled by the world.
pub fn drop_ended<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    s.as_ref().drop_requested.is_some_and(|t| frame.tick > t)
}

/// `did-search-expire`: the search budget is spent (never when resting is off).
pub fn did_search_expire<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    let f = s.as_ref();
    f.resting
        && f.phase == Phase::Search
        && frame.tick.saturating_sub(f.phase_started) >= f.search_budget
}

/// `did-rest-expire`: the current rest period is over.
pub fn did_rest_expire<S: AsRef<Forager>>(s: &S, frame: &SensorFrame) -> bool {
    let f = s.as_ref();
    f.phase == Phase::Rest && frame.tick.saturating_sub(f.phase_started) >= f.rest_ticks
}

/// `Go` and `rest-wait`: straight ahead.
pub fn go<S: AsMut<Forager>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [s.as_mut().velocity; 2];
}

/// `Stop`: the real rest begins.
pub fn stop<S: AsMut<Forager>>(s: &mut S, frame: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [0.0; 2];
    s.as_mut().enter(Phase::Rest, frame, command);
}

/// `turn-left`: pivot counter-clockwise.
pub fn turn_left<S: AsMut<Forager>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    s.as_mut().pivot(true, command);
}

/// `turn-right`: pivot clockwise.
pub fn turn_right<S: AsMut<Forager>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    s.as_mut().pivot(false, command);
}

/// `turn-inv-obs`: pivot away from the front side with the larger reading (ties turn right).
pub fn turn_inv_obs<S: AsMut<Forager>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    let p = &frame.proximity;
    let left = p[0].max(p[1]);
    let right = p[7].max(p[6]);
    s.as_mut().pivot(left < right, command);
}

/// Whether the brightest light sensor is on the robot's left (sensors 0-3 sit at +17 to +150 degrees).
fn light_on_left(frame: &SensorFrame) -> bool {
    let brightest = frame
        .light
        .iter()
        .enumerate()
        .fold(
            (0, f32::MIN),
            |best, (i, &v)| if v > best.1 { (i, v) } else { best },
        )
        .0;
    brightest < 4
}

/// `turn-to-home`: pivot towards the brightest light sensor.
pub fn turn_to_home<S: AsMut<Forager>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    s.as_mut().pivot(light_on_left(frame), command);
}

/// `turn-inv-home`: pivot away from the brightest light sensor.
pub fn turn_inv_home<S: AsMut<Forager>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    s.as_mut().pivot(!light_on_left(frame), command);
}

/// `turn-to-food`: pivot towards the nearest target, or straight on when it is nearly ahead.
pub fn turn_to_food<S: AsMut<Forager>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    let f = s.as_mut();
    match f.nearest_food(frame).map(|b| b.bearing) {
        Some(bearing) => f.steer(bearing, command),
        None => command.wheels = [f.velocity; 2],
    }
}

/// `pick-food`: stop and ask the gripper for the target in reach.
pub fn pick_food<S: AsMut<Forager>>(s: &mut S, frame: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [0.0; 2];
    command.gripper = GripperAction::Pick;
    s.as_mut().pick_requested = Some(frame.tick);
}

/// `drop-food`: stop and ask the gripper to let go.
pub fn drop_food<S: AsMut<Forager>>(s: &mut S, frame: &SensorFrame, command: &mut ActuatorCommand) {
    command.wheels = [0.0; 2];
    command.gripper = GripperAction::Drop;
    s.as_mut().drop_requested = Some(frame.tick);
}

/// `inc-food-count` and `lost-food`: the pick-up request is over; the gripper stays idle from now on.
pub fn pick_done<S: AsMut<Forager>>(s: &mut S, _: &SensorFrame, command: &mut ActuatorCommand) {
    command.gripper = GripperAction::Hold;
    s.as_mut().pick_requested = None;
}

/// `search-food` and `start-search`: the search phase begins; a finished drop request is cleared.
pub fn search_food<S: AsMut<Forager>>(
    s: &mut S,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    let f = s.as_mut();
    command.gripper = GripperAction::Hold;
    f.drop_requested = None;
    f.enter(Phase::Search, frame, command);
}

/// `rest`: the rest phase begins (the walk home).
pub fn rest<S: AsMut<Forager>>(s: &mut S, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.as_mut().enter(Phase::Return, frame, command);
}

/// `continue-rest`: another rest period begins.
pub fn continue_rest<S: AsMut<Forager>>(s: &mut S, frame: &SensorFrame, _: &mut ActuatorCommand) {
    s.as_mut().phase_started = frame.tick;
}

/// Start, end and shadow events: the supervisors move; the robot does nothing new.
pub fn nothing<S>(_: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {}

/// The procedures of the foraging models, generic over any memory holding a [`Forager`]; the pheromone profile
/// extends this table.
pub const fn procedures<S: AsRef<Forager> + AsMut<Forager>>() -> [(&'static str, Procedure<S>); 40]
{
    [
        ("saw-obs", Procedure::Check(saw_obs::<S>)),
        ("saw-home", Procedure::Check(saw_home::<S>)),
        ("is-in-home", Procedure::Check(is_in_home::<S>)),
        ("saw-food", Procedure::Check(saw_food::<S>)),
        ("is-on-food", Procedure::Check(is_on_food::<S>)),
        ("have-food", Procedure::Check(have_food::<S>)),
        ("pick-ended", Procedure::Check(pick_ended::<S>)),
        ("drop-ended", Procedure::Check(drop_ended::<S>)),
        (
            "did-search-expire",
            Procedure::Check(did_search_expire::<S>),
        ),
        ("did-rest-expire", Procedure::Check(did_rest_expire::<S>)),
        ("Go", Procedure::Act(go::<S>)),
        ("rest-wait", Procedure::Act(go::<S>)),
        ("Stop", Procedure::Act(stop::<S>)),
        ("turn-left", Procedure::Act(turn_left::<S>)),
        ("turn-right", Procedure::Act(turn_right::<S>)),
        ("turn-inv-obs", Procedure::Act(turn_inv_obs::<S>)),
        ("turn-to-home", Procedure::Act(turn_to_home::<S>)),
        ("turn-inv-home", Procedure::Act(turn_inv_home::<S>)),
        ("turn-to-food", Procedure::Act(turn_to_food::<S>)),
        ("pick-food", Procedure::Act(pick_food::<S>)),
        ("drop-food", Procedure::Act(drop_food::<S>)),
        ("inc-food-count", Procedure::Act(pick_done::<S>)),
        ("lost-food", Procedure::Act(pick_done::<S>)),
        ("search-food", Procedure::Act(search_food::<S>)),
        ("start-search", Procedure::Act(search_food::<S>)),
        ("rest", Procedure::Act(rest::<S>)),
        ("continue-rest", Procedure::Act(continue_rest::<S>)),
        ("avoid-obs", Procedure::Act(nothing::<S>)),
        ("avoid-obs-ended", Procedure::Act(nothing::<S>)),
        ("exit-home", Procedure::Act(nothing::<S>)),
        ("exit-home-ended", Procedure::Act(nothing::<S>)),
        ("return-home", Procedure::Act(nothing::<S>)),
        ("return-home-ended", Procedure::Act(nothing::<S>)),
        ("return-not-in-home", Procedure::Act(nothing::<S>)),
        ("rest-ended", Procedure::Act(nothing::<S>)),
        ("rest-not-in-home", Procedure::Act(nothing::<S>)),
        ("search-food-ended", Procedure::Act(nothing::<S>)),
        ("search-no-food-ended", Procedure::Act(nothing::<S>)),
        ("search-not-have-food", Procedure::Act(nothing::<S>)),
        ("not-have-food", Procedure::Act(nothing::<S>)),
    ]
}

const FORAGER_PROCEDURES: [(&str, Procedure<Forager>); 40] = procedures::<Forager>();

impl Profile for Forager {
    const NAME: &'static str = "foraging";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &FORAGER_PROCEDURES;

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        Forager::from_params(params)
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::profiles::bind_profile;
    use crate::supervisors::load;

    fn forager(pairs: &[(&str, &str)]) -> Forager {
        Forager::from_params(&Params::new(pairs.iter().copied())).unwrap()
    }

    /// An e-puck's frame with its light and ground sensors declared, as the foraging controller has them.
    fn frame(tick: u64) -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        f.tick = tick;
        f.light_len = 8;
        f.ground_len = 3;
        f
    }

    fn with_blob(tick: u64, color: Rgb, bearing: f32, distance_cm: f32) -> SensorFrame {
        let mut f = frame(tick);
        f.camera[0] = swarm_contract::messages::CameraBlob {
            color,
            bearing,
            distance_cm,
        };
        f.camera_len = 1;
        f
    }

    const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };

    #[test]
    fn profile_binds_every_event_of_the_foraging_models() {
        let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/foraging/models");
        let set = load(&[models]).unwrap();
        assert_eq!(set.events.len(), FORAGER_PROCEDURES.len());
        assert!(bind_profile("foraging", &Params::default(), &set.events).is_ok());
    }

    #[test]
    fn did_search_expire_after_a_budget_of_4000_steps() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        search_food(&mut f, &frame(100), &mut c);
        assert!(!did_search_expire(&f, &frame(4099)));
        assert!(did_search_expire(&f, &frame(4100)));
    }

    #[test]
    fn did_search_expire_never_holds_when_resting_is_off() {
        let mut f = forager(&[("resting", "false")]);
        let mut c = ActuatorCommand::idle(0, 1);
        search_food(&mut f, &frame(1), &mut c);
        assert!(!did_search_expire(&f, &frame(1_000_000)));
    }

    #[test]
    fn did_rest_expire_after_1000_ticks_and_continue_rest_restarts_the_period() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        stop(&mut f, &frame(50), &mut c);
        assert_eq!(c.wheels, [0.0, 0.0]);
        assert!(!did_rest_expire(&f, &frame(1049)));
        assert!(did_rest_expire(&f, &frame(1050)));
        continue_rest(&mut f, &frame(1050), &mut c);
        assert!(!did_rest_expire(&f, &frame(2049)));
        assert!(did_rest_expire(&f, &frame(2050)));
        search_food(&mut f, &frame(2051), &mut c);
        assert!(!did_rest_expire(&f, &frame(9000)));
    }

    #[test]
    fn led_shows_search_return_and_rest_phases_never_the_target_colour() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        search_food(&mut f, &frame(1), &mut c);
        assert_eq!(c.led, SEARCH_LED);
        rest(&mut f, &frame(2), &mut c);
        assert_eq!(c.led, RETURN_LED);
        stop(&mut f, &frame(3), &mut c);
        assert_eq!(c.led, REST_LED);
        for led in [SEARCH_LED, RETURN_LED, REST_LED] {
            assert_ne!(led, f.food_color);
        }
    }

    #[test]
    fn saw_home_needs_a_light_reading_above_0_05() {
        let f = forager(&[]);
        let mut fr = frame(1);
        fr.light[3] = 0.05;
        assert!(!saw_home(&f, &fr));
        fr.light[3] = 0.051;
        assert!(saw_home(&f, &fr));
    }

    #[test]
    fn is_in_home_when_the_middle_ground_sensor_reads_black() {
        let f = forager(&[]);
        let mut fr = frame(1);
        fr.ground[..3].copy_from_slice(&[0.0, 1.0, 0.0]);
        assert!(!is_in_home(&f, &fr));
        fr.ground[..3].copy_from_slice(&[1.0, 0.2, 1.0]);
        assert!(is_in_home(&f, &fr));
    }

    #[test]
    fn is_on_food_within_6_2_cm_of_a_red_blob_only() {
        let f = forager(&[]);
        assert!(saw_food(&f, &with_blob(1, RED, 0.0, 30.0)));
        assert!(!is_on_food(&f, &with_blob(1, RED, 0.0, 6.3)));
        assert!(is_on_food(&f, &with_blob(1, RED, 0.0, 6.2)));
        assert!(!saw_food(&f, &with_blob(1, SEARCH_LED, 0.0, 5.0)));
    }

    #[test]
    fn turn_to_food_pivots_towards_the_blob_and_drives_on_when_aligned() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        turn_to_food(&mut f, &with_blob(1, RED, 0.5, 20.0), &mut c);
        assert_eq!(c.wheels, [-6.4, 6.4]);
        turn_to_food(&mut f, &with_blob(1, RED, -0.5, 20.0), &mut c);
        assert_eq!(c.wheels, [6.4, -6.4]);
        turn_to_food(&mut f, &with_blob(1, RED, 0.1, 20.0), &mut c);
        assert_eq!(c.wheels, [12.8, 12.8]);
    }

    #[test]
    fn pick_ended_holds_from_the_tick_after_pick_food() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        assert!(!pick_ended(&f, &frame(10)));
        pick_food(&mut f, &frame(10), &mut c);
        assert_eq!(c.gripper, GripperAction::Pick);
        assert!(!pick_ended(&f, &frame(10)));
        assert!(pick_ended(&f, &frame(11)));
        pick_done(&mut f, &frame(11), &mut c);
        assert_eq!(c.gripper, GripperAction::Hold);
        assert!(!pick_ended(&f, &frame(12)));
    }

    #[test]
    fn turn_to_home_pivots_towards_the_brightest_light_sensor() {
        let mut f = forager(&[]);
        let mut c = ActuatorCommand::idle(0, 1);
        let mut fr = frame(1);
        fr.light[2] = 0.4;
        turn_to_home(&mut f, &fr, &mut c);
        assert_eq!(c.wheels, [-6.4, 6.4]);
        turn_inv_home(&mut f, &fr, &mut c);
        assert_eq!(c.wheels, [6.4, -6.4]);
    }

    #[test]
    fn malformed_resting_switch_names_the_parameter() {
        let err = Forager::from_params(&Params::new([("resting", "yes")])).unwrap_err();
        assert_eq!(
            err.to_string(),
            "parameter `resting` = \"yes\" is not `true` or `false`"
        );
    }
}
