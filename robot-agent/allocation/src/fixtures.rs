//! Small problems for the unit tests.

use crate::model::{Kind, Problem, Robot, Task, Weights};

/// A robot of `kind` at `(x, 0)`, value 1 for type 1 and 2 for type 2.
pub fn robot(kind: Kind, x: f32) -> Robot {
    Robot {
        kind,
        position: (x, 0.0),
        value: if kind == Kind::One { 1.0 } else { 2.0 },
    }
}

/// A task of `kind` at `(x, 1)` with `utility` and a window of 100.
pub fn task(kind: Kind, x: f32, utility: f32) -> Task {
    Task {
        kind,
        position: (x, 1.0),
        utility,
        window: 100.0,
    }
}

/// A problem with the default weights on a 10 x 10 workspace.
pub fn problem(robots: Vec<Robot>, tasks: Vec<Task>) -> Problem {
    Problem {
        robots,
        tasks,
        weights: Weights::default(),
        diagonal: 14.14,
    }
}
