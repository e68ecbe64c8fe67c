//! Peak resident memory of the agent processes of a run, read from `/proc` while the run goes on.
//!
//! The launcher reaps its children through `std::process::Child`, which reports no resource usage, so a
//! sampler thread reads the kernel's high-water mark (`VmHWM` in `/proc/<pid>/status`) of every child of this
//! process whose program is the agent. `VmHWM` only grows, so sampling every few hundred milliseconds loses at
//! most what an agent added in its last moments.

use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the sampler walks `/proc`.
const SAMPLE_PERIOD: Duration = Duration::from_millis(250);

/// Samples the peak RSS of this process's children named `program` until stopped.
pub struct RssSampler {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<HashMap<u32, u64>>,
}

impl RssSampler {
    /// Starts sampling children whose command name is `program` (as in `/proc/<pid>/comm`, at most 15 bytes).
    pub fn start(program: &str) -> RssSampler {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let comm: String = program.chars().take(15).collect();
        let parent = std::process::id();
        let thread = std::thread::spawn(move || {
            let mut peaks = HashMap::new();
            loop {
                sample(parent, &comm, &mut peaks);
                if flag.load(Ordering::Relaxed) {
                    return peaks;
                }
                std::thread::sleep(SAMPLE_PERIOD);
            }
        });
        RssSampler { stop, thread }
    }

    /// Stops sampling; returns each sampled agent's peak RSS in KiB, by process id.
    pub fn finish(self) -> HashMap<u32, u64> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap_or_default()
    }
}

fn sample(parent: u32, comm: &str, peaks: &mut HashMap<u32, u64>) {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return;
    };
    for entry in entries.flatten() {
        let Some(pid) = entry
            .file_name()
            .to_str()
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        if parent_and_comm(pid).is_none_or(|(ppid, name)| ppid != parent || name != comm) {
            continue;
        }
        if let Some(kib) = peak_rss_kib(pid) {
            let peak = peaks.entry(pid).or_insert(0);
            *peak = (*peak).max(kib);
        }
    }
}

/// Parent pid and command name from `/proc/<pid>/stat` ("pid (comm) state ppid ...").
fn parent_and_comm(pid: u32) -> Option<(u32, String)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let open = stat.find('(')?;
    let close = stat.rfind(')')?;
    let comm = stat.get(open + 1..close)?.to_owned();
    let ppid = stat
        .get(close + 1..)?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some((ppid, comm))
}

/// `VmHWM` of `/proc/<pid>/status`, in KiB.
fn peak_rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|kib| kib.parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sleeping_child_is_found_and_has_a_peak() {
        let mut child = std::process::Command::new("sleep")
            .arg("5")
            .spawn()
            .expect("spawn sleep");
        let mut peaks = HashMap::new();
        // The child may not have exec'd yet on the first walk; its comm then is still ours.
        for _ in 0..200 {
            sample(std::process::id(), "sleep", &mut peaks);
            if !peaks.is_empty() {
                break;
            }
            std::thread::yield_now();
        }
        let _ = child.kill();
        let _ = child.wait();
        assert!(
            peaks.get(&child.id()).is_some_and(|&kib| kib > 0),
            "{peaks:?}"
        );
    }
}
