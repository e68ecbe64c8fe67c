//! Native controller `footbot_foraging`: a port of ARGoS' foot-bot foraging example, written from its documented
//! behaviour. It runs with the example's loop functions (`foraging_loop_functions` with `<foraging items=...>`),
//! which hand a robot a food item when it drives over one and take it back in the nest.
//!
//! Three states, shown on the LEDs (ring and beacon):
//!
//! - **resting** (red), in the nest. After `minimum_resting_time` ticks it leaves with probability
//!   `rest_to_explore` per tick. Meanwhile it listens to range-and-bearing byte 0 of the robots around it: a
//!   neighbour's successful exploration raises `rest_to_explore` and lowers `explore_to_rest` by the social deltas,
//!   an unsuccessful one does the opposite.
//! - **exploring** (green): diffusion (turn away from what the proximity ring sees unless the mean vector lies
//!   within `go_straight_angle_range` and is shorter than `delta`), pushed away from the light while still in the
//!   nest. Every collision makes resting likelier. Finding food makes exploring likelier and sends it home; after
//!   `minimum_unsuccessful_explore_time` ticks without food it goes home with probability `explore_to_rest`, or
//!   else shifts the probabilities towards resting.
//! - **returning to the nest** (blue): towards the light with diffusion. Once in the nest (motor-ground sensors
//!   2 and 3 read grey) for `minimum_search_for_place_in_nest_time` ticks it stops, broadcasts the outcome of its
//!   exploration (1 successful, 2 unsuccessful) and rests.
//!
//! Parameters as in the example's `<params>`: `<diffusion go_straight_angle_range="-5:5" delta>`,
//! `<wheel_turning .../>` ([`WheelTurning`]) and `<state .../>` with the ten numbers below; ARGoS requires them all,
//! here the example's values are the defaults. Draws come from a ChaCha8 stream of the run's seed and the robot.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarm_contract::messages::{ActuatorCommand, Rgb, SensorFrame};

use crate::params::{ParamError, Params};

use super::NativeController;
use super::footbot::{WheelTurning, ring_sum};

const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };
const GREEN: Rgb = Rgb { r: 0, g: 255, b: 0 };
const BLUE: Rgb = Rgb { r: 0, g: 0, b: 255 };

/// What a robot broadcasts about its last exploration (range-and-bearing byte 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
enum Outcome {
    None = 0,
    Successful = 1,
    Unsuccessful = 2,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Resting,
    Exploring,
    ReturningToNest,
}

/// The `<state>` parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Rules {
    initial_rest_to_explore: f32,
    initial_explore_to_rest: f32,
    food_explore_to_rest_delta: f32,
    food_rest_to_explore_delta: f32,
    collision_explore_to_rest_delta: f32,
    social_rest_to_explore_delta: f32,
    social_explore_to_rest_delta: f32,
    minimum_resting_time: u32,
    minimum_unsuccessful_explore_time: u32,
    minimum_search_for_place_in_nest_time: u32,
}

/// The ARGoS example controller.
#[derive(Debug, Clone)]
pub struct FootbotForaging {
    go_straight: (f32, f32),
    delta: f32,
    wheels: WheelTurning,
    rules: Rules,
    seed: u64,
    rng: Option<ChaCha8Rng>,
    state: State,
    in_nest: bool,
    rest_to_explore: f32,
    explore_to_rest: f32,
    time_exploring_unsuccessfully: u32,
    time_rested: u32,
    time_searching_for_place_in_nest: u32,
    last_outcome: Outcome,
    broadcast: Outcome,
    led: Rgb,
    wheel_speeds: [f32; 2],
}

/// `name` as `min:max` in degrees, or `default` when absent.
fn degree_range(
    params: &Params,
    name: &str,
    default: (f32, f32),
) -> Result<(f32, f32), ParamError> {
    let Some(raw) = params.get(name) else {
        return Ok((default.0.to_radians(), default.1.to_radians()));
    };
    let malformed = || ParamError::Malformed {
        name: name.to_owned(),
        value: raw.to_owned(),
        expected: "a range `min:max` of finite angles in degrees, min <= max",
    };
    let (lo, hi) = raw.split_once(':').ok_or_else(malformed)?;
    let parse = |s: &str| {
        s.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(malformed)
    };
    let (lo, hi) = (parse(lo)?, parse(hi)?);
    if lo > hi {
        return Err(malformed());
    }
    Ok((lo.to_radians(), hi.to_radians()))
}

impl FootbotForaging {
    /// Registry name.
    pub const NAME: &'static str = "footbot_foraging";

    /// Reads `diffusion.*`, `wheel_turning.*` and `state.*`.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let p = |name: &str, default: f32| params.unit_f32_or(&format!("state.{name}"), default);
        let rules = Rules {
            initial_rest_to_explore: p("initial_rest_to_explore_prob", 0.1)?,
            initial_explore_to_rest: p("initial_explore_to_rest_prob", 0.1)?,
            food_explore_to_rest_delta: p("food_rule_explore_to_rest_delta_prob", 0.01)?,
            food_rest_to_explore_delta: p("food_rule_rest_to_explore_delta_prob", 0.01)?,
            collision_explore_to_rest_delta: p("collision_rule_explore_to_rest_delta_prob", 0.01)?,
            social_rest_to_explore_delta: p("social_rule_rest_to_explore_delta_prob", 0.01)?,
            social_explore_to_rest_delta: p("social_rule_explore_to_rest_delta_prob", 0.01)?,
            minimum_resting_time: params.whole_or("state.minimum_resting_time", 50)?,
            minimum_unsuccessful_explore_time: params
                .whole_or("state.minimum_unsuccessful_explore_time", 600)?,
            minimum_search_for_place_in_nest_time: params
                .whole_or("state.minimum_search_for_place_in_nest_time", 50)?,
        };
        Ok(Self {
            go_straight: degree_range(params, "diffusion.go_straight_angle_range", (-10.0, 10.0))?,
            delta: params.non_negative_f32_or("diffusion.delta", 0.1)?,
            wheels: WheelTurning::from_params(params)?,
            seed: params.run_seed(),
            rng: None,
            state: State::Resting,
            in_nest: true,
            rest_to_explore: rules.initial_rest_to_explore,
            explore_to_rest: rules.initial_explore_to_rest,
            time_exploring_unsuccessfully: 0,
            // Starting as if rested long enough makes robots decide at once instead of waiting.
            time_rested: rules.minimum_resting_time,
            time_searching_for_place_in_nest: 0,
            last_outcome: Outcome::None,
            broadcast: Outcome::None,
            led: RED,
            wheel_speeds: [0.0; 2],
            rules,
        })
    }

    /// Moves probability from exploring to resting (`delta` > 0) or back, both kept in [0, 1].
    fn shift_towards_rest(&mut self, to_rest: f32, from_explore: f32) {
        self.explore_to_rest = (self.explore_to_rest + to_rest).clamp(0.0, 1.0);
        self.rest_to_explore = (self.rest_to_explore - from_explore).clamp(0.0, 1.0);
    }

    fn update_in_nest(&mut self, frame: &SensorFrame) {
        let grey = |v: f32| v > 0.25 && v < 0.75;
        let g = frame.ground_readings();
        self.in_nest = g.len() >= 4 && grey(g[2]) && grey(g[3]);
    }

    /// The unit vector away from what the proximity ring sees, or straight ahead when the way is clear; and
    /// whether something was in the way.
    fn diffusion(&self, frame: &SensorFrame) -> ((f32, f32), bool) {
        let (x, y) = ring_sum(frame.proximity_readings());
        let angle = y.atan2(x);
        let length = x.hypot(y);
        let clear =
            angle >= self.go_straight.0 && angle <= self.go_straight.1 && length < self.delta;
        if clear || length == 0.0 {
            ((1.0, 0.0), false)
        } else {
            ((-x / length, -y / length), true)
        }
    }

    /// The unit vector towards the light, or zero when none is seen.
    fn to_light(frame: &SensorFrame) -> (f32, f32) {
        let (x, y) = ring_sum(frame.light_readings());
        let length = x.hypot(y);
        if length > 0.0 {
            (x / length, y / length)
        } else {
            (0.0, 0.0)
        }
    }

    fn rest(&mut self, frame: &SensorFrame, draw: f32) {
        if self.time_rested > self.rules.minimum_resting_time && draw < self.rest_to_explore {
            self.led = GREEN;
            self.state = State::Exploring;
            self.time_rested = 0;
            return;
        }
        self.time_rested += 1;
        if self.time_rested == 1 {
            self.broadcast = Outcome::None;
        }
        for message in frame.rab_messages() {
            let social_rest = self.rules.social_explore_to_rest_delta;
            let social_explore = self.rules.social_rest_to_explore_delta;
            match message.payload[0] {
                1 => {
                    self.rest_to_explore = (self.rest_to_explore + social_explore).clamp(0.0, 1.0);
                    self.explore_to_rest = (self.explore_to_rest - social_rest).clamp(0.0, 1.0);
                }
                2 => self.shift_towards_rest(social_rest, social_explore),
                _ => {}
            }
        }
    }

    fn explore(&mut self, frame: &SensorFrame, draw: f32) {
        let mut go_home = false;
        if frame.gripper_holding != 0 {
            let rules = self.rules;
            self.shift_towards_rest(
                -rules.food_explore_to_rest_delta,
                -rules.food_rest_to_explore_delta,
            );
            self.last_outcome = Outcome::Successful;
            go_home = true;
        } else if self.time_exploring_unsuccessfully > self.rules.minimum_unsuccessful_explore_time
        {
            if draw < self.explore_to_rest {
                self.last_outcome = Outcome::Unsuccessful;
                go_home = true;
            } else {
                let rules = self.rules;
                self.shift_towards_rest(
                    rules.food_explore_to_rest_delta,
                    rules.food_rest_to_explore_delta,
                );
            }
        }
        if go_home {
            self.time_exploring_unsuccessfully = 0;
            self.time_searching_for_place_in_nest = 0;
            self.led = BLUE;
            self.state = State::ReturningToNest;
            return;
        }
        self.time_exploring_unsuccessfully += 1;
        self.update_in_nest(frame);
        let ((dx, dy), collision) = self.diffusion(frame);
        if collision {
            let delta = self.rules.collision_explore_to_rest_delta;
            self.shift_towards_rest(delta, delta);
        }
        let v = self.wheels.max_speed;
        let heading = if self.in_nest {
            let (lx, ly) = Self::to_light(frame);
            (v * dx - 0.25 * v * lx, v * dy - 0.25 * v * ly)
        } else {
            (v * dx, v * dy)
        };
        self.wheel_speeds = self.wheels.wheels_towards(heading);
    }

    fn return_to_nest(&mut self, frame: &SensorFrame) {
        self.update_in_nest(frame);
        if self.in_nest {
            if self.time_searching_for_place_in_nest
                > self.rules.minimum_search_for_place_in_nest_time
            {
                self.wheel_speeds = [0.0; 2];
                self.broadcast = self.last_outcome;
                self.led = RED;
                self.state = State::Resting;
                self.time_searching_for_place_in_nest = 0;
                self.last_outcome = Outcome::None;
                return;
            }
            self.time_searching_for_place_in_nest += 1;
        } else {
            self.time_searching_for_place_in_nest = 0;
        }
        let ((dx, dy), _) = self.diffusion(frame);
        let (lx, ly) = Self::to_light(frame);
        let v = self.wheels.max_speed;
        self.wheel_speeds = self
            .wheels
            .wheels_towards((v * dx + v * lx, v * dy + v * ly));
    }
}

impl NativeController for FootbotForaging {
    fn step(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let seed = self.seed;
        let rng = self.rng.get_or_insert_with(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(u64::from(frame.robot));
            rng
        });
        let draw: f32 = rng.random();
        match self.state {
            State::Resting => self.rest(frame, draw),
            State::Exploring => self.explore(frame, draw),
            State::ReturningToNest => self.return_to_nest(frame),
        }
        command.wheels = self.wheel_speeds;
        command.led = self.led;
        command.beacon = self.led;
        command.rab_len = 1;
        command.rab_payload[0] = self.broadcast as u8;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controller() -> FootbotForaging {
        FootbotForaging::from_params(&Params::default().with_run_seed(3)).unwrap()
    }

    fn frame() -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        f.proximity_len = 24;
        f.light_len = 24;
        f.ground_len = 4;
        f
    }

    #[test]
    fn a_robot_starts_resting_red_and_broadcasting_nothing() {
        let mut c = controller();
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&frame(), &mut cmd);
        assert!(cmd.led == RED || cmd.led == GREEN);
        assert_eq!(cmd.rab_len, 1);
        assert_eq!(cmd.rab_payload[0], 0);
    }

    #[test]
    fn found_food_sends_it_home_blue_and_home_it_rests_and_reports_success() {
        let mut c = controller();
        c.state = State::Exploring;
        c.led = GREEN;
        let mut f = frame();
        f.gripper_holding = 1;
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        assert_eq!(cmd.led, BLUE);
        // In the nest: grey under sensors 2 and 3, for longer than the search time.
        let mut nest = frame();
        nest.ground[..4].copy_from_slice(&[0.5; 4]);
        for _ in 0..=c.rules.minimum_search_for_place_in_nest_time + 1 {
            c.step(&nest, &mut cmd);
        }
        assert_eq!(cmd.led, RED);
        assert_eq!(cmd.wheels, [0.0, 0.0]);
        assert_eq!(cmd.rab_payload[0], Outcome::Successful as u8);
    }

    #[test]
    fn neighbours_successes_make_resting_robots_likelier_to_explore() {
        let mut c = controller();
        c.time_rested = 0;
        let before = c.rest_to_explore;
        let mut f = frame();
        f.rab_len = 1;
        f.rab[0].payload[0] = Outcome::Successful as u8;
        let mut cmd = ActuatorCommand::idle(0, 1);
        c.step(&f, &mut cmd);
        assert!(c.rest_to_explore > before);
    }

    #[test]
    fn go_straight_range_must_read_min_colon_max() {
        let p = Params::new([("diffusion.go_straight_angle_range", "5")]);
        assert!(FootbotForaging::from_params(&p).is_err());
        let p = Params::new([("diffusion.go_straight_angle_range", "-5:5")]);
        assert!(FootbotForaging::from_params(&p).is_ok());
    }
}
