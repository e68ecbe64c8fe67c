//! Time per allocation of the fast genetic allocator (P = 50, G = 40, Pc = 0.95, Pm = 0.3) for 12 tasks x 9
//! robots (the largest of the method's test problems) and for 100 tasks x 50 robots, half of each type, on a
//! 10 x 10 workspace. `cargo bench -p swarm-allocation --bench allocation`; the figures are in BENCHMARKS.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use swarm_allocation::fga::{FgaParams, allocate};
use swarm_allocation::{Kind, Problem, Robot, Task, Weights};

fn problem(tasks: usize, robots: usize) -> Problem {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
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

fn allocation(c: &mut Criterion) {
    let mut group = c.benchmark_group("fga");
    group.sample_size(20);
    for (tasks, robots) in [(12, 9), (100, 50)] {
        let p = problem(tasks, robots);
        let mut seed = 0;
        group.bench_with_input(
            BenchmarkId::new("allocate", format!("{tasks}x{robots}")),
            &p,
            |b, p| {
                b.iter(|| {
                    seed += 1;
                    black_box(
                        allocate(
                            p,
                            &FgaParams::default(),
                            &mut ChaCha8Rng::seed_from_u64(seed),
                        )
                        .objective,
                    )
                })
            },
        );
    }
    group.finish();
}

criterion_group!(benches, allocation);
criterion_main!(benches);
