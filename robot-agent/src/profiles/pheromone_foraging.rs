//! Profile `pheromone_foraging`: the foraging procedures (see [`super::foraging`]) plus artificial pheromones
//! (docs/tasks.md 5), for the models of `configs/pheromone_foraging/models` (G1-G9, E1-E7 with the 5.4 changes).
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `smell-food-trail` / `smell-home-trail` | u | the food / home channel's concentration under the robot > `theta_p` (default 0.05) |
//! | `follow-food-trail` / `follow-home-trail` | c | steer up that channel's gradient (pivot towards it, straight on within 0.15 rad) |
//!
//! Deposits are folded into the motion (docs/tasks.md 5.4): after every action the robot sets what it lays per tick
//! until its next action. While carrying a target it lays the **food trail**, `q_food` (default 1) faded by
//! exp(-ticks since the pick-up / `trail_fade_ticks`) (default 400); while searching without a target it lays the
//! **home trail**, `q_home` (default 1); otherwise nothing. The fade is our choice: it makes each trail strongest
//! at its source, so the gradient leads searchers to the target rather than back home (evaporation alone,
//! rho = 0.001 per tick, would leave the freshest end, near home, strongest). Channels are the sensor's channel
//! indices `food_channel` (default 0) and `home_channel` (default 1).

use swarm_contract::messages::{ActuatorCommand, PHEROMONE_CHANNELS, SensorFrame};

use super::foraging::{self, Forager, Phase};
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default smell threshold θ_p (docs/tasks.md 5.3).
pub const DEFAULT_THETA_P: f32 = 0.05;
/// Default ticks over which the food-trail deposit fades by a factor e.
pub const DEFAULT_TRAIL_FADE_TICKS: f32 = 400.0;

/// A pheromone forager: the foraging memory plus the trail parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct PheromoneForager {
    /// The foraging memory.
    pub forager: Forager,
    /// Channel index of the food trail.
    pub food_channel: usize,
    /// Channel index of the home trail.
    pub home_channel: usize,
    /// Smell threshold.
    pub theta_p: f32,
    /// Food-trail deposit per tick right after a pick-up.
    pub q_food: f32,
    /// Home-trail deposit per tick while searching.
    pub q_home: f32,
    /// Fade time of the food-trail deposit in ticks.
    pub trail_fade_ticks: f32,
    carrying_since: Option<u64>,
}

impl AsRef<Forager> for PheromoneForager {
    fn as_ref(&self) -> &Forager {
        &self.forager
    }
}

impl AsMut<Forager> for PheromoneForager {
    fn as_mut(&mut self) -> &mut Forager {
        &mut self.forager
    }
}

fn channel(params: &Params, name: &str, default: usize) -> Result<usize, ParamError> {
    let Some(raw) = params.get(name) else {
        return Ok(default);
    };
    match raw.trim().parse::<usize>() {
        Ok(c) if c < PHEROMONE_CHANNELS => Ok(c),
        Ok(_) => Err(ParamError::OutOfRange {
            name: name.to_owned(),
            value: raw.to_owned(),
            rule: "must be a channel index below PHEROMONE_CHANNELS (2)",
        }),
        Err(_) => Err(ParamError::Malformed {
            name: name.to_owned(),
            value: raw.to_owned(),
            expected: "a channel index (0 or 1)",
        }),
    }
}

impl PheromoneForager {
    /// What the robot lays from now on, per tick: see the module documentation.
    fn lay(&mut self, frame: &SensorFrame, command: &mut ActuatorCommand) {
        command.pheromone_deposit = [0.0; PHEROMONE_CHANNELS];
        if frame.gripper_holding != 0 {
            let since = *self.carrying_since.get_or_insert(frame.tick);
            let age = frame.tick.saturating_sub(since) as f32;
            command.pheromone_deposit[self.food_channel] =
                self.q_food * (-age / self.trail_fade_ticks).exp();
        } else {
            self.carrying_since = None;
            if self.forager.phase() == Phase::Search {
                command.pheromone_deposit[self.home_channel] = self.q_home;
            }
        }
    }

    fn follow(&self, channel: usize, frame: &SensorFrame, command: &mut ActuatorCommand) {
        let [gx, gy] = frame.pheromone_gradient[channel];
        if gx == 0.0 && gy == 0.0 {
            command.wheels = [self.forager.velocity; 2];
        } else {
            self.forager.steer(gy.atan2(gx), command);
        }
    }
}

/// `smell-food-trail`: the food trail under the robot is above θ_p.
pub fn smell_food_trail(s: &PheromoneForager, frame: &SensorFrame) -> bool {
    frame.pheromone[s.food_channel] > s.theta_p
}

/// `smell-home-trail`: the home trail under the robot is above θ_p.
pub fn smell_home_trail(s: &PheromoneForager, frame: &SensorFrame) -> bool {
    frame.pheromone[s.home_channel] > s.theta_p
}

/// `follow-food-trail`: steer up the food trail, then lay as usual.
pub fn follow_food_trail(
    s: &mut PheromoneForager,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    s.follow(s.food_channel, frame, command);
    s.lay(frame, command);
}

/// `follow-home-trail`: steer up the home trail, then lay as usual.
pub fn follow_home_trail(
    s: &mut PheromoneForager,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    s.follow(s.home_channel, frame, command);
    s.lay(frame, command);
}

const BASE: [(&str, Procedure<PheromoneForager>); 40] = foraging::procedures::<PheromoneForager>();

/// Foraging action `I` of [`BASE`], then the trail deposit.
fn laying<const I: usize>(
    s: &mut PheromoneForager,
    frame: &SensorFrame,
    command: &mut ActuatorCommand,
) {
    if let Procedure::Act(act) = BASE[I].1 {
        act(s, frame, command);
    }
    s.lay(frame, command);
}

macro_rules! with_laying {
    ($($i:literal)*) => {
        /// [`BASE`] with every action followed by the trail deposit, plus the four pheromone events.
        const fn table() -> [(&'static str, Procedure<PheromoneForager>); 44] {
            let mut t = [("", Procedure::Act(foraging::nothing::<PheromoneForager>)); 44];
            $(
                t[$i] = match BASE[$i] {
                    (name, Procedure::Act(_)) => (name, Procedure::Act(laying::<$i>)),
                    check => check,
                };
            )*
            t[40] = ("smell-food-trail", Procedure::Check(smell_food_trail));
            t[41] = ("smell-home-trail", Procedure::Check(smell_home_trail));
            t[42] = ("follow-food-trail", Procedure::Act(follow_food_trail));
            t[43] = ("follow-home-trail", Procedure::Act(follow_home_trail));
            t
        }
    };
}

with_laying!(0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33 34 35 36 37 38 39);

const PHEROMONE_PROCEDURES: [(&str, Procedure<PheromoneForager>); 44] = table();

impl Profile for PheromoneForager {
    const NAME: &'static str = "pheromone_foraging";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &PHEROMONE_PROCEDURES;

    /// The foraging parameters plus `food_channel`, `home_channel`, `theta_p`, `q_food`, `q_home` and
    /// `trail_fade_ticks`.
    fn from_params(params: &Params) -> Result<Self, ParamError> {
        let food_channel = channel(params, "food_channel", 0)?;
        let home_channel = channel(params, "home_channel", 1)?;
        if food_channel == home_channel {
            return Err(ParamError::OutOfRange {
                name: "home_channel".to_owned(),
                value: home_channel.to_string(),
                rule: "must differ from food_channel",
            });
        }
        let trail_fade_ticks =
            params.non_negative_f32_or("trail_fade_ticks", DEFAULT_TRAIL_FADE_TICKS)?;
        if trail_fade_ticks == 0.0 {
            return Err(ParamError::OutOfRange {
                name: "trail_fade_ticks".to_owned(),
                value: "0".to_owned(),
                rule: "must be > 0",
            });
        }
        Ok(Self {
            forager: Forager::from_params(params)?,
            food_channel,
            home_channel,
            theta_p: params.non_negative_f32_or("theta_p", DEFAULT_THETA_P)?,
            q_food: params.non_negative_f32_or("q_food", 1.0)?,
            q_home: params.non_negative_f32_or("q_home", 1.0)?,
            trail_fade_ticks,
            carrying_since: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::profiles::bind_profile;
    use crate::supervisors::load;

    fn frame(tick: u64) -> SensorFrame {
        let mut f = SensorFrame::empty(0);
        f.tick = tick;
        f
    }

    #[test]
    fn profile_binds_every_event_of_the_pheromone_models() {
        let models =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/pheromone_foraging/models");
        let set = load(&[models]).unwrap();
        assert_eq!(set.events.len(), PHEROMONE_PROCEDURES.len());
        assert!(bind_profile("pheromone_foraging", &Params::default(), &set.events).is_ok());
    }

    #[test]
    fn searching_robot_lays_the_home_trail() {
        let mut s = PheromoneForager::from_params(&Params::default()).unwrap();
        let mut c = ActuatorCommand::idle(0, 1);
        let search = PHEROMONE_PROCEDURES
            .iter()
            .find(|(n, _)| *n == "search-food")
            .unwrap()
            .1;
        let Procedure::Act(search) = search else {
            panic!("search-food is an action")
        };
        search(&mut s, &frame(1), &mut c);
        assert_eq!(c.pheromone_deposit, [0.0, 1.0]);
    }

    #[test]
    fn carrier_lays_a_food_trail_that_fades_with_400_tick_time_constant() {
        let mut s = PheromoneForager::from_params(&Params::default()).unwrap();
        let mut c = ActuatorCommand::idle(0, 1);
        let mut f = frame(100);
        f.gripper_holding = 1;
        s.lay(&f, &mut c);
        assert_eq!(c.pheromone_deposit, [1.0, 0.0]);
        f.tick = 500;
        s.lay(&f, &mut c);
        assert!((c.pheromone_deposit[0] - (-1.0f32).exp()).abs() < 1e-6);
        f.gripper_holding = 0;
        s.lay(&f, &mut c);
        assert_eq!(c.pheromone_deposit, [0.0, 0.0]);
    }

    #[test]
    fn smell_food_trail_above_theta_p_0_05() {
        let s = PheromoneForager::from_params(&Params::default()).unwrap();
        let mut f = frame(1);
        f.pheromone = [0.05, 0.0];
        assert!(!smell_food_trail(&s, &f));
        f.pheromone = [0.06, 0.0];
        assert!(smell_food_trail(&s, &f));
        assert!(!smell_home_trail(&s, &f));
    }

    #[test]
    fn follow_food_trail_steers_up_the_gradient() {
        let mut s = PheromoneForager::from_params(&Params::default()).unwrap();
        let mut c = ActuatorCommand::idle(0, 1);
        let mut f = frame(1);
        f.pheromone_gradient[0] = [0.0, 2.0];
        follow_food_trail(&mut s, &f, &mut c);
        assert_eq!(c.wheels, [-6.4, 6.4]);
        f.pheromone_gradient[0] = [2.0, 0.1];
        follow_food_trail(&mut s, &f, &mut c);
        assert_eq!(c.wheels, [12.8, 12.8]);
    }

    #[test]
    fn equal_channels_are_rejected() {
        let err = PheromoneForager::from_params(&Params::new([
            ("food_channel", "1"),
            ("home_channel", "1"),
        ]))
        .unwrap_err();
        assert!(
            err.to_string().contains("must differ from food_channel"),
            "{err}"
        );
    }
}
