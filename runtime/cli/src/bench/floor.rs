//! The lockstep floor, measured in the same hour as the rest: N forked processes with no work and no iceoryx2,
//! woken each tick by one `FUTEX_WAKE` broadcast on a shared word; each bumps one shared counter, and the last
//! one wakes the world. This is the reference the issue's targets are stated against ("a minimal
//! futex-broadcast lockstep of N processes with no work"); measuring it next to the bare lockstep turns the
//! comparison into a ratio that a noisy machine cannot skew.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use crate::bench::stats::median;
use swarm_contract::cpu::CpuMark;
use swarm_contract::transport::futex::{self, LineWord};

/// Ticks run before measuring.
const WARMUP_TICKS: usize = 100;
/// A tick that takes longer than this means a child died: give up instead of waiting forever.
const TICK_LIMIT: Duration = Duration::from_secs(10);

/// The shared words: the tick the children sleep on, the answer count the world sleeps on, the stop flag.
#[repr(C)]
struct Words {
    epoch: LineWord,
    acks: LineWord,
    stop: LineWord,
}

/// Why the floor could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum FloorError {
    /// A system call failed.
    #[error("{what}: {source}")]
    Os {
        /// The call.
        what: &'static str,
        /// Why.
        source: std::io::Error,
    },
    /// A tick was not answered in time.
    #[error("tick {tick}: {answered} of {robots} processes answered within {TICK_LIMIT:?}")]
    Unanswered {
        /// The tick.
        tick: u32,
        /// Answers received.
        answered: u32,
        /// Processes.
        robots: u32,
    },
}

/// The shared mapping and the children; dropping it stops, reaps and unmaps, also after a failure.
struct Floor {
    words: *mut Words,
    children: Vec<libc::pid_t>,
}

impl Floor {
    fn words(&self) -> &Words {
        // SAFETY: `words` is a live shared mapping of one `Words` until drop, accessed only through atomics.
        unsafe { &*self.words }
    }
}

impl Drop for Floor {
    fn drop(&mut self) {
        let words = self.words();
        words.stop.0.store(1, Ordering::Release);
        words.epoch.0.fetch_add(1, Ordering::AcqRel);
        futex::wake(&words.epoch.0, i32::MAX);
        for &pid in &self.children {
            // SAFETY: plain system calls on our own children.
            unsafe {
                let mut status = 0;
                if libc::waitpid(pid, &mut status, libc::WNOHANG) == 0 {
                    libc::kill(pid, libc::SIGKILL);
                    libc::waitpid(pid, &mut status, 0);
                }
            }
        }
        // SAFETY: unmapping exactly what `run` mapped; no reference outlives `self`.
        unsafe {
            libc::munmap(self.words.cast(), size_of::<Words>());
        }
    }
}

/// The body of one forked process: only atomics and raw system calls, which are safe after `fork`.
fn child(words: &Words, robots: u32) -> ! {
    // Forked before the first tick: the epoch it must see change is the initial 0, even if the world has
    // already opened tick 1 by the time this process runs.
    let mut seen = 0;
    loop {
        let epoch = words.epoch.0.load(Ordering::Acquire);
        if words.stop.0.load(Ordering::Acquire) != 0 {
            // SAFETY: leaves the forked child without running the parent's destructors.
            unsafe { libc::_exit(0) };
        }
        if epoch == seen {
            futex::wait(&words.epoch.0, seen, None);
            continue;
        }
        seen = epoch;
        if words.acks.0.fetch_add(1, Ordering::AcqRel) + 1 == robots {
            futex::wake(&words.acks.0, 1);
        }
    }
}

/// What the floor measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorReport {
    /// Robot-steps per second, the median over the windows.
    pub robot_steps_per_second: f64,
    /// CPU time of this process and every child per robot-step, over all windows ([`swarm_contract::cpu`]).
    pub cpu_per_robot_step: Duration,
}

/// Measures the floor with `robots` processes over `windows` windows of `ticks` ticks.
pub fn run(robots: u32, ticks: usize, windows: usize) -> Result<FloorReport, FloorError> {
    // SAFETY: a fresh anonymous shared mapping; zero-filled memory is a valid `Words`.
    let mapping = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            size_of::<Words>(),
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_SHARED | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    if mapping == libc::MAP_FAILED {
        return Err(FloorError::Os {
            what: "mapping the shared words",
            source: std::io::Error::last_os_error(),
        });
    }
    let mut floor = Floor {
        words: mapping.cast(),
        children: Vec::with_capacity(robots as usize),
    };
    for _ in 0..robots {
        // SAFETY: the child runs only `child` (atomics, futex, prctl, _exit), all async-signal-safe.
        match unsafe { libc::fork() } {
            -1 => {
                return Err(FloorError::Os {
                    what: "fork",
                    source: std::io::Error::last_os_error(),
                });
            }
            0 => {
                // SAFETY: as above; the child dies with the benchmark.
                unsafe { libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) };
                child(floor.words(), robots)
            }
            pid => floor.children.push(pid),
        }
    }
    let words = floor.words();
    let mut tick = 0u32;
    let mut step = || -> Result<(), FloorError> {
        tick += 1;
        words.acks.0.store(0, Ordering::Release);
        words.epoch.0.store(tick, Ordering::Release);
        futex::wake(&words.epoch.0, i32::MAX);
        let limit = Instant::now() + TICK_LIMIT;
        loop {
            let answered = words.acks.0.load(Ordering::Acquire);
            if answered == robots {
                return Ok(());
            }
            let now = Instant::now();
            if now >= limit {
                return Err(FloorError::Unanswered {
                    tick,
                    answered,
                    robots,
                });
            }
            futex::wait(&words.acks.0, answered, Some(limit - now));
        }
    };
    for _ in 0..WARMUP_TICKS {
        step()?;
    }
    let mut rates = Vec::with_capacity(windows);
    let child_pids = || {
        floor
            .children
            .iter()
            .filter_map(|&pid| u32::try_from(pid).ok())
    };
    let cpu = CpuMark::take(child_pids());
    for _ in 0..windows.max(1) {
        let window = Instant::now();
        for _ in 0..ticks.max(1) {
            step()?;
        }
        rates.push(f64::from(robots) * ticks.max(1) as f64 / window.elapsed().as_secs_f64());
    }
    let robot_steps = f64::from(robots) * (ticks.max(1) * windows.max(1)) as f64;
    Ok(FloorReport {
        robot_steps_per_second: median(&rates).unwrap_or(0.0),
        cpu_per_robot_step: cpu.per_step(child_pids(), robot_steps),
    })
}

#[cfg(test)]
mod tests {
    use super::run;

    #[test]
    fn every_forked_process_answers_every_tick_from_the_first() {
        // A process that starts after the world opened tick 1 must still answer it, or this fails after
        // TICK_LIMIT with "tick 1: 3 of 4 processes answered".
        let report = run(4, 20, 2).expect("the floor runs");
        assert!(report.robot_steps_per_second > 0.0);
    }
}
