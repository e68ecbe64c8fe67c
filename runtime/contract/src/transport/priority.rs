//! Real-time scheduling for the lockstep: the thread that ticks the world (or a host's share) and every agent
//! run under `SCHED_RR`, the world's thread one level above the agents.
//!
//! Under the normal scheduler every wake-up and every sleep of an agent goes through its fair-share bookkeeping (load
//! averages, group runqueues, the choice whether the woken agent should preempt its waker), once per agent per tick.
//! Round-robin real-time scheduling does none of that: woken agents queue behind the one running on their CPU, which
//! goes on until it sleeps (long before its 100 ms slice ends; the slice only bounds how long a runaway agent keeps the
//! others of its CPU waiting). The world's thread, one level above, is never held up by an agent: it senses and starts
//! every chain at once, and runs as soon as the last answer wakes it. At N = 1,000 on two CPUs this took the whole
//! system from 125.5k to 142.5k robot-steps per second (median of four alternated pairs; docs/transport.md, "Real-time
//! priorities").
//!
//! Every thread that enters real time does so with `SCHED_RESET_ON_FORK`: the threads and processes it starts
//! afterwards (the recorder, agents spawned by a host) run normally until they choose otherwise. Real-time
//! scheduling needs `CAP_SYS_NICE` or an `RLIMIT_RTPRIO` of at least [`WORLD_PRIORITY`]; without either,
//! [`enter_realtime`] fails and the run goes on with normal priorities.

use std::io;

/// `SCHED_RR` priority of the thread that ticks a world or a host's share.
pub const WORLD_PRIORITY: i32 = 2;
/// `SCHED_RR` priority of an agent.
pub const AGENT_PRIORITY: i32 = 1;

/// Makes the calling thread `SCHED_RR` at `priority`; threads and processes it starts afterwards run under the
/// normal policy.
pub fn enter_realtime(priority: i32) -> io::Result<()> {
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: sched_setscheduler only reads `param`; pid 0 is the calling thread.
    let result =
        unsafe { libc::sched_setscheduler(0, libc::SCHED_RR | libc::SCHED_RESET_ON_FORK, &param) };
    if result == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// For the thread about to tick a world or a host's share: enters real time at [`WORLD_PRIORITY`] if `wanted`
/// and says in the log what it got. Returns whether it runs at real-time priority, which is whether the agents
/// should too ([`LinkConfig::realtime`](super::LinkConfig::realtime)).
pub fn tick_at_realtime(wanted: bool) -> bool {
    if !wanted {
        return false;
    }
    match enter_realtime(WORLD_PRIORITY) {
        Ok(()) => {
            tracing::info!(
                "ticking and agents run at real-time priority (SCHED_RR {WORLD_PRIORITY} and {AGENT_PRIORITY})"
            );
            true
        }
        Err(e) => {
            tracing::warn!(
                "real-time priority unavailable ({e}): ticking and agents run at normal priority \
                 (CAP_SYS_NICE or an rtprio limit of {WORLD_PRIORITY} allows it; docs/transport.md)"
            );
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The calling thread's policy, without the reset-on-fork flag, and its priority.
    fn policy() -> (i32, i32) {
        // SAFETY: pid 0 is the calling thread; sched_getparam fills `param`.
        unsafe {
            let mut param = libc::sched_param { sched_priority: 0 };
            libc::sched_getparam(0, &mut param);
            (
                libc::sched_getscheduler(0) & !libc::SCHED_RESET_ON_FORK,
                param.sched_priority,
            )
        }
    }

    #[test]
    fn a_realtime_thread_starts_normal_threads() {
        // A thread of its own, so that the test runner's threads keep their policy.
        let seen = std::thread::spawn(|| {
            enter_realtime(AGENT_PRIORITY).map(|()| {
                let started = std::thread::spawn(policy)
                    .join()
                    .expect("the child thread ends");
                (policy(), started)
            })
        })
        .join()
        .expect("the test thread ends");
        match seen {
            Ok((own, started)) => {
                assert_eq!(own, (libc::SCHED_RR, AGENT_PRIORITY));
                assert_eq!(started, (libc::SCHED_OTHER, 0), "reset on fork");
            }
            // Without CAP_SYS_NICE or an rtprio limit the call must fail cleanly, as runs expect.
            Err(e) => assert_eq!(e.raw_os_error(), Some(libc::EPERM), "{e}"),
        }
    }
}
