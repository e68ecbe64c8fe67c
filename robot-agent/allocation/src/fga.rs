//! The fast genetic allocator, FGA (A.5.3): one gene per available robot (0: keep exploring, j + 1: task j),
//! one-point crossover, a mutation that swaps the tasks of two robots, a repair that makes every task's team
//! feasible or empty (tasks in order of importance `u_j / W_j`), and (mu + lambda) elitist selection on the
//! objective of [`Problem::objective`].

use rand::Rng;
use rand::seq::SliceRandom;

use crate::model::{Kind, Problem};
use crate::team::feasible;

/// The allocator's parameters: the levels the method's Taguchi design chose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FgaParams {
    /// Population size P.
    pub population: usize,
    /// Generations G.
    pub generations: usize,
    /// Crossover probability Pc.
    pub crossover: f64,
    /// Mutation probability Pm.
    pub mutation: f64,
}

impl Default for FgaParams {
    fn default() -> Self {
        FgaParams {
            population: 50,
            generations: 40,
            crossover: 0.95,
            mutation: 0.3,
        }
    }
}

/// The best allocation found.
#[derive(Debug, Clone, PartialEq)]
pub struct Allocation {
    /// Each robot's task, or `None` to keep exploring.
    pub assignment: Vec<Option<usize>>,
    /// Whether each task has a (feasible) team.
    pub performed: Vec<bool>,
    /// Its objective F.
    pub objective: f64,
}

/// A chromosome: gene r is 0 for "explore" or j + 1 for task j.
type Genes = Vec<u32>;

#[derive(Clone)]
struct Scored {
    genes: Genes,
    objective: f64,
}

/// Task indices by importance `u_j / W_j`, highest first (ties by index).
fn by_importance(problem: &Problem) -> Vec<usize> {
    let importance = |j: usize| {
        let t = &problem.tasks[j];
        f64::from(t.utility) / f64::from(t.window.max(1e-6))
    };
    let mut order: Vec<usize> = (0..problem.tasks.len()).collect();
    order.sort_by(|&a, &b| importance(b).total_cmp(&importance(a)).then(a.cmp(&b)));
    order
}

/// Makes every task's team feasible or empty, tasks in `order` (A.5.3's repair): excess robots are freed at
/// random; a type-2 task with one type-1 robot takes a free type-1 robot, or else a free type-2 robot in its
/// place, or else is given up. Robots are only ever taken from the free ones.
fn repair(problem: &Problem, order: &[usize], genes: &mut Genes, rng: &mut impl Rng) {
    let kind = |r: usize| problem.robots[r].kind;
    let mut team = Vec::new();
    let mut free = Vec::new();
    for &j in order {
        let gene = j as u32 + 1;
        team.clear();
        team.extend((0..genes.len()).filter(|&r| genes[r] == gene));
        team.shuffle(rng);
        let keep: &[usize] = match problem.tasks[j].kind {
            Kind::One => &team[..team.len().min(1)],
            Kind::Two => {
                if let Some(i) = team.iter().position(|&r| kind(r) == Kind::Two) {
                    team.swap(0, i);
                    &team[..1]
                } else if team.len() >= 2 {
                    &team[..2]
                } else if team.len() == 1 {
                    free.clear();
                    free.extend((0..genes.len()).filter(|&r| genes[r] == 0));
                    free.shuffle(rng);
                    let one = free.iter().copied().find(|&r| kind(r) == Kind::One);
                    let two = free.iter().copied().find(|&r| kind(r) == Kind::Two);
                    match (one, two) {
                        (Some(r), _) => {
                            genes[r] = gene;
                            team.push(r);
                            &team[..2]
                        }
                        (None, Some(r)) => {
                            genes[r] = gene;
                            genes[team[0]] = 0;
                            team[0] = r;
                            &team[..1]
                        }
                        (None, None) => &[],
                    }
                } else {
                    &[]
                }
            }
        };
        let kept = keep.to_vec();
        for &r in &team {
            if !kept.contains(&r) {
                genes[r] = 0;
            }
        }
    }
}

fn decode(problem: &Problem, genes: &[u32]) -> (Vec<Option<usize>>, Vec<bool>) {
    let assignment: Vec<Option<usize>> = genes
        .iter()
        .map(|&g| (g > 0).then(|| g as usize - 1))
        .collect();
    let performed = (0..problem.tasks.len())
        .map(|j| {
            let kinds: Vec<Kind> = (0..genes.len())
                .filter(|&r| assignment[r] == Some(j))
                .map(|r| problem.robots[r].kind)
                .collect();
            feasible(problem.tasks[j].kind, &kinds)
        })
        .collect();
    (assignment, performed)
}

fn score(problem: &Problem, genes: Genes) -> Scored {
    let (assignment, performed) = decode(problem, &genes);
    Scored {
        objective: problem.objective(&assignment, &performed),
        genes,
    }
}

/// Assigns `problem`'s robots to its tasks. A pure function of its inputs and `rng`'s state.
pub fn allocate(problem: &Problem, params: &FgaParams, rng: &mut impl Rng) -> Allocation {
    let (n, m) = (problem.robots.len(), problem.tasks.len() as u32);
    let order = by_importance(problem);
    let population = params.population.max(2);
    let mut pool: Vec<Scored> = (0..population)
        .map(|_| {
            let mut genes: Genes = (0..n).map(|_| rng.random_range(0..=m)).collect();
            repair(problem, &order, &mut genes, rng);
            score(problem, genes)
        })
        .collect();
    for _ in 0..params.generations {
        for _ in 0..population / 2 {
            let mut a = pool[rng.random_range(0..population)].genes.clone();
            let mut b = pool[rng.random_range(0..population)].genes.clone();
            if n >= 2 && rng.random_bool(params.crossover) {
                let cut = rng.random_range(1..n);
                a[cut..].swap_with_slice(&mut b[cut..]);
            }
            for child in [&mut a, &mut b] {
                if rng.random_bool(params.mutation) {
                    swap_two_tasks(child, rng);
                }
                repair(problem, &order, child, rng);
            }
            pool.push(score(problem, a));
            pool.push(score(problem, b));
        }
        // (mu + lambda): the best P of parents and children; the sort is stable, so ties keep their order.
        pool.sort_by(|x, y| y.objective.total_cmp(&x.objective));
        pool.truncate(population);
    }
    pool.sort_by(|x, y| y.objective.total_cmp(&x.objective));
    let best = &pool[0];
    let (assignment, performed) = decode(problem, &best.genes);
    Allocation {
        assignment,
        performed,
        objective: best.objective,
    }
}

/// Swaps the genes of two robots with different genes, picked at random (no-op when all genes are equal).
fn swap_two_tasks(genes: &mut Genes, rng: &mut impl Rng) {
    if genes.len() < 2 {
        return;
    }
    let i = rng.random_range(0..genes.len());
    let others = genes.iter().filter(|&&g| g != genes[i]).count();
    if others == 0 {
        return;
    }
    let pick = rng.random_range(0..others);
    let j = (0..genes.len())
        .filter(|&j| genes[j] != genes[i])
        .nth(pick)
        .unwrap_or(i);
    genes.swap(i, j);
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::model::{Robot, Task, Weights};

    fn robot(kind: Kind, x: f32) -> Robot {
        Robot {
            kind,
            position: (x, 0.0),
            value: if kind == Kind::One { 1.0 } else { 2.0 },
        }
    }

    fn task(kind: Kind, x: f32, utility: f32) -> Task {
        Task {
            kind,
            position: (x, 1.0),
            utility,
            window: 100.0,
        }
    }

    fn problem(robots: Vec<Robot>, tasks: Vec<Task>) -> Problem {
        Problem {
            robots,
            tasks,
            weights: Weights::default(),
            diagonal: 14.14,
        }
    }

    fn run(p: &Problem, seed: u64) -> Allocation {
        allocate(
            p,
            &FgaParams::default(),
            &mut ChaCha8Rng::seed_from_u64(seed),
        )
    }

    /// The best objective over every assignment whose teams are feasible or empty.
    fn brute_force(p: &Problem) -> f64 {
        let (n, m) = (p.robots.len() as u32, p.tasks.len() as u32);
        let mut best = f64::NEG_INFINITY;
        for code in 0..(m + 1).pow(n) {
            let genes: Vec<u32> = (0..n).map(|r| code / (m + 1).pow(r) % (m + 1)).collect();
            let (assignment, performed) = decode(p, &genes);
            let all_fine = (0..p.tasks.len())
                .all(|j| performed[j] || assignment.iter().all(|a| *a != Some(j)));
            if all_fine {
                best = best.max(p.objective(&assignment, &performed));
            }
        }
        best
    }

    #[test]
    fn a_type_one_task_takes_the_near_cheap_robot() {
        let p = problem(
            vec![
                robot(Kind::Two, 1.0),
                robot(Kind::One, 1.2),
                robot(Kind::One, 6.0),
            ],
            vec![task(Kind::One, 1.0, 50.0)],
        );
        let a = run(&p, 1);
        assert_eq!(a.assignment, vec![None, Some(0), None]);
        assert_eq!(a.performed, vec![true]);
    }

    #[test]
    fn a_type_two_task_takes_two_type_one_robots_when_no_type_two_is_free() {
        let p = problem(
            vec![
                robot(Kind::One, 0.0),
                robot(Kind::One, 2.0),
                robot(Kind::One, 9.0),
            ],
            vec![task(Kind::Two, 1.0, 50.0)],
        );
        let a = run(&p, 1);
        assert_eq!(a.assignment, vec![Some(0), Some(0), None]);
        // With a type-2 robot at hand, it alone does the task.
        let p = problem(
            vec![
                robot(Kind::One, 0.0),
                robot(Kind::Two, 1.0),
                robot(Kind::One, 2.0),
            ],
            vec![task(Kind::Two, 1.0, 50.0)],
        );
        assert_eq!(run(&p, 1).assignment, vec![None, Some(0), None]);
    }

    #[test]
    fn on_small_problems_it_finds_the_optimum_that_enumeration_finds() {
        let p = problem(
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
        );
        let optimum = brute_force(&p);
        for seed in 0..5 {
            let a = run(&p, seed);
            assert!(
                (a.objective - optimum).abs() < 1e-9,
                "seed {seed}: {} against {optimum}",
                a.objective
            );
        }
    }

    #[test]
    fn the_repair_leaves_no_partial_team_and_takes_only_free_robots() {
        // Task 0 (type 2, most important) holds one type-1 robot; the only free robot is a type-2: it replaces
        // the type-1, which becomes free. Task 1 (type 1) holds two robots: one is freed.
        let p = problem(
            vec![
                robot(Kind::One, 0.0),
                robot(Kind::Two, 1.0),
                robot(Kind::One, 2.0),
                robot(Kind::One, 3.0),
            ],
            vec![
                Task {
                    window: 10.0,
                    ..task(Kind::Two, 0.0, 50.0)
                },
                task(Kind::One, 3.0, 10.0),
            ],
        );
        let order = by_importance(&p);
        assert_eq!(order, vec![0, 1]);
        let mut genes = vec![1, 0, 2, 2];
        repair(&p, &order, &mut genes, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(genes[..2], [0, 1]);
        assert_eq!(genes[2..].iter().filter(|&&g| g == 2).count(), 1);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// Every task of an allocation has a feasible team or none, and the same seed gives the same allocation.
        #[test]
        fn allocations_are_feasible_and_reproducible(
            robots in proptest::collection::vec((proptest::bool::ANY, 0f32..10.0), 0..12),
            tasks in proptest::collection::vec((proptest::bool::ANY, 0f32..10.0, 1f32..100.0), 0..10),
            seed in 0u64..1000,
        ) {
            let kind = |two: bool| if two { Kind::Two } else { Kind::One };
            let p = problem(
                robots.iter().map(|&(two, x)| robot(kind(two), x)).collect(),
                tasks.iter().map(|&(two, x, u)| task(kind(two), x, u)).collect(),
            );
            let params = FgaParams { population: 10, generations: 5, ..FgaParams::default() };
            let a = allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(seed));
            proptest::prop_assert_eq!(&a, &allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(seed)));
            for j in 0..p.tasks.len() {
                let team: Vec<Kind> = (0..p.robots.len()).filter(|&r| a.assignment[r] == Some(j)).map(|r| p.robots[r].kind).collect();
                proptest::prop_assert!(team.is_empty() || feasible(p.tasks[j].kind, &team), "task {} team {:?}", j, team);
                proptest::prop_assert_eq!(a.performed[j], !team.is_empty());
            }
        }
    }
}
