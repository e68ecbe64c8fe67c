//! CPU time of a set of processes, read from `/proc/<pid>/stat` (user + system time).
//!
//! Throughput on a shared virtual machine swings by 10 % and more between minutes, with the hypervisor's steal
//! time; the CPU time the kernel charges to the processes themselves moves much less (steal is not charged to
//! them), so CPU time per robot-step ranks changes that throughput pairs cannot. The kernel accounts in clock
//! ticks (usually 10 ms), so only sums over many processes and seconds are meaningful.

use std::time::Duration;

/// The CPU time a set of processes had used when it was taken; [`CpuMark::per_step`] turns the time used since
/// into CPU per robot-step.
pub struct CpuMark(Duration);

impl CpuMark {
    /// Marks the CPU time used so far by this process and `pids`.
    pub fn take(pids: impl IntoIterator<Item = u32>) -> CpuMark {
        CpuMark(total_cpu(pids))
    }

    /// The CPU time this process and `pids` used since the mark, divided by `robot_steps`.
    pub fn per_step(&self, pids: impl IntoIterator<Item = u32>, robot_steps: f64) -> Duration {
        total_cpu(pids)
            .saturating_sub(self.0)
            .div_f64(robot_steps.max(1.0))
    }
}

/// The summed CPU time of this process and `pids` (processes that are gone count nothing).
fn total_cpu(pids: impl IntoIterator<Item = u32>) -> Duration {
    let ticks_per_second = clock_ticks_per_second();
    std::iter::once(std::process::id())
        .chain(pids)
        .filter_map(|pid| process_cpu(pid, ticks_per_second))
        .sum()
}

/// User plus system CPU time of process `pid` so far; `None` when it is gone or its stat is unreadable.
fn process_cpu(pid: u32, ticks_per_second: u64) -> Option<Duration> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    cpu_from_stat(&stat, ticks_per_second)
}

/// utime + stime of a `/proc/<pid>/stat` line: fields 14 and 15, counted after the parenthesised command name
/// (which may itself hold spaces and parentheses).
fn cpu_from_stat(stat: &str, ticks_per_second: u64) -> Option<Duration> {
    let after_name = &stat[stat.rfind(')')? + 1..];
    let mut fields = after_name.split_whitespace().skip(11);
    let utime: u64 = fields.next()?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    Some(Duration::from_secs_f64(
        (utime + stime) as f64 / ticks_per_second as f64,
    ))
}

fn clock_ticks_per_second() -> u64 {
    // SAFETY: sysconf only reads a configuration value.
    let ticks = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    u64::try_from(ticks).ok().filter(|&t| t > 0).unwrap_or(100)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn user_and_system_ticks_are_read_after_the_command_name() {
        let stat =
            "4242 (a (b) c) S 1 4242 4242 0 -1 4194560 100 0 0 0 250 125 0 0 20 0 1 0 100 0 0";
        assert_eq!(cpu_from_stat(stat, 100), Some(Duration::from_millis(3750)));
        assert_eq!(cpu_from_stat("garbage", 100), None);
    }

    #[test]
    fn a_live_process_has_a_cpu_time_and_a_missing_one_none() {
        assert!(process_cpu(std::process::id(), 100).is_some());
        assert_eq!(process_cpu(u32::MAX, 100), None);
    }
}
