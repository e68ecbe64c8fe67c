//! The allocation problem (A.5.2): robots and tasks of two types, and the weighted objective
//! `F = w1 f1 / UB - w2 f2 / (n diagonal) - w3 f3 / sum v` that an allocation maximises.

/// A robot's or a task's type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Kind {
    /// Type 1: cheaper robots; tasks one robot of either type can do.
    One,
    /// Type 2: more capable robots; tasks that need a type-2 robot or two type-1 robots.
    Two,
}

/// A robot available for allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Robot {
    /// Its type.
    pub kind: Kind,
    /// Where it is.
    pub position: (f32, f32),
    /// What using it costs (v_ij, the same for every task): valuable robots are kept for later tasks.
    pub value: f32,
}

/// A discovered task not yet allocated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Task {
    /// Its type.
    pub kind: Kind,
    /// Where it is.
    pub position: (f32, f32),
    /// Its utility u_j now (after any decay).
    pub utility: f32,
    /// Its time window W_j (time units); shorter is more urgent.
    pub window: f32,
}

/// The objective's weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// Utility of performed tasks.
    pub utility: f64,
    /// Robot-task distances.
    pub distance: f64,
    /// Value of the robots used.
    pub value: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            utility: 1.0,
            distance: 0.5,
            value: 0.2,
        }
    }
}

/// One allocation problem: the available robots, the open tasks and how to weigh the objective.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The robots that may be assigned (exploring or finished).
    pub robots: Vec<Robot>,
    /// The tasks discovered and not yet allocated.
    pub tasks: Vec<Task>,
    /// The objective's weights.
    pub weights: Weights,
    /// The workspace's diagonal, for normalising distances.
    pub diagonal: f32,
}

impl Problem {
    /// Distance from robot `r` to task `t`.
    pub fn distance(&self, r: usize, t: usize) -> f64 {
        let (a, b) = (self.robots[r].position, self.tasks[t].position);
        f64::from((a.0 - b.0).hypot(a.1 - b.1))
    }

    /// The three normalised objectives of an assignment (`assignment[r]`: robot r's task, if any) in which
    /// `performed[t]` says whether task t has a feasible team: utility of the performed tasks over that of all
    /// open tasks (maximised), robot-task distances over robots times the diagonal, and values of the robots
    /// used over all robots' values (both minimised).
    pub fn objectives(&self, assignment: &[Option<usize>], performed: &[bool]) -> [f64; 3] {
        let upper: f64 = self.tasks.iter().map(|t| f64::from(t.utility)).sum();
        let values: f64 = self.robots.iter().map(|r| f64::from(r.value)).sum();
        let f1: f64 = self
            .tasks
            .iter()
            .zip(performed)
            .filter(|(_, p)| **p)
            .map(|(t, _)| f64::from(t.utility))
            .sum();
        let (mut f2, mut f3) = (0.0, 0.0);
        for (r, task) in assignment.iter().enumerate() {
            if let Some(t) = *task {
                f2 += self.distance(r, t);
                f3 += f64::from(self.robots[r].value);
            }
        }
        let scaled = |x: f64, by: f64| if by > 0.0 { x / by } else { 0.0 };
        [
            scaled(f1, upper),
            scaled(f2, self.robots.len() as f64 * f64::from(self.diagonal)),
            scaled(f3, values),
        ]
    }

    /// The objective F of an assignment: the weighted sum of [`Problem::objectives`], utility counting for and
    /// the costs against.
    pub fn objective(&self, assignment: &[Option<usize>], performed: &[bool]) -> f64 {
        let [f1, f2, f3] = self.objectives(assignment, performed);
        let w = self.weights;
        w.utility * f1 - w.distance * f2 - w.value * f3
    }
}
