//! The launcher's lines to the world process, on the world's standard input.
//!
//! `dead 3` (the OS reported robot 3's agent gone), `rejoin 3 58` (robot 3's replacement takes part from tick
//! 58: the world holds that tick until it has joined) and `applied 50` (every fault due at tick 50 is done: the
//! world may open the tick), `kill-host 1` (host 1 of the placement is to die: `swarm ctl kill-host`) and
//! `respawn 3` (robot 3's restart policy replaces its agent: the world takes it back once the replacement is
//! there; for a robot on a host the world has the host start it, resuming from the world's record). Plain text,
//! so a person can drive a world by hand.

use std::fmt;

/// One line from the launcher to the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WorldCommand {
    /// Robot's agent is gone (death notice).
    Dead(u32),
    /// Robot's replacement agent takes part from this tick on.
    Rejoin {
        /// The robot.
        robot: u32,
        /// The tick.
        tick: u64,
    },
    /// The faults due at this tick are applied.
    Applied(u64),
    /// Host with this index in the placement is to die.
    KillHost(u32),
    /// Robot gets a replacement agent.
    Respawn(u32),
}

impl fmt::Display for WorldCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldCommand::Dead(robot) => write!(f, "dead {robot}"),
            WorldCommand::Rejoin { robot, tick } => write!(f, "rejoin {robot} {tick}"),
            WorldCommand::Applied(tick) => write!(f, "applied {tick}"),
            WorldCommand::KillHost(host) => write!(f, "kill-host {host}"),
            WorldCommand::Respawn(robot) => write!(f, "respawn {robot}"),
        }
    }
}

impl WorldCommand {
    /// Parses one line; `None` for anything else.
    pub fn parse(line: &str) -> Option<WorldCommand> {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["dead", robot] => Some(WorldCommand::Dead(robot.parse().ok()?)),
            ["rejoin", robot, tick] => Some(WorldCommand::Rejoin {
                robot: robot.parse().ok()?,
                tick: tick.parse().ok()?,
            }),
            ["applied", tick] => Some(WorldCommand::Applied(tick.parse().ok()?)),
            ["kill-host", host] => Some(WorldCommand::KillHost(host.parse().ok()?)),
            ["respawn", robot] => Some(WorldCommand::Respawn(robot.parse().ok()?)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_parses_back_from_its_line() {
        for command in [
            WorldCommand::Dead(3),
            WorldCommand::Rejoin { robot: 3, tick: 58 },
            WorldCommand::Applied(50),
            WorldCommand::KillHost(1),
            WorldCommand::Respawn(4),
        ] {
            assert_eq!(WorldCommand::parse(&command.to_string()), Some(command));
        }
        assert_eq!(WorldCommand::parse("dead three"), None);
    }
}
