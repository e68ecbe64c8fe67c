//! Reproducible allocation problems for the benchmark and `examples/allocation_eval.rs`: robots and tasks half
//! of each type, scattered over a 10 x 10 workspace.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::model::{Kind, Problem, Robot, Task, Weights};

/// `tasks` tasks (utilities 20-99, windows 130-299) and `robots` robots (values 1 and 2 by type) drawn from
/// `seed`.
pub fn scattered(tasks: usize, robots: usize, seed: u64) -> Problem {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut at = || (rng.random_range(0.0..10.0), rng.random_range(0.0..10.0));
    let kind = |i: usize| {
        if i.is_multiple_of(2) {
            Kind::One
        } else {
            Kind::Two
        }
    };
    Problem {
        robots: (0..robots)
            .map(|i| Robot {
                kind: kind(i),
                position: at(),
                value: if kind(i) == Kind::One { 1.0 } else { 2.0 },
            })
            .collect(),
        tasks: (0..tasks)
            .map(|j| Task {
                kind: kind(j / 2),
                position: at(),
                utility: 20.0 + (j * 37 % 80) as f32,
                window: 130.0 + (j * 53 % 170) as f32,
            })
            .collect(),
        weights: Weights::default(),
        diagonal: 200f32.sqrt(),
    }
}
