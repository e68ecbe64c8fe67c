//! The operating-system side of the agent zygote (`robot-agent zygote`): forking an initialised agent process
//! into one process per robot, each a child of the process that started the zygote.
//!
//! Why: starting a program costs this machine kind about 0.6 ms of CPU even for `/bin/true` (exec, the dynamic
//! loader, page faults), and a robot agent another 0.8 ms to parse the configuration and build its controller.
//! A thousand robots started one after the other waited seconds for their first tick. The zygote pays the
//! program start and the configuration once; each robot then costs one fork of a small process.
//!
//! How: the fork is a raw `clone(CLONE_PARENT)`, so each agent's parent is the zygote's parent (the launcher or a
//! host daemon). That keeps every rule the launcher relies on: it reaps its agents, gets their exit statuses,
//! and each agent dies with it (`PR_SET_PDEATHSIG`); the zygote itself exits once it has forked every robot.
//! glibc's `fork()` takes no flags, so the clone bypasses it; that is sound only while the zygote has one thread
//! (no lock can be held by another thread), which [`Zygote::prepare`] checks, and the few things glibc's `fork()`
//! redoes in a child that matter to an agent are redone in [`Zygote::become_agent`].

use std::fs::OpenOptions;
use std::io;
use std::path::Path;

use nix::libc;
use nix::sys::signal::Signal;
use nix::unistd::{Pid, dup2_stderr, dup2_stdin, dup2_stdout, getppid, setpgid};

/// What the zygote learnt about itself before forking: its parent, and glibc's robust-futex list head of its
/// thread (the kernel forgets a thread's robust list in a forked child; glibc's `fork()` registers it again).
#[derive(Debug)]
pub struct Zygote {
    parent: Pid,
    robust_head: usize,
    robust_len: usize,
}

/// Which side of a fork this process is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Forked {
    /// The zygote: the new agent has this process id.
    Zygote(u32),
    /// The new agent.
    Agent,
}

impl Zygote {
    /// Prepares this process to fork agents; refused unless it has exactly one thread.
    pub fn prepare() -> io::Result<Zygote> {
        let threads = std::fs::read_dir("/proc/self/task")?.count();
        if threads != 1 {
            return Err(io::Error::other(format!(
                "the zygote has {threads} threads; it can only fork agents with one"
            )));
        }
        let mut head: usize = 0;
        let mut len: usize = 0;
        // SAFETY: get_robust_list writes a pointer and a length to the two locations given.
        let got = unsafe {
            libc::syscall(
                libc::SYS_get_robust_list,
                0,
                &mut head as *mut usize,
                &mut len as *mut usize,
            )
        };
        if got != 0 {
            return Err(io::Error::last_os_error());
        }
        Ok(Zygote {
            parent: getppid(),
            robust_head: head,
            robust_len: len,
        })
    }

    /// Forks one agent whose parent is the zygote's parent.
    pub fn fork_agent(&self) -> io::Result<Forked> {
        let flags = (libc::CLONE_PARENT | libc::SIGCHLD) as libc::c_ulong;
        // SAFETY: without CLONE_VM and with no new stack this is fork(2) with one more flag: the child gets a
        // copy of the address space. `prepare` checked that this process has one thread, so no lock of glibc
        // or of Rust is held by a thread the child would not have.
        let pid = unsafe { libc::syscall(libc::SYS_clone, flags, 0usize, 0usize, 0usize, 0usize) };
        match pid {
            -1 => Err(io::Error::last_os_error()),
            0 => Ok(Forked::Agent),
            pid => Ok(Forked::Zygote(pid as u32)),
        }
    }

    /// Turns a freshly forked child into a robot's agent process, as the launcher's own spawn would have
    /// started it: killed with its parent, in its own process group, standard output on /dev/null, standard
    /// error appended to `log`. Standard input stays the zygote's until [`Zygote::wait_for_the_run`].
    pub fn become_agent(&self, log: &Path) -> io::Result<()> {
        // SAFETY: the head is the one glibc registered for this (copied) thread, at the same address.
        let set = unsafe {
            libc::syscall(
                libc::SYS_set_robust_list,
                self.robust_head as *mut libc::c_void,
                self.robust_len,
            )
        };
        if set != 0 {
            return Err(io::Error::last_os_error());
        }
        nix::sys::prctl::set_pdeathsig(Signal::SIGKILL)?;
        // A parent that died before the prctl sends no signal any more: this agent must not start.
        if getppid() != self.parent {
            return Err(io::Error::other(
                "the launcher died while starting this agent",
            ));
        }
        setpgid(Pid::from_raw(0), Pid::from_raw(0))?;
        let null = OpenOptions::new().write(true).open("/dev/null")?;
        let log = OpenOptions::new().create(true).append(true).open(log)?;
        // Also closes the zygote's reply pipe in this process, so the launcher sees the end of the zygote's
        // replies when the zygote exits.
        dup2_stdout(&null)?;
        dup2_stderr(&log)?;
        Ok(())
    }

    /// Waits until the zygote's standard input ends (the launcher closes it when the run's shared memory
    /// exists), then puts /dev/null in its place.
    pub fn wait_for_the_run(&self) -> io::Result<()> {
        let mut buffer = [0u8; 64];
        loop {
            match nix::unistd::read(std::io::stdin(), &mut buffer) {
                Ok(0) => break,
                Ok(_) | Err(nix::errno::Errno::EINTR) => continue,
                Err(e) => return Err(e.into()),
            }
        }
        let null = OpenOptions::new().read(true).open("/dev/null")?;
        dup2_stdin(&null)?;
        Ok(())
    }

    /// Ends a forked agent with exit code `code` the way a forked child should: with `_exit`, which skips the
    /// exit handlers and library destructors the agent inherited from the zygote (they belong to the zygote's
    /// life, and each agent running them touched pages at exit that it never used otherwise). Nothing of the
    /// agent is left in a buffer: its log lines go to standard error unbuffered, its standard output is
    /// /dev/null.
    pub fn exit_agent(&self, code: i32) -> ! {
        // SAFETY: `_exit` has no preconditions; it ends the process without returning.
        unsafe { libc::_exit(code) }
    }
}
