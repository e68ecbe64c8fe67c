//! The launcher's part of fault handling: applying the faults the world reports due, following deaths and
//! returns the world reports, restarting agents by policy, and answering `swarm ctl`.
//!
//! The launcher is the only one that signals local processes; the world is the one that decides at which tick
//! something takes effect. A scheduled kill is applied and reaped before the launcher answers `applied`, so
//! the killed agent never produces a second, unscheduled death. In a run on hosts the launcher keeps the fault
//! log and decides restarts just the same, but the agents are the hosts' processes: the world has the hosts
//! carry out the faults, and a restart is a `respawn r` line to the world, which has the robot's host start the
//! replacement.

use std::process::ExitStatus;
use std::time::Instant;

use nix::sys::signal::Signal;

use super::agents::{AgentState, present_robots};
use super::control::{CtlCommand, CtlRequest};
use super::fault_log::{FaultRecord, RestartRecord};
use super::restart::{Ending, Restart};
use super::{LaunchError, Supervision};
use swarm_contract::config::faults::FaultKind;
use swarm_contract::fault_plan::FaultAction;
use swarm_contract::process::children;
use swarm_contract::protocol::launcher_to_world::WorldCommand;
use swarm_contract::protocol::resume::ResumePoint;
use swarm_contract::protocol::world_to_launcher::DownCause;

impl Supervision {
    /// Starts every robot's agent that the zygote did not fork (see
    /// [`AgentSpawner::fork_held`](super::agents::AgentSpawner::fork_held)); robots the schedule kills at
    /// start-up are killed right after their start (before they can join), and the world hears of their death
    /// at once.
    pub(super) fn start_agents(&mut self, startup: &[FaultAction]) -> Result<(), LaunchError> {
        self.children.agents.resize_with(self.robots.len(), || None);
        self.spawner
            .spawn_missing(&present_robots(&self.robots), &mut self.children.agents)?;
        for (entry, agent) in self.robots.iter_mut().zip(&self.children.agents) {
            if let Some(agent) = agent {
                entry.pid = agent.id();
                entry.first_pid = agent.id();
            }
        }
        for action in startup {
            if let (FaultKind::Kill, Some(robot)) = (action.kind, action.robot) {
                let agent = self.robots[robot as usize].pid;
                self.kill_and_reap(robot);
                self.send_world(WorldCommand::Dead { robot, agent });
                let index = self.log_fault("kill", Some(robot), Some(0));
                self.faults[index].detection_tick = Some(0);
                self.faults[index].status = Some("killed at start-up".into());
                self.restart_scheduled(robot, 0, index, false)?;
            }
        }
        Ok(())
    }

    /// Applies a fault the world reported due at `tick`.
    pub(super) fn on_fault(
        &mut self,
        tick: u64,
        kind: FaultKind,
        robot: Option<u32>,
    ) -> Result<(), LaunchError> {
        let index = self.log_fault(kind.name(), robot, Some(tick));
        self.faults[index].detection_tick = Some(tick);
        let Some(robot) = robot.filter(|&r| (r as usize) < self.robots.len()) else {
            if kind == FaultKind::KillWorld
                && let Some(world) = &self.children.world
            {
                tracing::warn!(tick, "the fault schedule kills the world");
                children::signal(world, Signal::SIGKILL);
            }
            return Ok(());
        };
        match kind {
            FaultKind::Kill => {
                self.kill_and_reap(robot);
                self.faults[index].status = Some("killed by the fault schedule".into());
                self.deaths.push(super::Death {
                    robot,
                    after_tick: tick.saturating_sub(1),
                    status: "killed by the fault schedule".into(),
                });
                self.restart_scheduled(robot, tick, index, true)?;
            }
            FaultKind::Freeze => self.signal_agent(robot, Signal::SIGSTOP, AgentState::Frozen),
            FaultKind::Thaw => self.signal_agent(robot, Signal::SIGCONT, AgentState::Running),
            FaultKind::KillWorld => {}
        }
        Ok(())
    }

    /// The world was killed by the schedule before `tick`: collect it and fail the run with that reason.
    pub(super) fn world_killed(&mut self, tick: u64) -> Result<(), LaunchError> {
        let status = match self.children.world.take() {
            Some(mut world) => world
                .wait()
                .map_or_else(|e| e.to_string(), |s| s.to_string()),
            None => "gone".to_owned(),
        };
        Err(LaunchError::WorldDied {
            status: format!("{status}, killed by the fault schedule"),
            when: format!("before tick {tick}"),
        })
    }

    /// The world ran tick `tick` without `robot`.
    pub(super) fn on_down(&mut self, tick: u64, robot: u32, cause: DownCause) {
        let Some(entry) = self.robots.get(robot as usize) else {
            return;
        };
        let gone_at = entry.gone_at;
        let index = match (entry.open_fault, cause) {
            (_, DownCause::HostLost) => self.log_fault("host-lost", Some(robot), None),
            (Some(index), _) if self.faults[index].detection_tick.is_none() => index,
            (_, DownCause::Notice) if self.on_hosts() => self.log_fault("exit", Some(robot), None),
            _ => self.log_fault("deadline", Some(robot), None),
        };
        self.faults[index].detection_tick = Some(tick);
        self.faults[index].detection_ms = gone_at.map(millis_since);
        if cause == DownCause::Deadline {
            // Its agent still runs (frozen or late); the world takes it back when it answers again.
            return;
        }
        let entry = &mut self.robots[robot as usize];
        // A death the launcher did not see (a notice from elsewhere) counts as a failure.
        let ending = std::mem::replace(&mut entry.ending, Ending::Failure);
        match entry.tracker.decide(ending, tick, self.ticks_per_second) {
            Some(Restart { attempt, delay, .. }) => {
                entry.state = AgentState::Restarting;
                entry.open_fault = Some(index);
                self.faults[index].restart = Some(RestartRecord {
                    attempt,
                    pid: 0,
                    rejoin_tick: None,
                });
                self.pending_restarts.push((robot, Instant::now() + delay));
            }
            None => {
                tracing::info!(
                    "robot {robot} stays out of the run from tick {tick} (restart policy)"
                );
                entry.state = AgentState::Dead;
                entry.open_fault = None;
                entry.gone_at = None;
            }
        }
    }

    /// `robot` takes part again from `tick`.
    pub(super) fn on_up(&mut self, tick: u64, robot: u32) {
        let Some(entry) = self.robots.get_mut(robot as usize) else {
            return;
        };
        tracing::info!("robot {robot} takes part again from tick {tick}");
        entry.state = AgentState::Running;
        let gone_at = entry.gone_at.take();
        if let Some(index) = entry.open_fault.take() {
            let fault = &mut self.faults[index];
            if fault.restart.is_some() {
                fault.rejoin_ms = gone_at.map(millis_since);
            }
            match fault.restart.as_mut() {
                Some(restart) => restart.rejoin_tick = Some(tick),
                None if fault.detection_tick.is_none() => fault.detection_tick = Some(tick),
                None => {}
            }
        }
    }

    /// An agent ended on its own (or by someone's signal): log it; the world's `down` decides the rest.
    pub(super) fn on_exit(&mut self, robot: u32, status: ExitStatus) {
        let entry = &mut self.robots[robot as usize];
        entry.gone_at = entry.gone_at.or(Some(Instant::now()));
        entry.ending = if status.success() {
            Ending::Success
        } else {
            Ending::Failure
        };
        let what = if self.robots[robot as usize].ctl_killed {
            "ctl-kill"
        } else {
            "exit"
        };
        self.robots[robot as usize].ctl_killed = false;
        let index = self.log_fault(what, Some(robot), None);
        self.faults[index].status = Some(status.to_string());
        self.robots[robot as usize].open_fault = Some(index);
    }

    /// Starts the replacements whose backoff has passed.
    pub(super) fn start_due_restarts(&mut self) -> Result<(), LaunchError> {
        let now = Instant::now();
        let due: Vec<u32> = self
            .pending_restarts
            .iter()
            .filter(|(_, at)| *at <= now)
            .map(|(robot, _)| *robot)
            .collect();
        self.pending_restarts.retain(|(_, at)| *at > now);
        for robot in due {
            let pid = self.spawn_replacement(robot, true)?;
            if let Some(restart) = self.robots[robot as usize]
                .open_fault
                .and_then(|i| self.faults[i].restart.as_mut())
            {
                restart.pid = pid;
            }
        }
        Ok(())
    }

    /// Answers the `swarm ctl` requests that came in.
    pub(super) fn answer_control(&mut self) {
        let requests: Vec<CtlRequest> = match &self.control {
            Some(control) => control.pending().collect(),
            None => return,
        };
        for request in requests {
            if matches!(
                request.command,
                CtlCommand::Spawn { .. } | CtlCommand::Remove(_)
            ) {
                self.request_arrival(request);
                continue;
            }
            let reply = self.control_request(request.command.clone());
            request.answer(reply);
        }
    }

    fn control_request(&mut self, command: CtlCommand) -> Result<String, String> {
        if let CtlCommand::List = command {
            let mut text = format!("tick {}\n", self.last_tick);
            for (robot, entry) in self.robots.iter().enumerate() {
                text.push_str(&format!(
                    "robot {robot} {} pid {} {} restarts {}\n",
                    self.roster_ids.get(robot).map_or("", String::as_str),
                    entry.pid,
                    entry.state.name(),
                    entry.tracker.restarts()
                ));
            }
            return Ok(text);
        }
        if let CtlCommand::KillHost(host) = &command {
            return self.kill_host(host);
        }
        if self.on_hosts() {
            return Err(
                "this run's robots run on hosts: `swarm ctl` kills, freezes and thaws local agents only; \
                 schedule robot faults with <faults> or --fault, or use kill-host"
                    .into(),
            );
        }
        let (CtlCommand::Kill(robot) | CtlCommand::Freeze(robot) | CtlCommand::Thaw(robot)) =
            command
        else {
            return Err("unsupported request".into());
        };
        let Some(entry) = self.robots.get(robot as usize) else {
            return Err(format!(
                "robot {robot} does not exist: the run has {} robots",
                self.robots.len()
            ));
        };
        let running = self
            .children
            .agents
            .get(robot as usize)
            .is_some_and(Option::is_some);
        if !running || matches!(entry.state, AgentState::Dead | AgentState::Restarting) {
            return Err(format!("robot {robot} has no running agent"));
        }
        match (command, entry.state) {
            (CtlCommand::Kill(_), _) => {
                self.robots[robot as usize].ctl_killed = true;
                self.robots[robot as usize].gone_at = Some(Instant::now());
                // Reaped here, so the world hears of the death in this round, not at the next poll.
                if let Some(status) = self.children.kill_agent(robot) {
                    self.reaped.push((robot, status));
                }
                Ok(format!("robot {robot} killed\n"))
            }
            (CtlCommand::Freeze(_), AgentState::Running) => {
                self.signal_agent(robot, Signal::SIGSTOP, AgentState::Frozen);
                let index = self.log_fault("ctl-freeze", Some(robot), None);
                self.robots[robot as usize].open_fault = Some(index);
                Ok(format!("robot {robot} frozen\n"))
            }
            (CtlCommand::Thaw(_), AgentState::Frozen) => {
                self.signal_agent(robot, Signal::SIGCONT, AgentState::Running);
                let index = self.log_fault("ctl-thaw", Some(robot), None);
                self.robots[robot as usize].open_fault = Some(index);
                Ok(format!("robot {robot} thawed\n"))
            }
            (_, state) => Err(format!("robot {robot} is {}", state.name())),
        }
    }

    /// Lets frozen agents run again (so they can see the run end and exit).
    pub(super) fn thaw_all(&mut self) {
        for robot in 0..self.robots.len() as u32 {
            if self.robots[robot as usize].state == AgentState::Frozen {
                self.signal_agent(robot, Signal::SIGCONT, AgentState::Running);
            }
        }
    }

    /// Decides on a restart after a scheduled kill at `tick` (fault log entry `index`): the replacement starts
    /// now and takes part from the tick the backoff sets, which the world holds until it has joined.
    fn restart_scheduled(
        &mut self,
        robot: u32,
        tick: u64,
        index: usize,
        resume: bool,
    ) -> Result<(), LaunchError> {
        let entry = &mut self.robots[robot as usize];
        let Some(restart) = entry
            .tracker
            .decide(Ending::Failure, tick, self.ticks_per_second)
        else {
            entry.state = AgentState::Dead;
            return Ok(());
        };
        entry.state = AgentState::Restarting;
        entry.open_fault = Some(index);
        let rejoin = tick + restart.delay_ticks;
        self.send_world(WorldCommand::Rejoin {
            robot,
            tick: rejoin,
        });
        let pid = self.spawn_replacement(robot, resume)?;
        self.faults[index].restart = Some(RestartRecord {
            attempt: restart.attempt,
            pid,
            rejoin_tick: None,
        });
        Ok(())
    }

    /// Starts a replacement agent for `robot` (from its resume point when `resume`) and tells the world, which
    /// takes a restarted robot back once its agent is there; returns its pid (0 on hosts: the world has the
    /// robot's host start it, always from the world's record).
    fn spawn_replacement(&mut self, robot: u32, resume: bool) -> Result<u32, LaunchError> {
        self.send_world(WorldCommand::Respawn(robot));
        if self.on_hosts() {
            tracing::info!(robot, "restarting the robot's agent on its host");
            return Ok(0);
        }
        let point = resume.then(|| ResumePoint::path(&self.out_dir, robot));
        let child = self
            .spawner
            .spawn(robot, &self.robots[robot as usize].controller, point)?;
        let pid = child.id();
        tracing::info!(robot, pid, "restarting the robot's agent");
        self.robots[robot as usize].pid = pid;
        if let Some(slot) = self.children.agents.get_mut(robot as usize) {
            *slot = Some(child);
        }
        Ok(pid)
    }

    /// `swarm ctl kill-host`: the world tells the host to die; its loss is logged when the world notices it.
    fn kill_host(&mut self, host: &str) -> Result<String, String> {
        let Some(index) = self.host_names.iter().position(|h| h == host) else {
            return Err(if self.host_names.is_empty() {
                "this run has no hosts: its robots run on this machine".to_owned()
            } else {
                format!(
                    "unknown host '{host}' (hosts: {})",
                    self.host_names.join(", ")
                )
            });
        };
        self.send_world(WorldCommand::KillHost(index as u32));
        let record = self.log_fault("ctl-kill-host", None, None);
        self.faults[record].status = Some(format!("host {host}"));
        Ok(format!("host {host} killed\n"))
    }

    /// Whether the run's robots run on hosts.
    pub(super) fn on_hosts(&self) -> bool {
        !self.host_names.is_empty()
    }

    /// SIGKILLs `robot`'s agent and reaps it, so its end is not seen again as an unscheduled death.
    fn kill_and_reap(&mut self, robot: u32) {
        self.children.kill_agent(robot);
        self.robots[robot as usize].state = AgentState::Dead;
    }

    /// Sends `signal` to `robot`'s agent and records its new state (on hosts only the state: the world has the
    /// robot's host send the signal).
    fn signal_agent(&mut self, robot: u32, signal: Signal, state: AgentState) {
        if self.on_hosts() {
            self.robots[robot as usize].state = state;
        } else if let Some(Some(child)) = self.children.agents.get(robot as usize) {
            child.signal(signal);
            self.robots[robot as usize].state = state;
        }
    }

    /// Appends a fault to the log; returns its index.
    fn log_fault(&mut self, what: &str, robot: Option<u32>, scheduled_tick: Option<u64>) -> usize {
        let mut record = FaultRecord::new(what, robot);
        record.scheduled_tick = scheduled_tick;
        self.faults.push(record);
        self.faults.len() - 1
    }
}

/// Milliseconds from `start` to now.
fn millis_since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
