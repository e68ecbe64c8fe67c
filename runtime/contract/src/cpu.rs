//! CPU time of a set of processes, read from `/proc/<pid>/task/<tid>/schedstat`: the scheduler's own sum of the
//! time each thread ran, in nanoseconds.
//!
//! Throughput on a shared virtual machine swings by 10 % and more between minutes, with the hypervisor's steal
//! time; the CPU time the scheduler charges to the processes themselves moves less, so CPU time per robot-step
//! can rank changes that throughput pairs cannot. `utime` and `stime` of `/proc/<pid>/stat` are no use here:
//! they are sampled at the timer tick, and an agent that runs for microseconds per tick is mostly missed (they
//! once read 0.7 µs per robot-step for a run that kept both cores busy). Threads that end between two marks
//! take their time with them; the agents' threads live as long as the agents.

use std::time::Duration;

/// The CPU time a set of processes had used when it was taken; [`CpuMark::per_step`] turns the time used since
/// into CPU per robot-step.
pub struct CpuMark(Duration);

impl CpuMark {
    /// Marks the CPU time used so far by this process and `pids`.
    pub fn take(pids: impl IntoIterator<Item = u32>) -> CpuMark {
        Self::take_of(std::iter::once(std::process::id()).chain(pids))
    }

    /// Marks the CPU time used so far by `pids` alone.
    pub fn take_of(pids: impl IntoIterator<Item = u32>) -> CpuMark {
        CpuMark(total_cpu(pids))
    }

    /// The CPU time this process and `pids` used since the mark (taken with [`CpuMark::take`]), divided by
    /// `robot_steps`.
    pub fn per_step(&self, pids: impl IntoIterator<Item = u32>, robot_steps: f64) -> Duration {
        self.per_step_of(std::iter::once(std::process::id()).chain(pids), robot_steps)
    }

    /// The CPU time `pids` used since the mark (taken with [`CpuMark::take_of`]), divided by `steps`.
    pub fn per_step_of(&self, pids: impl IntoIterator<Item = u32>, steps: f64) -> Duration {
        total_cpu(pids)
            .saturating_sub(self.0)
            .div_f64(steps.max(1.0))
    }
}

/// The summed CPU time of `pids` (processes that are gone count nothing).
fn total_cpu(pids: impl IntoIterator<Item = u32>) -> Duration {
    pids.into_iter().map(process_cpu).sum()
}

/// CPU time of every live thread of process `pid` so far; zero when it is gone.
fn process_cpu(pid: u32) -> Duration {
    let Ok(threads) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return Duration::ZERO;
    };
    threads
        .filter_map(|thread| {
            let text = std::fs::read_to_string(thread.ok()?.path().join("schedstat")).ok()?;
            ran_for(&text)
        })
        .sum()
}

/// The first field of a `schedstat` line: nanoseconds on a CPU.
fn ran_for(schedstat: &str) -> Option<Duration> {
    let nanos = schedstat.split_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(nanos))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_schedstat_field_is_the_time_on_a_cpu() {
        assert_eq!(
            ran_for("511542364 234877448 995\n"),
            Some(Duration::from_nanos(511_542_364))
        );
        assert_eq!(ran_for("garbage"), None);
    }

    #[test]
    fn a_busy_process_has_a_cpu_time_and_a_missing_one_none() {
        let before = process_cpu(std::process::id());
        // Busy for several scheduler ticks, so that the kernel has brought the running thread's sum up to date.
        let busy_until = std::time::Instant::now() + Duration::from_millis(30);
        let mut x = 0u64;
        while std::time::Instant::now() < busy_until {
            x = std::hint::black_box(x.wrapping_mul(31).wrapping_add(1));
        }
        assert!(process_cpu(std::process::id()) > before);
        assert_eq!(process_cpu(u32::MAX), Duration::ZERO);
    }
}
