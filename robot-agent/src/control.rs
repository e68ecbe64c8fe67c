//! A robot's built controller: everything loaded, bound and checked before the first tick.
//!
//! Building turns a [`Plan`] into a [`Control`]: it loads or synthesises the supervisor set, binds every event to
//! the profile's callbacks (one error listing all mismatches), or builds the native controller. Every failure here
//! happens at startup, so the agent can exit non-zero with the reason before tick 1.

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::{Player, PlayerError};
use swarm_contract::supervisor_gen::compiled::SupervisorSet;
use thiserror::Error;
use tracing::debug;

use crate::binding::Talk;
use crate::controller::{Plan, Supervisors};
use crate::native::{self, BoxedNative, NativeError};
use crate::params::Params;
use crate::profiles::{self, BoxedCallbacks, ProfileError};
use crate::supervisors::{self, SupervisorError};

/// A controller ready to run.
pub enum Control {
    /// Supervisors and the profile callbacks bound to their events.
    Supervised {
        /// The player executing the robot's supervisor set.
        player: Box<Player>,
        /// The bound callbacks.
        callbacks: BoxedCallbacks,
    },
    /// A native controller.
    Native(BoxedNative),
}

/// Why a controller could not be built.
#[derive(Debug, Error)]
pub enum BuildError {
    /// The supervisors could not be loaded.
    #[error("supervisors {where_}: {problem}")]
    Supervisors {
        /// Where they were loaded from.
        where_: String,
        /// What went wrong.
        problem: SupervisorError,
    },
    /// The profile could not be set up or bound.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// The player refused the supervisor set.
    #[error("supervisors {where_}: {problem}")]
    Player {
        /// Where they were loaded from.
        where_: String,
        /// What the player refused.
        problem: PlayerError,
    },
    /// The native controller could not be built.
    #[error(transparent)]
    Native(#[from] NativeError),
}

impl Control {
    /// Names of the events the controller's supervisors fire, by event id (empty for a native controller).
    pub fn event_names(&self) -> Vec<String> {
        match self {
            Control::Supervised { player, .. } => {
                player.events().iter().map(|e| e.name.clone()).collect()
            }
            Control::Native(_) => Vec::new(),
        }
    }

    /// One control step with the tick's `inbox` and an `outbox` for what the robot sends: the profile takes in
    /// its messages, the player steps with the bound callbacks, the profile sends; or the native controller's
    /// step. `command` carries the actuator state over from the previous tick; allocates nothing.
    #[unsafe(link_section = "swarm_hot")]
    pub fn step(
        &mut self,
        frame: &SensorFrame,
        inbox: &Mailbox,
        outbox: &mut Mailbox,
        command: &mut ActuatorCommand,
    ) {
        match self {
            Control::Supervised { player, callbacks } => {
                callbacks.receive(inbox);
                player.step(frame, callbacks, command);
                callbacks.send(outbox);
            }
            Control::Native(native) => {
                command.events_len = 0;
                native.step_with_mail(frame, inbox, outbox, command);
            }
        }
    }
}

/// Loads (or synthesises) the supervisor set of a supervised plan; `None` for a native controller.
pub fn supervisor_set(plan: &Plan) -> Result<Option<SupervisorSet>, BuildError> {
    match plan {
        Plan::Supervised {
            supervisors,
            reduce,
            ..
        } => load_set(supervisors, *reduce).map(Some),
        Plan::Native { .. } => Ok(None),
    }
}

fn load_set(source: &Supervisors, reduce: bool) -> Result<SupervisorSet, BuildError> {
    let loaded = match source {
        Supervisors::Builtin(_, models) => supervisors::synthesise_with(models, reduce),
        Supervisors::Files(files) => supervisors::load_with(files, reduce),
    };
    loaded.map_err(|problem| BuildError::Supervisors {
        where_: source.to_string(),
        problem,
    })
}

/// Loads, binds and checks everything `plan` needs, with parameters from `params`, for robot `robot` of a run
/// seeded with `run_seed` (the player's random stream).
pub fn build(
    plan: &Plan,
    params: &Params,
    run_seed: u64,
    robot: u32,
) -> Result<Control, BuildError> {
    match plan {
        Plan::Supervised {
            profile,
            supervisors,
            reduce,
        } => {
            let where_ = supervisors.to_string();
            let set = load_set(supervisors, *reduce)?;
            let params = params.clone().with_run_seed(run_seed);
            let callbacks = profiles::bind_profile(profile, &params, &set.events)?;
            debug!(
                profile = profile.as_str(),
                supervisors = where_.as_str(),
                count = set.supervisors.len(),
                events = set.events.len(),
                "supervised controller bound"
            );
            let player =
                Player::new(set, run_seed, robot).map_err(|problem| BuildError::Player {
                    where_: where_.clone(),
                    problem,
                })?;
            Ok(Control::Supervised {
                player: Box::new(player),
                callbacks,
            })
        }
        Plan::Native { name } => {
            let controller = native::build_native(name, &params.clone().with_run_seed(run_seed))?;
            debug!(native = name.as_str(), "native controller built");
            Ok(Control::Native(controller))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::supervisors::OBSTACLE_AVOIDANCE_PTSCT;

    #[test]
    fn builtin_thesis_controller_builds_and_binds() {
        let plan = Plan::Supervised {
            profile: "obstacle_avoidance".to_owned(),
            supervisors: Supervisors::Builtin("obstacle_avoidance/ptsct", OBSTACLE_AVOIDANCE_PTSCT),
            reduce: false,
        };
        assert!(matches!(
            build(&plan, &Params::default(), 1, 0),
            Ok(Control::Supervised { .. })
        ));
    }

    #[test]
    fn wrong_profile_for_the_builtin_models_fails_at_build() {
        let plan = Plan::Supervised {
            profile: "obstacle_avoidance_sct".to_owned(),
            supervisors: Supervisors::Builtin("obstacle_avoidance/ptsct", OBSTACLE_AVOIDANCE_PTSCT),
            reduce: false,
        };
        let err = build(&plan, &Params::default(), 1, 0).err().unwrap();
        assert!(matches!(err, BuildError::Profile(ProfileError::Bind(_))));
    }

    #[test]
    fn missing_supervisor_file_names_the_path() {
        let plan = Plan::Supervised {
            profile: "obstacle_avoidance".to_owned(),
            supervisors: Supervisors::Files(vec!["/nonexistent/oa.sup".into()]),
            reduce: false,
        };
        let err = build(&plan, &Params::default(), 1, 0)
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.starts_with("supervisors /nonexistent/oa.sup: "),
            "{err}"
        );
    }

    #[test]
    fn native_plan_builds_the_argos_port() {
        let plan = Plan::Native {
            name: "epuck_obstacleavoidance".to_owned(),
        };
        assert!(matches!(
            build(&plan, &Params::default(), 1, 0),
            Ok(Control::Native(_))
        ));
    }
}
