//! Bare lockstep benchmark: the world publishes empty frames and collects echo commands from N real agent
//! processes (`swarm-lockstep-agent`), with no world work and no player (the same measurement as
//! `swarm bench --bare-only`).
//!
//! Reports, per N: time from spawning the agents to the end of the first tick, robot-steps per second and the
//! p50/p99 tick time, each as the median over several measurement windows.
//! `cargo bench -p swarm-cli --bench lockstep` (N = 10, 100, 1000); `LOCKSTEP_N=100,500` picks other sizes,
//! `LOCKSTEP_TICKS` the ticks per window, `LOCKSTEP_WINDOWS` the number of windows, `LOCKSTEP_SPIN_US` the world's spin
//! and `LOCKSTEP_AGENT_SPIN` the agents' polls before sleeping.

use std::path::Path;
use std::time::Duration;

use anyhow::Result;
use swarm_cli::bench::bare::{self, BareOptions};

const AGENT: &str = env!("CARGO_BIN_EXE_swarm-lockstep-agent");

fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

fn main() -> Result<()> {
    // `cargo bench` passes `--bench`; `cargo test --benches` passes nothing and expects a quick smoke run.
    let benchmarking = std::env::args().any(|a| a == "--bench");
    let sizes: Vec<u32> = std::env::var("LOCKSTEP_N")
        .ok()
        .map(|v| v.split(',').filter_map(|n| n.trim().parse().ok()).collect())
        .unwrap_or_else(|| {
            if benchmarking {
                vec![10, 100, 1000]
            } else {
                vec![4]
            }
        });
    for robots in sizes {
        let default_ticks = if benchmarking {
            (200_000 / robots as usize).clamp(200, 5000)
        } else {
            20
        };
        let options = BareOptions {
            robots,
            ticks: env("LOCKSTEP_TICKS").unwrap_or(default_ticks),
            windows: env("LOCKSTEP_WINDOWS").unwrap_or(if benchmarking { 5 } else { 1 }),
            world_spin: env("LOCKSTEP_SPIN_US").map(Duration::from_micros),
            agent_spin: env("LOCKSTEP_AGENT_SPIN"),
        };
        let report = bare::run(Path::new(AGENT), &options)?;
        println!(
            "lockstep N={robots:5}: first tick {:8.1} ms, {:9.0} robot-steps/s, tick p50 {:8.1} us, p99 {:8.1} us  \
             (median of {} windows x {} ticks)",
            report.first_tick.as_secs_f64() * 1e3,
            report.robot_steps_per_second,
            report.tick_p50.as_secs_f64() * 1e6,
            report.tick_p99.as_secs_f64() * 1e6,
            options.windows,
            options.ticks,
        );
    }
    Ok(())
}
