//! The child processes of a run.
//!
//! Children run in their own process group, so a Ctrl-C in the terminal reaches only the launcher, which then
//! stops the run in order (world first, so it flushes its records). Each child also gets `SIGKILL` from the kernel
//! when the launcher dies (`PR_SET_PDEATHSIG`), so no robot outlives a killed launcher. Dropping [`Children`]
//! kills and reaps every child that is still running.

use std::os::unix::process::CommandExt;
use std::process::{Child, Command, ExitStatus};
use std::time::{Duration, Instant};

use nix::errno::Errno;
use nix::sys::signal::{Signal, kill};
use nix::sys::wait::{Id, WaitPidFlag, WaitStatus, waitid};
use nix::unistd::Pid;

/// Starts `command` as a supervised child: own process group, killed with the launcher.
pub fn spawn(command: &mut Command) -> std::io::Result<Child> {
    command.process_group(0);
    let parent = nix::unistd::getpid();
    // SAFETY: the closure runs between fork and exec and only makes async-signal-safe system calls (prctl,
    // getppid).
    unsafe {
        command.pre_exec(move || {
            nix::sys::prctl::set_pdeathsig(Signal::SIGKILL).map_err(std::io::Error::from)?;
            // A parent that died between fork and prctl sends no signal any more: the child must not start.
            if nix::unistd::getppid() != parent {
                return Err(std::io::Error::other(
                    "the launcher died while starting this process",
                ));
            }
            Ok(())
        });
    }
    command.spawn()
}

/// Sends `signal` to a child; a child that already exited is not an error.
pub fn signal(child: &Child, signal: Signal) {
    if let Ok(pid) = i32::try_from(child.id()) {
        let _ = kill(Pid::from_raw(pid), signal);
    }
}

/// Whether some child of this process has exited and waits to be reaped: one system call, which reaps nothing.
fn a_child_exited() -> bool {
    let flags = WaitPidFlag::WEXITED | WaitPidFlag::WNOHANG | WaitPidFlag::WNOWAIT;
    !matches!(
        waitid(Id::All, flags),
        Ok(WaitStatus::StillAlive) | Err(Errno::ECHILD)
    )
}

/// A run's processes: the world and one agent per robot (by robot index).
#[derive(Debug, Default)]
pub struct Children {
    /// The world process, while it runs.
    pub world: Option<Child>,
    /// Agent processes by robot index; `None` once reaped.
    pub agents: Vec<Option<Child>>,
}

impl Children {
    /// Agents that exited since the last call, with their robot index and exit status (reaped).
    pub fn reap_agents(&mut self) -> Vec<(u32, ExitStatus)> {
        let mut exited = Vec::new();
        // Asking each of 1,000 agents every supervision period cost the launcher 2-3 % of a core.
        if !a_child_exited() {
            return exited;
        }
        for (robot, slot) in self.agents.iter_mut().enumerate() {
            if let Some(child) = slot
                && let Ok(Some(status)) = child.try_wait()
            {
                exited.push((robot as u32, status));
                *slot = None;
            }
        }
        exited
    }

    /// SIGKILLs `robot`'s agent and reaps it; its exit status, or `None` if it had no running agent.
    pub fn kill_agent(&mut self, robot: u32) -> Option<ExitStatus> {
        let mut child = self.agents.get_mut(robot as usize)?.take()?;
        signal(&child, Signal::SIGKILL);
        child.wait().ok()
    }

    /// Number of agent processes not yet reaped.
    pub fn agents_running(&self) -> usize {
        self.agents.iter().filter(|a| a.is_some()).count()
    }

    /// Gives the agents up to `grace` ([`Limits::agent_exit_grace_ms`](crate::limits::Limits)) to exit by
    /// themselves (reaping every `period`), then kills the rest; returns how many had to be killed. Launchers and
    /// host daemons end their agents this way after the run's shared memory told them the run is over.
    pub fn end_agents(&mut self, grace: Duration, period: Duration) -> usize {
        let deadline = Instant::now() + grace;
        while self.agents_running() > 0 && Instant::now() < deadline {
            self.reap_agents();
            std::thread::sleep(period);
        }
        let stragglers = self.agents_running();
        self.kill_all();
        stragglers
    }

    /// Kills and reaps every child still running.
    pub fn kill_all(&mut self) {
        for child in self
            .agents
            .iter_mut()
            .flatten()
            .chain(self.world.iter_mut())
        {
            signal(child, Signal::SIGKILL);
        }
        for child in self
            .agents
            .iter_mut()
            .flatten()
            .chain(self.world.iter_mut())
        {
            let _ = child.wait();
        }
        self.agents.clear();
        self.world = None;
    }
}

impl Drop for Children {
    fn drop(&mut self) {
        self.kill_all();
    }
}
