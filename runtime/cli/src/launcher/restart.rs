//! Restart policy: whether and when the launcher starts a new agent for a robot whose agent ended.
//!
//! `never | on-failure | always`, at most `max_restarts` restarts within a sliding `restart_window`, and a
//! backoff that doubles with every restart already in the window. Windows are counted in ticks (simulated
//! time), so a scheduled fault's restart is the same in every run. This module only decides; it never starts
//! or signals a process.

use std::time::Duration;

use swarm_contract::config::faults::{RestartPolicy, RestartRule};

/// How an agent ended, as far as the policy cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// Killed, crashed, exited non-zero, or stopped answering.
    Failure,
    /// Exited successfully before the run ended.
    Success,
}

/// When to start the replacement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Restart {
    /// Which restart of this robot within the window this is (1 for the first).
    pub attempt: u32,
    /// The backoff as wall time (unscheduled deaths).
    pub delay: Duration,
    /// The backoff in ticks, at least 1 (scheduled faults: the robot rejoins this many ticks after its death).
    pub delay_ticks: u64,
}

/// One robot's restart history under its rule.
#[derive(Debug, Clone, Default)]
pub struct RestartTracker {
    rule: Option<RestartRule>,
    /// Ticks at which restarts were decided.
    history: Vec<u64>,
}

impl RestartTracker {
    /// A tracker for a robot governed by `rule` (`None`: never restart).
    pub fn new(rule: Option<RestartRule>) -> RestartTracker {
        RestartTracker {
            rule,
            history: Vec::new(),
        }
    }

    /// Restarts decided so far.
    pub fn restarts(&self) -> u32 {
        self.history.len() as u32
    }

    /// Decides on an agent that ended as `ending` at `tick` of a run at `ticks_per_second`; a `Some` is recorded
    /// as a restart.
    pub fn decide(&mut self, ending: Ending, tick: u64, ticks_per_second: u32) -> Option<Restart> {
        let rule = self.rule.as_ref()?;
        let wanted = match (rule.policy, ending) {
            (RestartPolicy::Never, _) => false,
            (RestartPolicy::OnFailure, ending) => ending == Ending::Failure,
            (RestartPolicy::Always, _) => true,
        };
        if !wanted {
            return None;
        }
        let window = (rule.restart_window * f64::from(ticks_per_second)).ceil() as u64;
        let in_window = self.history.iter().filter(|&&t| t + window > tick).count() as u32;
        if in_window >= rule.max_restarts {
            return None;
        }
        let seconds = rule.backoff * f64::from(1u32 << in_window.min(16));
        self.history.push(tick);
        Some(Restart {
            attempt: in_window + 1,
            delay: Duration::from_secs_f64(seconds),
            delay_ticks: ((seconds * f64::from(ticks_per_second)).ceil() as u64).max(1),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use swarm_contract::config::faults::Origin;

    fn rule(policy: RestartPolicy, max_restarts: u32, window: f64) -> RestartRule {
        RestartRule {
            policy,
            max_restarts,
            restart_window: window,
            backoff: 0.2,
            controller: None,
            robots: None,
            origin: Origin {
                path: "x".into(),
                location: Default::default(),
            },
        }
    }

    #[test]
    fn on_failure_restarts_up_to_max_restarts_with_doubling_backoff() {
        let mut t = RestartTracker::new(Some(rule(RestartPolicy::OnFailure, 2, 60.0)));
        let first = t.decide(Ending::Failure, 20, 10).expect("first restart");
        assert_eq!((first.attempt, first.delay_ticks), (1, 2));
        let second = t.decide(Ending::Failure, 60, 10).expect("second restart");
        assert_eq!((second.attempt, second.delay_ticks), (2, 4));
        assert_eq!(
            t.decide(Ending::Failure, 100, 10),
            None,
            "max_restarts reached"
        );
        assert_eq!(t.restarts(), 2);
    }

    #[test]
    fn restarts_older_than_the_window_no_longer_count() {
        let mut t = RestartTracker::new(Some(rule(RestartPolicy::OnFailure, 1, 5.0)));
        assert!(t.decide(Ending::Failure, 10, 10).is_some());
        assert!(t.decide(Ending::Failure, 59, 10).is_none());
        assert!(t.decide(Ending::Failure, 60, 10).is_some());
    }

    #[test]
    fn policies_differ_on_successful_exits() {
        let mut never = RestartTracker::new(Some(rule(RestartPolicy::Never, 3, 60.0)));
        let mut on_failure = RestartTracker::new(Some(rule(RestartPolicy::OnFailure, 3, 60.0)));
        let mut always = RestartTracker::new(Some(rule(RestartPolicy::Always, 3, 60.0)));
        assert!(never.decide(Ending::Failure, 1, 10).is_none());
        assert!(on_failure.decide(Ending::Success, 1, 10).is_none());
        assert!(always.decide(Ending::Success, 1, 10).is_some());
        assert!(
            RestartTracker::new(None)
                .decide(Ending::Failure, 1, 10)
                .is_none()
        );
    }
}
