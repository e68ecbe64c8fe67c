//! Local transport of the lockstep tick protocol over iceoryx2 shared memory.
//!
//! One tick: the world writes every robot's [`SensorFrame`](crate::messages::SensorFrame) into its entry of an
//! iceoryx2 blackboard in shared memory, opens the tick and wakes one agent of each chain of robots, which wakes
//! the rest of its chain. Each agent loads its own frame entry, writes its
//! [`ActuatorCommand`](crate::messages::ActuatorCommand) into its robot's own command slot and bumps one shared
//! acknowledgement counter; the last one wakes the world. The world waits on that one counter until every robot
//! is accounted for or the tick's deadline passes, then reads each robot's command from its own slot, so its
//! view never depends on arrival order.
//! docs/transport.md explains the choices.
//!
//! [`WorldLink`] is the world's side, [`AgentLink`] an agent's side, [`RunSpec`] names a run and cleans it up.

mod agent;
mod cleaner;
mod command_slots;
pub mod futex;
mod placement;
pub mod priority;
mod run;
mod services;
mod shared_map;
mod sync_block;
mod world;
mod world_watch;

use std::path::PathBuf;
use std::process::Command;

pub use agent::{AgentLink, AgentNode, Tick, WorldEnd};
pub use run::{RUN_ROOTS_DIR, RunSpec};
pub use sync_block::MAX_ROBOTS;
pub use world::{
    CommandStatus, DEFAULT_TICK_DEADLINE, DeathNotices, LinkConfig, TickOutcome, WorldLink,
};

/// Whether the world has ended `run` (or its sync block is gone): an agent exiting now exits with the run, not
/// before it.
pub fn run_ended(run: &RunSpec) -> bool {
    sync_block::SyncBlock::open(&run.sync_block_path()).map_or(true, |sync| sync.stopped())
}

/// Prepares the command line of an agent process for the lockstep with two glibc tunables, added to any
/// `GLIBC_TUNABLES` already set (docs/transport.md):
///
/// - `glibc.pthread.rseq=0` switches off restartable-sequences registration. With it, the kernel rewrites the
///   thread's rseq area in user memory on every return to user space after a context switch; an agent is
///   switched in once per tick, and that write to a cold page cost ~6 % of the agents' CPU at N = 1,000.
/// - `glibc.cpu.hwcaps=-AVX512F,...` keeps glibc's string functions off the AVX-512 registers. Once a process
///   has used them, every context switch saves and restores their 2 KiB of state; an agent's `memcpy` of its
///   frame was enough to keep that state live, and without it agents needed about 1.5 % less CPU per step
///   at N = 1,000 (within-run comparison, docs/transport.md). The copies are a few hundred bytes, for which
///   the AVX2 versions are as fast.
pub fn tune_agent_command(command: &mut Command) -> &mut Command {
    const AGENT_TUNABLES: &str =
        "glibc.pthread.rseq=0:glibc.cpu.hwcaps=-AVX512F,-AVX512VL,-AVX512BW,-AVX512DQ,-AVX512CD";
    let tunables = match std::env::var("GLIBC_TUNABLES") {
        Ok(existing) if !existing.is_empty() => format!("{existing}:{AGENT_TUNABLES}"),
        _ => AGENT_TUNABLES.to_string(),
    };
    command.env("GLIBC_TUNABLES", tunables)
}

/// What can go wrong in the local transport.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// A run name that cannot be part of a shared-memory file name.
    #[error("invalid run name '{name}': use 1-48 ASCII letters, digits or '-'")]
    InvalidRunName {
        /// The rejected name.
        name: String,
    },
    /// The iceoryx2 root directory must be absolute.
    #[error("the iceoryx2 root directory {path} is not an absolute path")]
    RootDirNotAbsolute {
        /// The rejected path.
        path: PathBuf,
    },
    /// A run must hold at least one robot and at most [`MAX_ROBOTS`].
    #[error("a run needs 1 to {max} robots, not {robots}")]
    RobotCount {
        /// Requested number of robots.
        robots: u32,
        /// Largest supported number.
        max: u32,
    },
    /// A robot index beyond the run's capacity.
    #[error(
        "robot {robot} cannot join: the service was created for {capacity} robots (0..{capacity})"
    )]
    RobotOutOfRange {
        /// The robot index.
        robot: u32,
        /// Number of robots of the run.
        capacity: u32,
    },
    /// Another live agent already owns this robot.
    #[error("robot {robot} cannot join: another agent already runs it")]
    RobotTaken {
        /// The robot index.
        robot: u32,
    },
    /// An iceoryx2 limit fixed at service creation was reached.
    #[error(
        "robot {robot} cannot join: the {service} service was created for {limit} {what} and all are in use \
         (a dead agent's place is freed by the world's dead-node cleanup)"
    )]
    ServiceFull {
        /// The robot index.
        robot: u32,
        /// Service name.
        service: String,
        /// The exhausted limit.
        limit: usize,
        /// What is limited (subscribers, publishers, nodes).
        what: &'static str,
    },
    /// The sync block of the run could not be created, opened or mapped.
    #[error("lockstep sync block {path}: {source}")]
    SyncBlock {
        /// Path of the block.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The sync block exists but is not what this build expects.
    #[error("lockstep sync block {path}: {reason}")]
    InvalidSyncBlock {
        /// Path of the block.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A file of the run could not be removed.
    #[error("cleaning up {path}: {source}")]
    Cleanup {
        /// The file or directory.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// Not every agent joined before the timeout.
    #[error("only {joined} of {expected} agents joined within {waited_ms} ms")]
    JoinTimeout {
        /// Agents that joined.
        joined: u32,
        /// Agents expected.
        expected: u32,
        /// How long the world waited.
        waited_ms: u128,
    },
    /// A file of the run other than the sync block (the command slots) could not be created, opened or mapped.
    #[error("lockstep file {path}: {source}")]
    RunFile {
        /// Path of the file.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// A file of the run exists but is not what this build expects.
    #[error("lockstep file {path}: {reason}")]
    InvalidRunFile {
        /// Path of the file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The robot's command slot stayed taken by a live process, a predecessor stopped in the middle of a write.
    #[error(
        "robot {robot} cannot join: its command slot is held by process {pid}, a previous agent of the robot \
         stopped in the middle of writing a command (continue or kill it)"
    )]
    CommandSlotHeld {
        /// The robot index.
        robot: u32,
        /// The process holding the slot.
        pid: u32,
    },
    /// The world process no longer exists and never ended the run.
    #[error("the world process (pid {pid}) is gone without ending the run")]
    WorldGone {
        /// The world's process id.
        pid: u32,
    },
    /// An iceoryx2 operation failed.
    #[error("iceoryx2: {action}: {detail}")]
    Iceoryx {
        /// What was being done.
        action: String,
        /// The iceoryx2 error.
        detail: String,
    },
}

impl TransportError {
    /// Wraps an iceoryx2 error with what was being done.
    pub(crate) fn iceoryx(
        action: impl Into<String>,
        error: impl std::fmt::Debug,
    ) -> TransportError {
        TransportError::Iceoryx {
            action: action.into(),
            detail: format!("{error:?}"),
        }
    }
}
