//! The profile registry: operational-procedure profiles under the names configs use (`<params profile="...">`).
//!
//! [`bind_profile`] builds one robot's memory from its parameters and binds it to a supervisor set's events.

pub mod aggregation;
mod assembly;
pub mod exploration;
pub mod foraging;
pub mod navigation;
pub mod obstacle_avoidance;
pub mod path_planning;
pub mod pheromone_foraging;
pub mod phototaxis;
pub mod synchronisation;
pub mod timer;
pub mod transport;

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::EventCallbacks;
use swarm_contract::supervisor_gen::compiled::CompiledEvent;
use thiserror::Error;

use crate::binding::{BindError, Talk, bind};
use crate::params::{ParamError, Params};
use crate::profile::Profile;

use aggregation::Aggregation;
use exploration::Explorer;
use foraging::Forager;
use navigation::Navigator;
use obstacle_avoidance::{ObstacleAvoidance, ObstacleAvoidanceSct};
use path_planning::PathPlanner;
use pheromone_foraging::PheromoneForager;
use phototaxis::Phototaxis;
use synchronisation::{Synchronisation, SynchronisationSct};
use transport::Carrier;

/// What a bound profile is to the agent: the player's callbacks and the profile's messages.
trait ProfileCallbacks: EventCallbacks + Talk + Send {}

impl<T: EventCallbacks + Talk + Send> ProfileCallbacks for T {}

/// Callbacks of a bound profile, whatever its memory type, ready for the player.
pub struct BoxedCallbacks {
    callbacks: Box<dyn ProfileCallbacks>,
    /// The profile's [`Profile::TALKS`]: a profile that does not talk is not called for its messages at all
    /// (the call would cost an agent a page of code it otherwise never touches, every tick).
    talks: bool,
}

impl Talk for BoxedCallbacks {
    fn receive(&mut self, inbox: &Mailbox) {
        if self.talks {
            self.callbacks.receive(inbox);
        }
    }

    fn send(&mut self, outbox: &mut Mailbox) {
        if self.talks {
            self.callbacks.send(outbox);
        }
    }
}

impl EventCallbacks for BoxedCallbacks {
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool {
        self.callbacks.check(event, frame)
    }

    fn act(&mut self, event: u8, frame: &SensorFrame, command: &mut ActuatorCommand) {
        self.callbacks.act(event, frame, command);
    }
}

type BindFn = fn(&Params, &[CompiledEvent]) -> Result<BoxedCallbacks, ProfileError>;

/// Every profile, by name.
const PROFILES: &[(&str, BindFn)] = &[
    (ObstacleAvoidance::NAME, bind_boxed::<ObstacleAvoidance>),
    (
        ObstacleAvoidanceSct::NAME,
        bind_boxed::<ObstacleAvoidanceSct>,
    ),
    (Aggregation::NAME, bind_boxed::<Aggregation>),
    (Synchronisation::NAME, bind_boxed::<Synchronisation>),
    (SynchronisationSct::NAME, bind_boxed::<SynchronisationSct>),
    (Forager::NAME, bind_boxed::<Forager>),
    (PheromoneForager::NAME, bind_boxed::<PheromoneForager>),
    (Phototaxis::NAME, bind_boxed::<Phototaxis>),
    (Navigator::NAME, bind_boxed::<Navigator>),
    (PathPlanner::NAME, bind_boxed::<PathPlanner>),
    (Explorer::NAME, bind_boxed::<Explorer>),
    (Carrier::NAME, bind_boxed::<Carrier>),
];

/// Why a profile could not be set up.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ProfileError {
    /// No profile has this name.
    #[error("unknown profile `{name}` (known profiles: {known})")]
    Unknown {
        /// The name asked for.
        name: String,
        /// Comma-separated registered names.
        known: String,
    },
    /// A parameter of the profile is bad.
    #[error("profile `{profile}`: {problem}")]
    Param {
        /// The profile.
        profile: &'static str,
        /// The parameter problem.
        problem: ParamError,
    },
    /// The profile's callbacks do not fit the supervisors.
    #[error(transparent)]
    Bind(#[from] BindError),
}

/// Names of all registered profiles.
pub fn profile_names() -> impl Iterator<Item = &'static str> {
    PROFILES.iter().map(|(name, _)| *name)
}

/// Whether a profile of this name is registered.
pub fn is_profile(name: &str) -> bool {
    PROFILES.iter().any(|(n, _)| *n == name)
}

/// Builds profile `name` from `params` and binds it to `events` (index = event id).
pub fn bind_profile(
    name: &str,
    params: &Params,
    events: &[CompiledEvent],
) -> Result<BoxedCallbacks, ProfileError> {
    let Some((_, bind_fn)) = PROFILES.iter().find(|(n, _)| *n == name) else {
        return Err(ProfileError::Unknown {
            name: name.to_owned(),
            known: profile_names().collect::<Vec<_>>().join(", "),
        });
    };
    bind_fn(params, events)
}

fn bind_boxed<P: Profile>(
    params: &Params,
    events: &[CompiledEvent],
) -> Result<BoxedCallbacks, ProfileError> {
    let state = P::from_params(params).map_err(|problem| ProfileError::Param {
        profile: P::NAME,
        problem,
    })?;
    Ok(BoxedCallbacks {
        callbacks: Box::new(bind(state, events)?),
        talks: P::TALKS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn events(names: &[(&str, bool)]) -> Vec<CompiledEvent> {
        names
            .iter()
            .map(|&(name, controllable)| CompiledEvent {
                name: name.to_owned(),
                controllable,
            })
            .collect()
    }

    #[test]
    fn unknown_profile_lists_the_known_ones() {
        let err = bind_profile("flocking", &Params::default(), &[])
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "unknown profile `flocking` (known profiles: obstacle_avoidance, obstacle_avoidance_sct, \
             aggregation, synchronisation, synchronisation_sct, foraging, pheromone_foraging, phototaxis, navigation, path_planning, exploration, transport)"
        );
    }

    #[test]
    fn obstacle_avoidance_binds_the_ptsct_events() {
        let ev = events(&[
            ("Go", true),
            ("turn-left", true),
            ("turn-right", true),
            ("turn-inv-obs", true),
            ("saw-obs", false),
        ]);
        assert!(bind_profile("obstacle_avoidance", &Params::default(), &ev).is_ok());
    }

    #[test]
    fn obstacle_avoidance_rejects_timer_events_of_the_sct_models() {
        let ev = events(&[
            ("Go", true),
            ("turn-left", true),
            ("turn-right", true),
            ("turn-inv-obs", true),
            ("saw-obs", false),
            ("start_timer_1", true),
        ]);
        let err = bind_profile("obstacle_avoidance", &Params::default(), &ev)
            .err()
            .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `obstacle_avoidance` does not fit the supervisors\n  \
             supervisor events without a callback: `start_timer_1` (controllable)"
        );
    }

    #[test]
    fn bad_velocity_is_reported_with_the_profile_name() {
        let err = bind_profile(
            "obstacle_avoidance",
            &Params::new([("velocity", "-1")]),
            &[],
        )
        .err()
        .unwrap();
        assert_eq!(
            err.to_string(),
            "profile `obstacle_avoidance`: parameter `velocity` = -1 is out of range: must be >= 0"
        );
    }
}
