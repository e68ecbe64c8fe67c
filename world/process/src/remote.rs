//! The world's link to its robots: the local lockstep over iceoryx2, or `swarm host` daemons over zenoh when the
//! run places its robots on hosts (`--hosts` or the experiment's `<hosts>`).
//!
//! Both give the main loop the same tick: fill the frames, get each robot's command or none, and give the fault
//! driver the same handles on agents: stop waiting for one, wait for it again, replace it. Locally the launcher
//! signals and restarts processes and the link only changes who the ticks wait for; on hosts each of these is a
//! fault order to the robot's host. Deaths reach the world differently (the launcher's notices for local agents,
//! the hosts' replies and liveliness for remote ones). A local run never opens a zenoh session.

use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use swarm_contract::limits::Limits;
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame, SupervisorSnapshot};
use swarm_contract::protocol::launcher_to_world::WorldArgs;
use swarm_contract::run_dir;
use swarm_contract::transport::{CommandStatus, TickOutcome, WorldLink};
use swarm_remote::plan::HostsPlan;
use swarm_remote::world_bridge::{HostEvent, RemoteHosts, RemoteOptions, RobotNews};
use swarm_remote::world_to_host::OrderAction;

/// Why the ticks stop waiting for a robot's agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The schedule kills it (locally the launcher sends the signal).
    Kill,
    /// The schedule freezes it (likewise).
    Freeze,
    /// It missed a tick's deadline; its agent may still run.
    Skip,
}

/// The compiled supervisor sets the launcher left in the run directory, by controller id, for the hosts.
fn compiled_supervisors(
    run_dir: &std::path::Path,
    controllers: &[String],
) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let mut ids: Vec<&String> = controllers.iter().collect();
    ids.sort();
    ids.dedup();
    let mut sets = Vec::new();
    for id in ids {
        let path = run_dir::compiled_supervisors(run_dir, id)?;
        if path.is_file() {
            let bytes =
                std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
            sets.push((id.clone(), bytes));
        }
    }
    Ok(sets)
}

/// Where the world's robots run.
// One value per world process, created once: the size difference between the variants costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum Link {
    /// Agents on this machine (their deaths and restarts go through the fault driver).
    Local(WorldLink),
    /// Agents on `swarm host` daemons.
    Remote(RemoteHosts),
}

impl Link {
    /// Ends the run for the agents as the world exits: a local run's shared memory is left to the launcher,
    /// which removes it whole (see `WorldLink::end_run`); hosts are told the run is over.
    pub fn end(self) {
        match self {
            Link::Local(link) => link.end_run(),
            Link::Remote(hosts) => drop(hosts),
        }
    }

    /// The link of a run whose robots are placed on hosts: opens the world's zenoh session.
    pub fn remote(
        mut plan: HostsPlan,
        args: &WorldArgs,
        controllers: Vec<String>,
        limits: &Limits,
        pin_agents: bool,
        realtime_priority: bool,
        mail: bool,
    ) -> anyhow::Result<Link> {
        let robots = controllers.len() as u32;
        let hosts = plan.place(robots);
        let config = std::path::absolute(&args.config).context("resolving the config path")?;
        let compiled_supervisors = compiled_supervisors(&args.out, &controllers)?;
        let keys = plan.load_keys().context("reading the hosts' keys")?;
        let options = RemoteOptions {
            listen: plan.listen,
            zenoh: plan.zenoh,
            hosts,
            controllers,
            config,
            seed: args.seed,
            robots_override: args.robots,
            tick_deadline: limits.tick_deadline(),
            join_timeout: limits.join_timeout(),
            agent_exit_grace: limits.agent_exit_grace(),
            pin_agents,
            realtime_priority,
            mail,
            max_payload: limits.max_host_message(),
            compiled_supervisors,
            limits: args.limits.clone(),
            keys,
        };
        let run = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64)
            ^ (u64::from(std::process::id()) << 40);
        let hosts = RemoteHosts::start(options, robots, run).context("listening for hosts")?;
        Ok(Link::Remote(hosts))
    }

    /// Waits until every robot has an agent (locally) or every host runs its share.
    pub fn wait(&mut self, timeout: Duration) -> anyhow::Result<()> {
        match self {
            Link::Local(link) => link
                .wait_for_agents(timeout)
                .context("waiting for the robot agents to join"),
            Link::Remote(hosts) => hosts
                .wait_for_hosts(timeout)
                .context("waiting for the hosts"),
        }
    }

    /// Robots in the run.
    pub fn robots(&self) -> usize {
        self.statuses().len()
    }

    /// The last tick run.
    pub fn tick(&self) -> u64 {
        match self {
            Link::Local(link) => link.tick(),
            Link::Remote(hosts) => hosts.tick(),
        }
    }

    /// Runs one tick; see `WorldLink::tick_with`.
    pub fn tick_with(
        &mut self,
        sense: impl FnMut(u64, usize, &mut [SensorFrame]),
    ) -> anyhow::Result<TickOutcome> {
        Ok(match self {
            Link::Local(link) => link.tick_with(sense)?,
            Link::Remote(hosts) => hosts.tick_with(sense)?,
        })
    }

    /// The command `robot` sent in the last tick.
    pub fn command(&self, robot: u32) -> Option<&ActuatorCommand> {
        match self {
            Link::Local(link) => link.command(robot),
            Link::Remote(hosts) => hosts.command(robot),
        }
    }

    /// Puts `inbox` into `robot`'s inbox for the next tick; see `WorldLink::post`.
    pub fn post(&mut self, robot: u32, inbox: &mut Mailbox) {
        match self {
            Link::Local(link) => {
                link.post(robot, inbox);
            }
            Link::Remote(hosts) => hosts.post(robot, inbox),
        }
    }

    /// The messages `robot` sent in the last tick; see `WorldLink::outbox`.
    pub fn outbox(&self, robot: u32) -> Option<Mailbox> {
        match self {
            Link::Local(link) => link.outbox(robot),
            Link::Remote(hosts) => hosts.outbox(robot),
        }
    }

    /// The robots' command statuses of the last tick.
    pub fn statuses(&self) -> &[CommandStatus] {
        match self {
            Link::Local(link) => link.statuses(),
            Link::Remote(hosts) => hosts.statuses(),
        }
    }

    /// Ticks stop waiting for `robot`'s agent (on a host: killed or frozen there as well).
    pub fn stop(&mut self, robot: u32, why: Stop) -> anyhow::Result<()> {
        match self {
            Link::Local(link) => link.mark_dead(robot)?,
            Link::Remote(hosts) => {
                let action = match why {
                    Stop::Kill => OrderAction::Kill,
                    Stop::Freeze => OrderAction::Freeze,
                    Stop::Skip => OrderAction::Skip,
                };
                // A host that cannot carry it out is lost or its agent is gone: the robot is out either way.
                hosts.order(robot, action)?;
            }
        }
        Ok(())
    }

    /// Ticks wait for `robot`'s agent again (on a host, `thaw` also continues it there); `false` when its agent
    /// is gone.
    pub fn revive(&mut self, robot: u32, thaw: bool) -> anyhow::Result<bool> {
        Ok(match self {
            Link::Local(link) => link.revive(robot),
            Link::Remote(hosts) => {
                let action = if thaw {
                    OrderAction::Thaw
                } else {
                    OrderAction::Revive
                };
                hosts.order(robot, action)?
            }
        })
    }

    /// The launcher replaces `robot`'s agent, resuming from `snapshot` of tick `tick`: locally the launcher
    /// starts the process; on a host the host does, and this returns once it joined (`false`: it could not).
    pub fn respawn(
        &mut self,
        robot: u32,
        tick: u64,
        snapshot: SupervisorSnapshot,
    ) -> anyhow::Result<bool> {
        Ok(match self {
            Link::Local(_) => true,
            Link::Remote(hosts) => hosts.order(
                robot,
                OrderAction::Respawn {
                    tick,
                    snapshot: Box::new(snapshot),
                },
            )?,
        })
    }

    /// Whether `robot` has an agent the ticks can wait for (e.g. a replacement has joined).
    pub fn agent_present(&self, robot: u32) -> bool {
        match self {
            Link::Local(link) => link.agent_present(robot),
            Link::Remote(hosts) => hosts.agent_present(robot),
        }
    }

    /// Waits up to `poll` for local agents to join (serving replacements' requests); `false` for hosts, whose
    /// replacements have joined when their order was answered, so there is nothing to wait for.
    pub fn poll_agents(&mut self, poll: Duration) -> bool {
        match self {
            Link::Local(link) => {
                let _ = link.wait_for_agents(poll);
                true
            }
            Link::Remote(_) => false,
        }
    }

    /// What the hosts reported since the last call (nothing for a local run, whose deaths come from the launcher).
    pub fn take_news(&mut self, news: &mut Vec<RobotNews>) {
        if let Link::Remote(hosts) = self {
            news.extend(hosts.take_news());
        }
    }

    /// `swarm ctl kill-host`: tells host `index` of the placement to die (nothing for a local run).
    pub fn kill_host(&self, index: usize) -> anyhow::Result<()> {
        if let Link::Remote(hosts) = self {
            hosts.kill_host(index)?;
        }
        Ok(())
    }

    /// What happened to each host, for `summary.json` (`None` for a local run).
    pub fn summary(&self) -> Option<serde_json::Value> {
        let Link::Remote(hosts) = self else {
            return None;
        };
        let per_host: Vec<serde_json::Value> = hosts
            .host_events()
            .map(|(share, events)| {
                let ticks = |lost: bool| -> Vec<u64> {
                    events
                        .iter()
                        .filter_map(|e| match (e, lost) {
                            (HostEvent::Lost { tick }, true)
                            | (HostEvent::Rejoined { tick }, false) => Some(*tick),
                            _ => None,
                        })
                        .collect()
                };
                serde_json::json!({
                    "name": share.name,
                    "robots": share.robots,
                    "lost_at_ticks": ticks(true),
                    "rejoined_at_ticks": ticks(false),
                })
            })
            .collect();
        let dropped = hosts.dropped();
        Some(serde_json::json!({
            "hosts": per_host,
            "stale_payloads": dropped.stale,
            "rejected_payloads": dropped.rejected,
            "unauthenticated_payloads": dropped.unauthenticated,
        }))
    }
}
