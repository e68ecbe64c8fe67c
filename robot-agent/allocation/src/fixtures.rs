//! Small problems for the unit tests.

use crate::fga::Allocation;
use crate::model::{Kind, Problem, Robot, Task, Weights};
use crate::team::feasible;

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

/// Five robots and four tasks of both types: small enough to enumerate (625 assignments).
pub fn five_robots_four_tasks() -> Problem {
    problem(
        vec![
            robot(Kind::One, 0.0),
            robot(Kind::Two, 3.0),
            robot(Kind::One, 5.0),
            robot(Kind::One, 8.0),
            robot(Kind::Two, 9.0),
        ],
        vec![
            task(Kind::Two, 2.0, 40.0),
            task(Kind::One, 7.0, 20.0),
            task(Kind::Two, 9.0, 75.0),
            task(Kind::One, 4.0, 10.0),
        ],
    )
}

/// Why some task of `a` has a team that cannot do it, or says it is performed without one.
pub fn infeasible_team(p: &Problem, a: &Allocation) -> Option<String> {
    (0..p.tasks.len()).find_map(|j| {
        let team: Vec<Kind> = (0..p.robots.len())
            .filter(|&r| a.assignment[r] == Some(j))
            .map(|r| p.robots[r].kind)
            .collect();
        let fine = (team.is_empty() || feasible(p.tasks[j].kind, &team))
            && a.performed[j] != team.is_empty();
        (!fine).then(|| format!("task {j}: team {team:?}, performed {}", a.performed[j]))
    })
}
