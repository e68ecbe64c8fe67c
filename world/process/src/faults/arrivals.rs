//! Robots joining and leaving a running swarm (docs/joins.md), between two ticks like the faults: the
//! configuration's schedule (`join_tick`, `join_time`), `swarm ctl spawn` and `swarm ctl remove`.
//!
//! A join at tick k: the world places the robot's body (where it was configured or asked to be, or at the nearest
//! free place; refused with the reason if there is none), reports `joined k r`, and the launcher (or, on hosts,
//! the robot's host) starts its agent; the world holds tick k until the agent is there, so the robot takes part
//! from tick k in every run. A leave at tick k: the body leaves the arena, the world stops waiting for the
//! robot, reports `left k r`, and the launcher stops its agent. Each is an `events.csv` row (`join`,
//! `join:refused`, `leave`) and an entry of `summary.json`'s `arrivals`.

use swarm_contract::config::{Arrival, Experiment};
use swarm_contract::messages::SupervisorSnapshot;
use swarm_contract::protocol::launcher_to_world::SpawnPose;
use swarm_contract::protocol::world_to_launcher::WorldReport;
use swarm_world::World;
use swarm_world::entities::RobotId;
use swarm_world::geometry::Vec2;
use swarm_world::recorder::Recorder;

use super::{FaultDriver, Robot};
use crate::remote::{Link, Stop};
use crate::report;

/// How a robot came or went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cause {
    Schedule,
    Ctl,
}

impl Cause {
    fn name(self) -> &'static str {
        match self {
            Cause::Schedule => "schedule",
            Cause::Ctl => "ctl",
        }
    }
}

/// The joins and leaves of a run: what is due, what was asked, and what happened.
#[derive(Default)]
pub struct Arrivals {
    /// Scheduled joins not yet carried out, in tick order.
    schedule: Vec<(u64, u32)>,
    /// `swarm ctl spawn` requests, for the next tick.
    spawns: Vec<(u32, Option<SpawnPose>)>,
    /// `swarm ctl remove` requests, for the next tick.
    removals: Vec<u32>,
    /// What happened, for `summary.json`.
    log: Vec<serde_json::Value>,
    /// Per robot: where the configuration declares it (`file:line:column`), for refusals.
    declared: Vec<String>,
}

impl Arrivals {
    /// The arrivals of `experiment`'s run: the robots that join by schedule (`join_tick`, `join_time`), nothing
    /// asked yet.
    pub fn new(experiment: &Experiment) -> Arrivals {
        let participants = experiment.participants();
        let ticks_per_second = experiment.framework.ticks_per_second;
        let mut schedule: Vec<(u64, u32)> = participants
            .iter()
            .filter_map(|p| match p.arrival {
                Arrival::At(at) => Some((at.tick(ticks_per_second).max(1), p.index)),
                Arrival::Start | Arrival::Spare => None,
            })
            .collect();
        // Stable: robots due at one tick join in index order.
        schedule.sort_by_key(|&(tick, _)| tick);
        Arrivals {
            schedule,
            spawns: Vec::new(),
            removals: Vec::new(),
            log: Vec::new(),
            declared: participants
                .iter()
                .map(|p| format!("{}:{}", experiment.path.display(), p.location))
                .collect(),
        }
    }

    /// `swarm ctl spawn`: `robot` is to join at the next tick.
    pub fn request_spawn(&mut self, robot: u32, pose: Option<SpawnPose>) {
        self.spawns.push((robot, pose));
    }

    /// `swarm ctl remove`: `robot` is to leave at the next tick.
    pub fn request_removal(&mut self, robot: u32) {
        self.removals.push(robot);
    }

    /// Every join, refusal and leave so far, for `summary.json`'s `arrivals`.
    pub fn summary(&self) -> serde_json::Value {
        serde_json::Value::Array(self.log.clone())
    }
}

impl FaultDriver {
    /// Carries out the leaves and joins due at `tick`: see the module documentation.
    pub(super) fn arrivals(
        &mut self,
        tick: u64,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
    ) -> anyhow::Result<()> {
        let due = self
            .arrivals
            .schedule
            .partition_point(|&(at, _)| at <= tick);
        let scheduled: Vec<(u32, Option<SpawnPose>, Cause)> = self
            .arrivals
            .schedule
            .drain(..due)
            .map(|(_, robot)| (robot, None, Cause::Schedule))
            .collect();
        let asked = self.arrivals.spawns.drain(..);
        let joins: Vec<_> = scheduled
            .into_iter()
            .chain(asked.map(|(robot, pose)| (robot, pose, Cause::Ctl)))
            .collect();
        let removals = std::mem::take(&mut self.arrivals.removals);
        if joins.is_empty() && removals.is_empty() {
            return Ok(());
        }
        for robot in removals {
            self.leave(robot, tick, link, world, recorder)?;
        }
        let mut joined = Vec::new();
        for (robot, pose, cause) in joins {
            if self.join(robot, pose, cause, tick, world, recorder) {
                joined.push(robot);
            }
        }
        recorder.sync()?;
        report(WorldReport::Await { tick });
        self.wait_applied(tick)?;
        for robot in joined {
            // Locally the launcher has started the agent; on a host, the host starts it now.
            let started = link.respawn(robot, tick, SupervisorSnapshot::default())?;
            if started && self.wait_for_replacement(robot, link)? {
                self.robots[robot as usize] = Robot::Alive;
            } else {
                tracing::warn!(robot, tick, "the joined robot has no agent: it stays down");
                self.robots[robot as usize] = Robot::Down(super::Down::Notice);
                world.set_alive(RobotId(robot), false);
            }
        }
        Ok(())
    }

    /// Places the absent `robot` for `tick` and reports the outcome; whether it joined.
    fn join(
        &mut self,
        robot: u32,
        pose: Option<SpawnPose>,
        cause: Cause,
        tick: u64,
        world: &mut World,
        recorder: &mut Recorder,
    ) -> bool {
        let id = world
            .arena
            .robots
            .get(robot as usize)
            .map(|r| r.name.clone())
            .unwrap_or_default();
        let placed = match self.robots.get(robot as usize) {
            Some(Robot::Absent) => {
                // Only robots are ever absent, so `robot` is one of the arena's.
                let wanted = pose.map(|p| {
                    let heading = p.heading_deg.map_or_else(
                        || world.arena.robots[robot as usize].heading,
                        f32::to_radians,
                    );
                    (Vec2::new(p.x, p.y), heading)
                });
                world.join(RobotId(robot), wanted).map_err(|refused| {
                    match self.arrivals.declared.get(robot as usize) {
                        Some(at) => format!("{at}: robot '{id}': {}", refused.0),
                        None => refused.0,
                    }
                })
            }
            Some(_) => Err(format!("robot {robot} is in the run already")),
            None => Err(format!("there is no robot {robot}")),
        };
        match placed {
            Ok((at, heading)) => {
                recorder.record_fault(tick, robot as usize, "join");
                self.arrivals.log.push(serde_json::json!({
                    "what": "join", "robot": robot, "id": id, "tick": tick, "by": cause.name(),
                    "x": at.x, "y": at.y, "heading": heading,
                }));
                report(WorldReport::Joined { tick, robot });
                true
            }
            Err(reason) => {
                tracing::warn!(robot, tick, "robot {robot} cannot join: {reason}");
                if (robot as usize) < world.arena.robots.len() {
                    recorder.record_fault(tick, robot as usize, "join:refused");
                }
                self.arrivals.log.push(serde_json::json!({
                    "what": "join-refused", "robot": robot, "id": id, "tick": tick, "by": cause.name(),
                    "reason": reason,
                }));
                report(WorldReport::Refused {
                    tick,
                    robot,
                    reason,
                });
                false
            }
        }
    }

    /// `robot` leaves the run before `tick`: its body leaves the arena and nothing waits for it any more.
    fn leave(
        &mut self,
        robot: u32,
        tick: u64,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
    ) -> anyhow::Result<()> {
        let Some(state) = self.robots.get(robot as usize) else {
            return Ok(());
        };
        if *state == Robot::Absent || robot as usize >= world.robot_count() {
            tracing::warn!(
                robot,
                "ignoring the removal of a robot that is not in the arena"
            );
            return Ok(());
        }
        link.stop(robot, Stop::Kill)?;
        self.robots[robot as usize] = Robot::Absent;
        self.rejoin_at[robot as usize] = None;
        self.restart_due[robot as usize] = false;
        world.park(RobotId(robot));
        recorder.record_fault(tick, robot as usize, "leave");
        let id = world.arena.robots[robot as usize].name.clone();
        self.arrivals.log.push(serde_json::json!({
            "what": "leave", "robot": robot, "id": id, "tick": tick, "by": Cause::Ctl.name(),
        }));
        report(WorldReport::Left { tick, robot });
        Ok(())
    }
}
