//! From the world to a host daemon: the host's share of a run ([`Assignment`]), fault orders for its robots'
//! agents ([`Order`]) and, every tick, one batch of its robots' sensor frames with their inboxes (a
//! [`Kind::Frames`](crate::codec::Kind) batch of [`FrameEntry`]s, see [`crate::codec`]).
//!
//! **The share** names the experiment by path (every host must see the same configuration and model files at the
//! same path, e.g. one checkout or a shared file system), the run seed, the run-wide ids and controllers of the
//! robots the host runs, the run's compiled supervisor sets, and when the host rejoins, where each robot's
//! supervisors left off.
//!
//! **Fault orders**: fault schedules and restart policies work for robots on hosts as they do for local robots:
//! the world decides at which tick something takes effect and the launcher decides restarts, but the host daemon
//! owns the agent processes, so it carries out the process part. Each order is one zenoh query on the host's
//! `swarm/hosts/<host>/orders` queryable, and the world waits for the answer before it opens the next tick, so an
//! order always takes effect between the same two ticks. An order names the run and the assignment epoch; a host
//! refuses one of another run or epoch.
//!
//! Every message travels with the wire's bincode configuration ([`crate::codec`]); the answers are in
//! [`crate::host_to_world`].

use std::path::PathBuf;

use bincode::{Decode, Encode};

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{SensorFrame, SupervisorSnapshot};

/// One robot's entry of a frames batch: its frame and, when messages wait for it, its inbox. The world encodes
/// the pair `(&SensorFrame, Option<&Mailbox>)`, which has the same encoding.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub struct FrameEntry {
    /// The frame.
    pub frame: SensorFrame,
    /// The messages delivered to the robot this tick, if any.
    pub inbox: Option<Box<Mailbox>>,
}

impl FrameEntry {
    /// An empty entry for `robot`.
    pub fn empty(robot: u32) -> FrameEntry {
        FrameEntry {
            frame: SensorFrame::empty(robot),
            inbox: None,
        }
    }
}

/// The entries of a frames batch whose robots receive no messages, for [`crate::codec::encode_batch`].
pub fn without_inboxes(
    frames: &[SensorFrame],
) -> impl Iterator<Item = (&SensorFrame, Option<&Mailbox>)> {
    frames.iter().map(|frame| (frame, None))
}

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
    /// Whether the run has a messages medium: the host's local run then carries inboxes and outboxes.
    pub mail: bool,
    /// The run's compiled supervisor sets (the launcher compiles each controller's models once per run), by
    /// controller id: the host's agents load these instead of compiling the models themselves. A native
    /// controller has none.
    pub compiled_supervisors: Vec<(String, Vec<u8>)>,
    /// The run's `--limit` overrides (`NAME=VALUE`), passed on to the host's agents.
    pub limits: Vec<String>,
    /// For a host that rejoins: each robot's last recorded supervisor snapshot and the tick it came with, in the
    /// order of `robots`, so its fresh agent resumes where the robot left off. Empty on the first assignment.
    pub resume: Vec<(u64, SupervisorSnapshot)>,
}

/// One order for one robot's agent.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub struct Order {
    /// Identity of the run.
    pub run: u64,
    /// The host's assignment epoch the order belongs to.
    pub epoch: u32,
    /// The world's number for the order; it grows with every order of the run, so a host refuses a replayed one.
    pub number: u64,
    /// Run-wide robot id (a robot of the host's share).
    pub robot: u32,
    /// What to do.
    pub action: OrderAction,
}

/// What to do to the agent.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub enum OrderAction {
    /// The schedule kills the robot: SIGKILL its agent; ticks stop waiting for it.
    Kill,
    /// The schedule freezes the robot: SIGSTOP its agent; ticks stop waiting for it.
    Freeze,
    /// The schedule thaws the robot: SIGCONT its agent; ticks wait for it again.
    Thaw,
    /// The robot missed a tick's deadline: ticks stop waiting for its agent, which may still run.
    Skip,
    /// The robot answered again after missing deadlines: ticks wait for it again.
    Revive,
    /// The restart policy replaces the robot's agent: end the current one if it still runs, start a new one that
    /// resumes from this snapshot, and answer once it has joined.
    Respawn {
        /// Tick of the command the snapshot came with (0: the robot never answered).
        tick: u64,
        /// The robot's last recorded supervisor states and timers.
        snapshot: Box<SupervisorSnapshot>,
    },
}

impl OrderAction {
    /// A short name for logs.
    pub fn name(&self) -> &'static str {
        match self {
            OrderAction::Kill => "kill",
            OrderAction::Freeze => "freeze",
            OrderAction::Thaw => "thaw",
            OrderAction::Skip => "skip",
            OrderAction::Revive => "revive",
            OrderAction::Respawn { .. } => "respawn",
        }
    }
}

/// The payload of `swarm ctl kill-host` for the share of `run` in `epoch`: run then epoch, little-endian.
pub fn kill_payload(run: u64, epoch: u32) -> Vec<u8> {
    let mut bytes = run.to_le_bytes().to_vec();
    bytes.extend_from_slice(&epoch.to_le_bytes());
    bytes
}

/// The run and epoch of a [`kill_payload`]; `None` for any other length.
pub fn parse_kill(bytes: &[u8]) -> Option<(u64, u32)> {
    let run = u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?);
    let epoch = u32::from_le_bytes(bytes.get(8..)?.try_into().ok()?);
    Some((run, epoch))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::{DEFAULT_MAX_PAYLOAD, decode_message, encode_message};
    use crate::host_to_world::OrderReply;

    #[test]
    fn orders_and_replies_survive_the_wire_and_hostile_bytes_are_rejected() {
        assert_eq!(parse_kill(&kill_payload(7, 2)), Some((7, 2)));
        assert_eq!(parse_kill(&[0; 8]), None);
        assert_eq!(parse_kill(&[0; 13]), None);
        let order = Order {
            run: 7,
            epoch: 2,
            number: 3,
            robot: 41,
            action: OrderAction::Respawn {
                tick: 19,
                snapshot: Box::default(),
            },
        };
        let bytes = encode_message(&order).unwrap();
        assert_eq!(
            decode_message::<Order>(&bytes, DEFAULT_MAX_PAYLOAD).unwrap(),
            order
        );
        let reply = OrderReply::Failed {
            reason: "gone".into(),
        };
        let bytes = encode_message(&reply).unwrap();
        assert_eq!(
            decode_message::<OrderReply>(&bytes, DEFAULT_MAX_PAYLOAD).unwrap(),
            reply
        );
        for cut in 0..bytes.len() {
            assert!(decode_message::<OrderReply>(&bytes[..cut], DEFAULT_MAX_PAYLOAD).is_err());
        }
        assert!(decode_message::<Order>(&[0xff; 40], DEFAULT_MAX_PAYLOAD).is_err());
    }
}
