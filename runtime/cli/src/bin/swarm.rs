//! `swarm`: runs experiments.
//!
//! `swarm run <config.argos>` starts the world and one agent process per robot, shows progress, and leaves the
//! run directory (summary, trajectories, events, snapshot, logs). Ctrl-C stops the run cleanly: the world finishes
//! its tick and flushes its records, and every process and shared-memory file of the run is removed.
//! `swarm run --fault "kill robots=3 tick=50"` adds faults to the configuration's `<faults>`, and
//! `swarm ctl <run dir> list | kill <robot> | freeze <robot> | thaw <robot> | spawn <robot> [x y [heading]] |
//! remove <robot> | kill-host <host>` drives a live run (docs/faults.md, docs/joins.md).
//!
//! `swarm host --connect <endpoint>` runs one machine's share of multi-host runs (docs/hosts.md); `swarm run
//! --hosts a,b` places a run's robots on such hosts.
//!
//! `swarm experiment <grid.toml>` runs a grid of configurations x seeds into a batch folder (`docs/experiments.md`):
//! several runs at once, resumable, with `results.csv`, figures and `report.md`.

use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use swarm_cli::bench::BenchOptions;
use swarm_cli::experiment::{self, ExperimentOptions, Shard};
use swarm_cli::launcher::control::{self, CtlCommand};
use swarm_cli::launcher::{self, RunOptions};
use swarm_contract::config::hosts::TlsFiles;
use swarm_contract::process::binaries::Binaries;
use swarm_contract::protocol::launcher_to_world::Records;
use swarm_contract::protocol::launcher_to_world::SpawnPose;
use swarm_remote::auth::{HostKey, Seal, create_missing_keys, default_key_dir, key_path};
use swarm_remote::codec::DEFAULT_MAX_PAYLOAD;
use swarm_remote::host::{self, HostOptions};
use swarm_remote::plan::HostsArgs;
use swarm_remote::session::{DEFAULT_LEASE, ZenohOptions};

/// Runs swarms of robot processes executing ptSCT supervisors.
#[derive(Debug, Parser)]
#[command(
    name = "swarm",
    version,
    about,
    after_help = "Documents (in the repository's docs/): tutorial.md (start here), configuration.md (the .argos \
                  file), records.md (what a run writes), controllers.md (your own profiles and loop functions), \
                  faults.md, hosts.md, experiments.md, models.md (the model XML) and ptsct.md."
)]
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
        /// Run directory (default: a new runs/<config name>-<YYYYMMDD-HHMMSS>-<4 hex digits>). A folder that
        /// holds an earlier run's files is refused unless --overwrite is given; one that another run is writing
        /// into is always refused.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Empty --out first when it holds an earlier run's files.
        #[arg(long, requires = "out")]
        overwrite: bool,
        /// Milliseconds a tick waits for a missing command before it goes on without it (the same as
        /// --limit tick_deadline_ms=MS; default 500).
        #[arg(long = "tick-deadline-ms")]
        tick_deadline_ms: Option<u64>,
        /// Milliseconds the run waits for its robots (or hosts) to join before it gives up (the same as
        /// --limit join_timeout_ms=MS; default 120000).
        #[arg(long = "join-timeout-ms")]
        join_timeout_ms: Option<u64>,
        /// A timeout or size limit, overriding the configuration's <system> attribute of the same name
        /// (repeatable): tick_deadline_ms, join_timeout_ms, world_ready_timeout_ms, agent_exit_grace_ms,
        /// fault_apply_timeout_ms, ctl_reply_timeout_ms, max_host_message_bytes, agent_join_retry_ms,
        /// agent_board_wait_ms (docs/configuration.md).
        #[arg(long = "limit", value_name = "NAME=VALUE")]
        limits: Vec<String>,
        /// Do not draw a progress bar.
        #[arg(long)]
        no_progress: bool,
        /// Real-time mode: pace the ticks at the configuration's ticks_per_second; summary.json says whether
        /// every tick kept its slot.
        #[arg(long)]
        real_time: bool,
        /// A fault added to the configuration's <faults>, as the element in words (repeatable), e.g.
        /// "kill robots=3 tick=50", "chaos every=2 count=1", "restart policy=on-failure max_restarts=2".
        #[arg(long = "fault", value_name = "FAULT")]
        faults: Vec<String>,
        /// Hosts to run the robots on.
        #[command(flatten)]
        hosts: HostsArgs,
        /// Watch the run live in the browser: serve the viewer (the same page as `swarm view`) while the run
        /// goes on, and after it until Ctrl-C. The URL is printed when the run directory exists.
        #[arg(long)]
        view: bool,
        /// Port of the live viewer (default: any free port).
        #[arg(long, value_name = "PORT", requires = "view", default_value_t = 0)]
        view_port: u16,
        /// Address the live viewer listens on (default 127.0.0.1: this machine only).
        #[arg(
            long,
            value_name = "IP",
            requires = "view",
            default_value = "127.0.0.1"
        )]
        view_bind: IpAddr,
        /// What the run leaves of its record tables (trajectory, events, messages): Parquet files, the CSV files
        /// the world appends while the run goes, or none at all (docs/records.md).
        #[arg(long, value_enum, value_name = "RECORDS", default_value_t = Records::Parquet)]
        records: Records,
    },
    /// Convert a run's record files (trajectory, events, messages) to CSV beside the Parquet files a run leaves,
    /// or to Apache Parquet beside the CSV files of a `--records csv` run (docs/records.md).
    Export {
        /// The run directory.
        run: PathBuf,
        /// The format to write.
        #[arg(long, value_enum)]
        format: swarm_records::Format,
    },
    /// Replay a run in the browser: serves a local web page of the run directory and prints its URL; Ctrl-C
    /// stops it (docs/viewer.md). With --gif, writes an animated GIF of the run instead.
    View {
        /// The run directory (a `swarm run --out`, or a run of an experiment batch).
        run: PathBuf,
        /// Port to serve on (default: any free port).
        #[arg(long, default_value_t = 0)]
        port: u16,
        /// Address to listen on (default 127.0.0.1: this machine only).
        #[arg(long, default_value = "127.0.0.1")]
        bind: IpAddr,
        /// Serve nothing: write an animated GIF of the run to this file and exit.
        #[arg(long, value_name = "FILE")]
        gif: Option<PathBuf>,
        /// Frames of the GIF, spread evenly over the run.
        #[arg(long, value_name = "N", requires = "gif", default_value_t = swarm_viewer::animation::DEFAULT_FRAMES)]
        gif_frames: u32,
        /// Width of the GIF in pixels (its height follows the arena).
        #[arg(long, value_name = "PX", requires = "gif", default_value_t = swarm_viewer::animation::DEFAULT_WIDTH_PX)]
        gif_width: u32,
    },
    /// Drive a live run from another terminal: list its robots, kill, freeze or thaw one.
    Ctl {
        /// The run directory of the live run (its `--out`), or its control socket.
        run: PathBuf,
        #[command(subcommand)]
        request: CtlRequestArg,
    },
    /// Benchmark: the whole system at ARGoS' obstacle-avoidance density (one process per robot), the bare
    /// lockstep transport, and a real-time check; prints Markdown tables and writes <out>/bench.json.
    Bench(BenchArgs),
    /// Run this machine's share of multi-host runs: announce this host, start the robots the world assigns it,
    /// and bridge their frames and commands over zenoh.
    Host(HostCli),
    /// Create the keys of hosts that have none yet (one private file per host; give each to its host for
    /// `swarm host --key`). `swarm run --hosts` creates missing keys itself.
    HostKey {
        /// Host names.
        #[arg(required = true)]
        names: Vec<String>,
        /// Key folder (default: ~/.config/swarm/keys).
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
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
        /// Run only share I of N of the grid's runs (e.g. 2/4), into <out>/shard-I-of-N unless --out is given;
        /// combine the shards' folders afterwards with --merge.
        #[arg(long, value_name = "I/N")]
        shard: Option<Shard>,
        /// Run nothing: write one results.csv, figures and report.md (into --out, default the grid's out) from
        /// the finished runs of these shard folders (repeatable).
        #[arg(long, value_name = "DIR", conflicts_with_all = ["shard", "jobs"])]
        merge: Vec<PathBuf>,
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
    /// Make a `swarm host` daemon of a multi-host run die, as if its machine failed: its robots are dead from
    /// the tick the world notices.
    KillHost {
        /// Host name.
        host: String,
    },
    /// Bring a robot that is not in the run (declared with `spare="true"`, or one that left) into the arena at
    /// the next tick: where the configuration put it, or at X Y, at the nearest free place if that is taken.
    Spawn {
        /// Robot index.
        robot: u32,
        /// Position in metres (with Y).
        #[arg(requires = "y", allow_negative_numbers = true)]
        x: Option<f32>,
        /// Position in metres.
        #[arg(allow_negative_numbers = true)]
        y: Option<f32>,
        /// Heading in degrees, counter-clockwise from +X (default: the configured one).
        #[arg(requires = "y", allow_negative_numbers = true)]
        heading: Option<f32>,
    },
    /// Take a robot out of the run at the next tick: its agent stops (no restart) and its body leaves the arena.
    Remove {
        /// Robot index.
        robot: u32,
    },
}

/// Flags of `swarm bench`.
#[derive(Debug, clap::Args)]
struct BenchArgs {
    /// Robot counts, comma-separated (each needs <configs>/density_N<N>.argos).
    #[arg(long, value_delimiter = ',', default_values_t = [10, 100, 1000])]
    sizes: Vec<u32>,
    /// Folder of the density configurations.
    #[arg(long, default_value = "configs/obstacle_avoidance")]
    configs: PathBuf,
    /// Ticks per whole-system run (default 200,000 / N, clamped to 200..2,000).
    #[arg(long)]
    ticks: Option<u64>,
    /// Whole-system runs per size; figures are medians.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
    /// Folder for run directories and bench.json.
    #[arg(long, default_value = "runs/bench")]
    out: PathBuf,
    /// Skip the whole-system runs.
    #[arg(long)]
    no_system: bool,
    /// Skip the bare lockstep.
    #[arg(long)]
    no_bare: bool,
    /// Also run a real-time check with this many robots (needs density_N<N>.argos; N = 2000 ships at 10 ticks/s).
    #[arg(long)]
    real_time_robots: Option<u32>,
    /// Ticks of the real-time check.
    #[arg(long, default_value_t = swarm_cli::bench::DEFAULT_REAL_TIME_TICKS)]
    real_time_ticks: u64,
    /// Also run ARGoS headless on the same experiment per size, alternating with ours, and compare whole-run wall
    /// times: an ARGoS install prefix (holding bin/argos3 and lib/argos3).
    #[arg(long, value_name = "PREFIX", conflicts_with = "no_system")]
    argos: Option<PathBuf>,
    /// The argos3-examples work tree with its build/ (the e-puck obstacle-avoidance controller); ARGoS runs from
    /// there [default: <PREFIX>/../argos3-examples].
    #[arg(long, value_name = "DIR", requires = "argos")]
    argos_examples: Option<PathBuf>,
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
    /// For a tls/... endpoint: the PEM certificate authority the world's certificate must be signed by.
    #[arg(long = "tls-root-ca")]
    tls_root_ca: Option<PathBuf>,
    /// For mutual TLS: this host's PEM certificate (with --tls-private-key).
    #[arg(long = "tls-certificate", requires = "tls_private_key")]
    tls_certificate: Option<PathBuf>,
    /// For mutual TLS: this host's PEM private key (with --tls-certificate).
    #[arg(long = "tls-private-key", requires = "tls_certificate")]
    tls_private_key: Option<PathBuf>,
    /// Folder for the agents' logs (default: <temp>/swarm-host-<name>).
    #[arg(long)]
    logs: Option<PathBuf>,
    /// This host's key, from the world's machine (default: ~/.config/swarm/keys/<name>.key).
    #[arg(long, value_name = "FILE")]
    key: Option<PathBuf>,
    /// Run without a key: accept orders from anyone who can reach this host's zenoh link. Only for a network
    /// you trust, with a world run with --insecure-hosts.
    #[arg(long, conflicts_with = "key")]
    insecure: bool,
}

/// Exit status of a run stopped by Ctrl-C (or SIGTERM) with its records complete, as shells report SIGINT.
const INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    // SAFETY: the process has one thread here.
    if let Err(e) = unsafe { swarm_remote::session::configure_zenoh_runtime() } {
        eprintln!("error: {e}");
        return ExitCode::FAILURE;
    }
    swarm_contract::logging::init("info");
    match run(Cli::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!(
                "error: {}",
                swarm_contract::logging::error_chain(e.as_ref())
            );
            ExitCode::FAILURE
        }
    }
}

fn bench(args: BenchArgs) -> anyhow::Result<()> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    let argos = args
        .argos
        .as_deref()
        .map(|prefix| {
            swarm_cli::bench::argos::ArgosInstall::locate(prefix, args.argos_examples.as_deref())
        })
        .transpose()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let options = BenchOptions {
        configs_dir: args.configs,
        sizes: args.sizes,
        ticks: args.ticks,
        repeat: args.repeat,
        out: args.out.clone(),
        system: !args.no_system,
        bare: !args.no_bare,
        real_time_robots: args.real_time_robots,
        real_time_ticks: args.real_time_ticks,
        argos,
    };
    let progress = indicatif::ProgressBar::new_spinner();
    progress.enable_steady_tick(Duration::from_millis(200));
    progress.set_message("measuring");
    let report = swarm_cli::bench::run(&options, &stop, |partial| {
        progress.set_message(format!(
            "measured {} whole-system, {} bare, {} real-time",
            partial.system.len(),
            partial.bare.len(),
            usize::from(partial.real_time.is_some())
        ));
    })?;
    progress.finish_and_clear();
    print!("{}", swarm_cli::bench::markdown(&report));
    println!("written: {}", args.out.join("bench.json").display());
    Ok(())
}

/// Runs a subcommand; its exit status is 0, or 130 for a run stopped by Ctrl-C.
fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    let done = |result: anyhow::Result<()>| result.map(|()| ExitCode::SUCCESS);
    match cli.command {
        Commands::Bench(args) => done(bench(args)),
        Commands::Experiment {
            grid,
            out,
            jobs,
            no_progress,
            shard,
            merge,
        } => done(run_experiment(ExperimentOptions {
            grid,
            out,
            jobs,
            progress: !no_progress,
            shard,
            merge,
        })),
        Commands::Run {
            config,
            robots,
            ticks,
            seed,
            out,
            overwrite,
            tick_deadline_ms,
            join_timeout_ms,
            mut limits,
            no_progress,
            real_time,
            faults,
            hosts,
            view,
            view_port,
            view_bind,
            records,
        } => {
            let stop = Arc::new(AtomicBool::new(false));
            let interrupts = interrupt_channel(&stop)?;
            let options = RunOptions {
                config: config.clone(),
                robots,
                ticks,
                seed,
                out,
                overwrite,
                progress: !no_progress,
                limits: {
                    let shorthands = [
                        ("tick_deadline_ms", tick_deadline_ms),
                        ("join_timeout_ms", join_timeout_ms),
                    ];
                    for (name, value) in shorthands {
                        if let Some(value) = value {
                            limits.push(format!("{name}={value}"));
                        }
                    }
                    limits
                },
                real_time,
                faults,
                hosts,
                view: view.then_some(SocketAddr::new(view_bind, view_port)),
                records,
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
            if report.interrupted {
                return Ok(ExitCode::from(INTERRUPTED));
            }
            if view {
                println!("the run is over; its viewer stays up until Ctrl-C");
                // Either a Ctrl-C or the handler's end: both mean stop serving.
                let _ = interrupts.recv();
            }
            Ok(ExitCode::SUCCESS)
        }
        Commands::Export { run, format } => {
            let report = swarm_records::export(&run, format)
                .with_context(|| format!("exporting {} as {format}", run.display()))?;
            for file in &report.files {
                println!("{file}");
            }
            Ok(ExitCode::SUCCESS)
        }
        Commands::View {
            gif: Some(gif),
            run,
            gif_frames,
            gif_width,
            ..
        } => {
            let options = swarm_viewer::animation::GifOptions {
                frames: gif_frames,
                width_px: gif_width,
                ..Default::default()
            };
            let report = swarm_viewer::animation::write_gif(&run, &gif, &options)
                .with_context(|| format!("drawing {} as a GIF", run.display()))?;
            println!("{report}");
            Ok(ExitCode::SUCCESS)
        }
        Commands::View {
            run, port, bind, ..
        } => {
            let stop = Arc::new(AtomicBool::new(false));
            let interrupts = interrupt_channel(&stop)?;
            let viewer = swarm_viewer::Viewer::start(&run, false, bind, port)
                .with_context(|| format!("viewing {}", run.display()))?;
            println!(
                "viewer of {}: {} (Ctrl-C stops it)",
                run.display(),
                viewer.url()
            );
            let _ = interrupts.recv();
            Ok(ExitCode::from(INTERRUPTED))
        }
        Commands::Ctl { run, request } => done(ctl(&run, request)),
        Commands::Host(cli) => done(run_host(cli)),
        Commands::HostKey { names, dir } => done(host_key(&names, dir)),
    }
}

/// Installs the Ctrl-C (and SIGTERM) handler: it sets `stop` and sends on the returned channel.
fn interrupt_channel(stop: &Arc<AtomicBool>) -> anyhow::Result<mpsc::Receiver<()>> {
    let flag = Arc::clone(stop);
    let (sender, receiver) = mpsc::sync_channel(1);
    ctrlc::set_handler(move || {
        flag.store(true, Ordering::Relaxed);
        let _ = sender.try_send(());
    })
    .context("installing the Ctrl-C handler")?;
    Ok(receiver)
}

/// `swarm ctl`: one request to a live run, its answer on standard output.
fn ctl(run: &std::path::Path, request: CtlRequestArg) -> anyhow::Result<()> {
    let command = match request {
        CtlRequestArg::List => CtlCommand::List,
        CtlRequestArg::Kill { robot } => CtlCommand::Kill(robot),
        CtlRequestArg::Freeze { robot } => CtlCommand::Freeze(robot),
        CtlRequestArg::Thaw { robot } => CtlCommand::Thaw(robot),
        CtlRequestArg::KillHost { host } => CtlCommand::KillHost(host),
        CtlRequestArg::Spawn {
            robot,
            x,
            y,
            heading,
        } => CtlCommand::Spawn {
            robot,
            pose: x.zip(y).map(|(x, y)| SpawnPose {
                x,
                y,
                heading_deg: heading,
            }),
        },
        CtlRequestArg::Remove { robot } => CtlCommand::Remove(robot),
    };
    let shown = command.to_string();
    let answer = control::request(run, command)
        .with_context(|| format!("swarm ctl {} {shown}", run.display()))?;
    print!("{answer}");
    Ok(())
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
    let seal = if cli.insecure {
        tracing::warn!(
            "running without a key: anyone who can reach this host's link can command its robots"
        );
        Seal::Off
    } else {
        let path = cli
            .key
            .or_else(|| default_key_dir().map(|dir| key_path(&dir, &name)))
            .context("no key file: pass --key FILE (or set HOME)")?;
        let key = HostKey::read(&path).with_context(|| {
            format!(
                "host '{name}' needs its key from the world's machine (`swarm run --hosts` creates it there, as \
                 does `swarm host-key {name}`)"
            )
        })?;
        Seal::Key(Arc::new(key))
    };
    // Without the operator's own zenoh credentials, the host is admitted with its name and its key's password.
    let (user, password) = match (cli.user, password, &seal) {
        (Some(user), password, _) => (Some(user), password),
        (None, _, Seal::Key(key)) => (
            Some(name.clone()),
            Some(key.admission_password().to_owned()),
        ),
        (None, _, Seal::Off) => (None, None),
    };
    let tls = TlsFiles {
        root_ca: cli.tls_root_ca,
        certificate: cli.tls_certificate,
        private_key: cli.tls_private_key,
    };
    tls.check_readable()?;
    let logs = cli
        .logs
        .unwrap_or_else(|| std::env::temp_dir().join(format!("swarm-host-{name}")));
    let options = HostOptions {
        connect: cli.connect,
        capacity: cli.capacity,
        zenoh: ZenohOptions {
            config_file: cli.zenoh_config,
            lease: Duration::from_millis(cli.lease_ms),
            user,
            password,
            credentials_file: None,
            admitted: Vec::new(),
            tls,
        },
        max_payload: DEFAULT_MAX_PAYLOAD,
        logs,
        name,
        seal,
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("installing the Ctrl-C handler")?;
    host::serve(&options, &stop).with_context(|| format!("host '{}'", options.name))
}

/// `swarm host-key`: creates the missing keys and says where each host's key is.
fn host_key(names: &[String], dir: Option<PathBuf>) -> anyhow::Result<()> {
    for name in names {
        swarm_contract::config::hosts::check_host_name(name)?;
    }
    let dir = dir
        .or_else(default_key_dir)
        .context("no key folder: pass --dir DIR (or set HOME)")?;
    let created = create_missing_keys(&dir, names.iter().map(String::as_str))?;
    for name in names {
        let path = key_path(&dir, name);
        let state = if created.contains(&path) {
            "created"
        } else {
            "exists"
        };
        println!("{name}\t{}\t{state}", path.display());
    }
    Ok(())
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
