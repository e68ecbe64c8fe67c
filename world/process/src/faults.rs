//! Faults in the world process: the schedule, death notices, deadline detection, restarts and thaws, applied
//! between two ticks so that a scheduled fault always takes effect at its tick whatever the OS timing.
//!
//! Between tick k − 1 and tick k ([`FaultDriver::before_tick`]), in this order:
//! 1. the launcher's death notices: each robot still alive is marked dead from tick k (`down k r notice`);
//! 2. robots that missed tick k − 1's deadline are marked dead (`down k r deadline`): a frozen or hung agent
//!    never stalls more than one tick;
//! 3. robots come back (`up k r`): a robot marked dead by the deadline whose agent answered again, a restarted
//!    robot whose replacement has joined (at its `rejoin` tick when the launcher gave one: the world holds that
//!    tick until the replacement is there);
//! 4. the faults the schedule has due at tick k are recorded and reported (`fault k kill 3`, then `await k`),
//!    and the world waits for the launcher's `applied k` before it opens the tick; thawed robots then take part
//!    again.
//!
//! 5. robots join and leave ([`arrivals`]): by the configuration's schedule, `swarm ctl spawn` and `swarm ctl
//!    remove`.
//!
//! Every robot marked dead gets a resume point (its last recorded supervisor snapshot) before the launcher hears
//! of it, so a replacement agent can continue from it. A dead robot stays in the arena as an inert body with its
//! LEDs off; its frame says `alive = 0`, and anything its agent sends is ignored until it is back.
//! This module never signals a process: the launcher does that for local agents, and for robots on hosts the
//! [`Link`] turns each step into a fault order to the robot's host. There the deaths come from the hosts (an
//! agent that ended, a host lost) instead of the launcher's notices, and the launcher's `respawn r` lines
//! become replacement agents on the robot's host. A robot whose host is lost is down like a dead one: if its
//! restart policy restarts it, the host's fresh agent (or one the host starts, if it is already back) is its
//! replacement; otherwise the returning host's agent for it is killed again.

use std::io::BufRead;
use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use swarm_contract::config::faults::{FaultKind, FaultSchedule};
use swarm_contract::fault_plan::{FaultAction, FaultPlan};
use swarm_contract::limits::Limits;
use swarm_contract::messages::ActuatorCommand;
use swarm_contract::protocol::launcher_to_world::WorldCommand;
use swarm_contract::protocol::resume::ResumePoint;
use swarm_contract::protocol::world_to_launcher::{DownCause, WorldReport};
use swarm_contract::transport::{CommandStatus, DeathNotices};
use swarm_remote::world_bridge::RobotNews;
use swarm_world::World;
use swarm_world::entities::RobotId;
use swarm_world::recorder::Recorder;

use crate::remote::{Link, Stop};
use crate::report;

mod arrivals;

pub use arrivals::Arrivals;

/// How often the world looks at joins and notices while it waits for agents before the first tick.
const JOIN_POLL: Duration = Duration::from_millis(20);

/// Why a robot is not taking part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Down {
    /// Killed by the schedule.
    Killed,
    /// The launcher's death notice.
    Notice,
    /// Missed a deadline (its agent may still run).
    Deadline,
    /// Frozen by the schedule.
    Frozen,
    /// Its host was lost (back when the host is).
    HostLost,
}

/// A robot as the world sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Robot {
    Alive,
    Down(Down),
    /// Not in the run: before it joins, or after it left.
    Absent,
}

/// The world's fault state: the plan, each robot's state and the launcher's lines.
pub struct FaultDriver {
    plan: FaultPlan,
    robots: Vec<Robot>,
    /// Tick at which a restarted robot's replacement takes part (from the launcher's `rejoin`).
    rejoin_at: Vec<Option<u64>>,
    /// Robots the schedule kills at start-up (tick 0).
    startup_kills: Vec<u32>,
    commands: Receiver<WorldCommand>,
    notices: Vec<u32>,
    applied: Vec<u64>,
    /// Robots the launcher replaces (`respawn r`), in order.
    respawns: Vec<u32>,
    /// Per robot: the launcher restarted it and it has not taken part since; only such a robot comes back
    /// when an agent of it is present (a robot on a host whose host was away gets its agent with the host).
    restart_due: Vec<bool>,
    news: Vec<RobotNews>,
    /// `swarm ctl kill-host` requests (host indices).
    host_kills: Vec<u32>,
    /// Scratch: the faults due now and the live-robot mask for random picks.
    due: Vec<FaultAction>,
    alive_mask: Vec<bool>,
    out_dir: PathBuf,
    join_timeout: Duration,
    apply_timeout: Duration,
    /// Joins and leaves: the schedule's, and `swarm ctl`'s requests.
    arrivals: Arrivals,
}

/// Reads the launcher's lines on standard input: a death notice reaches the transport at once (so the current
/// tick stops waiting; a run on hosts has no local transport: `None`), and every line goes to the main loop,
/// which applies it between ticks.
pub fn follow_launcher(notices: Option<DeathNotices>) -> Receiver<WorldCommand> {
    let (sender, receiver) = mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::stdin().lock().lines() {
            let Ok(line) = line else { break };
            let Some(command) = WorldCommand::parse(&line) else {
                tracing::warn!("ignoring the launcher line '{line}'");
                continue;
            };
            if let (WorldCommand::Dead { robot, agent }, Some(notices)) = (command, &notices) {
                match notices.mark_agent_dead(robot, agent) {
                    Ok(true) => {}
                    // The main loop still hears of the death: the robot is down until its replacement rejoins.
                    Ok(false) => tracing::debug!(robot, agent, "the replacement joined first"),
                    Err(e) => {
                        tracing::warn!("ignoring death notice '{line}': {e}");
                        continue;
                    }
                }
            }
            if sender.send(command).is_err() {
                break;
            }
        }
    });
    receiver
}

impl FaultDriver {
    /// The driver of `world`'s run with `schedule`, seeded with `seed`: `link.robots()` participants, of which
    /// the world's robots come first (random picks choose among those, never a coordinator). Call it before any
    /// agent can join: every participant starts without an agent in the transport (a death notice each), so it
    /// counts as present only once its agent has connected, not merely claimed its slot.
    pub fn new(
        link: &Link,
        world: &World,
        schedule: &FaultSchedule,
        seed: u64,
        commands: Receiver<WorldCommand>,
        out_dir: PathBuf,
        limits: &Limits,
    ) -> anyhow::Result<FaultDriver> {
        let robots = link.robots();
        if let Link::Local(local) = link {
            local.start_without_agents();
        }
        let bodies = world.robot_count();
        let mut plan = FaultPlan::new(schedule, world.arena.ticks_per_second, seed);
        let mut due = Vec::new();
        plan.due(0, &vec![true; bodies], &mut due);
        let startup_kills = due
            .iter()
            .filter(|a| a.kind == FaultKind::Kill)
            .filter_map(|a| a.robot)
            .collect();
        due.clear();
        Ok(FaultDriver {
            plan,
            robots: (0..robots)
                .map(|r| match world.arena.robots.get(r) {
                    Some(robot) if !robot.present => Robot::Absent,
                    _ => Robot::Alive,
                })
                .collect(),
            arrivals: Arrivals::default(),
            rejoin_at: vec![None; robots],
            startup_kills,
            commands,
            notices: Vec::new(),
            applied: Vec::new(),
            respawns: Vec::new(),
            restart_due: vec![false; robots],
            news: Vec::new(),
            host_kills: Vec::new(),
            due,
            alive_mask: vec![true; bodies],
            out_dir,
            join_timeout: limits.join_timeout(),
            apply_timeout: limits.fault_apply_timeout(),
        })
    }

    /// Whether robot `robot` takes part in the coming tick.
    pub fn is_alive(&self, robot: usize) -> bool {
        self.robots.get(robot) == Some(&Robot::Alive)
    }

    /// Carries out `arrivals` (the driver starts with none).
    pub fn with_arrivals(mut self, arrivals: Arrivals) -> FaultDriver {
        self.arrivals = arrivals;
        self
    }

    /// Every join, refusal and leave of the run so far, for `summary.json`.
    pub fn arrivals_summary(&self) -> serde_json::Value {
        self.arrivals.summary()
    }

    /// Robots taking part (coordinators, the participants after the robots, are not counted).
    pub fn alive_count(&self) -> usize {
        // The random-pick mask has one place per robot.
        let robots = self.alive_mask.len();
        self.robots[..robots]
            .iter()
            .filter(|r| **r == Robot::Alive)
            .count()
    }

    /// Waits until every robot has an agent, except those killed at start-up. Locally the launcher kills those
    /// and their death notices must have arrived; on hosts the world has their hosts kill them, as faults of
    /// tick 0 the launcher applies (deciding their restarts). Either way a start-up kill takes effect before
    /// tick 1 in every run.
    pub fn wait_for_agents(
        &mut self,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        if let Link::Remote(_) = link {
            link.wait(self.join_timeout)?;
            for robot in self.startup_kills.clone() {
                link.stop(robot, Stop::Kill)?;
                self.mark_down(robot, Down::Killed, 0, world, recorder, commands)?;
                recorder.record_fault(0, robot as usize, "fault:kill");
                report(WorldReport::Fault {
                    tick: 0,
                    kind: FaultKind::Kill,
                    robot: Some(robot),
                });
            }
            if !self.startup_kills.is_empty() {
                recorder.sync()?;
                report(WorldReport::Await { tick: 0 });
                self.wait_applied(0)?;
                self.respawn_requested(link, commands)?;
            }
            return Ok(());
        }
        let deadline = Instant::now() + self.join_timeout;
        loop {
            self.drain();
            for robot in std::mem::take(&mut self.notices) {
                if self.robots[robot as usize] == Robot::Alive {
                    if self.startup_kills.contains(&robot) {
                        self.mark_down(robot, Down::Killed, 0, world, recorder, commands)?;
                        recorder.record_fault(0, robot as usize, "fault:kill");
                    } else {
                        self.mark_down(robot, Down::Notice, 0, world, recorder, commands)?;
                    }
                }
            }
            let missing: Vec<u32> = (0..self.robots.len() as u32)
                .filter(|&r| self.robots[r as usize] == Robot::Alive && !link.agent_present(r))
                .collect();
            if missing.is_empty() {
                return Ok(());
            }
            if Instant::now() > deadline {
                bail!(
                    "waiting for the robot agents to join: robots {missing:?} did not join within {:?}",
                    self.join_timeout
                );
            }
            // Wakes early when an agent joins; notices are polled.
            link.poll_agents(JOIN_POLL);
        }
    }

    /// Applies everything due between the last tick and tick `tick` (see the module documentation).
    pub fn before_tick(
        &mut self,
        tick: u64,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        self.drain();
        for host in std::mem::take(&mut self.host_kills) {
            link.kill_host(host as usize)?;
        }
        self.respawn_requested(link, commands)?;
        self.hosts_news(tick, link, world, recorder, commands)?;
        for robot in std::mem::take(&mut self.notices) {
            match self.robots[robot as usize] {
                Robot::Alive => {
                    self.mark_down(robot, Down::Notice, tick, world, recorder, commands)?;
                }
                Robot::Down(Down::Deadline | Down::Frozen) => {
                    self.robots[robot as usize] = Robot::Down(Down::Notice);
                }
                Robot::Down(Down::Notice | Down::Killed | Down::HostLost) | Robot::Absent => {
                    continue;
                }
            }
            report(WorldReport::Down {
                tick,
                robot,
                cause: DownCause::Notice,
            });
        }
        if tick > 1 {
            for robot in 0..self.robots.len() as u32 {
                let status = link.statuses()[robot as usize];
                match self.robots[robot as usize] {
                    Robot::Alive if status == CommandStatus::Missing => {
                        link.stop(robot, Stop::Skip)?;
                        self.mark_down(robot, Down::Deadline, tick, world, recorder, commands)?;
                        report(WorldReport::Down {
                            tick,
                            robot,
                            cause: DownCause::Deadline,
                        });
                    }
                    Robot::Down(Down::Deadline)
                        if link.command(robot).is_some() && link.revive(robot, false)? =>
                    {
                        self.mark_up(robot, tick, world, recorder)?;
                    }
                    _ => {}
                }
            }
        }
        for robot in 0..self.robots.len() as u32 {
            let r = robot as usize;
            if !matches!(
                self.robots[r],
                Robot::Down(Down::Notice | Down::Killed | Down::HostLost)
            ) {
                continue;
            }
            match self.rejoin_at[r] {
                Some(at) if at > tick => {}
                Some(at) if at == tick => {
                    self.rejoin_at[r] = None;
                    if self.wait_for_replacement(robot, link)? {
                        self.mark_up(robot, tick, world, recorder)?;
                    }
                }
                _ => {
                    if self.restart_due[r] && link.agent_present(robot) {
                        self.rejoin_at[r] = None;
                        self.mark_up(robot, tick, world, recorder)?;
                    }
                }
            }
        }
        self.arrivals(tick, link, world, recorder)?;
        self.scheduled(tick, link, world, recorder, commands)
    }

    /// Takes in the launcher's restarts; on hosts, has each robot's host start the replacement from the robot's
    /// last recorded command, the one its resume point was written from (a dead robot's command is not updated;
    /// a local launcher starts its own replacement). A host that is away starts one when it is back.
    fn respawn_requested(
        &mut self,
        link: &mut Link,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        for robot in std::mem::take(&mut self.respawns) {
            let last = last_command(commands, robot);
            self.restart_due[robot as usize] = true;
            if !link.respawn(robot, last.tick, last.supervisors)? {
                tracing::info!(robot, "the robot's replacement waits for its host");
            }
        }
        Ok(())
    }

    /// Takes in what the hosts reported: an agent that ended is a death notice; a lost host's robots are down
    /// like dead ones (their restart policy decides whether they come back with the host); a returning host's
    /// fresh agents are the replacements of robots the launcher restarted, and are killed again for the others.
    fn hosts_news(
        &mut self,
        tick: u64,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        link.take_news(&mut self.news);
        for news in std::mem::take(&mut self.news) {
            match news {
                RobotNews::Died(robot) => self.notices.push(robot),
                RobotNews::HostLost(robot) => {
                    if matches!(
                        self.robots[robot as usize],
                        Robot::Alive | Robot::Down(Down::Frozen | Down::Deadline)
                    ) {
                        self.mark_down(robot, Down::HostLost, tick, world, recorder, commands)?;
                        report(WorldReport::Down {
                            tick,
                            robot,
                            cause: DownCause::HostLost,
                        });
                    }
                }
                RobotNews::HostBack(robot) => {
                    let r = robot as usize;
                    // A restarted robot's fresh agent is its replacement: the restarts take it in.
                    if !self.restart_due[r] && self.rejoin_at[r].is_none() {
                        link.stop(robot, Stop::Kill)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The schedule's faults at `tick`: record, report, wait for the launcher to apply them.
    fn scheduled(
        &mut self,
        tick: u64,
        link: &mut Link,
        world: &mut World,
        recorder: &mut Recorder,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        if self.plan.next_due(tick) != Some(tick) {
            return Ok(());
        }
        for (mask, robot) in self.alive_mask.iter_mut().zip(&self.robots) {
            *mask = *robot == Robot::Alive;
        }
        self.due.clear();
        self.plan.due(tick, &self.alive_mask, &mut self.due);
        let due = std::mem::take(&mut self.due);
        let mut reported = false;
        let mut thawed = Vec::new();
        for action in &due {
            let applies = match (action.kind, action.robot) {
                (FaultKind::KillWorld, _) => true,
                (FaultKind::Kill, Some(r)) => {
                    matches!(
                        self.robots[r as usize],
                        Robot::Alive | Robot::Down(Down::Frozen | Down::Deadline)
                    )
                }
                (FaultKind::Freeze, Some(r)) => self.robots[r as usize] == Robot::Alive,
                (FaultKind::Thaw, Some(r)) => self.robots[r as usize] == Robot::Down(Down::Frozen),
                _ => false,
            };
            if !applies {
                tracing::info!(
                    tick,
                    ?action,
                    "scheduled fault skipped: the robot is not in a state it applies to"
                );
                continue;
            }
            match (action.kind, action.robot) {
                (FaultKind::Kill, Some(robot)) => {
                    // A frozen robot's agent is killed too (on a host, by its host).
                    link.stop(robot, Stop::Kill)?;
                    if self.robots[robot as usize] == Robot::Alive {
                        self.mark_down(robot, Down::Killed, tick, world, recorder, commands)?;
                    }
                    self.robots[robot as usize] = Robot::Down(Down::Killed);
                    recorder.record_fault(tick, robot as usize, "fault:kill");
                }
                (FaultKind::Freeze, Some(robot)) => {
                    link.stop(robot, Stop::Freeze)?;
                    self.mark_down(robot, Down::Frozen, tick, world, recorder, commands)?;
                    recorder.record_fault(tick, robot as usize, "fault:freeze");
                }
                (FaultKind::Thaw, Some(robot)) => thawed.push(robot),
                // The launcher kills the world as soon as it reads this report, so every earlier tick must
                // be in the files first.
                (FaultKind::KillWorld, _) => recorder.sync()?,
                _ => {}
            }
            reported = true;
            report(WorldReport::Fault {
                tick,
                kind: action.kind,
                robot: action.robot,
            });
        }
        self.due = due;
        if !reported {
            return Ok(());
        }
        recorder.sync()?;
        report(WorldReport::Await { tick });
        self.wait_applied(tick)?;
        self.respawn_requested(link, commands)?;
        for robot in thawed {
            if link.revive(robot, true)? {
                recorder.record_fault(tick, robot as usize, "fault:thaw");
                self.mark_up(robot, tick, world, recorder)?;
            } else {
                tracing::warn!(robot, tick, "a thawed robot's agent is gone; it stays dead");
                self.robots[robot as usize] = Robot::Down(Down::Notice);
            }
        }
        Ok(())
    }

    /// Marks `robot` dead from `tick`: inert body, resume point, `events.csv` row.
    fn mark_down(
        &mut self,
        robot: u32,
        cause: Down,
        tick: u64,
        world: &mut World,
        recorder: &mut Recorder,
        commands: &[ActuatorCommand],
    ) -> anyhow::Result<()> {
        self.robots[robot as usize] = Robot::Down(cause);
        world.set_alive(RobotId(robot), false);
        let last = last_command(commands, robot);
        ResumePoint {
            robot,
            tick: last.tick,
            snapshot: last.supervisors,
        }
        .write(&self.out_dir)?;
        // Scheduled faults get their own row from the schedule.
        let name = match cause {
            Down::Killed | Down::Frozen => return Ok(()),
            Down::Notice => "fault:down",
            Down::Deadline => "fault:missed",
            Down::HostLost => "fault:host-lost",
        };
        recorder.record_fault(tick, robot as usize, name);
        Ok(())
    }

    /// `robot` takes part again from `tick`.
    fn mark_up(
        &mut self,
        robot: u32,
        tick: u64,
        world: &mut World,
        recorder: &mut Recorder,
    ) -> anyhow::Result<()> {
        self.robots[robot as usize] = Robot::Alive;
        self.restart_due[robot as usize] = false;
        world.set_alive(RobotId(robot), true);
        recorder.record_fault(tick, robot as usize, "fault:up");
        report(WorldReport::Up { tick, robot });
        Ok(())
    }

    /// Holds the tick until a restarted robot's replacement has joined (or the join timeout passes); `false`
    /// for a robot on a host without one (its host is away or could not start it: the robot stays down).
    fn wait_for_replacement(&mut self, robot: u32, link: &mut Link) -> anyhow::Result<bool> {
        let deadline = Instant::now() + self.join_timeout;
        while !link.agent_present(robot) {
            if Instant::now() > deadline {
                bail!(
                    "robot {robot}'s replacement agent did not join within {:?}",
                    self.join_timeout
                );
            }
            if !link.poll_agents(JOIN_POLL) {
                tracing::warn!(
                    robot,
                    "no replacement agent on its host: the robot stays down"
                );
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Takes the launcher's lines that arrived so far.
    fn drain(&mut self) {
        while let Ok(command) = self.commands.try_recv() {
            self.take(command);
        }
    }

    fn take(&mut self, command: WorldCommand) {
        match command {
            WorldCommand::Dead { robot, .. } if (robot as usize) < self.robots.len() => {
                self.notices.push(robot);
            }
            WorldCommand::Rejoin { robot, tick } if (robot as usize) < self.robots.len() => {
                self.rejoin_at[robot as usize] = Some(tick);
            }
            WorldCommand::Applied(tick) => self.applied.push(tick),
            WorldCommand::Respawn(robot) if (robot as usize) < self.robots.len() => {
                self.respawns.push(robot);
            }
            WorldCommand::KillHost(host) => self.host_kills.push(host),
            WorldCommand::Spawn { robot, pose } => self.arrivals.request_spawn(robot, pose),
            WorldCommand::Remove(robot) => self.arrivals.request_removal(robot),
            other => tracing::warn!(?other, "ignoring a launcher line that does not apply here"),
        }
    }

    /// Waits for `applied <tick>`, taking every other line on the way.
    fn wait_applied(&mut self, tick: u64) -> anyhow::Result<()> {
        let deadline = Instant::now() + self.apply_timeout;
        loop {
            if let Some(i) = self.applied.iter().position(|&t| t == tick) {
                self.applied.swap_remove(i);
                return Ok(());
            }
            let left = deadline.saturating_duration_since(Instant::now());
            match self.commands.recv_timeout(left) {
                Ok(command) => self.take(command),
                Err(RecvTimeoutError::Timeout) => {
                    bail!(
                        "the launcher did not apply the faults of tick {tick} within {:?} (limit \
                         fault_apply_timeout_ms)",
                        self.apply_timeout
                    )
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(anyhow::anyhow!("the launcher closed the world's input")).context(
                        format!("waiting for the faults of tick {tick} to be applied"),
                    );
                }
            }
        }
    }
}

/// The last command recorded for `robot` (idle at tick 0 if it never answered).
fn last_command(commands: &[ActuatorCommand], robot: u32) -> ActuatorCommand {
    commands
        .get(robot as usize)
        .copied()
        .unwrap_or_else(|| ActuatorCommand::idle(robot, 0))
}
