//! The world process's progress reports to the launcher: one line each on the world's standard output.
//!
//! Lines are plain text so a person can read them when starting the world by hand:
//! `ready 40`, `tick 120 answered 39 missing 0 dead 1`, `finished 600`. Anything else on the world's standard
//! output is ignored by the launcher.

use std::fmt;

/// One progress report of the world process.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorldReport {
    /// The services exist; agents may join. Carries the number of robots.
    Ready {
        /// Robots in the run.
        robots: u32,
    },
    /// A tick completed.
    Tick {
        /// The tick.
        tick: u64,
        /// Robots whose command arrived.
        answered: u32,
        /// Robots that missed the deadline.
        missing: u32,
        /// Robots known dead.
        dead: u32,
    },
    /// The experiment ended after this many ticks and every record is flushed.
    Finished {
        /// Ticks run.
        ticks: u64,
    },
}

impl fmt::Display for WorldReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldReport::Ready { robots } => write!(f, "ready {robots}"),
            WorldReport::Tick {
                tick,
                answered,
                missing,
                dead,
            } => write!(
                f,
                "tick {tick} answered {answered} missing {missing} dead {dead}"
            ),
            WorldReport::Finished { ticks } => write!(f, "finished {ticks}"),
        }
    }
}

impl WorldReport {
    /// Parses one line; `None` for anything that is not a report.
    pub fn parse(line: &str) -> Option<WorldReport> {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["ready", robots] => Some(WorldReport::Ready {
                robots: robots.parse().ok()?,
            }),
            [
                "tick",
                tick,
                "answered",
                answered,
                "missing",
                missing,
                "dead",
                dead,
            ] => Some(WorldReport::Tick {
                tick: tick.parse().ok()?,
                answered: answered.parse().ok()?,
                missing: missing.parse().ok()?,
                dead: dead.parse().ok()?,
            }),
            ["finished", ticks] => Some(WorldReport::Finished {
                ticks: ticks.parse().ok()?,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_report_parses_back_from_its_line() {
        for report in [
            WorldReport::Ready { robots: 40 },
            WorldReport::Tick {
                tick: 7,
                answered: 38,
                missing: 1,
                dead: 1,
            },
            WorldReport::Finished { ticks: 600 },
        ] {
            assert_eq!(WorldReport::parse(&report.to_string()), Some(report));
        }
    }

    #[test]
    fn other_lines_are_not_reports() {
        for line in [
            "",
            "ready",
            "ready forty",
            "tick 1 answered 2",
            "hello world",
        ] {
            assert_eq!(WorldReport::parse(line), None, "{line:?}");
        }
    }
}
