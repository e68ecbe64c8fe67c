//! The protocol between the processes of a run, one file per direction, each type defined once and used by both
//! ends so that they cannot drift apart.
//!
//! - [`launcher_to_world`]: the world's command line and the lines the launcher writes on its standard input.
//! - [`world_to_launcher`]: the lines the world writes on its standard output.
//! - [`launcher_to_agent`]: an agent's command line, and how an agent process is started (locally by the
//!   launcher, on a host by the host daemon: the same function).
//! - [`resume`]: the resume point a restarted agent is handed (written from the world's records).
//!
//! World and agents talk through shared memory: the frames and commands of [`crate::messages`] over
//! [`crate::transport`]. Across machines the world talks to host daemons over zenoh (crate `swarm-remote`).

pub mod launcher_to_agent;
pub mod launcher_to_world;
pub mod resume;
pub mod world_to_launcher;
