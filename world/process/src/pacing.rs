//! Real-time mode: hold each tick to its slot of 1 / ticks_per_second and record how well the run kept up.
//!
//! Tick k (1-based) owns the slot ending at `start + k * period`. A tick that finishes early sleeps until its slot
//! ends; a tick that finishes late is counted and the next slot is not shifted, so a late run shows its total lag
//! instead of silently drifting. Lateness can be inherited (slow first ticks push the following ones past their
//! slots until the run catches up), so the pacer also counts the ticks whose own work took longer than a period,
//! and the lag left at the last tick: none of those and no lag at the end means the run keeps up once going.

use std::time::{Duration, Instant};

/// Paces ticks in real-time mode and measures lateness; does nothing when real time is off.
pub struct Pacer {
    period: Option<Duration>,
    start: Instant,
    ticks_late: u64,
    max_lag: Duration,
    ticks_over_period: u64,
    last_lag: Duration,
    tick_started: Instant,
}

impl Pacer {
    /// A pacer starting now; `real_time` off makes [`Pacer::end_of_tick`] return at once.
    pub fn new(real_time: bool, ticks_per_second: u32) -> Pacer {
        Pacer {
            period: real_time.then(|| Duration::from_secs(1) / ticks_per_second.max(1)),
            start: Instant::now(),
            ticks_late: 0,
            max_lag: Duration::ZERO,
            ticks_over_period: 0,
            last_lag: Duration::ZERO,
            tick_started: Instant::now(),
        }
    }

    /// Called after tick `tick` is complete: waits for the end of its slot, or records that it overran it.
    pub fn end_of_tick(&mut self, tick: u64) {
        let Some(period) = self.period else { return };
        let slot_end = self.start + period * u32::try_from(tick).unwrap_or(u32::MAX);
        let now = Instant::now();
        if now - self.tick_started > period {
            self.ticks_over_period += 1;
        }
        self.last_lag = now.saturating_duration_since(slot_end);
        if now <= slot_end {
            std::thread::sleep(slot_end - now);
        } else {
            self.ticks_late += 1;
            self.max_lag = self.max_lag.max(now - slot_end);
        }
        self.tick_started = Instant::now();
    }

    /// What summary.json says about real-time mode (`null` when it was off).
    pub fn summary(&self, ticks: u64) -> serde_json::Value {
        match self.period {
            None => serde_json::Value::Null,
            Some(period) => serde_json::json!({
                "tick_period_ms": period.as_secs_f64() * 1e3,
                "ticks_late": self.ticks_late,
                "max_lag_ms": self.max_lag.as_secs_f64() * 1e3,
                "ticks_over_period": self.ticks_over_period,
                "lag_at_end_ms": self.last_lag.as_secs_f64() * 1e3,
                "kept_up": ticks > 0 && self.ticks_late == 0,
            }),
        }
    }
}
