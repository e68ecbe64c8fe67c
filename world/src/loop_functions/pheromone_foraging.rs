//! Pheromone-foraging loop functions (docs/tasks.md 5), label `pheromone_foraging_loop_functions`: everything of
//! [`super::foraging`], plus trail removal at exhausted sources.
//!
//! Configuration: the `<foraging>` child as for foraging, and `<trails food_channel="0" source_radius="0.5"/>`.
//! When a robot picks up a target and no other target lies in the arena within `source_radius` metres of it, the
//! source is exhausted: the world clears the food-trail channel within that radius (docs/tasks.md 5.2, the world-side
//! alternative) and counts an erase event. The pheromone field itself (deposits, evaporation, diffusion) is the
//! world's medium, configured under `<media><pheromone>`.

use serde_json::json;
use swarm_contract::messages::{ActuatorCommand, PHEROMONE_CHANNELS};

use crate::arena::{Arena, GripperEvent};
use crate::entities::TargetState;
use crate::error::WorldError;
use crate::loop_functions::foraging::{Foraging, ForagingParams};
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "pheromone_foraging_loop_functions";
/// Default radius in metres around a pick-up within which a remaining target keeps the source alive.
pub const DEFAULT_SOURCE_RADIUS: f32 = 0.5;

/// Foraging bookkeeping plus trail removal.
#[derive(Debug, Clone)]
pub struct PheromoneForaging {
    foraging: Foraging,
    food_channel: usize,
    source_radius: f32,
    erase_events: u64,
}

impl PheromoneForaging {
    /// Foraging with `params`; the food trail is `food_channel`, sources span `source_radius` metres.
    pub fn new(params: ForagingParams, food_channel: usize, source_radius: f32) -> Self {
        Self {
            foraging: Foraging::new(params),
            food_channel,
            source_radius,
            erase_events: 0,
        }
    }

    /// The factory registered under [`LABEL`].
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let foraging = ForagingParams::parse(params, &["trails"])?;
        let invalid = |message: String| WorldError::Invalid {
            location: params.location.clone(),
            message,
        };
        let (mut food_channel, mut source_radius) = (0usize, DEFAULT_SOURCE_RADIUS);
        for (key, value) in &params.attributes {
            let Some(attr) = key.strip_prefix("trails.") else {
                continue;
            };
            match attr {
                "food_channel" => {
                    food_channel = value
                        .trim()
                        .parse()
                        .ok()
                        .filter(|&c: &usize| c < PHEROMONE_CHANNELS)
                        .ok_or_else(|| {
                            invalid(format!(
                                "<trails food_channel=\"{value}\">: expected a channel index below {PHEROMONE_CHANNELS}"
                            ))
                        })?;
                }
                "source_radius" => {
                    source_radius = value
                        .trim()
                        .parse()
                        .ok()
                        .filter(|&r: &f32| r.is_finite() && r >= 0.0)
                        .ok_or_else(|| {
                            invalid(format!(
                                "<trails source_radius=\"{value}\">: expected a distance >= 0 in metres"
                            ))
                        })?;
                }
                _ => {
                    return Err(invalid(format!(
                        "<trails> has no attribute '{attr}' (known: food_channel, source_radius)"
                    )));
                }
            }
        }
        Ok(Box::new(Self::new(foraging, food_channel, source_radius)))
    }

    /// Exhausted sources whose trail was cleared so far.
    pub fn erase_events(&self) -> u64 {
        self.erase_events
    }
}

impl LoopFunctions for PheromoneForaging {
    fn pre_step(&mut self, arena: &mut Arena) {
        self.foraging.pre_step(arena);
    }

    fn post_step(&mut self, arena: &mut Arena, commands: &[ActuatorCommand], has: &[bool]) {
        self.foraging.post_step(arena, commands, has);
        // Taken out and put back (no allocation) so that clearing may change the arena while we walk them.
        let events = std::mem::take(&mut arena.gripper_events);
        for &event in &events {
            let GripperEvent::Picked { robot, .. } = event else {
                continue;
            };
            let at = arena.robots[robot.index()].position;
            let r = self.source_radius;
            let alive = arena
                .targets
                .iter()
                .any(|t| t.state == TargetState::InArena && (t.placed.position - at).length() <= r);
            if !alive {
                arena.pheromone.clear_disc(self.food_channel, at, r);
                self.erase_events += 1;
            }
        }
        arena.gripper_events = events;
    }

    fn is_finished(&self, arena: &Arena) -> bool {
        self.foraging.is_finished(arena)
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let mut m = self.foraging.metrics(arena);
        if let Some(map) = m.as_object_mut() {
            map.insert("erase_events".to_owned(), json!(self.erase_events));
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use swarm_contract::messages::{GripperAction, Rgb};

    use super::*;
    use crate::devices::Devices;
    use crate::geometry::{Placed, Shape, Vec2};
    use crate::{World, WorldBuilder};

    const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };

    /// A robot at the origin facing +x, a target in its reach and one more target `second` away from it.
    fn world(second: Vec2) -> World {
        let mut b = WorldBuilder::new(Vec2::splat(-5.0), Vec2::splat(5.0), 20, 1);
        b.robot("ep0", "fc", Vec2::ZERO, 0.0, Devices::ALL);
        for (i, p) in [Vec2::new(0.06, 0.0), second].into_iter().enumerate() {
            let placed = Placed::new(Shape::Disc { radius: 0.02 }, p, 0.0);
            b.target(&format!("food{i}"), placed, 0.05, RED, 0.06);
        }
        b.loop_functions(Box::new(PheromoneForaging::new(
            ForagingParams::default(),
            0,
            DEFAULT_SOURCE_RADIUS,
        )));
        b.pheromone(
            crate::world::DEFAULT_PHEROMONE_CELL,
            [crate::media::pheromone::ChannelRates::STILL;
                swarm_contract::messages::PHEROMONE_CHANNELS],
        );
        let mut w = b.build();
        w.arena.pheromone.deposit(0, Vec2::new(0.1, 0.1), 1.0);
        w
    }

    fn pick(w: &mut World) {
        let mut c = ActuatorCommand::idle(0, 0);
        c.gripper = GripperAction::Pick;
        w.act_and_step(&[c], &[true]);
    }

    #[test]
    fn picking_the_last_target_of_a_source_clears_its_food_trail() {
        let mut w = world(Vec2::new(3.0, 3.0));
        pick(&mut w);
        assert_eq!(w.arena.pheromone.concentration(0, Vec2::new(0.1, 0.1)), 0.0);
        assert_eq!(w.metrics()["erase_events"], json!(1));
    }

    #[test]
    fn a_source_with_targets_left_keeps_its_trail() {
        let mut w = world(Vec2::new(0.3, 0.0));
        pick(&mut w);
        assert!(w.arena.pheromone.concentration(0, Vec2::new(0.1, 0.1)) > 0.0);
        assert_eq!(w.metrics()["erase_events"], json!(0));
    }
}
