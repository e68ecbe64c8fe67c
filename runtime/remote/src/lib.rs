//! swarm-remote: the link across machines. The world speaks zenoh with one `swarm host` daemon per machine;
//! robots always speak iceoryx2.
//!
//! Each host daemon ([`host`]) announces itself with a zenoh liveliness token, receives its share of a run,
//! runs it as a local lockstep run (its own iceoryx2 prefix and root, one agent process per robot) and bridges:
//! per tick one message of its robots' frames in, one message of their replies out; between ticks the world may
//! send it fault orders for its robots' agents. The messages are in files named by direction
//! ([`world_to_host`], [`host_to_world`]) and travel in the wire format of [`codec`]. The
//! world's side ([`world_bridge`]) publishes one batch per host per tick, waits for each host's batch with the
//! tick deadline, and treats the robots of a lost host as dead from the tick it notices the loss.
//! Key expressions are in [`keys`], session settings in [`session`]. docs/hosts.md explains the choices.
//!
//! Which hosts a run uses and how robots are shared among them is the [`plan`].
//!
//! A run with every robot local never opens a zenoh session.

#![warn(missing_docs)]

pub mod auth;
pub mod codec;
pub mod host;
pub mod host_to_world;
pub mod keys;
pub mod plan;
pub mod session;
pub mod world_bridge;
pub mod world_to_host;

/// What can go wrong across hosts.
#[derive(Debug, thiserror::Error)]
pub enum RemoteError {
    /// A host name that cannot be a key chunk.
    #[error(transparent)]
    InvalidHostName(#[from] swarm_contract::config::hosts::InvalidHostName),
    /// A zenoh operation failed.
    #[error("zenoh: {action}: {detail}")]
    Zenoh {
        /// What was being done.
        action: String,
        /// zenoh's error.
        detail: String,
    },
    /// A payload could not be encoded.
    #[error("encoding a message: {0}")]
    Wire(#[from] codec::WireError),
    /// The local transport of a host failed.
    #[error(transparent)]
    Transport(#[from] swarm_contract::transport::TransportError),
    /// A host refused its share of the run.
    #[error("host '{host}' refused its share of the run: {reason}")]
    Refused {
        /// The host.
        host: String,
        /// Its reason.
        reason: String,
    },
    /// The world of the host's run told it to die (`swarm ctl kill-host`).
    #[error("killed by `swarm ctl kill-host` in run {run:016x}")]
    Killed {
        /// The run.
        run: u64,
    },
    /// Authentication is on and a host of the placement has no key.
    #[error(
        "host '{0}' has no key (create it with `swarm host-key {0}`, or run with --insecure-hosts)"
    )]
    NoKey(String),
    /// A host key cannot be read or created.
    #[error(transparent)]
    Key(#[from] auth::KeyError),
    /// Hosts did not join in time.
    #[error("{0}")]
    HostsMissing(String),
    /// The robot-agent program is missing.
    #[error(transparent)]
    Binaries(#[from] swarm_contract::process::binaries::BinariesError),
    /// A rejoining share's resume point could not be written.
    #[error(transparent)]
    Resume(#[from] swarm_contract::protocol::resume::ResumeError),
    /// A file or process operation failed.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}
