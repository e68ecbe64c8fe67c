//! Progress for a run whose standard error is not a terminal (a log file, CI, a job array): plain log lines at a
//! low rate instead of a redrawn bar, which such a reader could not show. A run of known length says so at every
//! tenth of it; a run without a length every [`UNBOUNDED_PERIOD`].

use std::time::{Duration, Instant};

/// How often a run without a length reports its tick.
pub const UNBOUNDED_PERIOD: Duration = Duration::from_secs(10);

/// Where a run stands, said once per tenth of its length (or per period without one).
#[derive(Debug)]
pub struct PlainProgress {
    ticks: u64,
    robots: u32,
    next_tenth: u64,
    last_line: Instant,
}

impl PlainProgress {
    /// Progress of a run of `ticks` ticks (0: no length) with `robots` robots.
    pub fn new(ticks: u64, robots: u32) -> PlainProgress {
        PlainProgress {
            ticks,
            robots,
            next_tenth: 1,
            last_line: Instant::now(),
        }
    }

    /// The line to log now that the run reached `tick` with `alive` robots alive, if one is due.
    pub fn update(&mut self, tick: u64, alive: u32) -> Option<String> {
        let due = if self.ticks > 0 {
            let mut crossed = false;
            while self.next_tenth <= 10 && tick * 10 >= self.ticks * self.next_tenth {
                self.next_tenth += 1;
                crossed = true;
            }
            crossed
        } else {
            self.last_line.elapsed() >= UNBOUNDED_PERIOD
        };
        if !due {
            return None;
        }
        self.last_line = Instant::now();
        let of = if self.ticks > 0 {
            format!(
                "tick {tick}/{} ({}%)",
                self.ticks,
                tick.min(self.ticks) * 100 / self.ticks
            )
        } else {
            format!("tick {tick}")
        };
        Some(format!("{of}, {alive}/{} robots alive", self.robots))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_run_of_known_length_reports_each_tenth_once_even_when_ticks_are_skipped() {
        let mut progress = PlainProgress::new(200, 5);
        let lines: Vec<String> = [1, 19, 20, 35, 61, 120, 199, 200]
            .into_iter()
            .filter_map(|tick| progress.update(tick, 5))
            .collect();
        assert_eq!(
            lines,
            [
                "tick 20/200 (10%), 5/5 robots alive",
                "tick 61/200 (30%), 5/5 robots alive",
                "tick 120/200 (60%), 5/5 robots alive",
                "tick 199/200 (99%), 5/5 robots alive",
                "tick 200/200 (100%), 5/5 robots alive",
            ]
        );
    }
}
