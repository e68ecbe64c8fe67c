//! The NSGA-II baseline (A.5.5): the same encoding and operators as FGA ([`crate::operators`]), but the three
//! objectives of [`Problem::objectives`] kept apart (utility maximised, distance and robot value minimised),
//! with Deb's non-dominated sorting, crowding distances, binary tournaments and elitist selection by front. For
//! comparison with FGA, the member of the final first front with the best scalar objective is returned.

use rand::Rng;

use crate::fga::{Allocation, FgaParams};
use crate::model::Problem;
use crate::operators::{Genes, breed, by_importance, decode, random_genes, repair};

#[derive(Clone)]
struct Member {
    genes: Genes,
    /// All three as costs: `[-utility, distance, value]`.
    costs: [f64; 3],
    scalar: f64,
    rank: usize,
    crowding: f64,
}

fn member(problem: &Problem, genes: Genes) -> Member {
    let (assignment, performed) = decode(problem, &genes);
    let [f1, f2, f3] = problem.objectives(&assignment, &performed);
    Member {
        genes,
        costs: [-f1, f2, f3],
        scalar: problem.objective(&assignment, &performed),
        rank: 0,
        crowding: 0.0,
    }
}

fn dominates(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| x <= y) && a.iter().zip(b).any(|(x, y)| x < y)
}

/// Deb's fast non-dominated sort: the fronts, best first, and each member's rank set.
fn fronts(members: &mut [Member]) -> Vec<Vec<usize>> {
    let n = members.len();
    let mut dominated: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut count = vec![0usize; n];
    for i in 0..n {
        for j in 0..n {
            if dominates(&members[i].costs, &members[j].costs) {
                dominated[i].push(j);
            } else if dominates(&members[j].costs, &members[i].costs) {
                count[i] += 1;
            }
        }
    }
    let mut fronts = vec![(0..n).filter(|&i| count[i] == 0).collect::<Vec<_>>()];
    while let Some(front) = fronts.last().filter(|f| !f.is_empty()) {
        let mut next = Vec::new();
        for &i in front {
            for &j in &dominated[i] {
                count[j] -= 1;
                if count[j] == 0 {
                    next.push(j);
                }
            }
        }
        fronts.push(next);
    }
    fronts.pop();
    for (rank, front) in fronts.iter().enumerate() {
        for &i in front {
            members[i].rank = rank;
        }
    }
    fronts
}

/// Sets the crowding distance of each member of `front`.
fn crowd(members: &mut [Member], front: &[usize]) {
    for &i in front {
        members[i].crowding = 0.0;
    }
    let mut order = front.to_vec();
    for k in 0..3 {
        order.sort_by(|&a, &b| members[a].costs[k].total_cmp(&members[b].costs[k]));
        let (Some(&first), Some(&last)) = (order.first(), order.last()) else {
            return;
        };
        let span = members[last].costs[k] - members[first].costs[k];
        members[first].crowding = f64::INFINITY;
        members[last].crowding = f64::INFINITY;
        if span <= 0.0 {
            continue;
        }
        for w in order.windows(3) {
            let gap = (members[w[2]].costs[k] - members[w[0]].costs[k]) / span;
            members[w[1]].crowding += gap;
        }
    }
}

/// The better of two random members: lower rank, then larger crowding distance.
fn tournament<'a>(pool: &'a [Member], rng: &mut impl Rng) -> &'a Member {
    let a = &pool[rng.random_range(0..pool.len())];
    let b = &pool[rng.random_range(0..pool.len())];
    if (a.rank, -a.crowding) <= (b.rank, -b.crowding) {
        a
    } else {
        b
    }
}

/// Assigns `problem`'s robots to its tasks with NSGA-II. A pure function of its inputs and `rng`'s state.
pub fn allocate(problem: &Problem, params: &FgaParams, rng: &mut impl Rng) -> Allocation {
    let order = by_importance(problem);
    let population = params.population.max(2);
    let mut pool: Vec<Member> = (0..population)
        .map(|_| {
            let mut genes = random_genes(problem.robots.len(), problem.tasks.len(), rng);
            repair(problem, &order, &mut genes, rng);
            member(problem, genes)
        })
        .collect();
    for front in fronts(&mut pool) {
        crowd(&mut pool, &front);
    }
    for _ in 0..params.generations {
        let mut children = Vec::with_capacity(population);
        while children.len() < population {
            let a = tournament(&pool, rng).genes.clone();
            let b = tournament(&pool, rng).genes.clone();
            let rates = (params.crossover, params.mutation);
            let (a, b) = breed(problem, &order, (a, b), rates, rng);
            children.push(member(problem, a));
            children.push(member(problem, b));
        }
        pool.extend(children);
        let fronts = fronts(&mut pool);
        let mut next = Vec::with_capacity(population);
        for front in fronts {
            crowd(&mut pool, &front);
            if next.len() + front.len() <= population {
                next.extend(front);
                continue;
            }
            let mut last = front;
            last.sort_by(|&a, &b| pool[b].crowding.total_cmp(&pool[a].crowding));
            next.extend(last.into_iter().take(population - next.len()));
            break;
        }
        pool = next.into_iter().map(|i| pool[i].clone()).collect();
    }
    let best = pool
        .iter()
        .filter(|m| m.rank == 0)
        .fold(None::<&Member>, |best, m| match best {
            Some(b) if b.scalar >= m.scalar => Some(b),
            _ => Some(m),
        })
        .unwrap_or(&pool[0]);
    let (assignment, performed) = decode(problem, &best.genes);
    Allocation {
        assignment,
        performed,
        objective: best.scalar,
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::fixtures::{five_robots_four_tasks, infeasible_team};

    #[test]
    fn dominance_and_fronts() {
        assert!(dominates(&[-1.0, 0.1, 0.2], &[-1.0, 0.2, 0.2]));
        assert!(!dominates(&[-1.0, 0.1, 0.2], &[-1.0, 0.1, 0.2]));
        assert!(!dominates(&[-1.0, 0.3, 0.1], &[-1.0, 0.2, 0.2]));
        let mut members: Vec<Member> = [
            [-1.0, 0.1, 0.1],
            [-1.0, 0.2, 0.2],
            [-0.5, 0.0, 0.0],
            [-0.5, 0.3, 0.3],
        ]
        .into_iter()
        .map(|costs| Member {
            genes: Vec::new(),
            costs,
            scalar: 0.0,
            rank: 9,
            crowding: 0.0,
        })
        .collect();
        assert_eq!(fronts(&mut members), vec![vec![0, 2], vec![1], vec![3]]);
        assert_eq!(
            members.iter().map(|m| m.rank).collect::<Vec<_>>(),
            vec![0, 1, 0, 2]
        );
    }

    #[test]
    fn it_allocates_feasible_teams_reproducibly() {
        let p = five_robots_four_tasks();
        let params = FgaParams::default();
        let a = allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(4));
        assert_eq!(a, allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(4)));
        assert_eq!(infeasible_team(&p, &a), None);
        // On this small problem it reaches FGA's (the enumerated) optimum too.
        let fga = crate::fga::allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(4));
        assert!(
            (a.objective - fga.objective).abs() < 1e-9,
            "{} against {}",
            a.objective,
            fga.objective
        );
    }
}
