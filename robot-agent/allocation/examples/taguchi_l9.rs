//! The Taguchi L9 design of A.5.4 for FGA's four parameters, run on allocation problems: crossover probability
//! (0.75, 0.85, 0.95), mutation probability (0.2, 0.3, 0.4), population (40, 50, 60) and generations (20, 40, 80).
//! Each of the nine runs allocates five problems of 12 tasks x 9 robots (the method's largest test problem) with
//! ten seeds each; its response is the objective F, its signal-to-noise ratio larger-the-better. Prints the runs,
//! the main effects and the chosen levels as Markdown.
//! `cargo run --release -p swarm-allocation --example taguchi_l9`

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_allocation::fga::{FgaParams, allocate};
use swarm_allocation::instances::scattered;
use swarm_allocation::taguchi::{L9, best_levels, larger_the_better, main_effects};

const CROSSOVER: [f64; 3] = [0.75, 0.85, 0.95];
const MUTATION: [f64; 3] = [0.2, 0.3, 0.4];
const POPULATION: [usize; 3] = [40, 50, 60];
const GENERATIONS: [usize; 3] = [20, 40, 80];

fn main() {
    println!("| run | Pc | Pm | P | G | mean F | S/N dB | mean ms |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut ratios = [0.0; 9];
    for (run, row) in L9.iter().enumerate() {
        let params = FgaParams {
            crossover: CROSSOVER[row[0]],
            mutation: MUTATION[row[1]],
            population: POPULATION[row[2]],
            generations: GENERATIONS[row[3]],
        };
        let (mut responses, mut seconds) = (Vec::new(), 0.0);
        for problem in 0..5 {
            let p = scattered(12, 9, problem);
            for seed in 0..10 {
                let clock = Instant::now();
                responses
                    .push(allocate(&p, &params, &mut ChaCha8Rng::seed_from_u64(seed)).objective);
                seconds += clock.elapsed().as_secs_f64();
            }
        }
        let ratio = larger_the_better(&responses).unwrap_or(f64::NEG_INFINITY);
        ratios[run] = ratio;
        println!(
            "| {} | {} | {} | {} | {} | {:.4} | {ratio:.3} | {:.2} |",
            run + 1,
            params.crossover,
            params.mutation,
            params.population,
            params.generations,
            responses.iter().sum::<f64>() / responses.len() as f64,
            seconds * 1e3 / responses.len() as f64
        );
    }
    let effects = main_effects(&ratios);
    println!("\n| factor | level 1 | level 2 | level 3 | chosen |");
    println!("|---|---|---|---|---|");
    let chosen = best_levels(&effects);
    let names = ["Pc", "Pm", "P", "G"];
    let levels: [[String; 3]; 4] = [
        CROSSOVER.map(|v| v.to_string()),
        MUTATION.map(|v| v.to_string()),
        POPULATION.map(|v| v.to_string()),
        GENERATIONS.map(|v| v.to_string()),
    ];
    for f in 0..4 {
        println!(
            "| {} | {:.3} | {:.3} | {:.3} | {} |",
            names[f], effects[f][0], effects[f][1], effects[f][2], levels[f][chosen[f]]
        );
    }
}
