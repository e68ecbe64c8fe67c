//! `swarm-lockstep-agent`: a bare lockstep agent with no player, for the transport benchmark and system tests.
//!
//! It joins a run for one robot and answers every tick with a command that proves it read its own frame: its
//! wheel speeds echo the frame's `position` (where tests put a per-robot, per-tick marker). Fault options make it die or freeze at a
//! given tick, so tests can check that the world never blocks on a dead or frozen robot.

use anyhow::{Context, Result};
use clap::Parser;
use swarm_contract::messages::ActuatorCommand;
use swarm_contract::transport::{AgentLink, RunSpec};

/// A bare lockstep agent (no player): echoes its frame's position as wheel speeds.
#[derive(Parser, Debug)]
struct Args {
    /// Run name (shared by every process of the run).
    #[arg(long)]
    run: String,
    /// iceoryx2 root directory of the run.
    #[arg(long)]
    root: std::path::PathBuf,
    /// Robot index this agent runs.
    #[arg(long)]
    robot: u32,
    /// Polls of the tick word before sleeping on it.
    #[arg(long)]
    spin: Option<u32>,
    /// Exit abruptly (no answer, no cleanup) when this tick arrives.
    #[arg(long)]
    die_at: Option<u64>,
    /// Stop answering (but stay alive) from this tick on.
    #[arg(long)]
    freeze_at: Option<u64>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let run = RunSpec::new(&args.run, &args.root).context("invalid run")?;
    let mut link = AgentLink::join(&run, args.robot)
        .with_context(|| format!("robot {} joining run {}", args.robot, args.run))?;
    if let Some(spin) = args.spin {
        link.set_spin(spin);
    }
    while let Some(tick) = link.next_tick().context("waiting for a tick")? {
        let number = tick.number();
        if args.die_at == Some(number) {
            std::process::abort();
        }
        if args.freeze_at.is_some_and(|t| number >= t) {
            continue;
        }
        let mut command = ActuatorCommand::idle(args.robot, number);
        command.wheels = tick.frame().position;
        tick.answer(&mut command);
    }
    Ok(())
}
