//! Choosing a robot's controller from a parsed experiment, with errors located in the `.argos` file.
//!
//! The launcher passes the controller id of the robot (`--controller`); a configuration that declares only one
//! controller needs no id. The controller's `<params>` attributes become the [`Params`] of its profile or native
//! controller, and relative paths in them resolve against the configuration's folder.

use swarm_runtime::config::{Controller, Diagnostic, Experiment};

use crate::control::{self, Control};
use crate::controller::{self, Plan};
use crate::params::Params;

/// The controller element of `experiment` with id `id`, or its only controller when `id` is `None`.
pub fn choose<'a>(
    experiment: &'a Experiment,
    id: Option<&str>,
) -> Result<&'a Controller, Diagnostic> {
    let ids = || {
        experiment
            .controllers
            .iter()
            .map(|c| format!("`{}`", c.id))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let file_level = swarm_runtime::config::Location { line: 0, column: 0 };
    match id {
        Some(id) => experiment.controller(id).ok_or_else(|| {
            experiment.diagnostic(
                file_level,
                format!("no controller with id `{id}` (declared: {})", ids()),
            )
        }),
        None => match experiment.controllers.as_slice() {
            [only] => Ok(only),
            _ => Err(experiment.diagnostic(
                file_level,
                format!(
                    "{} controllers are declared ({}); say which one this robot runs with --controller",
                    experiment.controllers.len(),
                    ids()
                ),
            )),
        },
    }
}

/// The `<params>` attributes of `controller`.
pub fn params_of(controller: &Controller) -> Params {
    Params::new(
        controller
            .params
            .attributes
            .iter()
            .map(|(name, attribute)| (name.clone(), attribute.value.clone())),
    )
}

/// Plans and builds `controller` of `experiment` for robot `robot` of a run seeded with `run_seed`; any failure
/// is located at the controller's `<params>` element.
pub fn build(
    experiment: &Experiment,
    controller: &Controller,
    run_seed: u64,
    robot: u32,
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
    let plan = controller::plan(&controller.tag, &params, experiment.base_dir())
        .map_err(|e| located(e.to_string()))?;
    let control =
        control::build(&plan, &params, run_seed, robot).map_err(|e| located(e.to_string()))?;
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
    <epuck_obstacleavoidance_controller id="argos" library="robot-agent">
      <actuators><epuck_wheels implementation="default" /></actuators>
      <sensors><epuck_proximity implementation="default" /></sensors>
      <params velocity="fast" />
    </epuck_obstacleavoidance_controller>
  </controllers>
  <arena size="1,1,1" center="0,0,0.5">
    <e-puck id="r0"><body position="0,0,0" orientation="0,0,0" /><controller config="fdc" /></e-puck>
    <e-puck id="r1"><body position="0.2,0,0" orientation="0,0,0" /><controller config="argos" /></e-puck>
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
    fn controller_is_chosen_by_id() {
        let e = experiment();
        assert_eq!(
            choose(&e, Some("argos")).unwrap().tag,
            "epuck_obstacleavoidance_controller"
        );
    }

    #[test]
    fn several_controllers_need_an_id() {
        let e = experiment();
        assert_eq!(
            choose(&e, None).unwrap_err().to_string(),
            "/cfg/two.argos:0:0: 2 controllers are declared (`fdc`, `argos`); say which one this robot runs with \
             --controller"
        );
    }

    #[test]
    fn unknown_id_lists_the_declared_ones() {
        let e = experiment();
        assert_eq!(
            choose(&e, Some("x")).unwrap_err().to_string(),
            "/cfg/two.argos:0:0: no controller with id `x` (declared: `fdc`, `argos`)"
        );
    }

    #[test]
    fn thesis_controller_builds_from_the_config() {
        let e = experiment();
        let (plan, _) = build(&e, choose(&e, Some("fdc")).unwrap(), 1, 0).unwrap();
        assert_eq!(
            plan.to_string(),
            "profile `obstacle_avoidance` with supervisors built-in obstacle_avoidance/ptsct"
        );
    }

    #[test]
    fn bad_param_is_located_at_the_params_element() {
        let e = experiment();
        let err = build(&e, choose(&e, Some("argos")).unwrap(), 1, 0)
            .err()
            .unwrap()
            .to_string();
        assert_eq!(
            err,
            "/cfg/two.argos:15:7: controller `argos` (<epuck_obstacleavoidance_controller>): native controller \
             `epuck_obstacleavoidance`: parameter `velocity` = \"fast\" is not a finite number"
        );
    }
}
