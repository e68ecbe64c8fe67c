//! Planning time of the GSA planner (one run of N = 50 agents, t_max = 500, the defaults), of the Theta*
//! reference (5 cm grid) and of the tree planners ORT and RRT (steps of 0.2 m) on scattered maps of 10, 50 and
//! 200 discs, grown by a 0.1 m robot radius.
//! `cargo bench -p swarm-navigation --bench planners`; the figures are in BENCHMARKS.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_navigation::planning::gsa::{self, GsaParams};
use swarm_navigation::planning::scattered::scattered;
use swarm_navigation::planning::theta_star;
use swarm_navigation::planning::tree::{self, Tree, TreeParams};

const ROBOT_RADIUS: f32 = 0.1;

fn planners(c: &mut Criterion) {
    let mut group = c.benchmark_group("plan");
    group.sample_size(20);
    for obstacles in [10, 50, 200] {
        let problem = scattered(obstacles, 1);
        let map = problem.map.grown(ROBOT_RADIUS);
        let params = GsaParams::default();
        let mut seed = 0;
        group.bench_with_input(BenchmarkId::new("gsa", obstacles), &map, |b, map| {
            b.iter(|| {
                seed += 1;
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                // Failed runs (no collision-free trajectory) cost the same work and count too.
                black_box(gsa::plan(problem.start, problem.goal, map, &params, &mut rng).ok())
            })
        });
        for (label, kind) in [("ort", Tree::Ort), ("rrt", Tree::Rrt)] {
            let mut seed = 0;
            group.bench_with_input(BenchmarkId::new(label, obstacles), &map, |b, map| {
                b.iter(|| {
                    seed += 1;
                    let mut rng = ChaCha8Rng::seed_from_u64(seed);
                    let params = TreeParams::default();
                    black_box(
                        tree::plan(kind, problem.start, problem.goal, map, &params, &mut rng).ok(),
                    )
                })
            });
        }
        group.bench_with_input(BenchmarkId::new("theta_star", obstacles), &map, |b, map| {
            b.iter(|| {
                black_box(theta_star::shortest_path(problem.start, problem.goal, map, 0.05).ok())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, planners);
criterion_main!(benches);
