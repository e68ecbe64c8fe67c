//! Choosing a robot's controller from a parsed experiment, with errors located in the `.argos` file.
//!
//! A robot's controller is the one its robot element names, found by the robot's index in the canonical order
//! that the launcher, the world and the agents share (`Experiment::participants`: the robots, then the
//! coordinators, whose agents run their controllers the same way). The controller's `<params>` attributes
//! (and its children's, as `child.attribute`) become the [`Params`] of its profile or native controller, and
//! relative paths in them resolve against the configuration's folder.

use std::path::Path;

use swarm_contract::config::{Controller, Diagnostic, Experiment, Location};

use crate::control::{self, Control};
use crate::controller::{self, Plan, Supervisors};
use crate::params::Params;

/// The controller of participant `robot` (its index in the canonical order, `Experiment::participants`).
pub fn controller_of(experiment: &Experiment, robot: u32) -> Result<&Controller, Diagnostic> {
    let file_level = Location { line: 0, column: 0 };
    let participants = experiment.participants();
    let Some(entry) = participants.iter().find(|r| r.index == robot) else {
        return Err(experiment.diagnostic(
            file_level,
            format!(
                "there is no robot {robot}: the configuration has {} robots and coordinators",
                participants.len()
            ),
        ));
    };
    experiment.controller(entry.controller).ok_or_else(|| {
        experiment.diagnostic(
            entry.location,
            format!(
                "robot {robot} (`{}`) names controller `{}`, which is not declared",
                entry.id, entry.controller
            ),
        )
    })
}

/// The controller with id `id` (the launcher names it explicitly).
pub fn controller_by_id<'a>(
    experiment: &'a Experiment,
    id: &str,
) -> Result<&'a Controller, Diagnostic> {
    experiment.controller(id).ok_or_else(|| {
        let declared: Vec<String> = experiment
            .controllers
            .iter()
            .map(|c| format!("`{}`", c.id))
            .collect();
        experiment.diagnostic(
            Location { line: 0, column: 0 },
            format!(
                "no controller with id `{id}` (declared: {})",
                declared.join(", ")
            ),
        )
    })
}

/// The `<params>` attributes of `controller`, and each child element's as `child.attribute` (ARGoS controllers
/// such as the foot-bot flocking example group theirs in children: `<wheel_turning max_speed="10"/>` gives
/// `wheel_turning.max_speed`).
pub fn params_of(controller: &Controller) -> Params {
    let own = controller
        .params
        .attributes
        .iter()
        .map(|(name, attribute)| (name.clone(), attribute.value.clone()));
    let children = controller.params.children.iter().flat_map(|child| {
        child
            .attributes
            .iter()
            .map(|(name, attribute)| (format!("{}.{name}", child.name), attribute.value.clone()))
    });
    Params::new(own.chain(children))
}

/// Plans and builds `controller` of `experiment` for robot `robot` of a run seeded with `run_seed`; any failure
/// is located at the controller's `<params>` element. `compiled`, when given, is the controller's supervisor set
/// already compiled (by the launcher, once per run) and replaces the supervisors its parameters name.
pub fn build(
    experiment: &Experiment,
    controller: &Controller,
    run_seed: u64,
    robot: u32,
    compiled: Option<&Path>,
) -> Result<(Plan, Control), Diagnostic> {
    let params = params_of(controller);
    let located = |message: String| {
        experiment.diagnostic(
            controller.params.location,
            format!(
                "controller `{}` (<{}>): {message}",
                controller.id, controller.tag
            ),
        )
    };
    let mut plan = controller::plan(&controller.tag, &params, experiment.base_dir())
        .map_err(|e| located(e.to_string()))?;
    if let Some(file) = compiled
        && let Plan::Supervised { supervisors, .. } = &mut plan
    {
        *supervisors = Supervisors::Files(vec![file.to_path_buf()]);
    }
    let control =
        control::build(&plan, &params, run_seed, robot).map_err(|e| located(e.to_string()))?;
    for (name, hint) in params.unread() {
        let hint = hint.map_or_else(String::new, |h| format!(" ({h})"));
        tracing::warn!(
            "{}",
            located(format!(
                "parameter '{name}' is not used by this controller and is ignored{hint}"
            ))
        );
    }
    Ok((plan, control))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = r#"<?xml version="1.0" ?>
<argos-configuration>
  <framework>
    <experiment length="1" ticks_per_second="20" random_seed="1" />
  </framework>
  <controllers>
    <epuck_obstacle_avoidance_sct_prob_controller id="fdc" library="robot-agent">
      <actuators><epuck_wheels implementation="default" /></actuators>
      <sensors><epuck_proximity implementation="default" /></sensors>
      <params velocity="12.8" />
    </epuck_obstacle_avoidance_sct_prob_controller>
    <epuck_obstacle_avoidance_sct_prob_controller id="bad" library="robot-agent">
      <actuators><epuck_wheels implementation="default" /></actuators>
      <sensors><epuck_proximity implementation="default" /></sensors>
      <params theta_obs="2" />
    </epuck_obstacle_avoidance_sct_prob_controller>
  </controllers>
  <arena size="1,1,1" center="0,0,0.5">
    <e-puck id="r0"><body position="0,0,0" orientation="0,0,0" /><controller config="fdc" /></e-puck>
    <e-puck id="r1"><body position="0.2,0,0" orientation="0,0,0" /><controller config="bad" /></e-puck>
  </arena>
  <physics_engines><dynamics2d id="dyn2d" /></physics_engines>
  <media />
</argos-configuration>
"#;

    fn experiment() -> Experiment {
        match Experiment::parse("/cfg/two.argos", TWO) {
            Ok((experiment, _warnings)) => experiment,
            Err(errors) => panic!("{errors}"),
        }
    }

    #[test]
    fn robot_index_selects_its_controller() {
        let e = experiment();
        assert_eq!(controller_of(&e, 0).unwrap().id, "fdc");
        assert_eq!(controller_of(&e, 1).unwrap().id, "bad");
    }

    #[test]
    fn unknown_controller_id_lists_the_declared_ones() {
        let e = experiment();
        assert_eq!(
            controller_by_id(&e, "x").unwrap_err().to_string(),
            "/cfg/two.argos: no controller with id `x` (declared: `fdc`, `bad`)"
        );
    }

    #[test]
    fn robot_beyond_the_configuration_is_rejected() {
        let e = experiment();
        assert_eq!(
            controller_of(&e, 2).unwrap_err().to_string(),
            "/cfg/two.argos: there is no robot 2: the configuration has 2 robots and coordinators"
        );
    }

    #[test]
    fn thesis_controller_builds_from_the_config() {
        let e = experiment();
        let (plan, _) = build(&e, controller_of(&e, 0).unwrap(), 1, 0, None).unwrap();
        assert_eq!(
            plan.to_string(),
            "profile `obstacle_avoidance` with supervisors built-in obstacle_avoidance/ptsct"
        );
    }

    #[test]
    fn bad_param_is_located_at_the_params_element() {
        let e = experiment();
        let err = build(&e, controller_of(&e, 1).unwrap(), 1, 0, None)
            .err()
            .unwrap()
            .to_string();
        assert_eq!(
            err,
            "/cfg/two.argos:15:7: controller `bad` (<epuck_obstacle_avoidance_sct_prob_controller>): profile \
             `obstacle_avoidance`: parameter `theta_obs` = 2 is out of range: must be in [0, 1]"
        );
    }
}
