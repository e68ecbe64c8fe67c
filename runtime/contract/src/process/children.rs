//! The child processes of a run.
//!
//! Children run in their own process group, so a Ctrl-C in the terminal reaches only the launcher, which then
//! stops the run in order (world first, so it flushes its records). Each child also gets `SIGKILL` from the kernel
//! when the launcher dies (`PR_SET_PDEATHSIG`), so no robot outlives a killed launcher. Dropping [`Children`]
//! kills and reaps every child that is still running.

use std::os::unix::process::{CommandExt, ExitStatusExt};
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

/// A robot's agent process, a child of this process: started with [`spawn`] or forked by the agent zygote
/// (`robot-agent zygote`), which makes its children this process's children. Known by process id only, so that
/// both kinds are signalled and reaped the same way.
#[derive(Debug)]
pub struct AgentProcess {
    pid: Pid,
}

impl AgentProcess {
    /// The child with process id `pid`, which must be a child of this process that nobody else reaps.
    pub fn adopt(pid: u32) -> std::io::Result<AgentProcess> {
        let raw = i32::try_from(pid)
            .ok()
            .filter(|&p| p > 0)
            .ok_or_else(|| std::io::Error::other(format!("{pid} is not a process id")))?;
        Ok(AgentProcess {
            pid: Pid::from_raw(raw),
        })
    }

    /// Its process id.
    pub fn id(&self) -> u32 {
        self.pid.as_raw() as u32
    }

    /// Sends `signal`; a process that already exited is not an error.
    pub fn signal(&self, signal: Signal) {
        let _ = kill(self.pid, signal);
    }

    /// Its exit status if it has exited (reaping it), `None` while it runs.
    pub fn try_wait(&self) -> std::io::Result<Option<ExitStatus>> {
        self.wait_with(libc::WNOHANG)
    }

    /// Waits for it to exit and reaps it.
    pub fn wait(&self) -> std::io::Result<ExitStatus> {
        loop {
            match self.wait_with(0) {
                Ok(Some(status)) => return Ok(status),
                Ok(None) => continue,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            }
        }
    }

    fn wait_with(&self, flags: libc::c_int) -> std::io::Result<Option<ExitStatus>> {
        let mut status: libc::c_int = 0;
        // SAFETY: waitpid only writes the status word it is given.
        match unsafe { libc::waitpid(self.pid.as_raw(), &mut status, flags) } {
            0 => Ok(None),
            -1 => Err(std::io::Error::last_os_error()),
            _ => Ok(Some(ExitStatus::from_raw(status))),
        }
    }
}

impl From<Child> for AgentProcess {
    /// Takes over a child started with [`spawn`]; its standard streams, if any were piped, are closed.
    fn from(child: Child) -> AgentProcess {
        AgentProcess {
            pid: Pid::from_raw(child.id() as i32),
        }
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
    pub agents: Vec<Option<AgentProcess>>,
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
        let child = self.agents.get_mut(robot as usize)?.take()?;
        child.signal(Signal::SIGKILL);
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
        for agent in self.agents.iter().flatten() {
            agent.signal(Signal::SIGKILL);
        }
        if let Some(world) = &self.world {
            signal(world, Signal::SIGKILL);
        }
        for agent in self.agents.iter().flatten() {
            let _ = agent.wait();
        }
        if let Some(world) = &mut self.world {
            let _ = world.wait();
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
