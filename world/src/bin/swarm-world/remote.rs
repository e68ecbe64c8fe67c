//! The world's link to its robots: the local lockstep over iceoryx2, or `swarm host` daemons over zenoh when the
//! run places its robots on hosts (`--hosts` or the experiment's `<hosts>`).
//!
//! Both give the main loop the same tick: fill the frames, get each robot's command or none. Deaths reach the
//! world differently (the launcher's notices for local agents, the hosts' replies and liveliness for remote ones)
//! and are applied to the world between ticks. A local run never opens a zenoh session.

use std::sync::mpsc::Receiver;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use swarm_runtime::launcher::hosts::HostsPlan;
use swarm_runtime::launcher::process_args::WorldArgs;
use swarm_runtime::launcher::world_control::WorldCommand;
use swarm_runtime::messages::{ActuatorCommand, SensorFrame};
use swarm_runtime::remote::codec::DEFAULT_MAX_PAYLOAD;
use swarm_runtime::remote::world_bridge::{HostEvent, RemoteHosts, RemoteOptions};
use swarm_runtime::transport::{TickOutcome, WorldLink};
use swarm_world::World;
use swarm_world::entities::RobotId;

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
    /// The link of a run whose robots are placed on hosts: opens the world's zenoh session.
    pub fn remote(
        plan: HostsPlan,
        args: &WorldArgs,
        controllers: Vec<String>,
        tick_deadline: Duration,
    ) -> anyhow::Result<Link> {
        let robots = controllers.len() as u32;
        let hosts = plan.place(robots);
        let config = std::path::absolute(&args.config).context("resolving the config path")?;
        let options = RemoteOptions {
            listen: plan.listen,
            zenoh: plan.zenoh,
            hosts,
            controllers,
            config,
            seed: args.seed,
            robots_override: args.robots,
            tick_deadline,
            join_timeout: Duration::from_millis(args.join_timeout_ms),
            max_payload: DEFAULT_MAX_PAYLOAD,
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
        sense: impl FnOnce(u64, &mut [SensorFrame]),
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

    /// Applies deaths and returns learnt from the hosts since the last call to the world (local deaths go
    /// through the fault driver).
    pub fn apply_life_changes(&mut self, world: &mut World) {
        match self {
            Link::Local(_) => {}
            Link::Remote(hosts) => {
                for (robot, alive) in hosts.take_changes() {
                    world.set_alive(RobotId(robot), alive);
                }
            }
        }
    }

    /// Carries out the launcher's lines that arrived so far in a run on hosts (`kill-host`); local runs take
    /// theirs through the fault driver.
    pub fn apply_launcher_commands(
        &mut self,
        commands: &Receiver<WorldCommand>,
    ) -> anyhow::Result<()> {
        let Link::Remote(hosts) = self else {
            return Ok(());
        };
        while let Ok(command) = commands.try_recv() {
            match command {
                WorldCommand::KillHost(index) => hosts.kill_host(index as usize)?,
                other => {
                    tracing::warn!(?other, "ignoring a launcher line that does not apply here")
                }
            }
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
        }))
    }
}
