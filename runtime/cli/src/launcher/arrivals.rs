//! The launcher's part of joins and leaves (docs/joins.md): `swarm ctl spawn` and `swarm ctl remove` go to the
//! world, which decides the tick and the place; the world's `joined` starts the robot's agent, its `left` stops
//! it, and the `swarm ctl` client gets its answer once the world has decided.

use super::LaunchError;
use super::Supervision;
use super::agents::AgentState;
use super::control::{CtlCommand, CtlRequest};
use swarm_contract::protocol::launcher_to_world::WorldCommand;

impl Supervision {
    /// Passes a `swarm ctl spawn` or `remove` request to the world, or refuses it at once.
    pub(super) fn request_arrival(&mut self, request: CtlRequest) {
        let (robot, command, wanted) = match request.command {
            CtlCommand::Spawn { robot, pose } => (robot, WorldCommand::Spawn { robot, pose }, true),
            CtlCommand::Remove(robot) => (robot, WorldCommand::Remove(robot), false),
            _ => return request.answer(Err("not a join or a leave".into())),
        };
        let Some(entry) = self.robots.get(robot as usize) else {
            return request.answer(Err(format!(
                "robot {robot} does not exist: the run has {} robots",
                self.robots.len()
            )));
        };
        let absent = entry.state == AgentState::Absent;
        if wanted && !absent {
            return request.answer(Err(format!("robot {robot} is in the run already")));
        }
        if !wanted && absent {
            return request.answer(Err(format!("robot {robot} is not in the run")));
        }
        if self.pending_arrivals.iter().any(|(r, _)| *r == robot) {
            return request.answer(Err(format!(
                "robot {robot} has a spawn or remove request waiting for the next tick"
            )));
        }
        self.send_world(command);
        self.pending_arrivals.push((robot, request));
    }

    /// The world placed `robot` for `tick`: starts its agent (on hosts, its host does).
    pub(super) fn on_joined(&mut self, tick: u64, robot: u32) -> Result<(), LaunchError> {
        let Some(entry) = self.robots.get(robot as usize) else {
            return Ok(());
        };
        tracing::info!("robot {robot} joins the run at tick {tick}");
        if !self.on_hosts() {
            let child = self.spawner.spawn(robot, &entry.controller, None)?;
            let entry = &mut self.robots[robot as usize];
            entry.pid = child.id();
            if entry.first_pid == 0 {
                entry.first_pid = child.id();
            }
            if let Some(slot) = self.children.agents.get_mut(robot as usize) {
                *slot = Some(child);
            }
        }
        self.robots[robot as usize].state = AgentState::Running;
        self.answer_arrival(robot, Ok(format!("robot {robot} joins at tick {tick}\n")));
        Ok(())
    }

    /// The world could not place `robot`.
    pub(super) fn on_refused(&mut self, tick: u64, robot: u32, reason: &str) {
        tracing::warn!("robot {robot} cannot join at tick {tick}: {reason}");
        self.answer_arrival(robot, Err(format!("robot {robot} cannot join: {reason}")));
    }

    /// `robot` left the run before `tick`: stops its agent for good (no restart, no death).
    pub(super) fn on_left(&mut self, tick: u64, robot: u32) {
        let Some(entry) = self.robots.get_mut(robot as usize) else {
            return;
        };
        tracing::info!("robot {robot} leaves the run at tick {tick}");
        entry.state = AgentState::Absent;
        entry.open_fault = None;
        entry.gone_at = None;
        self.pending_restarts.retain(|(r, _)| *r != robot);
        if !self.on_hosts() {
            self.children.kill_agent(robot);
        }
        self.answer_arrival(robot, Ok(format!("robot {robot} left at tick {tick}\n")));
    }

    fn answer_arrival(&mut self, robot: u32, reply: Result<String, String>) {
        if let Some(at) = self.pending_arrivals.iter().position(|(r, _)| *r == robot) {
            self.pending_arrivals.swap_remove(at).1.answer(reply);
        }
    }
}
