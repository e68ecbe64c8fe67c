//! Starting robot agents and keeping track of each robot's agent: its process, its state and its restarts.

use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::ChildStdin;
use std::time::Instant;

use super::restart::{Ending, RestartTracker};
use super::{LaunchError, io};
use swarm_contract::config::Arrival;
use swarm_contract::process::children::AgentProcess;
use swarm_contract::protocol::launcher_to_agent::{
    AgentArgs, RunArgs, ZygoteArgs, ZygoteOrder, ZygoteReply, start_agent, start_zygote,
};
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

/// The robots that take part from the start (a robot that joins later gets its agent when it joins), with their
/// controllers.
pub fn present_robots(robots: &[RobotEntry]) -> Vec<(u32, &str)> {
    (0..)
        .zip(robots)
        .filter(|(_, entry)| entry.state != AgentState::Absent)
        .map(|(robot, entry)| (robot, entry.controller.as_str()))
        .collect()
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
    ) -> Result<AgentProcess, LaunchError> {
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
            .map(AgentProcess::from)
            .map_err(io(format!("starting {}", self.program.display())))
    }

    /// Has the agent zygote (`robot-agent zygote`) fork the agents of `robots` (robot index and controller): a
    /// fork per robot instead of a program start. They build their controllers at once but join the run only
    /// when [`HeldAgents::release`] says the run's shared memory exists, so this can run while the world is still
    /// creating it. Robots the zygote could not start are left out (with a warning): start them afterwards with
    /// [`AgentSpawner::spawn_missing`].
    pub fn fork_held(&self, robots: &[(u32, &str)]) -> HeldAgents {
        match self.fork_from_zygote(robots) {
            Ok(held) => held,
            Err(reason) => {
                tracing::warn!("starting every agent on its own: {reason}");
                HeldAgents::default()
            }
        }
    }

    /// Starts, one program start each, the agents of `robots` that have none in `agents` (by robot index).
    pub fn spawn_missing(
        &self,
        robots: &[(u32, &str)],
        agents: &mut [Option<AgentProcess>],
    ) -> Result<(), LaunchError> {
        for &(robot, controller) in robots {
            if let Some(slot @ None) = agents.get_mut(robot as usize) {
                *slot = Some(self.spawn(robot, controller, None)?);
            }
        }
        Ok(())
    }

    /// The agents the zygote forked; the robots it reported failed are left out (with a warning). Err when the
    /// zygote itself could not do its work.
    fn fork_from_zygote(&self, robots: &[(u32, &str)]) -> Result<HeldAgents, String> {
        let logs = run_dir::logs_dir(&self.out_dir);
        let log_path = logs.join(ZYGOTE_LOG);
        let log = File::create(&log_path)
            .map_err(|e| format!("cannot create {}: {e}", log_path.display()))?;
        let args = ZygoteArgs {
            run: self.run.clone(),
            seed: self.seed,
            config: self.config.clone(),
            robots: self.robots,
            compiled: self
                .compiled
                .iter()
                .map(|(controller, file)| format!("{controller}={}", file.display()))
                .collect(),
            logs,
            limits: self.limits.clone(),
        };
        let mut zygote = start_zygote(&self.program, &args, log)
            .map_err(|e| format!("cannot start {}: {e}", self.program.display()))?;
        let mut orders: String = robots
            .iter()
            .map(|&(robot, _)| format!("{}\n", ZygoteOrder { robot, slot: robot }))
            .collect();
        orders.push('\n');
        // The zygote reads every order before it forks, so this write cannot wait on its replies. The pipe stays
        // open: its end lets the agents in.
        let mut gate = zygote.stdin.take();
        let written = gate
            .as_mut()
            .map(|stdin| stdin.write_all(orders.as_bytes()));
        let mut agents = Vec::with_capacity(robots.len());
        let mut awaited: HashSet<u32> = robots.iter().map(|&(robot, _)| robot).collect();
        if let Some(stdout) = zygote.stdout.take() {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                match line.parse::<ZygoteReply>() {
                    Ok(ZygoteReply::Started { robot, pid }) if awaited.remove(&robot) => {
                        match AgentProcess::adopt(pid) {
                            Ok(agent) => agents.push((robot, agent)),
                            Err(e) => tracing::warn!(robot, "the zygote's reply: {e}"),
                        }
                    }
                    Ok(ZygoteReply::Started { robot, .. }) => {
                        tracing::warn!(robot, "the zygote started an agent nobody asked for");
                    }
                    Ok(ZygoteReply::Failed { robot, reason }) => {
                        tracing::warn!(robot, "the zygote could not start the agent: {reason}");
                    }
                    Err(e) => tracing::warn!("{e}"),
                }
            }
        }
        let status = zygote
            .wait()
            .map_err(|e| format!("waiting for the zygote: {e}"))?;
        if agents.is_empty() && !robots.is_empty() {
            let log = run_dir::tail(&log_path, 4);
            let written = written.and_then(Result::err).map(|e| format!(" ({e})"));
            return Err(format!(
                "the agent zygote started no agent ({status}){}: {log}",
                written.unwrap_or_default()
            ));
        }
        Ok(HeldAgents { agents, gate })
    }
}

/// Agents forked by the zygote that wait to join the run.
#[derive(Debug, Default)]
pub struct HeldAgents {
    /// The agents, by robot index.
    pub agents: Vec<(u32, AgentProcess)>,
    /// The zygote's standard input, which every agent holds: its end lets them in.
    gate: Option<ChildStdin>,
}

impl HeldAgents {
    /// Lets the agents join: the run's shared memory exists.
    pub fn release(&mut self) {
        self.gate = None;
    }
}

/// The agent zygote's log in the run's `logs/` folder.
pub const ZYGOTE_LOG: &str = "zygote.log";
