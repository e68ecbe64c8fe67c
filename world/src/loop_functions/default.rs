//! The loop functions of an experiment without `<loop_functions>`: no hooks, and basic run metrics.

use serde_json::json;

use crate::arena::Arena;
use crate::loop_functions::LoopFunctions;

/// No hooks; metrics are the ticks run and the body contacts started, summed over the robots.
#[derive(Debug, Clone, Copy, Default)]
pub struct DefaultLoopFunctions;

impl LoopFunctions for DefaultLoopFunctions {
    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        json!({
            "ticks": arena.tick,
            "collisions": arena.robots.iter().map(|r| r.collisions).sum::<u64>(),
        })
    }
}
