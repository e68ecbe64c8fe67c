//! Which controller a robot runs: the registry of controller names and the rules that turn a config's controller
//! element and `<params>` into a plan.
//!
//! A controller is either a supervisor set plus an operational-procedure profile, or a native controller. Configs
//! written for this project name both parts in `<params>`: `profile="obstacle_avoidance"` and
//! `supervisors="models/ptsct"` (a folder of XML models, synthesised local-modular at startup, or a compiled
//! supervisor file; relative to the config file). Controllers without these params are looked up by element name
//! (ARGoS style): the thesis' and ARGoS' controller names map to built-ins, and a native controller's own name
//! selects it.

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;
use tracing::info;

use crate::native;
use crate::params::Params;
use crate::profile::Profile;
use crate::profiles::{self, obstacle_avoidance::ObstacleAvoidance};
use crate::supervisors::{ModelText, OBSTACLE_AVOIDANCE_PTSCT};

/// What a robot will run, before anything is loaded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Plan {
    /// A supervisor set executed by the player, with events bound to a profile.
    Supervised {
        /// Registered profile name.
        profile: String,
        /// The supervisors.
        supervisors: Supervisors,
    },
    /// A native controller.
    Native {
        /// Registered native controller name.
        name: String,
    },
}

/// Owned form of [`SupervisorSource`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Supervisors {
    /// Models built into this binary.
    Builtin(&'static str, &'static [ModelText<'static>]),
    /// A folder of XML models or a compiled supervisor file, already resolved against the config's folder.
    Path(PathBuf),
}

impl fmt::Display for Supervisors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Supervisors::Builtin(name, _) => write!(f, "built-in {name}"),
            Supervisors::Path(path) => write!(f, "{}", path.display()),
        }
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Plan::Supervised {
                profile,
                supervisors,
            } => write!(f, "profile `{profile}` with supervisors {supervisors}"),
            Plan::Native { name } => write!(f, "native controller `{name}`"),
        }
    }
}

/// A built-in controller element name (ARGoS or thesis) and what it stands for.
struct Builtin {
    element: &'static str,
    plan: fn() -> Plan,
}

/// Controller element names from ARGoS and the thesis that map to built-ins.
const BUILTINS: &[Builtin] = &[
    Builtin {
        element: "epuck_obstacle_avoidance_sct_prob_controller",
        plan: || Plan::Supervised {
            profile: <ObstacleAvoidance as Profile>::NAME.to_owned(),
            supervisors: Supervisors::Builtin("obstacle_avoidance/ptsct", OBSTACLE_AVOIDANCE_PTSCT),
        },
    },
    Builtin {
        element: "epuck_obstacleavoidance_controller",
        plan: || Plan::Native {
            name: native::epuck_obstacleavoidance::EpuckObstacleAvoidance::NAME.to_owned(),
        },
    },
];

/// Why a controller element does not name something this agent can run.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PlanError {
    /// Neither params nor the element name select a controller.
    #[error(
        "unknown controller `{element}`: give `profile` and `supervisors` in <params>, or use one of: {known}"
    )]
    UnknownController {
        /// The element name.
        element: String,
        /// Comma-separated names this agent knows.
        known: String,
    },
    /// `profile` names no registered profile.
    #[error("unknown profile `{name}` in <params> (known profiles: {known})")]
    UnknownProfile {
        /// The name given.
        name: String,
        /// Comma-separated registered names.
        known: String,
    },
    /// Only one of `profile` and `supervisors` is given.
    #[error("<params> gives `{given}` but not `{missing}`; a supervised controller needs both")]
    Incomplete {
        /// The param present.
        given: &'static str,
        /// The param missing.
        missing: &'static str,
    },
}

/// The names a controller element may have without `profile`/`supervisors` params.
pub fn known_elements() -> impl Iterator<Item = &'static str> {
    BUILTINS
        .iter()
        .map(|b| b.element)
        .chain(native::native_names())
}

/// Decides what controller element `element` with `params` runs; relative paths resolve against `base_dir`.
pub fn plan(element: &str, params: &Params, base_dir: &Path) -> Result<Plan, PlanError> {
    let plan = match (params.get("profile"), params.get("supervisors")) {
        (Some(profile), Some(supervisors)) => {
            if !profiles::is_profile(profile) {
                return Err(PlanError::UnknownProfile {
                    name: profile.to_owned(),
                    known: profiles::profile_names().collect::<Vec<_>>().join(", "),
                });
            }
            Plan::Supervised {
                profile: profile.to_owned(),
                supervisors: Supervisors::Path(base_dir.join(supervisors)),
            }
        }
        (Some(_), None) => {
            return Err(PlanError::Incomplete {
                given: "profile",
                missing: "supervisors",
            });
        }
        (None, Some(_)) => {
            return Err(PlanError::Incomplete {
                given: "supervisors",
                missing: "profile",
            });
        }
        (None, None) => {
            if let Some(builtin) = BUILTINS.iter().find(|b| b.element == element) {
                let plan = (builtin.plan)();
                info!("controller element `{element}` maps to {plan}");
                plan
            } else if native::is_native(element) {
                Plan::Native {
                    name: element.to_owned(),
                }
            } else {
                return Err(PlanError::UnknownController {
                    element: element.to_owned(),
                    known: known_elements().collect::<Vec<_>>().join(", "),
                });
            }
        }
    };
    Ok(plan)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_controller_maps_to_obstacle_avoidance_with_builtin_supervisors() {
        let p = plan(
            "epuck_obstacle_avoidance_sct_prob_controller",
            &Params::new([("velocity", "12.8")]),
            Path::new("/cfg"),
        )
        .unwrap();
        assert_eq!(
            p,
            Plan::Supervised {
                profile: "obstacle_avoidance".to_owned(),
                supervisors: Supervisors::Builtin(
                    "obstacle_avoidance/ptsct",
                    OBSTACLE_AVOIDANCE_PTSCT
                ),
            }
        );
    }

    #[test]
    fn argos_example_controller_maps_to_the_native_port() {
        let p = plan(
            "epuck_obstacleavoidance_controller",
            &Params::default(),
            Path::new("/cfg"),
        )
        .unwrap();
        assert_eq!(
            p,
            Plan::Native {
                name: "epuck_obstacleavoidance".to_owned()
            }
        );
    }

    #[test]
    fn native_controller_is_selected_by_its_own_name() {
        let p = plan(
            "epuck_obstacleavoidance",
            &Params::default(),
            Path::new("/cfg"),
        )
        .unwrap();
        assert!(matches!(p, Plan::Native { .. }));
    }

    #[test]
    fn explicit_profile_and_supervisors_resolve_against_the_config_folder() {
        let params = Params::new([
            ("profile", "obstacle_avoidance"),
            ("supervisors", "models/ptsct"),
        ]);
        let p = plan("my_controller", &params, Path::new("/cfg/oa")).unwrap();
        assert_eq!(
            p,
            Plan::Supervised {
                profile: "obstacle_avoidance".to_owned(),
                supervisors: Supervisors::Path(PathBuf::from("/cfg/oa/models/ptsct")),
            }
        );
    }

    #[test]
    fn explicit_params_override_the_element_mapping() {
        let params = Params::new([
            ("profile", "obstacle_avoidance_sct"),
            ("supervisors", "models/sct"),
        ]);
        let p = plan(
            "epuck_obstacleavoidance_controller",
            &params,
            Path::new("/c"),
        )
        .unwrap();
        assert!(
            matches!(p, Plan::Supervised { profile, .. } if profile == "obstacle_avoidance_sct")
        );
    }

    #[test]
    fn profile_without_supervisors_is_incomplete() {
        let err = plan(
            "x",
            &Params::new([("profile", "obstacle_avoidance")]),
            Path::new("/c"),
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "<params> gives `profile` but not `supervisors`; a supervised controller needs both"
        );
    }

    #[test]
    fn unknown_profile_is_rejected_before_loading() {
        let params = Params::new([("profile", "flocking"), ("supervisors", "m")]);
        let err = plan("x", &params, Path::new("/c")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown profile `flocking` in <params> (known profiles: obstacle_avoidance, obstacle_avoidance_sct)"
        );
    }

    #[test]
    fn unknown_element_lists_the_known_names() {
        let err = plan("footbot_diffusion", &Params::default(), Path::new("/c")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown controller `footbot_diffusion`: give `profile` and `supervisors` in <params>, or use one of: \
             epuck_obstacle_avoidance_sct_prob_controller, epuck_obstacleavoidance_controller, \
             epuck_obstacleavoidance"
        );
    }
}
