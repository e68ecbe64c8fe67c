//! The genetic operators both allocators share (A.5.3): the robot-indexed encoding, random chromosomes,
//! one-point crossover, the swap mutation, the importance-ordered repair and decoding.

use rand::Rng;
use rand::seq::SliceRandom;

use crate::model::{Kind, Problem};
use crate::team::feasible;

/// A chromosome: gene r is 0 for "explore" or j + 1 for task j.
pub type Genes = Vec<u32>;

/// Task indices by importance `u_j / W_j`, highest first (ties by index).
pub fn by_importance(problem: &Problem) -> Vec<usize> {
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
pub fn repair(problem: &Problem, order: &[usize], genes: &mut Genes, rng: &mut impl Rng) {
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

/// The assignment a chromosome encodes, and which tasks get a feasible team.
pub fn decode(problem: &Problem, genes: &[u32]) -> (Vec<Option<usize>>, Vec<bool>) {
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

/// A random chromosome for `robots` robots and `tasks` tasks, each gene uniform in {0} and the task numbers.
pub fn random_genes(robots: usize, tasks: usize, rng: &mut impl Rng) -> Genes {
    (0..robots)
        .map(|_| rng.random_range(0..=tasks as u32))
        .collect()
}

/// Two children of `a` and `b`: one-point crossover with probability `crossover`, then each child mutated with
/// probability `mutation` and repaired.
pub fn breed(
    problem: &Problem,
    order: &[usize],
    (mut a, mut b): (Genes, Genes),
    (crossover, mutation): (f64, f64),
    rng: &mut impl Rng,
) -> (Genes, Genes) {
    let n = a.len();
    if n >= 2 && rng.random_bool(crossover) {
        let cut = rng.random_range(1..n);
        a[cut..].swap_with_slice(&mut b[cut..]);
    }
    for child in [&mut a, &mut b] {
        if rng.random_bool(mutation) {
            swap_two_tasks(child, rng);
        }
        repair(problem, order, child, rng);
    }
    (a, b)
}

/// Swaps the genes of two robots with different genes, picked at random (no-op when all genes are equal).
pub fn swap_two_tasks(genes: &mut Genes, rng: &mut impl Rng) {
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
    use crate::fixtures::{problem, robot, task};
    use crate::model::{Kind, Task};

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
}
