//! Starting robot agents and keeping track of each robot's agent: its process, its state and its restarts.

use std::collections::HashMap;
use std::fs::OpenOptions;
use std::path::PathBuf;
use std::process::Child;
use std::time::Instant;

use super::restart::{Ending, RestartTracker};
use super::{LaunchError, io};
use swarm_contract::config::Arrival;
use swarm_contract::protocol::launcher_to_agent::{AgentArgs, RunArgs, start_agent};
use swarm_contract::run_dir;

/// Where a robot's agent stands, as the launcher sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AgentState {
    /// Its process runs (it may still be joining).
    Running,
    /// Stopped with SIGSTOP.
    Frozen,
    /// Dead, a replacement is coming.
    Restarting,
    /// Dead for good.
    Dead,
    /// Not in the run: it joins later, or it left (docs/joins.md).
    Absent,
}

impl AgentState {
    /// The word `swarm ctl list` shows.
    pub fn name(self) -> &'static str {
        match self {
            AgentState::Running => "running",
            AgentState::Frozen => "frozen",
            AgentState::Restarting => "restarting",
            AgentState::Dead => "dead",
            AgentState::Absent => "absent",
        }
    }
}

/// One robot as the launcher tracks it.
#[derive(Debug)]
pub struct RobotEntry {
    /// Its controller id.
    pub controller: String,
    /// Its restart policy and history.
    pub tracker: RestartTracker,
    /// Its agent's state.
    pub state: AgentState,
    /// Process id of its current (or last) agent.
    pub pid: u32,
    /// Process id of its first agent.
    pub first_pid: u32,
    /// Its agent was killed through `swarm ctl`.
    pub ctl_killed: bool,
    /// Index in the fault log of the fault still waiting for the world's detection or rejoin tick.
    pub open_fault: Option<usize>,
    /// When the launcher killed its agent outside the schedule, or first saw it gone (for latencies).
    pub gone_at: Option<Instant>,
    /// How its last agent ended, for the restart policy (a failure unless it exited 0 before the run ended).
    pub ending: Ending,
}

impl RobotEntry {
    /// A robot whose agent is not started yet; one that joins later is absent until then.
    pub fn new(arrival: Arrival, controller: String, tracker: RestartTracker) -> RobotEntry {
        RobotEntry {
            controller,
            tracker,
            state: match arrival {
                Arrival::Start => AgentState::Running,
                Arrival::At(_) | Arrival::Spare => AgentState::Absent,
            },
            pid: 0,
            first_pid: 0,
            ctl_killed: false,
            open_fault: None,
            gone_at: None,
            ending: Ending::Failure,
        }
    }

    /// Whether the robot takes part in the run.
    pub fn is_alive(&self) -> bool {
        self.state == AgentState::Running
    }
}

/// Everything needed to start a robot's agent.
#[derive(Debug, Clone)]
pub struct AgentSpawner {
    /// The agent program.
    pub program: PathBuf,
    /// The run's shared memory.
    pub run: RunArgs,
    /// Absolute configuration path.
    pub config: PathBuf,
    /// Run seed.
    pub seed: u64,
    /// `swarm run --robots`, if given.
    pub robots: Option<u32>,
    /// The run directory (agent logs go to `logs/`).
    pub out_dir: PathBuf,
    /// Each supervised controller's supervisor set, compiled once for the run, by controller id.
    pub compiled: HashMap<String, PathBuf>,
    /// The run's `--limit` overrides, passed on to every agent.
    pub limits: Vec<String>,
}

impl AgentSpawner {
    /// Starts robot `robot`'s agent running `controller`; a restarted agent gets its resume point and appends
    /// to the robot's log.
    pub fn spawn(
        &self,
        robot: u32,
        controller: &str,
        resume: Option<PathBuf>,
    ) -> Result<Child, LaunchError> {
        let mut args = AgentArgs::launched(&self.run, robot, &self.config, controller, self.seed);
        args.robots = self.robots;
        args.compiled_supervisors = self.compiled.get(controller).cloned();
        args.resume = resume;
        args.limits = self.limits.clone();
        let log_path = run_dir::agent_log(&self.out_dir, robot);
        let log = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&log_path)
            .map_err(io(format!("opening {}", log_path.display())))?;
        start_agent(&self.program, &args, log)
            .map_err(io(format!("starting {}", self.program.display())))
    }
}
