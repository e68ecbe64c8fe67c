//! `swarm`: runs experiments.
//!
//! `swarm run <config.argos>` starts the world and one agent process per robot, shows progress, and leaves the
//! run directory (summary, trajectories, events, snapshot, logs). Ctrl-C stops the run cleanly: the world finishes
//! its tick and flushes its records, and every process and shared-memory file of the run is removed.
//! `swarm run --fault "kill robots=3 tick=50"` adds faults to the configuration's `<faults>`, and
//! `swarm ctl <run dir> list | kill <robot> | freeze <robot> | thaw <robot>` drives a live run (docs/faults.md).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Context;
use clap::{Parser, Subcommand};
use swarm_runtime::launcher::control::{self, CtlCommand};
use swarm_runtime::launcher::{self, RunOptions};

/// Runs swarms of robot processes executing ptSCT supervisors.
#[derive(Debug, Parser)]
#[command(name = "swarm", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Commands,
}

#[derive(Debug, Subcommand)]
enum Commands {
    /// Run an experiment: one world process and one robot-agent process per robot.
    Run {
        /// The experiment configuration (.argos).
        config: PathBuf,
        /// Number of robots (overrides the quantity of the configuration's e-puck <distribute>).
        #[arg(long)]
        robots: Option<u32>,
        /// Ticks to run (overrides the configuration's experiment length).
        #[arg(long)]
        ticks: Option<u64>,
        /// Run seed (overrides the configuration's random_seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Run directory (default: runs/<config name>-<unix seconds>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Milliseconds a tick waits for a missing command before it goes on without it.
        #[arg(long = "tick-deadline-ms")]
        tick_deadline_ms: Option<u64>,
        /// Do not draw a progress bar.
        #[arg(long)]
        no_progress: bool,
        /// A fault added to the configuration's <faults>, as the element in words (repeatable), e.g.
        /// "kill robots=3 tick=50", "chaos every=2 count=1", "restart policy=on-failure max_restarts=2".
        #[arg(long = "fault", value_name = "FAULT")]
        faults: Vec<String>,
    },
    /// Drive a live run from another terminal: list its robots, kill, freeze or thaw one.
    Ctl {
        /// The run directory of the live run (its `--out`), or its control socket.
        run: PathBuf,
        #[command(subcommand)]
        request: CtlRequestArg,
    },
}

/// What `swarm ctl` asks a live run.
#[derive(Debug, Subcommand)]
enum CtlRequestArg {
    /// Every robot with its agent's process id, state and restarts.
    List,
    /// SIGKILL a robot's agent (it is restarted if its restart policy says so).
    Kill {
        /// Robot index.
        robot: u32,
    },
    /// SIGSTOP a robot's agent; the world stops waiting for it after one tick deadline.
    Freeze {
        /// Robot index.
        robot: u32,
    },
    /// SIGCONT a frozen robot's agent; it takes part again from the tick after its next answer.
    Thaw {
        /// Robot index.
        robot: u32,
    },
}

fn main() -> ExitCode {
    swarm_runtime::logging::init("info");
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Commands::Run {
            config,
            robots,
            ticks,
            seed,
            out,
            tick_deadline_ms,
            no_progress,
            faults,
        } => {
            let stop = Arc::new(AtomicBool::new(false));
            let flag = Arc::clone(&stop);
            ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
                .context("installing the Ctrl-C handler")?;
            let options = RunOptions {
                config: config.clone(),
                robots,
                ticks,
                seed,
                out,
                progress: !no_progress,
                tick_deadline: tick_deadline_ms.map(Duration::from_millis),
                faults,
            };
            let report = launcher::run(&options, stop)
                .with_context(|| format!("running {}", config.display()))?;
            let ticking =
                (report.wall_seconds - report.time_to_first_tick_seconds).max(f64::EPSILON);
            let steps = f64::from(report.robots) * report.ticks as f64;
            println!(
                "{} after {} ticks: {} robots, seed {}, {:.1} s ({:.2} s to the first tick), {:.0} robot-steps/s, \
                 {} deaths, {} faults, {} alive; records in {}",
                if report.interrupted {
                    "stopped"
                } else {
                    "finished"
                },
                report.ticks,
                report.robots,
                report.seed,
                report.wall_seconds,
                report.time_to_first_tick_seconds,
                steps / ticking,
                report.deaths.len(),
                report.faults.len(),
                report.alive_final,
                report.out_dir.display()
            );
            Ok(())
        }
        Commands::Ctl { run, request } => ctl(&run, request),
    }
}

/// `swarm ctl`: one request to a live run, its answer on standard output.
fn ctl(run: &std::path::Path, request: CtlRequestArg) -> anyhow::Result<()> {
    let command = match request {
        CtlRequestArg::List => CtlCommand::List,
        CtlRequestArg::Kill { robot } => CtlCommand::Kill(robot),
        CtlRequestArg::Freeze { robot } => CtlCommand::Freeze(robot),
        CtlRequestArg::Thaw { robot } => CtlCommand::Thaw(robot),
    };
    let answer = control::request(run, command)
        .with_context(|| format!("swarm ctl {} {command}", run.display()))?;
    print!("{answer}");
    Ok(())
}
