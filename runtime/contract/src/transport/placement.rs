//! Where an agent runs: each chain on one CPU.
//!
//! The agents of a chain are woken together and run one after the other; left to itself, the scheduler often moved the
//! next one to the other CPU: in a virtual machine that means an interrupt to a halted CPU, an idle gap on both, and an
//! agent whose cache lines are on the other core. Pinned, a chain's agents take turns on one CPU, warm in its cache,
//! and the chains share the CPUs the run may use, in turn. At 100 robots on two CPUs this took the whole system from
//! 149k to 196k robot-steps per second in alternated runs (docs/transport.md, "Agents pinned by chain").
//!
//! Pinning is an optimisation only: when the CPUs cannot be read or set, the agent runs unpinned and says so.

use std::io;

/// Pins the calling thread to the CPU of `robot`'s chain (chains of `chain_len` robots) among the CPUs
/// this thread may use now; returns that CPU.
pub(crate) fn pin_to_chain_cpu(robot: u32, chain_len: u32) -> io::Result<usize> {
    let allowed = allowed_cpus()?;
    let cpu = chain_cpu((robot / chain_len.max(1)) as usize, &allowed);
    // SAFETY: a zeroed cpu_set_t is a valid empty set; CPU_SET and sched_setaffinity only read and write it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        if libc::sched_setaffinity(0, size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(io::Error::last_os_error());
        }
    }
    Ok(cpu)
}

/// The CPU of chain `chain` among `allowed` (from [`allowed_cpus`]): the chains take the CPUs in turn.
fn chain_cpu(chain: usize, allowed: &[usize]) -> usize {
    allowed[chain % allowed.len()]
}

/// The CPU each of `chains` chains runs on when its agents pin themselves, for agents that inherit the calling
/// thread's CPUs (the launcher's or the host's, like the world's); `None` when they cannot be read.
pub(crate) fn chain_cpus(chains: usize) -> Option<Vec<usize>> {
    let allowed = allowed_cpus().ok()?;
    Some(
        (0..chains)
            .map(|chain| chain_cpu(chain, &allowed))
            .collect(),
    )
}

/// The CPU the calling thread runs on at this moment; `None` where the kernel does not say.
pub(crate) fn current_cpu() -> Option<usize> {
    // SAFETY: sched_getcpu takes no arguments and touches no memory of ours.
    usize::try_from(unsafe { libc::sched_getcpu() }).ok()
}

/// The CPUs the calling thread may run on, ascending; never empty.
fn allowed_cpus() -> io::Result<Vec<usize>> {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; sched_getaffinity fills it and CPU_ISSET only reads it.
    let allowed: Vec<usize> = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Err(io::Error::last_os_error());
        }
        (0..libc::CPU_SETSIZE as usize)
            .filter(|&cpu| libc::CPU_ISSET(cpu, &set))
            .collect()
    };
    if allowed.is_empty() {
        return Err(io::Error::other("no CPU is allowed"));
    }
    Ok(allowed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_take_the_allowed_cpus_in_turn() {
        let allowed = allowed_cpus().expect("the test may read its CPUs");
        assert!(!allowed.is_empty());
        // Threads of their own, so that the test runner's threads keep their CPUs.
        let (first, after) = std::thread::spawn(|| {
            let cpu = pin_to_chain_cpu(3, 10).expect("pin robot 3 (chain 0)");
            (cpu, allowed_cpus().expect("read the CPUs back"))
        })
        .join()
        .expect("the pinning thread ends");
        assert_eq!(first, allowed[0], "chain 0 takes the first allowed CPU");
        assert_eq!(after, vec![first], "the thread may run on that CPU only");
        let second =
            std::thread::spawn(|| pin_to_chain_cpu(15, 10).expect("pin robot 15 (chain 1)"))
                .join()
                .expect("the pinning thread ends");
        assert_eq!(
            second,
            allowed[1 % allowed.len()],
            "chain 1 takes the next allowed CPU"
        );
        assert_eq!(
            chain_cpus(2),
            Some(vec![first, second]),
            "the world expects each chain where its agents pin themselves"
        );
    }

    #[test]
    fn the_current_cpu_is_one_the_thread_may_use() {
        let allowed = allowed_cpus().expect("the test may read its CPUs");
        let here = current_cpu().expect("Linux says where a thread runs");
        assert!(allowed.contains(&here), "{here} among {allowed:?}");
    }
}
