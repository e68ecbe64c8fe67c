//! `swarm`: runs experiments.
//!
//! `swarm run <config.argos>` starts the world and one agent process per robot, shows progress, and leaves the
//! run directory (summary, trajectories, events, snapshot, logs). Ctrl-C stops the run cleanly: the world finishes
//! its tick and flushes its records, and every process and shared-memory file of the run is removed.
//!
//! `swarm host --connect <endpoint>` runs one machine's share of multi-host runs (docs/hosts.md); `swarm run
//! --hosts a,b` places a run's robots on such hosts.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use swarm_runtime::launcher::hosts::HostsArgs;
use swarm_runtime::launcher::{self, RunOptions};
use swarm_runtime::remote::codec::DEFAULT_MAX_PAYLOAD;
use swarm_runtime::remote::host::{self, HostOptions};
use swarm_runtime::remote::session::{DEFAULT_LEASE, ZenohOptions};

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
        /// Hosts to run the robots on.
        #[command(flatten)]
        hosts: HostsArgs,
    },
    /// Run this machine's share of multi-host runs: announce this host, start the robots the world assigns it,
    /// and bridge their frames and commands over zenoh.
    Host(HostCli),
}

/// Flags of `swarm host`.
#[derive(Debug, Args)]
struct HostCli {
    /// The world's zenoh endpoint, e.g. tcp/10.0.0.1:7447.
    #[arg(long)]
    connect: String,
    /// Name of this host in placements (default: the machine's host name, dots as '-').
    #[arg(long)]
    name: Option<String>,
    /// Most robots this host accepts in one run.
    #[arg(long, default_value_t = 1000)]
    capacity: u32,
    /// Link lease in milliseconds: a frozen or cut-off host is noticed after about this long.
    #[arg(long = "lease-ms", default_value_t = DEFAULT_LEASE.as_millis() as u64)]
    lease_ms: u64,
    /// A zenoh configuration file (JSON5) to start from (e.g. for TLS).
    #[arg(long = "zenoh-config")]
    zenoh_config: Option<PathBuf>,
    /// zenoh user name (with --password-file).
    #[arg(long, requires = "password_file")]
    user: Option<String>,
    /// File holding the zenoh password.
    #[arg(long = "password-file", requires = "user")]
    password_file: Option<PathBuf>,
    /// Folder for the agents' logs (default: <temp>/swarm-host-<name>).
    #[arg(long)]
    logs: Option<PathBuf>,
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
            hosts,
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
                hosts,
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
        Commands::Host(cli) => run_host(cli),
    }
}

/// `swarm host`: serves runs until Ctrl-C or SIGTERM.
fn run_host(cli: HostCli) -> anyhow::Result<()> {
    let name = match cli.name {
        Some(name) => name,
        // Host names are one zenoh key chunk: dots and other characters become '-'.
        None => std::fs::read_to_string("/proc/sys/kernel/hostname")
            .context("reading the machine's host name (or pass --name)")?
            .trim()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' {
                    c
                } else {
                    '-'
                }
            })
            .collect(),
    };
    let password = match &cli.password_file {
        Some(path) => Some(
            std::fs::read_to_string(path)
                .with_context(|| format!("reading the password file {}", path.display()))?
                .trim_end_matches(['\r', '\n'])
                .to_owned(),
        ),
        None => None,
    };
    let logs = cli
        .logs
        .unwrap_or_else(|| std::env::temp_dir().join(format!("swarm-host-{name}")));
    let options = HostOptions {
        connect: cli.connect,
        capacity: cli.capacity,
        zenoh: ZenohOptions {
            config_file: cli.zenoh_config,
            lease: Duration::from_millis(cli.lease_ms),
            user: cli.user,
            password,
            credentials_file: None,
        },
        max_payload: DEFAULT_MAX_PAYLOAD,
        logs,
        name,
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    host::serve(&options, &stop).with_context(|| format!("host '{}'", options.name))
}
