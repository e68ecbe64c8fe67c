//! Obstacle-avoidance metrics (docs/tasks.md 3): body contacts per robot-minute and the fraction of robot-ticks
//! spent moving forward.
//!
//! A contact is counted when it starts, once for each robot involved. A live robot moves forward in a tick when
//! both wheels turn forward at the same speed (within 1 %), as the `Go` action does; turns do not count.

use serde_json::json;
use swarm_contract::messages::ActuatorCommand;

use crate::arena::Arena;
use crate::error::WorldError;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "obstacle_avoidance_loop_functions";

/// Counts forward ticks; collisions are counted by the physics.
#[derive(Debug, Clone, Default)]
pub struct ObstacleAvoidance {
    forward_ticks: u64,
    live_ticks: u64,
}

impl ObstacleAvoidance {
    /// The factory registered under [`LABEL`]; it takes no parameters (a child element is refused).
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        params.check_children(&[])?;
        Ok(Box::new(Self::default()))
    }
}

/// Whether wheel speeds `[left, right]` in cm/s drive straight ahead.
pub fn is_forward(wheels: [f32; 2]) -> bool {
    let [l, r] = wheels;
    l > 0.0 && r > 0.0 && (l - r).abs() <= 0.01 * l.max(r)
}

impl LoopFunctions for ObstacleAvoidance {
    fn post_step(
        &mut self,
        arena: &mut Arena,
        _commands: &[ActuatorCommand],
        _has_command: &[bool],
    ) {
        for r in arena.robots.iter().filter(|r| r.alive) {
            self.live_ticks += 1;
            if is_forward(r.wheels) {
                self.forward_ticks += 1;
            }
        }
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let collisions: u64 = arena.robots.iter().map(|r| r.collisions).sum();
        let robot_minutes = arena.robots.len() as f64 * arena.tick as f64
            / f64::from(arena.ticks_per_second)
            / 60.0;
        json!({
            "ticks": arena.tick,
            "collisions": collisions,
            "collisions_per_robot_minute": if robot_minutes > 0.0 { collisions as f64 / robot_minutes } else { 0.0 },
            "forward_fraction": if self.live_ticks > 0 { self.forward_ticks as f64 / self.live_ticks as f64 } else { 0.0 },
        })
    }
}
