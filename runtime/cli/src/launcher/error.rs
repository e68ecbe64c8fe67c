//! Why a run failed: the launcher's error type.

use std::path::PathBuf;
use std::time::Duration;

use swarm_contract::config::ConfigErrors;
use swarm_contract::limits::LimitError;
use swarm_contract::process::binaries::BinariesError;
use swarm_contract::run_dir::RunDirError;
use swarm_remote::plan::HostsError;

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum LaunchError {
    /// The configuration is invalid.
    #[error("{0}")]
    Config(#[from] ConfigErrors),
    /// The configuration has no robot to run.
    #[error(
        "{path}:{at}: the arena has no robot (e-puck, foot-bot or disc-robot), so there is nothing to run"
    )]
    NoRobots {
        /// The configuration.
        path: PathBuf,
        /// Where its `<arena>` element is.
        at: swarm_contract::config::model::Location,
    },
    /// The world or agent programs are missing.
    #[error(transparent)]
    Binaries(#[from] BinariesError),
    /// The hosts of the run cannot be resolved.
    #[error(transparent)]
    Hosts(#[from] HostsError),
    /// The world stopped the run before its end to stay within its disk budget; the records up to `ticks` are
    /// complete.
    #[error(
        "stopped after {ticks} ticks: {reason}; the records up to that tick are complete in {}",
        out_dir.display()
    )]
    StoppedEarly {
        /// Ticks completed.
        ticks: u64,
        /// Which limit, and by how much.
        reason: String,
        /// The run folder.
        out_dir: PathBuf,
    },
    /// The run folder's disk is below the run's reserve (or the folder past its size) before the run starts.
    #[error("not starting the run: {0}")]
    NoRoom(String),
    /// The configuration could not be rewritten as the run used it.
    #[error("{0}")]
    AsRun(String),
    /// The run directory cannot be used.
    #[error(transparent)]
    RunDir(#[from] RunDirError),
    /// The live viewer cannot be served.
    #[error("--view: {0}")]
    Viewer(#[from] swarm_viewer::ViewerError),
    /// A file or process operation failed.
    #[error("{what}: {source}")]
    Io {
        /// What the launcher was doing.
        what: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The world process ended before it was ready or before the experiment finished.
    #[error("the world process ended ({status}) {when}")]
    WorldDied {
        /// Exit status.
        status: String,
        /// At which point of the run.
        when: String,
    },
    /// The world did not say `ready` in time.
    #[error(
        "the world process did not create its services within {0:?} (limit world_ready_timeout_ms)"
    )]
    WorldNotReady(Duration),
    /// A `--limit` override is invalid.
    #[error("--limit: {0}")]
    Limit(#[from] LimitError),
    /// An agent failed before the first tick.
    #[error("robot {robot} ({id}) failed to start ({status}):\n{log}")]
    AgentFailed {
        /// Robot index.
        robot: u32,
        /// Robot id from the configuration.
        id: String,
        /// Exit status.
        status: String,
        /// The end of the agent's log.
        log: String,
    },
}

/// Maps an I/O error to [`LaunchError::Io`] saying what the launcher was doing.
pub(super) fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> LaunchError {
    let what = what.into();
    move |source| LaunchError::Io { what, source }
}
