//! From the launcher (or a host daemon) to a robot's agent: its command line, and how the process is started.
//!
//! The launcher and the host daemon build the command line with [`AgentArgs`] and start the agent with
//! [`start_agent`]; the agent parses its command line with the same type (flattened into its own flags, which add
//! the manual-use ones), so the two ends cannot drift apart. An agent can also be started by hand with the same
//! flags (see `robot-agent --help`).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use clap::Args;

use crate::process::children;
use crate::transport::tune_agent_command;

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

/// Flags of one robot's agent process (`robot-agent`) that say which robot of which run it is.
///
/// Launched agents get every field that matters from [`AgentArgs::launched`]; the options stay optional so that
/// a person can start an agent by hand (`--check` without a run's shared memory, a controller without a
/// configuration).
#[derive(Debug, Clone, PartialEq, Eq, Args)]
pub struct AgentArgs {
    /// Run name (shared by every process of the run); every shared-memory file of the run starts with
    /// `iox2_<run>_`.
    #[arg(long)]
    pub run: String,
    /// Absolute iceoryx2 root directory of the run (not needed with `--check`).
    #[arg(long = "iox-root")]
    pub iox_root: Option<PathBuf>,
    /// Index of the robot in the run (0..N).
    #[arg(long)]
    pub robot: u32,
    /// Slot of the robot in the local transport when it differs from --robot: a `swarm host` numbers its share
    /// 0..k locally, while --robot stays the run-wide id that seeds the random stream and picks the controller.
    #[arg(long)]
    pub slot: Option<u32>,
    /// Run seed; the robot's random stream is derived from it and the robot index. Default: the configuration's
    /// `random_seed`, or 0 without --config.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Experiment configuration (.argos); the robot runs the controller its `<e-puck>` names.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// With --config: id of the robot's controller in `<controllers>` (default: the one its `<e-puck>` names).
    #[arg(long, requires = "config")]
    pub controller: Option<String>,
    /// Number of robots of the run, when `swarm run --robots` changed the configuration's count (with --config).
    #[arg(long, requires = "config")]
    pub robots: Option<u32>,
    /// With --config: load this compiled supervisor-set file instead of the supervisors the controller's
    /// parameters name (the launcher compiles each controller's models once per run, so N agents do not
    /// synthesise the same models N times).
    #[arg(long = "compiled-supervisors", requires = "config")]
    pub compiled_supervisors: Option<PathBuf>,
    /// Resume point of a restarted robot ([`crate::protocol::resume`]): its supervisors continue from it.
    #[arg(long)]
    pub resume: Option<PathBuf>,
    /// Limits overriding the configuration's `<system>` ones, as NAME=VALUE (repeatable; see
    /// [`Limits`](crate::limits::Limits)): the run's `swarm run --limit` flags.
    #[arg(long = "limit", value_name = "NAME=VALUE")]
    pub limits: Vec<String>,
}

impl AgentArgs {
    /// The flags of robot `robot` of `run`, running `controller` of `config` with the run's `seed`; the other
    /// options unset.
    pub fn launched(
        run: &RunArgs,
        robot: u32,
        config: &Path,
        controller: &str,
        seed: u64,
    ) -> AgentArgs {
        AgentArgs {
            run: run.run.clone(),
            iox_root: Some(run.iox_root.clone()),
            robot,
            slot: None,
            seed: Some(seed),
            config: Some(config.to_path_buf()),
            controller: Some(controller.to_owned()),
            robots: None,
            compiled_supervisors: None,
            resume: None,
            limits: Vec::new(),
        }
    }

    /// The flags as a command line.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = vec![
            "--run".into(),
            self.run.clone(),
            "--robot".into(),
            self.robot.to_string(),
        ];
        let mut option = |flag: &str, value: Option<String>| {
            if let Some(value) = value {
                args.extend([flag.to_owned(), value]);
            }
        };
        let path = |p: &Option<PathBuf>| p.as_ref().map(|p| p.display().to_string());
        option("--iox-root", path(&self.iox_root));
        option("--slot", self.slot.map(|s| s.to_string()));
        option("--seed", self.seed.map(|s| s.to_string()));
        option("--config", path(&self.config));
        option("--controller", self.controller.clone());
        option("--robots", self.robots.map(|r| r.to_string()));
        option("--compiled-supervisors", path(&self.compiled_supervisors));
        option("--resume", path(&self.resume));
        for limit in &self.limits {
            args.extend(["--limit".to_owned(), limit.clone()]);
        }
        args
    }
}

/// Starts `program` (the agent program) as the agent `args` describe, its standard error into `log`, with the
/// process settings every agent gets ([`tune_agent_command`]) and in its own process group. The launcher and the
/// host daemon both start their agents here.
pub fn start_agent(program: &Path, args: &AgentArgs, log: File) -> std::io::Result<Child> {
    children::spawn(
        tune_agent_command(&mut Command::new(program))
            .args(args.to_args())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log),
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Agent {
        #[command(flatten)]
        args: AgentArgs,
    }

    pub(crate) fn run() -> RunArgs {
        RunArgs {
            run: "sw1-2".into(),
            iox_root: PathBuf::from("/tmp/iceoryx2-sw1-2"),
        }
    }

    #[test]
    fn agent_command_line_parses_back_to_the_same_flags() {
        let mut args = AgentArgs::launched(&run(), 7, Path::new("configs/x.argos"), "fdc", 124);
        args.slot = Some(2);
        args.robots = Some(40);
        args.compiled_supervisors = Some(PathBuf::from("runs/x/supervisors/fdc.ptsct"));
        args.resume = Some(PathBuf::from("runs/x/resume/robot-7.json"));
        args.limits = vec!["agent_join_retry_ms=500".into()];
        let line = std::iter::once("robot-agent".to_string()).chain(args.to_args());
        assert_eq!(Agent::parse_from(line).args, args);
    }

    #[test]
    fn a_launched_agent_names_its_run_robot_configuration_controller_and_seed() {
        let args = AgentArgs::launched(&run(), 7, Path::new("configs/x.argos"), "fdc", 124);
        assert_eq!(
            args.to_args().join(" "),
            "--run sw1-2 --robot 7 --iox-root /tmp/iceoryx2-sw1-2 --seed 124 --config configs/x.argos \
             --controller fdc"
        );
    }
}
