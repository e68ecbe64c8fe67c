//! Fault orders: what the world tells a host to do to one of its robots' agents between two ticks.
//!
//! Fault schedules and restart policies work for robots on hosts as they do for local robots: the world decides
//! at which tick something takes effect and the launcher decides restarts, but the host daemon owns the agent
//! processes, so it carries out the process part. Each order is one zenoh query on the host's
//! `swarm/hosts/<host>/orders` queryable, and the world waits for the answer before it opens the next tick, so an
//! order always takes effect between the same two ticks. An order names the run and the assignment epoch; a host
//! refuses one of another run or epoch. Both messages travel with the wire's bincode configuration
//! ([`super::codec`]).

use bincode::{Decode, Encode};

use swarm_contract::messages::SupervisorSnapshot;

/// One order for one robot's agent.
#[derive(Debug, Clone, PartialEq, Encode, Decode)]
pub struct Order {
    /// Identity of the run.
    pub run: u64,
    /// The host's assignment epoch the order belongs to.
    pub epoch: u32,
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

/// The host's answer to an [`Order`].
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::{DEFAULT_MAX_PAYLOAD, decode_message, encode_message};

    #[test]
    fn orders_and_replies_survive_the_wire_and_hostile_bytes_are_rejected() {
        let order = Order {
            run: 7,
            epoch: 2,
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
