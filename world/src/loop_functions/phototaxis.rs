//! Phototaxis metrics, the loop functions of docs/tutorial.md and the worked example of docs/controllers.md: how
//! close the robots come to the arena's first light.
//!
//! `<loop_functions label="phototaxis_loop_functions"><phototaxis reached="0.5"/></loop_functions>`: a live robot
//! within `reached` metres (default 0.5) of the light on the ground plane has reached it. Metrics: the live
//! robots' mean distance to the light at the start and now, the fraction of live robots that reached it, and the
//! first tick at which half of them had (absent until then).

use serde_json::json;
use swarm_contract::messages::ActuatorCommand;

use crate::arena::Arena;
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::params::ParamReader;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "phototaxis_loop_functions";
/// Default distance in metres within which a robot has reached the light.
pub const DEFAULT_REACHED: f64 = 0.5;

/// Distances of the robots to the light.
#[derive(Debug, Clone, Default)]
pub struct Phototaxis {
    reached: f32,
    start_mean: Option<f64>,
    half_reached_tick: Option<u64>,
}

impl Phototaxis {
    /// The factory registered under [`LABEL`].
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let reader = ParamReader::new(params, "phototaxis", &["reached"])?;
        Ok(Box::new(Self {
            reached: reader.non_negative("reached", DEFAULT_REACHED)? as f32,
            ..Self::default()
        }))
    }

    /// The live robots' distances to the first light (none without a light).
    fn distances(arena: &Arena) -> Vec<f32> {
        let Some(light) = arena.lights.first() else {
            return Vec::new();
        };
        arena
            .robots
            .iter()
            .filter(|r| r.alive)
            .map(|r| distance(r.position, light.position))
            .collect()
    }

    fn reached_fraction(&self, distances: &[f32]) -> f64 {
        if distances.is_empty() {
            return 0.0;
        }
        distances.iter().filter(|&&d| d <= self.reached).count() as f64 / distances.len() as f64
    }
}

fn distance(a: Vec2, b: Vec2) -> f32 {
    (a - b).length()
}

fn mean(values: &[f32]) -> Option<f64> {
    (!values.is_empty())
        .then(|| values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64)
}

impl LoopFunctions for Phototaxis {
    fn pre_step(&mut self, arena: &mut Arena) {
        if self.start_mean.is_none() {
            self.start_mean = mean(&Self::distances(arena));
        }
    }

    fn post_step(
        &mut self,
        arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
        if self.half_reached_tick.is_none() && self.reached_fraction(&Self::distances(arena)) >= 0.5
        {
            self.half_reached_tick = Some(arena.tick);
        }
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let distances = Self::distances(arena);
        let mut metrics = json!({
            "mean_distance_start_m": self.start_mean,
            "mean_distance_m": mean(&distances),
            "reached_fraction": self.reached_fraction(&distances),
        });
        if let (Some(tick), Some(object)) = (self.half_reached_tick, metrics.as_object_mut()) {
            object.insert("half_reached_tick".into(), tick.into());
        }
        metrics
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_misspelt_attribute_is_refused_with_the_known_ones() {
        let params = LoopFunctionsParams {
            label: LABEL.into(),
            location: "exp.argos:3:5".into(),
            attributes: [("phototaxis.reach".to_owned(), "1".to_owned())].into(),
            ..LoopFunctionsParams::default()
        };
        let err = Phototaxis::factory(&params)
            .err()
            .expect("refused")
            .to_string();
        assert!(err.contains("known: reached"), "{err}");
    }

    #[test]
    fn means_and_fractions_of_nothing_are_absent_or_zero() {
        let p = Phototaxis {
            reached: 0.5,
            ..Phototaxis::default()
        };
        assert_eq!(mean(&[]), None);
        assert_eq!(mean(&[1.0, 3.0]), Some(2.0));
        assert_eq!(p.reached_fraction(&[]), 0.0);
        assert_eq!(p.reached_fraction(&[0.2, 0.5, 0.9, 2.0]), 0.5);
    }
}
