//! The planner-level figures of docs/planning.md, as Markdown tables: GSA, and the tree planners ORT and RRT,
//! against the Theta* reference on scattered maps of 10, 50 and 200 discs (`MAPS` maps each, one run per map
//! and seed). The optional arguments change GSA's parameters.
//! `cargo run --release -p swarm-navigation --example planner_eval [-- <g0> <alpha_g> <max_step> <goal_anchor>]`

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_navigation::planning::gsa::{self, GsaParams};
use swarm_navigation::planning::map::{path_length, shortcut};
use swarm_navigation::planning::scattered::scattered;
use swarm_navigation::planning::theta_star;
use swarm_navigation::planning::tree::{self, Tree, TreeParams};

const MAPS: u64 = 10;
const SEEDS: u64 = 10;
const ROBOT_RADIUS: f32 = 0.1;

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let d = GsaParams::default();
    let number =
        |i: usize, default: f32| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(default);
    let params = GsaParams {
        g0: number(0, d.g0),
        alpha_g: number(1, d.alpha_g),
        max_step: number(2, d.max_step),
        goal_anchor: args.get(3).is_some_and(|a| a == "true"),
        ..d
    };
    println!("GSA {params:?}\n");
    println!(
        "| obstacles | runs | success | mean S_cf/N | median D/optimum | median shortcut/optimum | median GSA ms | median Theta* ms |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for obstacles in [10, 50, 200] {
        let (mut runs, mut found, mut free) = (0, 0, 0.0);
        let (mut ratio, mut short_ratio, mut gsa_ms, mut ref_ms) = (vec![], vec![], vec![], vec![]);
        for m in 0..MAPS {
            let problem = scattered(obstacles, m);
            let map = problem.map.grown(ROBOT_RADIUS);
            let clock = Instant::now();
            let Ok(optimum) = theta_star::shortest_length(problem.start, problem.goal, &map, 0.05)
            else {
                continue; // a map whose goal is walled in
            };
            ref_ms.push(clock.elapsed().as_secs_f64() * 1e3);
            for seed in 0..SEEDS {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let clock = Instant::now();
                let result = gsa::plan(problem.start, problem.goal, &map, &params, &mut rng);
                gsa_ms.push(clock.elapsed().as_secs_f64() * 1e3);
                runs += 1;
                match result {
                    Ok(plan) => {
                        found += 1;
                        free += plan.collision_free as f64 / params.agents as f64;
                        ratio.push(f64::from(plan.length / optimum));
                        short_ratio.push(f64::from(
                            path_length(&shortcut(&plan.path, &map)) / optimum,
                        ));
                    }
                    Err(gsa::GsaError::NoPath { collision_free, .. }) => {
                        free += collision_free as f64 / params.agents as f64;
                    }
                    Err(e) => panic!("map {m}: {e}"),
                }
            }
        }
        println!(
            "| {obstacles} | {runs} | {:.0} % | {:.2} | {:.2} | {:.3} | {:.1} | {:.1} |",
            100.0 * found as f64 / runs as f64,
            free / runs as f64,
            median(ratio),
            median(short_ratio),
            median(gsa_ms),
            median(ref_ms)
        );
    }
    trees();
}

/// ORT and RRT (steps of 0.2 m, the defaults) against Theta* on the same maps.
fn trees() {
    println!(
        "\n| obstacles | tree | runs | success | median length/optimum | median nodes | median ms |"
    );
    println!("|---|---|---|---|---|---|---|");
    for obstacles in [10, 50, 200] {
        for (label, kind) in [("ORT", Tree::Ort), ("RRT", Tree::Rrt)] {
            let (mut runs, mut found) = (0, 0);
            let (mut ratio, mut nodes, mut ms) = (vec![], vec![], vec![]);
            for m in 0..MAPS {
                let problem = scattered(obstacles, m);
                let map = problem.map.grown(ROBOT_RADIUS);
                let Ok(optimum) =
                    theta_star::shortest_length(problem.start, problem.goal, &map, 0.05)
                else {
                    continue;
                };
                for seed in 0..SEEDS {
                    let mut rng = ChaCha8Rng::seed_from_u64(seed);
                    let clock = Instant::now();
                    let params = TreeParams::default();
                    let result =
                        tree::plan(kind, problem.start, problem.goal, &map, &params, &mut rng);
                    ms.push(clock.elapsed().as_secs_f64() * 1e3);
                    runs += 1;
                    if let Ok(plan) = result {
                        found += 1;
                        ratio.push(f64::from(plan.length / optimum));
                        nodes.push(plan.nodes as f64);
                    }
                }
            }
            println!(
                "| {obstacles} | {label} | {runs} | {:.0} % | {:.3} | {:.0} | {:.1} |",
                100.0 * found as f64 / runs as f64,
                median(ratio),
                median(nodes),
                median(ms)
            );
        }
    }
}
