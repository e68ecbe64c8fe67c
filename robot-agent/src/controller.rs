//! Which controller a robot runs: the registry of controller names and the rules that turn a config's controller
//! element and `<params>` into a plan.
//!
//! A controller is either a supervisor set plus an operational-procedure profile, or a native controller. Configs
//! written for this project name both parts in `<params>`: `profile="obstacle_avoidance"` and
//! `supervisors="models/ptsct"` (comma-separated XML model files or one folder of them, synthesised local-modular
//! at startup, or one compiled supervisor file; relative to the config file). Either param alone completes the
//! built-in of the element name (its profile, or its supervisors). Controllers without these params are looked
//! up by element name (ARGoS style): the thesis' and ARGoS' controller names map to built-ins, and a native
//! controller's own name selects it. A supervised controller may also say `reduce_supervisors="true"` (default
//! `false`): supervisors synthesised from models are then reduced (supervisor-gen's `synth --reduce`).

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;
use tracing::debug;

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
        /// Reduce supervisors synthesised from models (`reduce_supervisors`).
        reduce: bool,
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
    /// XML model files, one folder of XML models, or one compiled supervisor file; resolved against the
    /// configuration's folder.
    Files(Vec<PathBuf>),
}

impl fmt::Display for Supervisors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Supervisors::Builtin(name, _) => write!(f, "built-in {name}"),
            Supervisors::Files(files) => {
                for (i, file) in files.iter().enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    write!(f, "{sep}{}", file.display())?;
                }
                Ok(())
            }
        }
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Plan::Supervised {
                profile,
                supervisors,
                reduce,
            } => {
                write!(f, "profile `{profile}` with supervisors {supervisors}")?;
                if *reduce {
                    write!(f, " (reduced)")?;
                }
                Ok(())
            }
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
            reduce: false,
        },
    },
    Builtin {
        element: "epuck_obstacleavoidance_controller",
        plan: || Plan::Native {
            name: native::epuck_obstacleavoidance::EpuckObstacleAvoidance::NAME.to_owned(),
        },
    },
    Builtin {
        element: "footbot_diffusion_controller",
        plan: || Plan::Native {
            name: native::footbot_diffusion::FootbotDiffusion::NAME.to_owned(),
        },
    },
    Builtin {
        element: "footbot_flocking_controller",
        plan: || Plan::Native {
            name: native::footbot_flocking::FootbotFlocking::NAME.to_owned(),
        },
    },
    Builtin {
        element: "footbot_foraging_controller",
        plan: || Plan::Native {
            name: native::footbot_foraging::FootbotForaging::NAME.to_owned(),
        },
    },
    Builtin {
        element: "footbot_gripping_controller",
        plan: || Plan::Native {
            name: native::footbot_gripping::FootbotGripping::NAME.to_owned(),
        },
    },
    Builtin {
        element: "footbot_synchronization_controller",
        plan: || Plan::Native {
            name: native::footbot_synchronization::FootbotSynchronization::NAME.to_owned(),
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
    /// `reduce_supervisors` is neither `true` nor `false`.
    #[error("parameter `{REDUCE_SUPERVISORS}` = \"{value}\" must be `true` or `false`")]
    BadReduce {
        /// The value given.
        value: String,
    },
}

/// The `<params>` attribute that asks for reduced supervisors.
pub const REDUCE_SUPERVISORS: &str = "reduce_supervisors";

/// The value of `reduce_supervisors` (`false` when absent).
fn reduce_param(params: &Params) -> Result<bool, PlanError> {
    match params.get(REDUCE_SUPERVISORS).map(str::trim) {
        None | Some("false") => Ok(false),
        Some("true") => Ok(true),
        Some(other) => Err(PlanError::BadReduce {
            value: other.to_owned(),
        }),
    }
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
    let builtin = BUILTINS
        .iter()
        .find(|b| b.element == element)
        .map(|b| (b.plan)());
    let files: Vec<PathBuf> = params
        .get("supervisors")
        .into_iter()
        .flat_map(|list| list.split(','))
        .map(str::trim)
        .filter(|f| !f.is_empty())
        .map(|f| base_dir.join(f))
        .collect();
    let mut plan = match (params.get("profile"), files.is_empty()) {
        (Some(profile), _) if !profiles::is_profile(profile) => {
            return Err(PlanError::UnknownProfile {
                name: profile.to_owned(),
                known: profiles::profile_names().collect::<Vec<_>>().join(", "),
            });
        }
        (Some(profile), false) => Plan::Supervised {
            profile: profile.to_owned(),
            supervisors: Supervisors::Files(files),
            reduce: false,
        },
        (Some(profile), true) => match builtin {
            Some(Plan::Supervised { supervisors, .. }) => Plan::Supervised {
                profile: profile.to_owned(),
                supervisors,
                reduce: false,
            },
            _ => {
                return Err(PlanError::Incomplete {
                    given: "profile",
                    missing: "supervisors",
                });
            }
        },
        (None, false) => match builtin {
            Some(Plan::Supervised { profile, .. }) => Plan::Supervised {
                profile,
                supervisors: Supervisors::Files(files),
                reduce: false,
            },
            _ => {
                return Err(PlanError::Incomplete {
                    given: "supervisors",
                    missing: "profile",
                });
            }
        },
        (None, true) => match builtin {
            Some(plan) => plan,
            None if native::is_native(element) => Plan::Native {
                name: element.to_owned(),
            },
            None => {
                return Err(PlanError::UnknownController {
                    element: element.to_owned(),
                    known: known_elements().collect::<Vec<_>>().join(", "),
                });
            }
        },
    };
    // Read for supervised controllers only, so that a native controller reports it as unused.
    if let Plan::Supervised { reduce, .. } = &mut plan {
        *reduce = reduce_param(params)?;
    }
    // Debug, as the details of binding below: every robot of the controller would log the same line, and its
    // `robot runs ...` line says what it runs (at N = 1,000 each info line per agent cost the first tick about
    // 7 ms).
    if BUILTINS.iter().any(|b| b.element == element) {
        debug!("controller element `{element}` maps to {plan}");
    }
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
                reduce: false,
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
                supervisors: Supervisors::Files(vec![PathBuf::from("/cfg/oa/models/ptsct")]),
                reduce: false,
            }
        );
    }

    #[test]
    fn reduce_supervisors_is_read_for_supervised_controllers_only() {
        let supervised = |value: &str| {
            let params = Params::new([
                ("profile", "obstacle_avoidance"),
                ("supervisors", "models/ptsct"),
                (REDUCE_SUPERVISORS, value),
            ]);
            plan("c", &params, Path::new("/cfg")).map(|p| p.to_string())
        };
        assert_eq!(
            supervised("true").unwrap(),
            "profile `obstacle_avoidance` with supervisors /cfg/models/ptsct (reduced)"
        );
        assert_eq!(
            supervised(" false ").unwrap(),
            "profile `obstacle_avoidance` with supervisors /cfg/models/ptsct"
        );
        assert_eq!(
            supervised("yes").unwrap_err().to_string(),
            "parameter `reduce_supervisors` = \"yes\" must be `true` or `false`"
        );
        let native = Params::new([(REDUCE_SUPERVISORS, "true")]);
        assert!(matches!(
            plan("epuck_obstacleavoidance", &native, Path::new("/c")),
            Ok(Plan::Native { .. })
        ));
        assert_eq!(native.unread(), [(REDUCE_SUPERVISORS, None)]);
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
    fn profile_alone_keeps_the_builtin_supervisors_of_the_element() {
        let params = Params::new([("profile", "obstacle_avoidance")]);
        let p = plan(
            "epuck_obstacle_avoidance_sct_prob_controller",
            &params,
            Path::new("/c"),
        )
        .unwrap();
        assert_eq!(
            p.to_string(),
            "profile `obstacle_avoidance` with supervisors built-in obstacle_avoidance/ptsct"
        );
    }

    #[test]
    fn supervisors_alone_take_the_profile_of_the_element() {
        let params = Params::new([("supervisors", "m/G.xml, m/E.xml")]);
        let p = plan(
            "epuck_obstacle_avoidance_sct_prob_controller",
            &params,
            Path::new("/c"),
        )
        .unwrap();
        assert_eq!(
            p.to_string(),
            "profile `obstacle_avoidance` with supervisors /c/m/G.xml, /c/m/E.xml"
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
            "unknown profile `flocking` in <params> (known profiles: obstacle_avoidance, obstacle_avoidance_sct, \
             aggregation, synchronisation, synchronisation_sct, foraging, pheromone_foraging, phototaxis, navigation, path_planning, exploration, \
             transport)"
        );
    }

    #[test]
    fn unknown_element_lists_the_known_names() {
        let err = plan("footbot_nn_controller", &Params::default(), Path::new("/c")).unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown controller `footbot_nn_controller`: give `profile` and `supervisors` in <params>, or use one \
             of: epuck_obstacle_avoidance_sct_prob_controller, epuck_obstacleavoidance_controller, \
             footbot_diffusion_controller, footbot_flocking_controller, footbot_foraging_controller, \
             footbot_gripping_controller, footbot_synchronization_controller, epuck_obstacleavoidance, \
             footbot_diffusion, footbot_flocking, footbot_foraging, footbot_gripping, footbot_synchronization, \
             disc_wander, mail_probe, exploration_coordinator, navigation_coordinator, sensor_probe"
        );
    }
}
