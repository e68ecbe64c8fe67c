//! Bare lockstep benchmark: the world publishes empty frames and collects echo commands from N real agent
//! processes (`swarm-lockstep-agent`), with no world work and no player.
//!
//! Reports, per N: time from spawning the agents to the end of the first tick, robot-steps per second and the
//! p50/p99 tick time, each as the median over several measurement windows.
//! `cargo bench -p swarm-runtime --bench lockstep` (N = 10, 100, 1000); `LOCKSTEP_N=100,500` picks other sizes,
//! `LOCKSTEP_TICKS` the ticks per window, `LOCKSTEP_WINDOWS` the number of windows, `LOCKSTEP_SPIN_US` the world's spin
//! and `LOCKSTEP_AGENT_SPIN` the agents' polls before sleeping.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use swarm_runtime::transport::{LinkConfig, RunSpec, WorldLink};

const AGENT: &str = env!("CARGO_BIN_EXE_swarm-lockstep-agent");
const WARMUP_TICKS: usize = 100;

/// Kills the agents and removes the run's files, also when the benchmark fails half-way.
struct Agents {
    run: RunSpec,
    children: Vec<Child>,
}

impl Drop for Agents {
    fn drop(&mut self) {
        for child in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = self.run.cleanup();
    }
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let index = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[index.min(sorted.len() - 1)]
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

fn bench(robots: u32, ticks: usize, windows: usize) -> Result<()> {
    let run = RunSpec::unique();
    let mut config = LinkConfig::new(robots);
    config.tick_deadline = Duration::from_secs(10);
    config.spin = Duration::from_micros(env_or("LOCKSTEP_SPIN_US", config.spin.as_micros() as u64));
    let agent_spin: Option<u32> = std::env::var("LOCKSTEP_AGENT_SPIN")
        .ok()
        .and_then(|v| v.parse().ok());
    let mut world = WorldLink::create(&run, config).context("creating the world link")?;
    let mut agents = Agents {
        run: run.clone(),
        children: Vec::with_capacity(robots as usize),
    };
    let start = Instant::now();
    for robot in 0..robots {
        let mut command = Command::new(AGENT);
        command
            .arg("--run")
            .arg(run.name())
            .arg("--root")
            .arg(run.root_dir())
            .arg("--robot")
            .arg(robot.to_string())
            .stdin(Stdio::null());
        if let Some(spin) = agent_spin {
            command.arg("--spin").arg(spin.to_string());
        }
        agents.children.push(
            command
                .spawn()
                .with_context(|| format!("spawning agent {robot}"))?,
        );
    }
    world
        .wait_for_agents(Duration::from_secs(600))
        .context("waiting for the agents")?;
    let joined = start.elapsed();
    let first = world.tick_with(|_, _| {})?;
    let first_tick = start.elapsed();
    if first.answered != robots {
        bail!("first tick: {first:?}");
    }
    for _ in 0..WARMUP_TICKS {
        world.tick_with(|_, _| {})?;
    }
    let mut rates = Vec::new();
    let mut p50s = Vec::new();
    let mut p99s = Vec::new();
    let mut times = Vec::with_capacity(ticks);
    for _ in 0..windows {
        times.clear();
        let window = Instant::now();
        for _ in 0..ticks {
            let t = Instant::now();
            let outcome = world.tick_with(|_, _| {})?;
            times.push(t.elapsed());
            if outcome.answered != robots {
                bail!("tick {}: {outcome:?}", outcome.tick);
            }
        }
        let elapsed = window.elapsed();
        rates.push(f64::from(robots) * ticks as f64 / elapsed.as_secs_f64());
        times.sort();
        p50s.push(percentile(&times, 0.5).as_secs_f64() * 1e6);
        p99s.push(percentile(&times, 0.99).as_secs_f64() * 1e6);
    }
    println!(
        "lockstep N={robots:5}: joined {:8.1} ms, first tick {:8.1} ms, {:9.0} robot-steps/s, tick p50 {:8.1} us, p99 {:8.1} us  (median of {windows} windows x {ticks} ticks; rates {:?})",
        joined.as_secs_f64() * 1e3,
        first_tick.as_secs_f64() * 1e3,
        median(rates.clone()),
        median(p50s),
        median(p99s),
        rates.iter().map(|r| r.round() as u64).collect::<Vec<_>>(),
    );
    drop(world);
    drop(agents);
    if !run.leftovers().is_empty() {
        bail!("files left behind: {:?}", run.leftovers());
    }
    Ok(())
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
    let windows = env_or("LOCKSTEP_WINDOWS", if benchmarking { 5 } else { 1 });
    for robots in sizes {
        let default_ticks = if benchmarking {
            (200_000 / robots as usize).clamp(200, 5000)
        } else {
            20
        };
        bench(robots, env_or("LOCKSTEP_TICKS", default_ticks), windows)?;
    }
    Ok(())
}
