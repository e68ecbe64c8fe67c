//! A host's share of a run: what the world sends a host daemon when it (re)joins, and the host's answer.
//!
//! The share names the experiment by path (every host must see the same configuration and model files at the same
//! path, e.g. one checkout or a shared file system), the run seed, and the run-wide ids and controllers of the
//! robots the host runs, and when the host rejoins, where each robot's supervisors left off. Both messages travel
//! with the wire's bincode configuration ([`super::codec`]).

use std::path::PathBuf;

use bincode::{Decode, Encode};

use swarm_contract::messages::SupervisorSnapshot;

/// What the world asks a host to run.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub struct Assignment {
    /// Identity of the run (every message of the run carries it).
    pub run: u64,
    /// Index of the host in the run's placement.
    pub host: u16,
    /// Host name, as in the placement.
    pub name: String,
    /// Assignment epoch; grows each time the host rejoins.
    pub epoch: u32,
    /// The experiment configuration (absolute path, valid on the host).
    pub config: PathBuf,
    /// Run seed.
    pub seed: u64,
    /// Robot count override of the run (`swarm run --robots`), if any.
    pub robots_override: Option<u32>,
    /// The host's robots: run-wide id and controller id, in the order of every batch.
    pub robots: Vec<(u32, String)>,
    /// How long the host waits for its agents in one tick (milliseconds).
    pub tick_deadline_ms: u64,
    /// How long the host may take to start its agents (milliseconds).
    pub join_timeout_ms: u64,
    /// How long the host's agents get to exit by themselves when the share ends (milliseconds).
    pub agent_exit_grace_ms: u64,
    /// Whether the host's agents pin themselves to CPUs by chain (`<system pin_threads_to_cores>`).
    pub pin_agents: bool,
    /// Whether the host's ticking thread and agents run at real-time priority if the host allows it
    /// (`<system realtime_priority>`).
    pub realtime_priority: bool,
    /// The run's compiled supervisor sets (the launcher compiles each controller's models once per run), by
    /// controller id: the host's agents load these instead of compiling the models themselves. A native
    /// controller has none.
    pub compiled_supervisors: Vec<(String, Vec<u8>)>,
    /// For a host that rejoins: each robot's last recorded supervisor snapshot and the tick it came with, in the
    /// order of `robots`, so its fresh agent resumes where the robot left off. Empty on the first assignment.
    pub resume: Vec<(u64, SupervisorSnapshot)>,
}

/// The host's answer to an [`Assignment`].
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode)]
pub enum AssignmentReply {
    /// Every agent of the share joined; frames may come.
    Ready {
        /// Epoch of the assignment this answers.
        epoch: u32,
    },
    /// The host cannot run the share, and why.
    Refused {
        /// Epoch of the assignment this answers.
        epoch: u32,
        /// What went wrong, for the user.
        reason: String,
    },
}
