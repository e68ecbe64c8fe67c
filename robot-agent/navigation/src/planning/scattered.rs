//! Reproducible test maps for planners (the benchmark's and `examples/planner_eval.rs`'): discs scattered at a fixed
//! density in a square whose side grows with their number, start and goal in opposite corners.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::map::{Bounds, Map};
use crate::V2;
use crate::apf::Disc;

/// Square metres of map per obstacle.
pub const AREA_PER_OBSTACLE: f32 = 10.0;

/// A planning problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The map, discs not yet grown.
    pub map: Map,
    /// Where the robot starts (0.5 m in from the lower-left corner).
    pub start: V2,
    /// Where it must go (0.5 m in from the upper-right corner).
    pub goal: V2,
}

/// `obstacles` discs of radius 0.2-0.5 m drawn uniformly from `seed` in a square of `AREA_PER_OBSTACLE` m^2 per
/// disc, none within 1 m of the start or the goal.
pub fn scattered(obstacles: usize, seed: u64) -> Problem {
    let side = (obstacles.max(1) as f32 * AREA_PER_OBSTACLE).sqrt();
    let bounds = Bounds {
        min: V2::ZERO,
        max: V2::new(side, side),
    };
    let (start, goal) = (V2::new(0.5, 0.5), V2::new(side - 0.5, side - 0.5));
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut discs = Vec::with_capacity(obstacles);
    while discs.len() < obstacles {
        let centre = V2::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
        let radius = rng.random_range(0.2..0.5);
        if (centre - start).length() > radius + 1.0 && (centre - goal).length() > radius + 1.0 {
            discs.push(Disc { centre, radius });
        }
    }
    Problem {
        map: Map { bounds, discs },
        start,
        goal,
    }
}
