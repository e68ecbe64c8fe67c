//! The open-file limit a run needs: the world holds about [`FILES_PER_ROBOT`] descriptors per robot (iceoryx2
//! services, the robot's command board and its node), so a large run hits the usual soft limit of 1,024 early,
//! and iceoryx2 then reports a corrupted service instead of the real reason. The launcher, the world and a host
//! daemon raise their soft limit up to the hard one before they start, and refuse a run that cannot fit with a
//! message that says what to do. Children inherit the raised limit.

/// Descriptors the world holds per robot, measured: 516 for 100 robots (2026-11-26), rounded up.
pub const FILES_PER_ROBOT: u64 = 6;
/// Descriptors the world holds whatever the robot count (logs, records, sockets, the sync block).
pub const FILES_BASE: u64 = 128;

/// A run that does not fit in the open-file limit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{robots} robots need about {needed} open files, but this process may open at most {hard} \
     (the hard limit, `ulimit -Hn`): raise it (e.g. `ulimit -n {needed}` as root or in limits.conf) or run \
     fewer robots"
)]
pub struct TooManyFiles {
    /// Robots of the run (or of the host's share).
    pub robots: u32,
    /// Descriptors the run needs.
    pub needed: u64,
    /// The hard limit.
    pub hard: u64,
}

/// Descriptors a process running `robots` robots needs.
pub fn needed(robots: u32) -> u64 {
    FILES_BASE + FILES_PER_ROBOT * u64::from(robots)
}

/// The soft limit to set for `needed` descriptors under limits `(soft, hard)`: `None` when the soft limit is
/// already enough, an error when even the hard limit is not.
pub fn plan(robots: u32, soft: u64, hard: u64) -> Result<Option<u64>, TooManyFiles> {
    let needed = needed(robots);
    if needed <= soft {
        Ok(None)
    } else if needed <= hard {
        Ok(Some(hard))
    } else {
        Err(TooManyFiles {
            robots,
            needed,
            hard,
        })
    }
}

/// Raises this process's soft open-file limit as far as a run of `robots` robots needs (up to the hard limit),
/// or says why the run cannot fit.
pub fn ensure(robots: u32) -> Result<(), TooManyFiles> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one rlimit into the value we own.
    if unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut limit) } != 0 {
        // Unknown limits: let the run try.
        return Ok(());
    }
    if let Some(soft) = plan(robots, limit.rlim_cur, limit.rlim_max)? {
        let raised = libc::rlimit {
            rlim_cur: soft,
            rlim_max: limit.rlim_max,
        };
        // SAFETY: setrlimit reads one rlimit we own; raising the soft limit up to the hard one is always allowed.
        unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, &raised) };
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_soft_limit_is_raised_to_the_hard_one_and_a_run_beyond_it_refused() {
        assert_eq!(plan(10, 1024, 4096), Ok(None));
        assert_eq!(plan(1000, 1024, 1 << 20), Ok(Some(1 << 20)));
        let err = plan(4000, 1024, 20_000).expect_err("24,128 > 20,000");
        assert_eq!(err.needed, 24_128);
        assert!(err.to_string().contains("ulimit -n 24128"), "{err}");
    }
}
