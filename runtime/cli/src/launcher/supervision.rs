//! The launcher's loop while a run goes: following the world's reports, reaping agents that exit, and, at the end,
//! collecting the agents and saying what the run did. Faults, restarts and `swarm ctl` requests are handled in
//! `fault_handling.rs`, joins and departures in `arrivals.rs`.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Instant;

use nix::sys::signal::Signal;
use swarm_contract::config::faults::FaultKind;
use swarm_contract::process::children;
use swarm_contract::protocol::launcher_to_world::WorldCommand;
use swarm_contract::protocol::world_to_launcher::WorldReport;
use swarm_contract::run_dir;
use swarm_contract::transport;

use super::{
    Death, EXIT_POLL_PERIOD, LOG_LINES_QUOTED, LaunchError, RunReport, SUPERVISION_PERIOD,
    Supervision, io,
};

impl Supervision {
    /// Follows the run until the world finishes (or is stopped and finishes), handling deaths, faults,
    /// restarts and `swarm ctl` requests on the way.
    pub(super) fn follow(
        &mut self,
        reports: &Receiver<WorldReport>,
        stop: &AtomicBool,
    ) -> Result<(), LaunchError> {
        let mut stop_sent = false;
        loop {
            if stop.load(Ordering::Relaxed) && !stop_sent {
                stop_sent = true;
                self.interrupted = true;
                tracing::info!("stopping: the world finishes its tick and flushes its records");
                self.thaw_all();
                if let Some(world) = &self.children.world {
                    children::signal(world, Signal::SIGTERM);
                }
            }
            match reports.recv_timeout(SUPERVISION_PERIOD) {
                Ok(WorldReport::Tick { tick, dead, .. }) => {
                    if self.first_tick.is_none() {
                        self.first_tick = Some(Instant::now());
                        tracing::info!(after = ?self.started.elapsed(), "first tick completed");
                    }
                    self.last_tick = tick;
                    self.progress.set_position(tick);
                    let total = self.roster_ids.len() as u32;
                    if let Some(plain) = &mut self.plain_progress
                        && let Some(line) = plain.update(tick, total.saturating_sub(dead))
                    {
                        tracing::info!("{line}");
                    }
                    self.progress.set_message(format!(
                        "{}/{total} robots alive",
                        total.saturating_sub(dead)
                    ));
                }
                Ok(WorldReport::Finished { ticks }) => {
                    tracing::debug!(ticks, "the world finished its records");
                    self.last_tick = ticks;
                    self.wait_world()?;
                    tracing::debug!("the world exited");
                    return Ok(());
                }
                Ok(WorldReport::Fault { tick, kind, robot }) => {
                    self.on_fault(tick, kind, robot)?;
                    if kind == FaultKind::KillWorld {
                        return self.world_killed(tick);
                    }
                }
                Ok(WorldReport::Await { tick }) => self.send_world(WorldCommand::Applied(tick)),
                Ok(WorldReport::Down { tick, robot, cause }) => self.on_down(tick, robot, cause),
                Ok(WorldReport::Up { tick, robot }) => self.on_up(tick, robot),
                Ok(WorldReport::Joined { tick, robot }) => self.on_joined(tick, robot)?,
                Ok(WorldReport::Refused {
                    tick,
                    robot,
                    reason,
                }) => self.on_refused(tick, robot, &reason),
                Ok(WorldReport::Left { tick, robot }) => self.on_left(tick, robot),
                Ok(WorldReport::Ready { .. }) | Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    // The world closed its output: it is exiting; its status says how.
                    self.wait_world()?;
                    return Err(LaunchError::WorldDied {
                        status: "without reporting the end of the experiment".into(),
                        when: format!("after tick {}", self.last_tick),
                    });
                }
            }
            self.answer_control();
            self.handle_agent_exits()?;
            self.start_due_restarts()?;
        }
    }

    /// Sends one line to the world (a world that is gone is noticed by the report loop).
    pub(super) fn send_world(&mut self, command: WorldCommand) {
        if let Some(stdin) = self.world_stdin.as_mut() {
            let _ = writeln!(stdin, "{command}");
        }
    }

    /// Reaps exited agents (and takes those `swarm ctl kill` reaped): before the first tick an exit is a failed
    /// start; afterwards an exit is a death the world hears of at once, unless the agent exited 0 with the run.
    pub(super) fn handle_agent_exits(&mut self) -> Result<(), LaunchError> {
        let mut exits = std::mem::take(&mut self.reaped);
        exits.extend(self.children.reap_agents());
        for (robot, status) in exits {
            // Agents exit 0 when the world has ended the run (its reports, even that of the first tick, may still
            // be queued), and when they are asked to stop (SIGTERM): that robot leaves the run, and only `always`
            // restarts it.
            let left_with_the_run =
                status.success() && (self.interrupted || transport::run_ended(&self.run));
            if self.first_tick.is_none()
                && !left_with_the_run
                && !self.robots[robot as usize].ctl_killed
            {
                let log =
                    run_dir::tail(&run_dir::agent_log(&self.out_dir, robot), LOG_LINES_QUOTED);
                return Err(LaunchError::AgentFailed {
                    robot,
                    id: self
                        .roster_ids
                        .get(robot as usize)
                        .cloned()
                        .unwrap_or_default(),
                    status: status.to_string(),
                    log,
                });
            }
            if left_with_the_run {
                continue;
            }
            if status.success() {
                tracing::warn!(robot, tick = self.last_tick, "robot agent left the run");
            } else {
                tracing::warn!(robot, %status, tick = self.last_tick, "robot agent died");
            }
            let agent = self.robots[robot as usize].pid;
            self.send_world(WorldCommand::Dead { robot, agent });
            self.deaths.push(Death {
                robot,
                after_tick: self.last_tick,
                status: status.to_string(),
            });
            self.on_exit(robot, status);
        }
        Ok(())
    }

    /// Waits for the world to exit and checks it succeeded.
    pub(super) fn wait_world(&mut self) -> Result<(), LaunchError> {
        let Some(mut world) = self.children.world.take() else {
            return Ok(());
        };
        let status = world.wait().map_err(io("waiting for the world process"))?;
        if status.success() {
            Ok(())
        } else {
            Err(LaunchError::WorldDied {
                status: status.to_string(),
                when: format!("after tick {}", self.last_tick),
            })
        }
    }

    /// Lets agents exit by themselves (the world's end tells them), then kills the rest.
    pub(super) fn collect_agents(&mut self) {
        self.thaw_all();
        let stragglers = self
            .children
            .end_agents(self.agent_exit_grace, EXIT_POLL_PERIOD);
        if stragglers > 0 {
            tracing::warn!(stragglers, "agents did not exit after the run; killed them");
        }
        tracing::debug!("every agent exited");
    }

    /// What the run did, for `summary.json` and the caller.
    pub(super) fn report(
        &self,
        seed: u64,
        robots: u32,
        world_pid: u32,
        agent_pids: Vec<u32>,
        ticks: u64,
    ) -> RunReport {
        RunReport {
            out_dir: self.out_dir.clone(),
            seed,
            robots,
            ticks,
            wall_seconds: self.started.elapsed().as_secs_f64(),
            time_to_first_tick_seconds: self
                .first_tick
                .map_or(0.0, |t| t.duration_since(self.started).as_secs_f64()),
            interrupted: self.interrupted,
            deaths: self.deaths.clone(),
            world_pid,
            agent_pids,
            faults: self.faults.clone(),
            alive_final: self.robots[..robots as usize]
                .iter()
                .filter(|r| r.is_alive())
                .count() as u32,
        }
    }
}
