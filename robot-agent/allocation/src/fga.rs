//! The fast genetic allocator, FGA (A.5.3): the operators of [`crate::operators`] (one gene per available robot,
//! one-point crossover, a swap mutation, the importance-ordered repair) with (mu + lambda) elitist selection on
//! the scalar objective of [`Problem::objective`].

use rand::Rng;

use crate::model::Problem;
use crate::operators::{Genes, breed, by_importance, decode, random_genes, repair};

/// The genetic parameters (of FGA and of the NSGA-II baseline): the levels the method's Taguchi design chose.
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

#[derive(Clone)]
struct Scored {
    genes: Genes,
    objective: f64,
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
    let order = by_importance(problem);
    let population = params.population.max(2);
    let mut pool: Vec<Scored> = (0..population)
        .map(|_| {
            let mut genes = random_genes(problem.robots.len(), problem.tasks.len(), rng);
            repair(problem, &order, &mut genes, rng);
            score(problem, genes)
        })
        .collect();
    for _ in 0..params.generations {
        for _ in 0..population / 2 {
            let a = pool[rng.random_range(0..population)].genes.clone();
            let b = pool[rng.random_range(0..population)].genes.clone();
            let rates = (params.crossover, params.mutation);
            let (a, b) = breed(problem, &order, (a, b), rates, rng);
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

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::fixtures::{five_robots_four_tasks, infeasible_team, problem, robot, task};
    use crate::model::Kind;
    use crate::operators::decode;

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
        let p = five_robots_four_tasks();
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
            proptest::prop_assert_eq!(infeasible_team(&p, &a), None);
        }
    }
}
