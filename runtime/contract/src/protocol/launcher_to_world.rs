//! From the launcher to the world process: its command line ([`WorldArgs`], parsed by the world with the same type)
//! and the lines the launcher writes on its standard input ([`WorldCommand`]).
//!
//! Those lines: `dead 3` (the OS reported robot 3's agent gone), `rejoin 3 58` (robot 3's replacement takes part from tick
//! 58: the world holds that tick until it has joined) and `applied 50` (every fault due at tick 50 is done: the
//! world may open the tick), `kill-host 1` (host 1 of the placement is to die: `swarm ctl kill-host`) and
//! `respawn 3` (robot 3's restart policy replaces its agent: the world takes it back once the replacement is
//! there; for a robot on a host the world has the host start it, resuming from the world's record), `spawn 7
//! [x y [heading]]` (`swarm ctl spawn`: absent robot 7 is to enter the arena) and `remove 7` (`swarm ctl
//! remove`: robot 7 is to leave the run). Plain text, so a person can drive a world by hand.

use std::fmt;
use std::path::PathBuf;

use clap::Args;

use super::launcher_to_agent::RunArgs;

/// Flags of the world process (`swarm-world`).
#[derive(Debug, Clone, PartialEq, Args)]
pub struct WorldArgs {
    /// The run's shared memory.
    #[command(flatten)]
    pub run: RunArgs,
    /// The experiment configuration.
    #[arg(long)]
    pub config: PathBuf,
    /// Run seed (already resolved: never 0-from-the-clock here).
    #[arg(long)]
    pub seed: u64,
    /// Ticks to run, replacing the experiment's `length` either way; 0 runs until the loop functions finish the
    /// experiment or the launcher stops it.
    #[arg(long, default_value_t = 0)]
    pub ticks: u64,
    /// Number of robots, overriding the configuration's e-puck `<distribute>` quantity.
    #[arg(long)]
    pub robots: Option<u32>,
    /// Run directory the world writes its records into.
    #[arg(long)]
    pub out: PathBuf,
    /// Limits overriding the configuration's `<system>` ones, as NAME=VALUE (repeatable; see
    /// [`Limits`](crate::limits::Limits)).
    #[arg(long = "limit", value_name = "NAME=VALUE")]
    pub limits: Vec<String>,
    /// Pace the ticks at the configuration's ticks_per_second instead of running as fast as possible.
    #[arg(long = "real-time")]
    pub real_time: bool,
    /// Faults given on the command line (`swarm run --fault`), added to the configuration's `<faults>`.
    #[arg(long = "fault")]
    pub faults: Vec<String>,
    /// What becomes of the record tables (`swarm run --records`).
    #[arg(long, value_enum, default_value_t = Records::Parquet)]
    pub records: Records,
}

/// What a run leaves of its record tables (trajectory, events, messages; docs/records.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Records {
    /// Parquet files: the world writes them beside the CSV files as the run goes, and the launcher removes the
    /// CSV files when it ends.
    #[default]
    Parquet,
    /// The CSV files the world appends to, only.
    Csv,
    /// None: no trajectory, events, messages or objects file (summary, snapshots and scene are still written),
    /// for runs whose records nobody reads and for measuring what recording costs.
    Off,
}

impl fmt::Display for Records {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Records::Parquet => "parquet",
            Records::Csv => "csv",
            Records::Off => "off",
        })
    }
}

impl WorldArgs {
    /// The flags as a command line.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = self.run.to_args();
        args.extend([
            "--config".into(),
            self.config.display().to_string(),
            "--seed".into(),
            self.seed.to_string(),
            "--ticks".into(),
            self.ticks.to_string(),
            "--out".into(),
            self.out.display().to_string(),
        ]);
        if let Some(robots) = self.robots {
            args.extend(["--robots".into(), robots.to_string()]);
        }
        for limit in &self.limits {
            args.extend(["--limit".into(), limit.clone()]);
        }
        if self.real_time {
            args.push("--real-time".into());
        }
        for fault in &self.faults {
            args.extend(["--fault".into(), fault.clone()]);
        }
        args.extend(["--records".into(), self.records.to_string()]);
        args
    }
}

/// Where `swarm ctl spawn` asks a robot to enter the arena.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpawnPose {
    /// Position in metres.
    pub x: f32,
    /// Position in metres.
    pub y: f32,
    /// Heading in degrees, counter-clockwise from +X (`None`: the heading it was given in the configuration).
    pub heading_deg: Option<f32>,
}

impl SpawnPose {
    /// Reads the words after a spawn request's robot: none, `x y`, or `x y heading`.
    pub fn parse_words(words: &[&str]) -> Result<Option<SpawnPose>, String> {
        let number = |w: &str| {
            w.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("'{w}' is not a number"))
        };
        match words {
            [] => Ok(None),
            [x, y] => Ok(Some(SpawnPose {
                x: number(x)?,
                y: number(y)?,
                heading_deg: None,
            })),
            [x, y, heading] => Ok(Some(SpawnPose {
                x: number(x)?,
                y: number(y)?,
                heading_deg: Some(number(heading)?),
            })),
            _ => Err("a spawn takes a robot, then optionally x y [heading in degrees]".into()),
        }
    }
}

/// The words `parse_words` reads: `x y` or `x y heading`.
impl fmt::Display for SpawnPose {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.x, self.y)?;
        match self.heading_deg {
            Some(heading) => write!(f, " {heading}"),
            None => Ok(()),
        }
    }
}

/// One line from the launcher to the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WorldCommand {
    /// A robot's agent is gone (death notice).
    Dead {
        /// The robot.
        robot: u32,
        /// The agent's process id, 0 when the launcher knows none. A notice that arrives after the robot's
        /// replacement agent has joined must not take the robot from the replacement.
        agent: u32,
    },
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
    /// `swarm ctl spawn`: the absent robot is to enter the arena at the next tick, where it was configured to
    /// or at `pose`.
    Spawn {
        /// The robot.
        robot: u32,
        /// Where, if not where the configuration put it.
        pose: Option<SpawnPose>,
    },
    /// `swarm ctl remove`: the robot is to leave the run at the next tick.
    Remove(u32),
}

impl fmt::Display for WorldCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldCommand::Dead { robot, agent } => write!(f, "dead {robot} {agent}"),
            WorldCommand::Rejoin { robot, tick } => write!(f, "rejoin {robot} {tick}"),
            WorldCommand::Applied(tick) => write!(f, "applied {tick}"),
            WorldCommand::KillHost(host) => write!(f, "kill-host {host}"),
            WorldCommand::Respawn(robot) => write!(f, "respawn {robot}"),
            WorldCommand::Spawn { robot, pose: None } => write!(f, "spawn {robot}"),
            WorldCommand::Spawn {
                robot,
                pose: Some(pose),
            } => write!(f, "spawn {robot} {pose}"),
            WorldCommand::Remove(robot) => write!(f, "remove {robot}"),
        }
    }
}

impl WorldCommand {
    /// Parses one line; `None` for anything else.
    pub fn parse(line: &str) -> Option<WorldCommand> {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["dead", robot, agent] => Some(WorldCommand::Dead {
                robot: robot.parse().ok()?,
                agent: agent.parse().ok()?,
            }),
            ["rejoin", robot, tick] => Some(WorldCommand::Rejoin {
                robot: robot.parse().ok()?,
                tick: tick.parse().ok()?,
            }),
            ["applied", tick] => Some(WorldCommand::Applied(tick.parse().ok()?)),
            ["kill-host", host] => Some(WorldCommand::KillHost(host.parse().ok()?)),
            ["respawn", robot] => Some(WorldCommand::Respawn(robot.parse().ok()?)),
            ["remove", robot] => Some(WorldCommand::Remove(robot.parse().ok()?)),
            ["spawn", robot, rest @ ..] => Some(WorldCommand::Spawn {
                robot: robot.parse().ok()?,
                pose: SpawnPose::parse_words(rest).ok()?,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;
    use crate::protocol::launcher_to_agent::tests::run;

    #[derive(Parser)]
    struct World {
        #[command(flatten)]
        args: WorldArgs,
    }

    #[test]
    fn world_command_line_parses_back_to_the_same_flags() {
        let args = WorldArgs {
            run: run(),
            config: PathBuf::from("configs/x.argos"),
            seed: 124,
            ticks: 600,
            robots: Some(40),
            out: PathBuf::from("runs/x"),
            limits: vec!["tick_deadline_ms=250".into(), "join_timeout_ms=5000".into()],
            real_time: true,
            faults: vec!["kill robots=3 tick=50".into()],
            records: Records::Csv,
        };
        let line = std::iter::once("swarm-world".to_string()).chain(args.to_args());
        assert_eq!(World::parse_from(line).args, args);
    }

    #[test]
    fn every_command_parses_back_from_its_line() {
        for command in [
            WorldCommand::Dead {
                robot: 3,
                agent: 4242,
            },
            WorldCommand::Rejoin { robot: 3, tick: 58 },
            WorldCommand::Applied(50),
            WorldCommand::KillHost(1),
            WorldCommand::Respawn(4),
            WorldCommand::Spawn {
                robot: 7,
                pose: None,
            },
            WorldCommand::Spawn {
                robot: 7,
                pose: Some(SpawnPose {
                    x: 0.5,
                    y: -1.25,
                    heading_deg: Some(90.0),
                }),
            },
            WorldCommand::Remove(7),
        ] {
            assert_eq!(WorldCommand::parse(&command.to_string()), Some(command));
        }
        assert_eq!(WorldCommand::parse("dead three"), None);
    }
}
