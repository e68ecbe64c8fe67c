//! Changing the number of robots of an experiment (`swarm run --robots N`).
//!
//! Robot numbering itself is [`Arena::robots`](super::model::Arena::robots); this only resizes the one robot
//! `<distribute>` (of e-pucks or foot-bots) so that the arena holds `N` robots in all, which the launcher and the
//! world do identically.

use super::diagnostic::ConfigErrors;
use super::model::{Entity, Experiment};

impl Experiment {
    /// The same experiment with `robots` robots in all: the one robot `<distribute>` gets the quantity that
    /// hand-placed robots leave. Fails (located) when there is no such distribution, more than one, or more
    /// hand-placed robots than `robots`.
    pub fn with_robot_count(mut self, robots: u32) -> Result<Experiment, ConfigErrors> {
        let error = |experiment: &Experiment, location, message: String| ConfigErrors {
            errors: vec![experiment.diagnostic(location, message)],
        };
        let robot_distributions: Vec<usize> = self
            .arena
            .distributions
            .iter()
            .enumerate()
            .filter(|(_, d)| matches!(d.template, Entity::Robot(_)))
            .map(|(i, _)| i)
            .collect();
        let index = match robot_distributions.as_slice() {
            [one] => *one,
            [] => {
                return Err(error(
                    &self,
                    self.arena.location,
                    format!(
                        "cannot run {robots} robots: the arena has no robot <distribute> whose quantity could change"
                    ),
                ));
            }
            [_, second, ..] => {
                let location = self.arena.distributions[*second].location;
                return Err(error(
                    &self,
                    location,
                    format!(
                        "cannot run {robots} robots: the arena has {} robot <distribute> blocks and the robot count \
                         applies to exactly one",
                        robot_distributions.len()
                    ),
                ));
            }
        };
        let placed = self
            .arena
            .entities
            .iter()
            .filter(|e| matches!(e.entity, Entity::Robot(_)))
            .count() as u32;
        if robots < placed {
            return Err(error(
                &self,
                self.arena.location,
                format!("cannot run {robots} robots: {placed} robots are placed by hand"),
            ));
        }
        self.arena.distributions[index].quantity = robots - placed;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARENA: &str = r#"<?xml version="1.0"?>
<argos-configuration>
  <framework><experiment length="1" ticks_per_second="10" random_seed="1"/></framework>
  <controllers>
    <epuck_obstacleavoidance_controller id="a" library="x"><actuators/><sensors/><params/></epuck_obstacleavoidance_controller>
    <epuck_obstacleavoidance_controller id="b" library="x"><actuators/><sensors/><params/></epuck_obstacleavoidance_controller>
  </controllers>
  <arena size="4,4,1" center="0,0,0.5">
    <e-puck id="lead"><body position="1,1,0" orientation="0,0,0"/><controller config="b"/></e-puck>
    <distribute>
      <position method="uniform" min="-1,-1,0" max="1,1,0"/>
      <orientation method="constant" values="0,0,0"/>
      <entity quantity="3" max_trials="100" base_num="5"><e-puck id="fb"><controller config="a"/></e-puck></entity>
    </distribute>
  </arena>
  <physics_engines><dynamics2d id="dyn2d"/></physics_engines>
  <media/>
</argos-configuration>
"#;

    fn experiment() -> Experiment {
        Experiment::parse("roster.argos", ARENA)
            .map(|(experiment, _)| experiment)
            .unwrap_or_else(|e| panic!("fixture parses: {e}"))
    }

    fn ids(experiment: &Experiment) -> Vec<String> {
        experiment
            .arena
            .robots()
            .into_iter()
            .map(|r| r.id)
            .collect()
    }

    #[test]
    fn robot_count_resizes_the_epuck_distribution_around_hand_placed_robots() {
        let resized = experiment()
            .with_robot_count(6)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(ids(&resized), ["lead", "fb5", "fb6", "fb7", "fb8", "fb9"]);
    }

    #[test]
    fn robot_count_below_hand_placed_robots_is_a_located_error() {
        let Err(errors) = experiment().with_robot_count(0) else {
            panic!("zero robots cannot keep the hand-placed one");
        };
        assert_eq!(
            errors.to_string(),
            "roster.argos:8:3: cannot run 0 robots: 1 robots are placed by hand"
        );
    }
}
