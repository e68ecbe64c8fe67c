//! The world process's progress reports to the launcher: one line each on the world's standard output.
//!
//! Lines are plain text so a person can read them when starting the world by hand:
//! `ready 40`, `tick 120 answered 39 missing 0 dead 1`, `finished 600`, and for faults `fault 50 kill 3`
//! (a scheduled fault is due; after the last one of a tick, `await 50`: the world waits for the launcher's
//! `applied 50`), `down 51 3 notice` (the world
//! marked robot 3 dead at tick 51; `deadline` when it missed one, `host` when its host was lost) and `up 80 3` (robot 3 takes part again from tick 80).
//! For joins and leaves (docs/joins.md): `joined 50 7` (robot 7 enters the arena at tick 50: the launcher starts
//! its agent before it answers `await 50`), `refused 50 7 <reason>` (it could not) and `left 60 7` (it left the
//! run: the launcher stops its agent). Anything else on the world's standard output is ignored by the launcher.

use std::fmt;

use crate::config::faults::FaultKind;

/// One progress report of the world process.
#[derive(Debug, Clone, PartialEq, Eq)]
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
    /// A scheduled fault is due before `tick`; the world has recorded it and waits for `applied <tick>`.
    Fault {
        /// The tick it happens at.
        tick: u64,
        /// What happens.
        kind: FaultKind,
        /// The robot, or `None` for the world itself.
        robot: Option<u32>,
    },
    /// Every fault due at `tick` has been reported; the world waits for `applied <tick>`.
    Await {
        /// The tick.
        tick: u64,
    },
    /// The world marked a robot dead from `tick` on (outside the schedule) and wrote its resume point.
    Down {
        /// First tick without the robot.
        tick: u64,
        /// The robot.
        robot: u32,
        /// How the world learnt of it.
        cause: DownCause,
    },
    /// A robot takes part again from `tick` on (restarted, thawed or answering again).
    Up {
        /// First tick with the robot.
        tick: u64,
        /// The robot.
        robot: u32,
    },
    /// The robot entered the arena for tick `tick`; its agent is to start now.
    Joined {
        /// The first tick it takes part in.
        tick: u64,
        /// The robot.
        robot: u32,
    },
    /// The robot could not enter the arena.
    Refused {
        /// The tick it was to join at.
        tick: u64,
        /// The robot.
        robot: u32,
        /// Why, for the user.
        reason: String,
    },
    /// The robot left the run before tick `tick`; its agent is to stop now.
    Left {
        /// The first tick without it.
        tick: u64,
        /// The robot.
        robot: u32,
    },
}

/// How the world learnt that a robot is gone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DownCause {
    /// The launcher's death notice (the OS reported the process ended).
    Notice,
    /// The robot missed a tick's deadline (frozen, hung, or gone without a notice).
    Deadline,
    /// The robot's host was lost (it is back when the host is).
    HostLost,
}

impl DownCause {
    /// The word on the report line.
    pub fn name(self) -> &'static str {
        match self {
            DownCause::Notice => "notice",
            DownCause::Deadline => "deadline",
            DownCause::HostLost => "host",
        }
    }
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
            WorldReport::Fault { tick, kind, robot } => match robot {
                Some(robot) => write!(f, "fault {tick} {} {robot}", kind.name()),
                None => write!(f, "fault {tick} {} world", kind.name()),
            },
            WorldReport::Down { tick, robot, cause } => {
                write!(f, "down {tick} {robot} {}", cause.name())
            }
            WorldReport::Up { tick, robot } => write!(f, "up {tick} {robot}"),
            WorldReport::Joined { tick, robot } => write!(f, "joined {tick} {robot}"),
            WorldReport::Refused {
                tick,
                robot,
                reason,
            } => write!(f, "refused {tick} {robot} {}", reason.replace('\n', " ")),
            WorldReport::Left { tick, robot } => write!(f, "left {tick} {robot}"),
            WorldReport::Await { tick } => write!(f, "await {tick}"),
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
            ["fault", tick, kind, robot] => Some(WorldReport::Fault {
                tick: tick.parse().ok()?,
                kind: FaultKind::from_name(kind)?,
                robot: match *robot {
                    "world" => None,
                    r => Some(r.parse().ok()?),
                },
            }),
            ["down", tick, robot, cause] => Some(WorldReport::Down {
                tick: tick.parse().ok()?,
                robot: robot.parse().ok()?,
                cause: [DownCause::Notice, DownCause::Deadline, DownCause::HostLost]
                    .into_iter()
                    .find(|c| c.name() == *cause)?,
            }),
            ["await", tick] => Some(WorldReport::Await {
                tick: tick.parse().ok()?,
            }),
            ["up", tick, robot] => Some(WorldReport::Up {
                tick: tick.parse().ok()?,
                robot: robot.parse().ok()?,
            }),
            ["joined", tick, robot] => Some(WorldReport::Joined {
                tick: tick.parse().ok()?,
                robot: robot.parse().ok()?,
            }),
            ["refused", tick, robot, reason @ ..] => Some(WorldReport::Refused {
                tick: tick.parse().ok()?,
                robot: robot.parse().ok()?,
                reason: reason.join(" "),
            }),
            ["left", tick, robot] => Some(WorldReport::Left {
                tick: tick.parse().ok()?,
                robot: robot.parse().ok()?,
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
            WorldReport::Fault {
                tick: 50,
                kind: FaultKind::Freeze,
                robot: Some(3),
            },
            WorldReport::Fault {
                tick: 90,
                kind: FaultKind::KillWorld,
                robot: None,
            },
            WorldReport::Down {
                tick: 51,
                robot: 3,
                cause: DownCause::Deadline,
            },
            WorldReport::Down {
                tick: 52,
                robot: 4,
                cause: DownCause::HostLost,
            },
            WorldReport::Up { tick: 80, robot: 3 },
            WorldReport::Await { tick: 50 },
            WorldReport::Joined { tick: 50, robot: 7 },
            WorldReport::Refused {
                tick: 50,
                robot: 7,
                reason: "(0.500, 0.500) is taken by robot 'ep3'".into(),
            },
            WorldReport::Left { tick: 60, robot: 7 },
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
