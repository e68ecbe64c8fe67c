//! Command lines of the processes a run is made of.
//!
//! The launcher builds these command lines and the world and agent binaries parse them with the same types, so the
//! process contract lives in one place. Both binaries can also be started by hand with the same flags (see
//! `swarm-world --help`, `robot-agent --help`).

use std::path::PathBuf;

use clap::Args;

/// Where a run's shared memory lives: the iceoryx2 run name and root directory (see
/// [`RunSpec`](crate::transport::RunSpec)).
#[derive(Debug, Clone, PartialEq, Eq, Args)]
pub struct RunArgs {
    /// Name of the run; every shared-memory file of the run starts with `iox2_<run>_`.
    #[arg(long = "run")]
    pub run: String,
    /// Absolute iceoryx2 root directory of the run.
    #[arg(long = "iox-root")]
    pub iox_root: PathBuf,
}

impl RunArgs {
    /// The flags as a command line.
    pub fn to_args(&self) -> Vec<String> {
        vec![
            "--run".into(),
            self.run.clone(),
            "--iox-root".into(),
            self.iox_root.display().to_string(),
        ]
    }
}

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
    /// Ticks to run; 0 runs until the loop functions finish the experiment or the launcher stops it.
    #[arg(long, default_value_t = 0)]
    pub ticks: u64,
    /// Number of robots, overriding the configuration's e-puck `<distribute>` quantity.
    #[arg(long)]
    pub robots: Option<u32>,
    /// Run directory the world writes its records into.
    #[arg(long)]
    pub out: PathBuf,
    /// Milliseconds a tick waits for missing commands before it goes on without them.
    #[arg(long = "tick-deadline-ms")]
    pub tick_deadline_ms: Option<u64>,
    /// Milliseconds the world waits for every agent to join before the first tick.
    #[arg(long = "join-timeout-ms", default_value_t = 120_000)]
    pub join_timeout_ms: u64,
    /// Pace the ticks at the configuration's ticks_per_second instead of running as fast as possible.
    #[arg(long = "real-time")]
    pub real_time: bool,
    /// Faults given on the command line (`swarm run --fault`), added to the configuration's `<faults>`.
    #[arg(long = "fault")]
    pub faults: Vec<String>,
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
            "--join-timeout-ms".into(),
            self.join_timeout_ms.to_string(),
        ]);
        if let Some(robots) = self.robots {
            args.extend(["--robots".into(), robots.to_string()]);
        }
        if let Some(ms) = self.tick_deadline_ms {
            args.extend(["--tick-deadline-ms".into(), ms.to_string()]);
        }
        if self.real_time {
            args.push("--real-time".into());
        }
        for fault in &self.faults {
            args.extend(["--fault".into(), fault.clone()]);
        }
        args
    }
}

/// Flags of one robot's agent process (`robot-agent`).
#[derive(Debug, Clone, PartialEq, Eq, Args)]
pub struct AgentArgs {
    /// The run's shared memory.
    #[command(flatten)]
    pub run: RunArgs,
    /// Index of the robot in the run (0..N).
    #[arg(long)]
    pub robot: u32,
    /// The experiment configuration (the controller's parameters and supervisors come from it).
    #[arg(long)]
    pub config: PathBuf,
    /// Id of the robot's controller in the configuration's `<controllers>`.
    #[arg(long)]
    pub controller: String,
    /// Run seed; the robot's random stream is derived from it and the robot index.
    #[arg(long)]
    pub seed: u64,
    /// Number of robots of the run, when `swarm run --robots` changed the configuration's count.
    #[arg(long)]
    pub robots: Option<u32>,
    /// The controller's supervisor set, compiled once per run by the launcher; replaces the controller's
    /// `supervisors` parameter, so N agents do not synthesise the same models N times.
    #[arg(long = "compiled-supervisors")]
    pub compiled_supervisors: Option<PathBuf>,
    /// A restarted agent's resume point (`launcher::resume`): its supervisors continue from it.
    #[arg(long)]
    pub resume: Option<PathBuf>,
}

impl AgentArgs {
    /// The flags as a command line.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = self.run.to_args();
        args.extend([
            "--robot".into(),
            self.robot.to_string(),
            "--config".into(),
            self.config.display().to_string(),
            "--controller".into(),
            self.controller.clone(),
            "--seed".into(),
            self.seed.to_string(),
        ]);
        if let Some(robots) = self.robots {
            args.extend(["--robots".into(), robots.to_string()]);
        }
        if let Some(file) = &self.compiled_supervisors {
            args.extend(["--compiled-supervisors".into(), file.display().to_string()]);
        }
        if let Some(resume) = &self.resume {
            args.extend(["--resume".into(), resume.display().to_string()]);
        }
        args
    }
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct World {
        #[command(flatten)]
        args: WorldArgs,
    }

    #[derive(Parser)]
    struct Agent {
        #[command(flatten)]
        args: AgentArgs,
    }

    fn run() -> RunArgs {
        RunArgs {
            run: "sw1-2".into(),
            iox_root: PathBuf::from("/tmp/iceoryx2-sw1-2"),
        }
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
            tick_deadline_ms: Some(250),
            join_timeout_ms: 5_000,
            real_time: true,
            faults: vec!["kill robots=3 tick=50".into()],
        };
        let line = std::iter::once("swarm-world".to_string()).chain(args.to_args());
        assert_eq!(World::parse_from(line).args, args);
    }

    #[test]
    fn agent_command_line_parses_back_to_the_same_flags() {
        let args = AgentArgs {
            run: run(),
            robot: 7,
            config: PathBuf::from("configs/x.argos"),
            controller: "fdc".into(),
            seed: 124,
            robots: Some(40),
            compiled_supervisors: Some(PathBuf::from("runs/x/supervisors/fdc.ptsct")),
            resume: Some(PathBuf::from("runs/x/resume/robot-7.json")),
        };
        let line = std::iter::once("robot-agent".to_string()).chain(args.to_args());
        assert_eq!(Agent::parse_from(line).args, args);
    }
}
