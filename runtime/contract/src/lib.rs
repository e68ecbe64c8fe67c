//! swarm-contract: what every process of a run shares, and nothing else.
//!
//! The world (`swarm-world`), each robot's agent (`robot-agent`), the host daemon and the launcher (`swarm`) all
//! link this crate, so it holds only what they must agree on:
//!
//! - what a controller may see and do: the sensor frame and actuator command ([`messages`], the world-to-agent
//!   and agent-to-world protocol), the robot bodies and where their sensors sit ([`bodies`]), and the ptSCT
//!   [`player`] that runs a robot's supervisors;
//! - the experiment configuration ([`config`]): the `.argos` model and its parser, with the fault schedule and
//!   the host list as sections of the same document, and the fault schedule expanded for one run ([`fault_plan`]);
//! - the local lockstep [`transport`] over iceoryx2 shared memory;
//! - the protocol between the processes of a run ([`protocol`], one file per direction), the programs and child
//!   processes of a run ([`process`]) and the files of a run directory ([`run_dir`]);
//! - every timeout and size limit of a run, with its default ([`limits`]);
//! - small shared services: [`logging`], scheduler CPU accounts ([`cpu`]) and an allocation counter for tests
//!   ([`alloc_count`]).
//!
//! It never depends on the world, the agent, zenoh or the launcher's tools (plots, grids, progress bars).

#![warn(missing_docs)]

pub mod alloc_count;
pub mod bodies;
mod compact_encoding;
pub mod config;
pub mod cpu;
pub mod disk_budget;
pub mod fault_plan;
pub mod fonts;
pub mod limits;
pub mod logging;
pub mod mail;
pub mod messages;
pub mod player;
pub mod process;
pub mod protocol;
pub mod run_dir;
pub mod transport;

/// The ptSCT toolchain's formats (compiled supervisor sets, models, synthesis), re-exported so that agents reach
/// them through the contract only.
pub use supervisor_gen;
