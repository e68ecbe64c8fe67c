//! Time per allocation of the fast genetic allocator and of its NSGA-II baseline (both P = 50, G = 40, Pc =
//! 0.95, Pm = 0.3) for 12 tasks x 9 robots (the largest of the method's test problems) and for 100 tasks x 50
//! robots (`instances::scattered`). `cargo bench -p swarm-allocation --bench allocation`; the figures are in BENCHMARKS.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_allocation::Problem;
use swarm_allocation::fga::{self, Allocation, FgaParams};
use swarm_allocation::instances::scattered;
use swarm_allocation::nsga2;

type Allocator = fn(&Problem, &FgaParams, &mut ChaCha8Rng) -> Allocation;

fn allocation(c: &mut Criterion) {
    let mut group = c.benchmark_group("allocate");
    group.sample_size(20);
    let allocators: [(&str, Allocator); 2] = [("fga", fga::allocate), ("nsga2", nsga2::allocate)];
    for (label, allocate) in allocators {
        for (tasks, robots) in [(12, 9), (100, 50)] {
            let p = scattered(tasks, robots, 7);
            let mut seed = 0;
            let id = BenchmarkId::new(label, format!("{tasks}x{robots}"));
            group.bench_with_input(id, &p, |b, p| {
                b.iter(|| {
                    seed += 1;
                    let mut rng = ChaCha8Rng::seed_from_u64(seed);
                    black_box(allocate(p, &FgaParams::default(), &mut rng).objective)
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, allocation);
criterion_main!(benches);
