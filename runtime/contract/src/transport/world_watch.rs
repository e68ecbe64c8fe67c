//! Noticing that the world process ended, without a timed wait on the tick path.
//!
//! An agent sleeps on its chain's wake word between ticks. A timed futex wait arms and cancels a kernel timer on every
//! tick (the bare lockstep at N = 1,000 had a ~3 % lower tick p50 without it, BENCHMARKS.md), so agents sleep
//! without a timeout and a thread of their own watches the world instead: it blocks in poll(2) on a pidfd of the
//! world process, and when the world ends it sets [`WorldWatch::gone`] and calls the agent's wake-up. Where no
//! pidfd can be had (kernels before 5.3), [`WorldWatch::start`] returns `None` and the agent keeps a timed wait
//! ([`WorldEndNotice::Poll`]). An agent whose parent ends it with the world needs neither
//! ([`WorldEndNotice::Parent`]).

use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

/// The watching thread's stack: it only polls, and an agent should not pay a default 2 MiB reservation for it.
const WATCH_STACK: usize = 64 * 1024;

/// How an agent's waits notice the end of the world process ([`SyncBlock::wait_chain`](super::sync_block::SyncBlock::wait_chain)).
pub(crate) enum WorldEndNotice {
    /// The agent's watch thread sets a flag and wakes the agent: it sleeps without a timeout.
    Thread(WorldWatch),
    /// Watched on a kernel without pidfds: the waits check the process every second of silence.
    Poll,
    /// The agent's parent ends it with the world: it sleeps without a timeout and checks nothing.
    Parent,
}

impl WorldEndNotice {
    /// Watches process `pid` from a thread that calls `wake` when it ends; [`WorldEndNotice::Poll`] where no
    /// pidfd can be had.
    pub(crate) fn watch(pid: u32, wake: impl FnOnce() + Send + 'static) -> WorldEndNotice {
        WorldWatch::start(pid, wake).map_or(WorldEndNotice::Poll, WorldEndNotice::Thread)
    }
}

/// A thread that waits for one process to end.
pub(crate) struct WorldWatch {
    gone: Arc<AtomicBool>,
    /// Dropping it hangs up the pipe the thread polls besides the pidfd, which ends the thread.
    hang_up: Option<OwnedFd>,
    thread: Option<JoinHandle<()>>,
}

impl WorldWatch {
    /// Starts watching process `pid`; `wake` runs once on the watching thread after [`WorldWatch::gone`] became
    /// true. `None` when the kernel gives no pidfd for `pid` or no thread could be started; a process that is
    /// already gone counts as gone at once.
    pub(crate) fn start(pid: u32, wake: impl FnOnce() + Send + 'static) -> Option<WorldWatch> {
        let gone = Arc::new(AtomicBool::new(false));
        let pidfd = match pidfd_open(pid) {
            Ok(fd) => Some(fd),
            Err(e) if e.raw_os_error() == Some(libc::ESRCH) => None,
            Err(_) => return None,
        };
        let (listen, hang_up) = pipe()?;
        let flag = Arc::clone(&gone);
        let thread = std::thread::Builder::new()
            .name("world-watch".into())
            .stack_size(WATCH_STACK)
            .spawn(move || {
                let ended = pidfd.is_none_or(|pidfd| wait_for_exit(&pidfd, &listen));
                if ended {
                    flag.store(true, Ordering::Release);
                    wake();
                }
            })
            .ok()?;
        Some(WorldWatch {
            gone,
            hang_up: Some(hang_up),
            thread: Some(thread),
        })
    }

    /// Whether the watched process has ended.
    pub(crate) fn gone(&self) -> &AtomicBool {
        &self.gone
    }
}

impl Drop for WorldWatch {
    fn drop(&mut self) {
        self.hang_up = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Blocks until the process behind `pidfd` ends (`true`) or the other end of `listen` hangs up (`false`).
fn wait_for_exit(pidfd: &OwnedFd, listen: &OwnedFd) -> bool {
    let mut fds = [
        libc::pollfd {
            fd: pidfd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        },
        libc::pollfd {
            fd: listen.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        },
    ];
    loop {
        // SAFETY: `fds` is a live array of two pollfd structs for open descriptors.
        let ready = unsafe { libc::poll(fds.as_mut_ptr(), 2, -1) };
        if ready < 0 {
            if std::io::Error::last_os_error().raw_os_error() == Some(libc::EINTR) {
                continue;
            }
            return false;
        }
        if fds[1].revents != 0 {
            return false;
        }
        if fds[0].revents != 0 {
            return true;
        }
    }
}

fn pidfd_open(pid: u32) -> std::io::Result<OwnedFd> {
    let pid =
        libc::pid_t::try_from(pid).map_err(|_| std::io::Error::from_raw_os_error(libc::ESRCH))?;
    // SAFETY: pidfd_open takes a pid and flags and returns a new descriptor or -1.
    let fd = unsafe { libc::syscall(libc::SYS_pidfd_open, pid, 0) };
    if fd < 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: the kernel just returned this descriptor to us alone.
    Ok(unsafe { OwnedFd::from_raw_fd(fd as i32) })
}

/// A close-on-exec pipe: (read end, write end).
fn pipe() -> Option<(OwnedFd, OwnedFd)> {
    let mut fds = [0; 2];
    // SAFETY: `fds` has room for the two descriptors pipe2 writes.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return None;
    }
    // SAFETY: both descriptors were just created for us alone.
    Some(unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) })
}

#[cfg(test)]
mod tests {
    use std::process::Command;
    use std::sync::mpsc;

    use super::*;

    #[test]
    fn the_watch_reports_the_end_of_a_process_and_wakes_once() {
        let mut child = Command::new("sleep")
            .arg("600")
            .spawn()
            .expect("spawn sleep");
        let (woken, wakes) = mpsc::channel();
        let watch = WorldWatch::start(child.id(), move || woken.send(()).expect("test listens"))
            .expect("pidfds on this kernel");
        assert!(!watch.gone().load(Ordering::Acquire));
        child.kill().expect("kill");
        wakes.recv().expect("woken once the process ended");
        assert!(watch.gone().load(Ordering::Acquire));
        let _ = child.wait();
        drop(watch);
        assert!(wakes.recv().is_err(), "woken exactly once");
    }

    #[test]
    fn dropping_the_watch_of_a_live_process_ends_its_thread_without_a_wake() {
        let mut child = Command::new("sleep")
            .arg("600")
            .spawn()
            .expect("spawn sleep");
        let (woken, wakes) = mpsc::channel::<()>();
        let watch = WorldWatch::start(child.id(), move || woken.send(()).expect("test listens"))
            .expect("pidfds on this kernel");
        drop(watch);
        assert!(
            wakes.recv().is_err(),
            "the thread ended and dropped its wake-up unused"
        );
        let _ = child.kill();
        let _ = child.wait();
    }
}
