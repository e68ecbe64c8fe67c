//! The launcher behind `swarm run`: validates an experiment, starts the world process and one robot-agent
//! process per robot, supervises them, and leaves a complete run directory and no shared-memory files behind.
//!
//! It never simulates or controls anything itself: the world and the agents are separate programs (found by
//! `swarm_contract::process::binaries`) that speak the protocol of `swarm_contract::protocol` with it.
//!
//! Order of a run: load and validate the configuration (all errors at once, located) -> resolve seed, ticks and
//! robots -> create the run directory -> start the world (it creates every shared-memory service with limits
//! for N robots and says `ready`) -> start the agents -> follow the world's tick reports on a progress bar; an agent
//! that dies is reported to the world at once on its standard input (`dead <robot>`) -> when the world says
//! `finished`, collect the agents, complete `summary.json`, remove the run's shared memory. [`run`] does these
//! steps in order; `supervision.rs` is the loop while the run goes, `summary.rs` the launcher's part of
//! `summary.json`, `error.rs` why a run fails.
//!
//! Faults (docs/faults.md): the world paces the schedule and reports each due fault between two ticks; the
//! launcher applies it to the processes (`fault_handling.rs`), restarts agents by their [`restart`] policy, and
//! takes `swarm ctl` requests on the run's [`control`] socket. If the world dies, the launcher stops every agent,
//! cuts the records back to the last complete tick ([`records`]), writes the summary and fails with the reason.

mod agents;
mod arrivals;
pub mod as_run;
pub mod control;
mod error;
mod fault_handling;
pub mod fault_log;
mod plain_progress;
pub mod records;
pub mod restart;
mod summary;
mod supervision;

use std::collections::HashMap;
use std::io::{BufRead, BufReader, IsTerminal};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{ChildStdin, Command, ExitStatus, Stdio};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use indicatif::{ProgressBar, ProgressStyle};

use agents::{AgentSpawner, HeldAgents, RobotEntry, present_robots};
use control::{ControlServer, CtlRequest};
pub use error::LaunchError;
use error::io;
use fault_log::FaultRecord;
use plain_progress::PlainProgress;
use restart::RestartTracker;
use summary::{Provenance, complete_summary};
use swarm_contract::config::Experiment;
use swarm_contract::config::faults::{FaultKind, FaultSchedule};
use swarm_contract::disk_budget::DiskBudget;
use swarm_contract::fault_plan::FaultPlan;
use swarm_contract::process::binaries::Binaries;
use swarm_contract::process::children::{self, Children};
use swarm_contract::protocol::launcher_to_agent::{AgentArgs, RunArgs};
use swarm_contract::protocol::launcher_to_world::{Records, WorldArgs};
use swarm_contract::protocol::world_to_launcher::WorldReport;
use swarm_contract::run_dir::{self, COMPILED_SUPERVISORS_DIR, EVENT_TABLES_FILE};
use swarm_contract::transport::RunSpec;
use swarm_remote::plan::{Authentication, HostsArgs, HostsError, HostsPlan};

/// How often the supervision loop looks at its children when the world is quiet.
const SUPERVISION_PERIOD: Duration = Duration::from_millis(20);
/// How often the launcher looks for agents that exited once the run has ended: they exit within milliseconds of
/// the world's end, and the run is not over before the last of them.
const EXIT_POLL_PERIOD: Duration = Duration::from_millis(1);
/// Lines of an agent's log quoted when it fails to start.
const LOG_LINES_QUOTED: usize = 8;

/// What `swarm run` was asked to do.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// The experiment configuration.
    pub config: PathBuf,
    /// Number of robots, overriding the configuration's e-puck `<distribute>` quantity.
    pub robots: Option<u32>,
    /// Ticks to run, overriding the configuration's `length`.
    pub ticks: Option<u64>,
    /// Run seed, overriding the configuration's `random_seed`.
    pub seed: Option<u64>,
    /// Run directory (default `runs/<config name>-<YYYYMMDD-HHMMSS>-<4 hex digits>`, new for every run).
    pub out: Option<PathBuf>,
    /// Empty `out` first if it holds an earlier run's files (otherwise such a folder is refused).
    pub overwrite: bool,
    /// Show a progress bar on the terminal.
    pub progress: bool,
    /// Limits overriding the configuration's, as `NAME=VALUE` (`swarm run --limit`; see
    /// [`Limits`](swarm_contract::limits::Limits)).
    pub limits: Vec<String>,
    /// Pace the ticks at the configuration's ticks_per_second (real-time mode) instead of running flat out.
    pub real_time: bool,
    /// Faults added to the configuration's `<faults>` (`swarm run --fault`, e.g. `kill robots=3 tick=50`).
    pub faults: Vec<String>,
    /// Hosts to run the robots on instead of locally (see [`swarm_remote::plan`]).
    pub hosts: HostsArgs,
    /// Serve the live viewer of the run at this address (`swarm run --view`); its URL is printed as soon as
    /// the run directory exists.
    pub view: Option<SocketAddr>,
    /// What the run leaves of its record tables (`swarm run --records`): Parquet files (the default), the CSV
    /// files the world appends to, or nothing.
    pub records: Records,
}

/// What a finished run reports.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// The run directory.
    pub out_dir: PathBuf,
    /// The seed used.
    pub seed: u64,
    /// Number of robots.
    pub robots: u32,
    /// Ticks completed.
    pub ticks: u64,
    /// Wall time from the start of the world to the end of the run, in seconds.
    pub wall_seconds: f64,
    /// Wall time from the start of the world to the first completed tick, in seconds.
    pub time_to_first_tick_seconds: f64,
    /// Whether the run was stopped early by Ctrl-C.
    pub interrupted: bool,
    /// Robots whose agent died during the run, with the tick the world had completed at the time.
    pub deaths: Vec<Death>,
    /// Process id of the world.
    pub world_pid: u32,
    /// Process id of each robot's (first) agent, by robot index.
    pub agent_pids: Vec<u32>,
    /// Every fault of the run, in the order the launcher learnt of them.
    pub faults: Vec<FaultRecord>,
    /// Robots taking part when the run ended.
    pub alive_final: u32,
}

/// An agent that died while the run went on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Death {
    /// Robot index.
    pub robot: u32,
    /// Last tick the world had completed when the launcher saw the death.
    pub after_tick: u64,
    /// How the process ended.
    pub status: String,
}

/// Removes every shared-memory file of a run when dropped, whatever happened before.
struct SharedMemoryGuard(RunSpec);

impl Drop for SharedMemoryGuard {
    fn drop(&mut self) {
        if let Err(e) = self.0.cleanup() {
            tracing::warn!("removing the run's shared memory: {e}");
        }
    }
}

/// Runs one experiment to its end; `stop` set (e.g. by Ctrl-C) ends it early and cleanly.
pub fn run(options: &RunOptions, stop: Arc<AtomicBool>) -> Result<RunReport, LaunchError> {
    let (experiment, warnings) = Experiment::load(&options.config)?;
    for warning in &warnings {
        tracing::warn!("{warning}");
    }
    let experiment = match options.robots {
        Some(n) => experiment.with_robot_count(n)?,
        None => experiment,
    };
    let mut limits = experiment.framework.limits;
    limits.apply(&options.limits)?;
    // Every process of the run besides the world: the robots, then the coordinators.
    let roster = experiment.participants();
    let bodies = roster.iter().filter(|p| p.robot.is_some()).count();
    if bodies == 0 {
        return Err(LaunchError::NoRobots {
            path: options.config.clone(),
            at: experiment.arena.location,
        });
    }
    let robots = roster.len() as u32;
    let seed = options
        .seed
        .or(experiment.framework.random_seed)
        .unwrap_or_else(clock_seed);
    if options.seed.is_none() && experiment.framework.random_seed.is_none() {
        tracing::warn!(
            seed,
            "no random_seed in the configuration: using one from the clock"
        );
    }
    let ticks = options
        .ticks
        .or(experiment.framework.max_ticks())
        .unwrap_or(0);
    if ticks == 0 {
        tracing::warn!(
            "the run has no length (the experiment's length is 0 and no --ticks was given): it runs until \
             Ctrl-C or until its loop functions end the experiment"
        );
    }
    let plan = HostsPlan::resolve(experiment.framework.hosts.as_ref(), &options.hosts)?;
    if let Some(plan) = &plan {
        announce_host_keys(plan)?;
    }
    let placement = plan.map(|plan| plan.place(robots));
    let started_at = SystemTime::now();
    // Held (locked) until the run is over.
    let run_folder = run_dir::create(options.out.as_deref(), options.overwrite, &options.config)?;
    let out_dir = run_folder.path.clone();
    if let Some(reason) =
        DiskBudget::new(&out_dir, limits.disk_reserve_mb, limits.records_max_mb).check()
    {
        return Err(LaunchError::NoRoom(reason));
    }
    if let Some(address) = options.view {
        let viewer = swarm_viewer::Viewer::start(&out_dir, true, address.ip(), address.port())?;
        println!("viewer: {}", viewer.url());
    }
    let binaries = Binaries::locate()?;
    RunSpec::remove_dead_runs();
    let spec = RunSpec::unique();
    let _shared_memory = SharedMemoryGuard(spec.clone());
    let run_args = RunArgs {
        run: spec.name().to_owned(),
        iox_root: spec.root_dir().to_path_buf(),
    };
    let config = std::path::absolute(&options.config).map_err(io("resolving the config path"))?;
    let provenance = Provenance {
        command_line: std::env::args().collect(),
        started_at,
        config: config.clone(),
    };
    let schedule = FaultSchedule::for_run(&experiment, &options.faults, robots)?;
    let ticks_per_second = experiment.framework.ticks_per_second;
    write_configuration_as_run(options, &experiment, &config, seed, &out_dir)?;
    let mut startup = Vec::new();
    // Random picks choose among robots, never coordinators.
    FaultPlan::new(&schedule, ticks_per_second, seed).due(0, &vec![true; bodies], &mut startup);
    tracing::info!(robots, seed, ticks, out = %out_dir.display(), run = spec.name(), "starting");

    let compiled = check_controllers(
        &binaries,
        &run_args,
        &config,
        seed,
        options.robots,
        &roster,
        &out_dir,
    )?;

    let spawner = AgentSpawner {
        program: binaries.agent.clone(),
        run: run_args.clone(),
        config: config.clone(),
        seed,
        robots: options.robots,
        out_dir: out_dir.clone(),
        compiled,
        limits: options.limits.clone(),
    };
    let robot_entries: Vec<RobotEntry> = roster
        .iter()
        .map(|r| {
            RobotEntry::new(
                r.arrival,
                r.controller.to_owned(),
                RestartTracker::new(schedule.restart_rule(r.index, r.controller).cloned()),
            )
        })
        .collect();

    let started = Instant::now();
    let mut children = Children::default();
    let world_args = WorldArgs {
        run: run_args.clone(),
        config: config.clone(),
        seed,
        ticks,
        robots: options.robots,
        out: out_dir.clone(),
        limits: options.limits.clone(),
        real_time: options.real_time,
        faults: options.faults.clone(),
        records: options.records,
    };
    let mut world = children::spawn(
        Command::new(&binaries.world)
            .args(world_args.to_args())
            .args(options.hosts.to_args())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped()),
    )
    .map_err(io(format!("starting {}", binaries.world.display())))?;
    let world_pid = world.id();
    let world_stdin = world.stdin.take();
    let reports = follow_reports(world.stdout.take());
    children.world = Some(world);
    // The agents are forked while the world creates the run's shared memory, and let in once it is ready.
    // With hosts, each host daemon starts its own robots' agents; the world waits for them.
    // Robots the schedule kills at start-up are started on their own and killed before they can join.
    let killed_at_start: Vec<u32> = startup
        .iter()
        .filter(|action| action.kind == FaultKind::Kill)
        .filter_map(|action| action.robot)
        .collect();
    let mut held = if placement.is_none() {
        let mut present = present_robots(&robot_entries);
        present.retain(|(robot, _)| !killed_at_start.contains(robot));
        spawner.fork_held(&present)
    } else {
        HeldAgents::default()
    };
    children.agents = (0..robots).map(|_| None).collect();
    for (robot, agent) in held.agents.drain(..) {
        children.agents[robot as usize] = Some(agent);
    }

    wait_ready(
        &mut children,
        &reports,
        robots,
        limits.world_ready_timeout(),
    )?;
    held.release();
    if let Some(placement) = &placement {
        for share in placement {
            tracing::info!(host = share.name, robots = share.robots.len(), "placed");
        }
    }
    let control = match ControlServer::listen(&out_dir, limits.ctl_reply_timeout()) {
        Ok(server) => Some(server),
        Err(e) => {
            tracing::warn!(
                "no `swarm ctl` for this run: cannot listen in {}: {e}",
                out_dir.display()
            );
            None
        }
    };
    let progress = progress_bar(options.progress, ticks, robots);
    let mut supervision = Supervision {
        children,
        world_stdin,
        roster_ids: roster.iter().map(|r| r.id.clone()).collect(),
        out_dir: out_dir.clone(),
        progress,
        started,
        run: spec.clone(),
        first_tick: None,
        last_tick: 0,
        deaths: Vec::new(),
        interrupted: false,
        robots: robot_entries,
        spawner,
        ticks_per_second,
        faults: Vec::new(),
        pending_restarts: Vec::new(),
        reaped: Vec::new(),
        agent_exit_grace: limits.agent_exit_grace(),
        plain_progress: (options.progress && !std::io::stderr().is_terminal())
            .then(|| PlainProgress::new(ticks, robots)),
        host_names: placement
            .iter()
            .flatten()
            .map(|share| share.name.clone())
            .collect(),
        control,
        pending_arrivals: Vec::new(),
    };
    if placement.is_none() {
        supervision.start_agents(&startup)?;
    }
    // Robots on hosts (and robots killed before they started) have no local process.
    let agent_pids: Vec<u32> = supervision
        .robots
        .iter()
        .map(|r| r.first_pid)
        .filter(|&pid| pid != 0)
        .collect();
    let followed = supervision.follow(&reports, &stop);
    if let Err(error) = followed {
        supervision.children.kill_all();
        supervision.progress.finish_and_clear();
        let complete = records::trim_to_complete_ticks(&out_dir, bodies as u32)
            .map_err(io("cutting the records back to the last complete tick"))?;
        if matches!(error, LaunchError::WorldDied { .. }) {
            let report = supervision.report(
                seed,
                bodies as u32,
                world_pid,
                agent_pids,
                complete.unwrap_or(0),
            );
            complete_summary(&out_dir, &report, &provenance, Some(&error.to_string()))?;
        }
        records::finish(&out_dir, options.records);
        return Err(error);
    }
    supervision.collect_agents();
    supervision.progress.finish_and_clear();
    let report = supervision.report(
        seed,
        bodies as u32,
        world_pid,
        agent_pids,
        supervision.last_tick,
    );
    let stopped_early = complete_summary(&out_dir, &report, &provenance, None)?;
    records::finish(&out_dir, options.records);
    if let Some(reason) = stopped_early {
        return Err(LaunchError::StoppedEarly {
            ticks: report.ticks,
            reason,
            out_dir,
        });
    }
    Ok(report)
}

/// Builds every controller of the run once, before any process of the run starts (`robot-agent --check` for the
/// first robot of each controller), so a missing callback or a bad supervisor file fails the run at once with the
/// agent's reason; records each controller's event names in [`EVENT_TABLES_FILE`]. The check also compiles each
/// supervised controller's models once, into `supervisors/<controller>.ptsct` of the run directory; returns those
/// files by controller id, for the agents to load instead of synthesising the models again.
fn check_controllers(
    binaries: &Binaries,
    run_args: &RunArgs,
    config: &Path,
    seed: u64,
    robots: Option<u32>,
    roster: &[swarm_contract::config::Participant<'_>],
    out_dir: &Path,
) -> Result<HashMap<String, PathBuf>, LaunchError> {
    let compiled_dir = out_dir.join(COMPILED_SUPERVISORS_DIR);
    std::fs::create_dir_all(&compiled_dir)
        .map_err(io(format!("creating {}", compiled_dir.display())))?;
    let mut compiled = HashMap::new();
    let mut tables = serde_json::Map::new();
    for robot in roster {
        let controller = robot.controller;
        if tables.contains_key(controller) {
            continue;
        }
        let mut args = AgentArgs::launched(run_args, robot.index, config, controller, seed);
        args.robots = robots;
        let compiled_file = run_dir::compiled_supervisors(out_dir, controller)
            .map_err(io("naming the compiled supervisors"))?;
        let output = Command::new(&binaries.agent)
            .args(args.to_args())
            .arg("--check")
            .arg("--write-supervisors")
            .arg(&compiled_file)
            .stdin(Stdio::null())
            .output()
            .map_err(io(format!("starting {}", binaries.agent.display())))?;
        if !output.status.success() {
            let stderr = String::from_utf8_lossy(&output.stderr);
            let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
            return Err(LaunchError::AgentFailed {
                robot: robot.index,
                id: robot.id.clone(),
                status: output.status.to_string(),
                log: lines[lines.len().saturating_sub(LOG_LINES_QUOTED)..].join("\n"),
            });
        }
        // The check's warnings (e.g. a parameter no callback reads) would otherwise be seen by nobody.
        for warning in String::from_utf8_lossy(&output.stderr)
            .lines()
            .filter_map(|line| line.split_once(" WARN "))
            .map(|(_, rest)| rest.split_once(": ").map_or(rest, |(_, message)| message))
        {
            tracing::warn!("{warning}");
        }
        let names: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap_or_default();
        tables.insert(controller.to_owned(), names);
        // Native controllers have no supervisors: no file, and their agents get no flag.
        if compiled_file.is_file() {
            compiled.insert(controller.to_owned(), compiled_file);
        }
    }
    let path = out_dir.join(EVENT_TABLES_FILE);
    let text = serde_json::to_string_pretty(&serde_json::Value::Object(tables)).unwrap_or_default();
    run_dir::write_atomically(&path, text.as_bytes())
        .map_err(io(format!("writing {}", path.display())))?;
    Ok(compiled)
}

/// Replaces the run folder's copy of the configuration with the configuration as this run used it (see
/// [`as_run`]), so that it reruns the same experiment from anywhere.
fn write_configuration_as_run(
    options: &RunOptions,
    experiment: &Experiment,
    config: &Path,
    seed: u64,
    out_dir: &Path,
) -> Result<(), LaunchError> {
    let text = swarm_contract::config::input::read_text(
        config,
        swarm_contract::config::input::MAX_CONFIG_BYTES,
    )
    .map_err(|e| LaunchError::AsRun(e.to_string()))?;
    let epuck_quantity = options.robots.and_then(|_| {
        experiment
            .arena
            .distributions
            .iter()
            .find(|d| matches!(d.template, swarm_contract::config::Entity::Robot(_)))
            .map(|d| d.quantity)
    });
    let overrides = as_run::Overrides {
        seed,
        ticks: options
            .ticks
            .map(|ticks| (ticks, experiment.framework.ticks_per_second)),
        epuck_quantity,
        limits: &options.limits,
        faults: &options.faults,
    };
    let rewritten = as_run::configuration_as_run(&text, config, &overrides)
        .map_err(|e| LaunchError::AsRun(e.to_string()))?;
    run_dir::write_atomically(
        &out_dir.join(run_dir::CONFIG_COPY_FILE),
        rewritten.as_bytes(),
    )
    .map_err(io("writing the configuration as run"))
}

/// Creates the keys of the run's hosts that do not exist yet and tells the operator where they are; warns when
/// authentication is off.
fn announce_host_keys(plan: &HostsPlan) -> Result<(), HostsError> {
    if plan.authentication == Authentication::Off {
        tracing::warn!(
            "host authentication is off: anyone who can reach {} can join, listen in and command robots",
            plan.listen.join(", ")
        );
    }
    for path in plan.create_missing_keys()? {
        tracing::warn!(
            "created the host key {}: copy it to that host (readable by its user only) and start it with `swarm \
             host --key <file>`",
            path.display()
        );
    }
    Ok(())
}

/// A seed from the clock, for configurations that ask for one.
fn clock_seed() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(1, |d| d.as_nanos() as u64)
        .max(1)
}

/// Reads the world's reports on a thread so the launcher can wait on them with timeouts.
fn follow_reports(stdout: Option<std::process::ChildStdout>) -> Receiver<WorldReport> {
    let (sender, receiver) = mpsc::channel();
    if let Some(stdout) = stdout {
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if let Some(report) = WorldReport::parse(&line)
                    && sender.send(report).is_err()
                {
                    break;
                }
            }
        });
    }
    receiver
}

/// Waits for the world's `ready`, failing early if it dies.
fn wait_ready(
    children: &mut Children,
    reports: &Receiver<WorldReport>,
    robots: u32,
    timeout: Duration,
) -> Result<(), LaunchError> {
    let deadline = Instant::now() + timeout;
    loop {
        match reports.recv_timeout(SUPERVISION_PERIOD) {
            Ok(WorldReport::Ready { robots: ready }) if ready == robots => return Ok(()),
            Ok(WorldReport::Ready { robots: ready }) => {
                return Err(LaunchError::WorldDied {
                    status: format!("ready for {ready} robots"),
                    when: format!("while the launcher expected {robots}"),
                });
            }
            // A closed channel means the world is exiting; its status below says how.
            Ok(_) | Err(_) => {}
        }
        if let Some(world) = children.world.as_mut()
            && let Ok(Some(status)) = world.try_wait()
        {
            children.world = None;
            return Err(LaunchError::WorldDied {
                status: status.to_string(),
                when: "before it was ready (its error is above)".into(),
            });
        }
        if Instant::now() > deadline {
            return Err(LaunchError::WorldNotReady(timeout));
        }
    }
}

fn progress_bar(visible: bool, ticks: u64, robots: u32) -> ProgressBar {
    if !visible {
        return ProgressBar::hidden();
    }
    let bar = if ticks > 0 {
        ProgressBar::new(ticks)
    } else {
        ProgressBar::new_spinner()
    };
    let template = if ticks > 0 {
        "{elapsed_precise} [{bar:40}] tick {pos}/{len} {per_sec} {msg}"
    } else {
        "{elapsed_precise} {spinner} tick {pos} {per_sec} {msg}"
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(format!("{robots}/{robots} robots alive"));
    bar
}

/// The launcher's view of a running experiment.
struct Supervision {
    children: Children,
    /// The run, to tell an agent that exits with it from one that exits before it.
    run: RunSpec,
    world_stdin: Option<ChildStdin>,
    roster_ids: Vec<String>,
    out_dir: PathBuf,
    progress: ProgressBar,
    started: Instant,
    first_tick: Option<Instant>,
    last_tick: u64,
    deaths: Vec<Death>,
    interrupted: bool,
    /// Per robot: its agent's process, state and restart history.
    robots: Vec<RobotEntry>,
    spawner: AgentSpawner,
    ticks_per_second: u32,
    faults: Vec<FaultRecord>,
    /// Replacement agents to start once their backoff has passed (robot, when).
    pending_restarts: Vec<(u32, Instant)>,
    /// Agents the launcher killed and reaped itself (`swarm ctl kill`), whose exit is still to be handled.
    reaped: Vec<(u32, ExitStatus)>,
    /// The hosts of a multi-host run, in placement order (empty for a local run).
    host_names: Vec<String>,
    control: Option<ControlServer>,
    /// `swarm ctl spawn` and `remove` requests waiting for the world's decision, by robot.
    pending_arrivals: Vec<(u32, CtlRequest)>,
    /// How long agents get to exit by themselves after the run.
    agent_exit_grace: Duration,
    /// Progress as log lines when standard error is not a terminal (the bar is drawn only on one).
    plain_progress: Option<PlainProgress>,
}
