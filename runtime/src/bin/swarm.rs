//! `swarm`: runs experiments.
//!
//! `swarm run <config.argos>` starts the world and one agent process per robot, shows progress, and leaves the
//! run directory (summary, trajectories, events, snapshot, logs). Ctrl-C stops the run cleanly: the world finishes
//! its tick and flushes its records, and every process and shared-memory file of the run is removed.
//!
//! `swarm experiment <grid.toml>` runs a grid of configurations x seeds into a batch folder (`docs/experiments.md`):
//! several runs at once, resumable, with `results.csv`, figures and `report.md`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Context;
use clap::{Parser, Subcommand};
use swarm_runtime::experiment::{self, ExperimentOptions};
use swarm_runtime::launcher::binaries::Binaries;
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
    },
    /// Run a grid of configurations x seeds (a TOML grid file); a rerun continues where a stopped one ended.
    Experiment {
        /// The grid file (.toml).
        grid: PathBuf,
        /// Batch folder (overrides the grid's `out`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Runs at once (default: one per core, fewer if memory is short).
        #[arg(long)]
        jobs: Option<usize>,
        /// Do not draw a progress bar.
        #[arg(long)]
        no_progress: bool,
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
        Commands::Experiment {
            grid,
            out,
            jobs,
            no_progress,
        } => run_experiment(ExperimentOptions {
            grid,
            out,
            jobs,
            progress: !no_progress,
        }),
        Commands::Run {
            config,
            robots,
            ticks,
            seed,
            out,
            tick_deadline_ms,
            no_progress,
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
            };
            let report = launcher::run(&options, stop)
                .with_context(|| format!("running {}", config.display()))?;
            let ticking =
                (report.wall_seconds - report.time_to_first_tick_seconds).max(f64::EPSILON);
            let steps = f64::from(report.robots) * report.ticks as f64;
            println!(
                "{} after {} ticks: {} robots, seed {}, {:.1} s ({:.2} s to the first tick), {:.0} robot-steps/s, \
                 {} deaths; records in {}",
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
                report.out_dir.display()
            );
            Ok(())
        }
    }
}

/// `swarm experiment`: runs the batch, prints where its results are, and fails if any run failed.
fn run_experiment(options: ExperimentOptions) -> anyhow::Result<()> {
    // Find (under cargo: build) the world and agent programs once, rather than once per run from parallel threads.
    let binaries = Binaries::locate().context("locating the world and agent programs")?;
    if std::env::var_os("SWARM_BIN_DIR").is_none()
        && let Some(dir) = binaries.world.parent()
    {
        // SAFETY: the process has one thread here; the Ctrl-C handler's thread and the runs start below.
        unsafe { std::env::set_var("SWARM_BIN_DIR", dir) };
    }
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    let report = experiment::run(&options, stop)
        .with_context(|| format!("running the grid {}", options.grid.display()))?;
    println!(
        "{}: {} configurations, {} of {} runs finished ({} by earlier invocations), {} failed, {} at once; results \
         in {}",
        if report.interrupted {
            "stopped"
        } else {
            "done"
        },
        report.configurations,
        report.runs_reused + report.runs_completed,
        report.runs_planned,
        report.runs_reused,
        report.failures.len(),
        report.jobs,
        report.dir.join("results.csv").display()
    );
    if let Some(reason) = &report.plots_missing {
        eprintln!("warning: no figures: {reason}");
    }
    if report.interrupted {
        println!("run the same command again to continue");
    }
    anyhow::ensure!(
        report.failures.is_empty(),
        "{} run(s) failed:\n{}",
        report.failures.len(),
        report.failures.join("\n")
    );
    Ok(())
}
