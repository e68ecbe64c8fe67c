//! The bare lockstep benchmark: the world publishes empty frames and collects echo commands from N real agent
//! processes (`swarm-lockstep-agent`), with no world work and no player, so the transport's own cost shows.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::bench::stats::{median, quantile};
use swarm_contract::cpu::CpuMark;
use swarm_contract::transport::{
    LinkConfig, RunSpec, TransportError, WorldLink, priority, tune_agent_command,
};

/// Ticks run before measuring, so that every agent is paged in and warm.
const WARMUP_TICKS: usize = 100;

/// What to measure.
#[derive(Debug, Clone)]
pub struct BareOptions {
    /// Number of agent processes.
    pub robots: u32,
    /// Ticks per measurement window.
    pub ticks: usize,
    /// Number of measurement windows; figures are medians over windows.
    pub windows: usize,
    /// The world's spin before it sleeps on the answer counter (`None`: the transport's default).
    pub world_spin: Option<Duration>,
    /// Agents' polls of the tick word before they sleep (`None`: the agent's default).
    pub agent_spin: Option<u32>,
}

/// Medians over the measurement windows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BareReport {
    /// Number of agent processes.
    pub robots: u32,
    /// From spawning the first agent to the end of the first tick.
    pub first_tick: Duration,
    /// Robot-steps (answered commands) per second.
    pub robot_steps_per_second: f64,
    /// Median tick time.
    pub tick_p50: Duration,
    /// 99th-percentile tick time.
    pub tick_p99: Duration,
    /// CPU time of the world and every agent per robot-step, over all windows ([`swarm_contract::cpu`]).
    pub cpu_per_robot_step: Duration,
}

/// Why the bare benchmark failed.
#[derive(Debug, thiserror::Error)]
pub enum BareError {
    /// The transport failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// An agent process could not be started.
    #[error("starting {program} for robot {robot}: {source}")]
    Spawn {
        /// The agent program.
        program: String,
        /// The robot.
        robot: u32,
        /// Why.
        source: std::io::Error,
    },
    /// A tick was not answered by every agent.
    #[error("tick {tick}: {answered} of {robots} agents answered")]
    Unanswered {
        /// The tick.
        tick: u64,
        /// Answers received.
        answered: u32,
        /// Agents.
        robots: u32,
    },
    /// The run left shared-memory files behind.
    #[error("files left behind: {0:?}")]
    Leftovers(Vec<std::path::PathBuf>),
}

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

/// Runs the bare lockstep with `agent` (the `swarm-lockstep-agent` program), ticked by a thread of its own at
/// real-time priority when the system allows it, as a world ticks (the calling thread keeps its priority).
pub fn run(agent: &Path, options: &BareOptions) -> Result<BareReport, BareError> {
    std::thread::scope(|scope| {
        scope
            .spawn(|| {
                let realtime = priority::tick_at_realtime(true);
                tick_bare(agent, options, realtime)
            })
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

fn tick_bare(agent: &Path, options: &BareOptions, realtime: bool) -> Result<BareReport, BareError> {
    let robots = options.robots;
    let run = RunSpec::unique();
    let mut config = LinkConfig::new(robots);
    config.realtime = realtime;
    config.tick_deadline = Duration::from_secs(10);
    if let Some(spin) = options.world_spin {
        config.spin = spin;
    }
    let mut world = WorldLink::create(&run, config)?;
    let mut agents = Agents {
        run: run.clone(),
        children: Vec::with_capacity(robots as usize),
    };
    let start = Instant::now();
    for robot in 0..robots {
        let mut command = Command::new(agent);
        tune_agent_command(&mut command)
            .arg("--run")
            .arg(run.name())
            .arg("--root")
            .arg(run.root_dir())
            .arg("--robot")
            .arg(robot.to_string())
            .stdin(Stdio::null());
        if let Some(spin) = options.agent_spin {
            command.arg("--spin").arg(spin.to_string());
        }
        let child = command.spawn().map_err(|source| BareError::Spawn {
            program: agent.display().to_string(),
            robot,
            source,
        })?;
        agents.children.push(child);
    }
    world.wait_for_agents(Duration::from_secs(600))?;
    tick_all(&mut world, robots)?;
    let first_tick = start.elapsed();
    for _ in 0..WARMUP_TICKS {
        tick_all(&mut world, robots)?;
    }
    let mut rates = Vec::with_capacity(options.windows);
    let mut p50s = Vec::with_capacity(options.windows);
    let mut p99s = Vec::with_capacity(options.windows);
    let mut times = Vec::with_capacity(options.ticks);
    let agent_pids = || agents.children.iter().map(Child::id);
    let cpu = CpuMark::take(agent_pids());
    for _ in 0..options.windows.max(1) {
        times.clear();
        let window = Instant::now();
        for _ in 0..options.ticks.max(1) {
            let tick = Instant::now();
            tick_all(&mut world, robots)?;
            times.push(tick.elapsed());
        }
        let elapsed = window.elapsed().as_secs_f64();
        rates.push(f64::from(robots) * times.len() as f64 / elapsed);
        times.sort();
        p50s.push(quantile(&times, 0.5).unwrap_or_default().as_secs_f64());
        p99s.push(quantile(&times, 0.99).unwrap_or_default().as_secs_f64());
    }
    let robot_steps = f64::from(robots) * (options.ticks.max(1) * options.windows.max(1)) as f64;
    let cpu_per_robot_step = cpu.per_step(agent_pids(), robot_steps);
    drop(world);
    drop(agents);
    let leftovers = run.leftovers();
    if !leftovers.is_empty() {
        return Err(BareError::Leftovers(leftovers));
    }
    Ok(BareReport {
        robots,
        first_tick,
        robot_steps_per_second: median(&rates).unwrap_or(0.0),
        tick_p50: Duration::from_secs_f64(median(&p50s).unwrap_or(0.0)),
        tick_p99: Duration::from_secs_f64(median(&p99s).unwrap_or(0.0)),
        cpu_per_robot_step,
    })
}

fn tick_all(world: &mut WorldLink, robots: u32) -> Result<(), BareError> {
    let outcome = world.tick_with(|_, _, _| {})?;
    if outcome.answered == robots {
        Ok(())
    } else {
        Err(BareError::Unanswered {
            tick: outcome.tick,
            answered: outcome.answered,
            robots,
        })
    }
}
