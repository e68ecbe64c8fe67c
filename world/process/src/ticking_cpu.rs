//! CPU time of the ticking phase, from the scheduler's own accounts (`swarm_contract::cpu`): the agents'
//! per robot-step and the world process's (every thread) per tick. Throughput on a shared machine swings with
//! the neighbours; the CPU an agent needs per step moves far less, so these two figures say where a tick's time
//! goes and rank changes that throughput alone cannot.
//!
//! Only local runs have them (the agents of hosts are other machines' processes), and the agents' figure only
//! when the agents that ended the run are the ones that started it: a replaced agent takes its CPU time with it.

use swarm_contract::cpu::CpuMark;

use crate::remote::Link;

/// The marks taken after the first tick (reading every agent's accounts takes tens of milliseconds at 1,000
/// robots, which the first tick should not wait for).
pub struct TickingCpu {
    agents: Vec<u32>,
    agents_mark: CpuMark,
    world_mark: CpuMark,
    first_tick: u64,
    first_steps: u64,
}

impl TickingCpu {
    /// Marks the CPU used so far by the agents of a local link and by this process, after `robot_steps`
    /// answered steps; `None` on hosts.
    pub fn start(link: &Link, robot_steps: u64) -> Option<TickingCpu> {
        let Link::Local(local) = link else {
            return None;
        };
        let agents = local.agent_pids();
        Some(TickingCpu {
            agents_mark: CpuMark::take_of(agents.iter().copied()),
            world_mark: CpuMark::take_of([std::process::id()]),
            agents,
            first_tick: link.tick(),
            first_steps: robot_steps,
        })
    }

    /// Whether the agents of `link` are still the ones marked (none was replaced); read on the world's thread,
    /// where the link stays.
    pub fn same_agents(&self, link: &Link) -> bool {
        match link {
            Link::Local(local) => local.agent_pids() == self.agents,
            Link::Remote(_) => false,
        }
    }

    /// The figures for summary.json at tick `tick` after `robot_steps` answered steps in all:
    /// `cpu_world_us_per_tick` and, when `same_agents`, `cpu_agents_us_per_robot_step`, both since the mark.
    /// Reads every agent's accounts: call it before the agents exit.
    pub fn summary(&self, tick: u64, robot_steps: u64, same_agents: bool) -> serde_json::Value {
        let robot_steps = robot_steps.saturating_sub(self.first_steps);
        let ticks = tick.saturating_sub(self.first_tick) as f64;
        let world = self.world_mark.per_step_of([std::process::id()], ticks);
        let agents = same_agents.then(|| {
            self.agents_mark
                .per_step_of(self.agents.iter().copied(), robot_steps as f64)
                .as_secs_f64()
                * 1e6
        });
        serde_json::json!({
            "cpu_world_us_per_tick": world.as_secs_f64() * 1e6,
            "cpu_agents_us_per_robot_step": agents,
        })
    }
}
