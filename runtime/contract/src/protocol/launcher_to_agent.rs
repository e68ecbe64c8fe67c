//! From the launcher (or a host daemon) to a robot's agent: its command line, and how the process is started.
//!
//! The launcher and the host daemon build the command line with [`AgentArgs`] and start the agent with
//! [`start_agent`]; the agent parses its command line with the same type (flattened into its own flags, which add
//! the manual-use ones), so the two ends cannot drift apart. An agent can also be started by hand with the same
//! flags (see `robot-agent --help`).

use std::fmt;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::str::FromStr;

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

/// Flags of the agent zygote (`robot-agent zygote`): one agent process that loads the run's configuration once
/// and then forks one agent per robot, so that N robots cost N forks of a small, initialised process instead of N
/// program starts. Each forked agent is a child of the process that started the zygote (the launcher or a host
/// daemon), which signals and reaps it like any agent ([`AgentProcess`](crate::process::children::AgentProcess)).
///
/// The zygote reads the robots to start from its standard input, one [`ZygoteOrder`] per line, up to an empty
/// line (or the end of input), and answers each with one [`ZygoteReply`] line on its standard output; then it
/// exits. Its agents keep its standard input and join the run only when that input ends: so the launcher can
/// have every agent forked and its controller built while the world is still creating the run's shared memory,
/// and let them all in at once by closing the pipe when the world is ready.
#[derive(Debug, Clone, PartialEq, Eq, Args)]
pub struct ZygoteArgs {
    /// The run's shared memory.
    #[command(flatten)]
    pub run: RunArgs,
    /// Run seed.
    #[arg(long)]
    pub seed: u64,
    /// Experiment configuration (.argos).
    #[arg(long)]
    pub config: PathBuf,
    /// Number of robots of the run, when `swarm run --robots` changed the configuration's count.
    #[arg(long)]
    pub robots: Option<u32>,
    /// A controller's compiled supervisor set, as CONTROLLER=FILE (repeatable; see
    /// [`AgentArgs::compiled_supervisors`]).
    #[arg(long = "compiled", value_name = "CONTROLLER=FILE")]
    pub compiled: Vec<String>,
    /// Folder of the agents' logs: robot `i` writes `robot-<i>.log` there (appending).
    #[arg(long)]
    pub logs: PathBuf,
    /// The run's `--limit` overrides, as NAME=VALUE (repeatable).
    #[arg(long = "limit", value_name = "NAME=VALUE")]
    pub limits: Vec<String>,
}

impl ZygoteArgs {
    /// The flags as a command line (after the `zygote` subcommand).
    pub fn to_args(&self) -> Vec<String> {
        let mut args = self.run.to_args();
        args.extend(["--seed".into(), self.seed.to_string()]);
        args.extend(["--config".into(), self.config.display().to_string()]);
        if let Some(robots) = self.robots {
            args.extend(["--robots".into(), robots.to_string()]);
        }
        for compiled in &self.compiled {
            args.extend(["--compiled".into(), compiled.clone()]);
        }
        args.extend(["--logs".into(), self.logs.display().to_string()]);
        for limit in &self.limits {
            args.extend(["--limit".into(), limit.clone()]);
        }
        args
    }

    /// The compiled supervisor file of `controller`, if one was given.
    pub fn compiled_for(&self, controller: &str) -> Option<PathBuf> {
        self.compiled.iter().find_map(|entry| {
            let (id, file) = entry.split_once('=')?;
            (id == controller).then(|| PathBuf::from(file))
        })
    }
}

/// One robot for the zygote to start: its run-wide index and its slot in the local transport (the same on the
/// launcher; a host daemon numbers its share locally). One line: `<robot> <slot>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ZygoteOrder {
    /// Run-wide robot index: picks the controller and seeds the robot's random stream.
    pub robot: u32,
    /// Slot in the local transport.
    pub slot: u32,
}

impl fmt::Display for ZygoteOrder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.robot, self.slot)
    }
}

impl FromStr for ZygoteOrder {
    type Err = String;

    fn from_str(line: &str) -> Result<ZygoteOrder, String> {
        let mut words = line.split_whitespace().map(str::parse::<u32>);
        match (words.next(), words.next(), words.next()) {
            (Some(Ok(robot)), Some(Ok(slot)), None) => Ok(ZygoteOrder { robot, slot }),
            _ => Err(format!("`{line}` is not `<robot> <slot>`")),
        }
    }
}

/// The zygote's answer for one robot: the process id of its agent, or why none was started. One line:
/// `<robot> started <pid>` or `<robot> failed <reason>`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ZygoteReply {
    /// The robot's agent runs as process `pid`.
    Started {
        /// Robot index.
        robot: u32,
        /// Its agent's process id.
        pid: u32,
    },
    /// No agent was started for the robot.
    Failed {
        /// Robot index.
        robot: u32,
        /// Why (one line).
        reason: String,
    },
}

impl fmt::Display for ZygoteReply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ZygoteReply::Started { robot, pid } => write!(f, "{robot} started {pid}"),
            ZygoteReply::Failed { robot, reason } => {
                write!(f, "{robot} failed {}", reason.replace('\n', " "))
            }
        }
    }
}

impl FromStr for ZygoteReply {
    type Err = String;

    fn from_str(line: &str) -> Result<ZygoteReply, String> {
        let bad = || format!("`{line}` is not a zygote reply");
        let mut parts = line.splitn(3, ' ');
        let robot = parts.next().and_then(|r| r.parse().ok()).ok_or_else(bad)?;
        match (parts.next(), parts.next()) {
            (Some("started"), Some(pid)) => Ok(ZygoteReply::Started {
                robot,
                pid: pid.parse().map_err(|_| bad())?,
            }),
            (Some("failed"), Some(reason)) => Ok(ZygoteReply::Failed {
                robot,
                reason: reason.to_owned(),
            }),
            _ => Err(bad()),
        }
    }
}

/// Starts the agent zygote `program zygote <args>` with the process settings every agent gets, its standard input
/// and output piped (orders in, replies out) and its standard error into `log`.
///
/// `LD_BIND_NOW=1` has the dynamic loader bind every symbol of the shared libraries (glibc's among them binds
/// lazily) once, when the zygote starts, instead of each forked agent running the loader's symbol lookup on its
/// first call of each function and copying the page it patched (docs/transport.md, "Starting the agents").
pub fn start_zygote(program: &Path, args: &ZygoteArgs, log: File) -> std::io::Result<Child> {
    children::spawn(
        tune_agent_command(&mut Command::new(program))
            .env("LD_BIND_NOW", "1")
            .arg("zygote")
            .args(args.to_args())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
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

    #[derive(Parser)]
    struct Zygote {
        #[command(flatten)]
        args: ZygoteArgs,
    }

    #[test]
    fn zygote_command_line_parses_back_to_the_same_flags() {
        let args = ZygoteArgs {
            run: run(),
            seed: 9,
            config: PathBuf::from("/c/x.argos"),
            robots: Some(12),
            compiled: vec!["fdc=/r/supervisors/fdc.ptsct".into()],
            logs: PathBuf::from("/r/logs"),
            limits: vec!["agent_join_retry_ms=500".into()],
        };
        let line = std::iter::once("zygote".to_string()).chain(args.to_args());
        let parsed = Zygote::parse_from(line).args;
        assert_eq!(parsed, args);
        assert_eq!(
            parsed.compiled_for("fdc"),
            Some(PathBuf::from("/r/supervisors/fdc.ptsct"))
        );
        assert_eq!(parsed.compiled_for("other"), None);
    }

    #[test]
    fn zygote_lines_read_back() {
        let order = ZygoteOrder { robot: 7, slot: 2 };
        assert_eq!(order.to_string().parse(), Ok(order));
        assert!("7".parse::<ZygoteOrder>().is_err());
        assert!("7 2 1".parse::<ZygoteOrder>().is_err());
        for reply in [
            ZygoteReply::Started {
                robot: 3,
                pid: 4242,
            },
            ZygoteReply::Failed {
                robot: 3,
                reason: "clone: out of memory".into(),
            },
        ] {
            assert_eq!(reply.to_string().parse(), Ok(reply));
        }
        let multi = ZygoteReply::Failed {
            robot: 1,
            reason: "a\nb".into(),
        };
        assert_eq!(multi.to_string(), "1 failed a b");
        assert!("x started 1".parse::<ZygoteReply>().is_err());
        assert!("1 started".parse::<ZygoteReply>().is_err());
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
