//! From a host daemon to the world: its answer to a share ([`AssignmentReply`]) and to a fault order
//! ([`OrderReply`]) and, every tick, one batch of its robots' [`ReplyEntry`]s (a
//! [`Kind::Replies`](crate::codec::Kind) batch, see [`crate::codec`]). What the world sends is in
//! `world_to_host.rs`.

use bincode::{Decode, Encode};

use swarm_contract::mail::Mailbox;
use swarm_contract::messages::ActuatorCommand;

/// A host's answer for one robot in one tick.
// Replies live in preallocated per-host slots and are decoded in place each tick; boxing the command would
// allocate per robot per tick.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Encode, Decode)]
pub enum Reply {
    /// The robot's agent answered with this command (its `robot` field is the run-wide robot id).
    Answered(ActuatorCommand),
    /// The agent did not answer before the host's deadline.
    Missing,
    /// The agent is dead (its process ended).
    Dead,
}

/// One robot's entry of a replies batch: its reply and, when it sent messages, its outbox. The host encodes the
/// pair `(&Reply, Option<&Mailbox>)`, which has the same encoding.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub struct ReplyEntry {
    /// The reply.
    pub reply: Reply,
    /// The messages the robot sent this tick, if any (the world takes the sender from the entry's robot).
    pub outbox: Option<Box<Mailbox>>,
}

impl ReplyEntry {
    /// The entry of a robot that did not answer.
    pub const MISSING: ReplyEntry = ReplyEntry {
        reply: Reply::Missing,
        outbox: None,
    };
}

/// The entries of a replies batch whose robots sent no messages, for [`crate::codec::encode_batch`].
pub fn without_outboxes(replies: &[Reply]) -> impl Iterator<Item = (&Reply, Option<&Mailbox>)> {
    replies.iter().map(|reply| (reply, None))
}

/// The host's answer to an [`Assignment`](crate::world_to_host::Assignment).
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode)]
pub enum AssignmentReply {
    /// Every agent of the share joined; frames may come.
    Ready {
        /// Epoch of the assignment this answers.
        epoch: u32,
    },
    /// The host cannot run the share, and why.
    Refused {
        /// Epoch of the assignment this answers; 0 when the host could not read it (another build's assignment).
        epoch: u32,
        /// What went wrong, for the user.
        reason: String,
    },
}

/// The host's answer to an [`Order`](crate::world_to_host::Order).
#[derive(Debug, Clone, PartialEq, Eq, Encode, Decode)]
pub enum OrderReply {
    /// Carried out.
    Done,
    /// Not carried out, and why (e.g. the agent to thaw is gone, a replacement failed to start).
    Failed {
        /// What went wrong, for the log.
        reason: String,
    },
}
