//! Timer generators for plain SCT (docs/tasks.md section 2): a counter driven one step per tick by supervisor events.
//!
//! Plain SCT has no lower bounds, so a delay of n ticks is modelled by a timer plant with the events
//! `start_timer_x` (c, counter to 0), `timer_x_lw_n` (u, running and counter < n), `inc_timer_x` (c, counter + 1),
//! `timer_x_eq_n` (u, running and counter reached n) and `end_timer_x` (c, stop). The procedures here are generic
//! over any profile memory that holds a [`StepTimer`], so every plain-SCT profile reuses them.

use swarm_contract::messages::{ActuatorCommand, SensorFrame};

/// The memory of one timer generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepTimer {
    bound: u16,
    count: u16,
    running: bool,
}

impl StepTimer {
    /// A stopped timer that reaches its bound after `bound` increments.
    pub const fn new(bound: u16) -> Self {
        Self {
            bound,
            count: 0,
            running: false,
        }
    }

    /// Increments done since the last start.
    pub fn count(&self) -> u16 {
        self.count
    }

    /// Whether the timer was started and not yet ended.
    pub fn is_running(&self) -> bool {
        self.running
    }
}

/// `start_timer_x`: restart the count from zero.
pub fn start<S: AsMut<StepTimer>>(s: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {
    let t = s.as_mut();
    t.count = 0;
    t.running = true;
}

/// `inc_timer_x`: one step of the count.
pub fn inc<S: AsMut<StepTimer>>(s: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {
    let t = s.as_mut();
    t.count = t.count.saturating_add(1);
}

/// `end_timer_x`: the delay is over; stop the timer.
pub fn end<S: AsMut<StepTimer>>(s: &mut S, _: &SensorFrame, _: &mut ActuatorCommand) {
    s.as_mut().running = false;
}

/// `timer_x_lw_n`: the running timer has not reached its bound.
pub fn lower<S: AsRef<StepTimer>>(s: &S, _: &SensorFrame) -> bool {
    let t = s.as_ref();
    t.running && t.count < t.bound
}

/// `timer_x_eq_n`: the running timer has reached its bound.
pub fn reached<S: AsRef<StepTimer>>(s: &S, _: &SensorFrame) -> bool {
    let t = s.as_ref();
    t.running && t.count >= t.bound
}

impl AsRef<StepTimer> for StepTimer {
    fn as_ref(&self) -> &StepTimer {
        self
    }
}

impl AsMut<StepTimer> for StepTimer {
    fn as_mut(&mut self) -> &mut StepTimer {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stopped_timer_fires_neither_check() {
        let t = StepTimer::new(5);
        let f = SensorFrame::empty(0);
        assert!(!lower(&t, &f));
        assert!(!reached(&t, &f));
    }

    #[test]
    fn timer_reaches_bound_after_five_increments() {
        let mut t = StepTimer::new(5);
        let f = SensorFrame::empty(0);
        let mut c = ActuatorCommand::idle(0, 1);
        start(&mut t, &f, &mut c);
        for _ in 0..4 {
            inc(&mut t, &f, &mut c);
            assert!(lower(&t, &f) && !reached(&t, &f));
        }
        inc(&mut t, &f, &mut c);
        assert!(!lower(&t, &f) && reached(&t, &f));
        end(&mut t, &f, &mut c);
        assert!(!t.is_running() && !reached(&t, &f));
    }

    #[test]
    fn restart_counts_from_zero() {
        let mut t = StepTimer::new(5);
        let f = SensorFrame::empty(0);
        let mut c = ActuatorCommand::idle(0, 1);
        start(&mut t, &f, &mut c);
        inc(&mut t, &f, &mut c);
        start(&mut t, &f, &mut c);
        assert_eq!(t.count(), 0);
    }
}
