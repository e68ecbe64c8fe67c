//! FGA against NSGA-II on the same problems (A.5.5): mean objective F over 20 seeds and median time per
//! allocation, for 12 tasks x 9 robots and 100 tasks x 50 robots (`instances::scattered`, five problems each),
//! as a Markdown table. `cargo run --release -p swarm-allocation --example allocation_eval`

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_allocation::Problem;
use swarm_allocation::fga::{self, Allocation, FgaParams};
use swarm_allocation::instances::scattered;
use swarm_allocation::nsga2;

type Allocator = fn(&Problem, &FgaParams, &mut ChaCha8Rng) -> Allocation;

fn main() {
    let allocators: [(&str, Allocator); 2] = [("FGA", fga::allocate), ("NSGA-II", nsga2::allocate)];
    println!("| tasks x robots | allocator | mean F | min F | max F | median ms |");
    println!("|---|---|---|---|---|---|");
    for (tasks, robots) in [(12, 9), (100, 50)] {
        for (label, allocate) in allocators {
            let (mut values, mut ms) = (Vec::new(), Vec::new());
            for problem_seed in 0..5 {
                let p = scattered(tasks, robots, problem_seed);
                for seed in 0..20 {
                    let clock = Instant::now();
                    let a = allocate(
                        &p,
                        &FgaParams::default(),
                        &mut ChaCha8Rng::seed_from_u64(seed),
                    );
                    ms.push(clock.elapsed().as_secs_f64() * 1e3);
                    values.push(a.objective);
                }
            }
            ms.sort_by(f64::total_cmp);
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let min = values.iter().copied().fold(f64::INFINITY, f64::min);
            let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            println!(
                "| {tasks} x {robots} | {label} | {mean:.4} | {min:.4} | {max:.4} | {:.2} |",
                ms[ms.len() / 2]
            );
        }
    }
}
