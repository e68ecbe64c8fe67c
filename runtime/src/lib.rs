//! swarm-runtime: the contract every process of a run shares.
//!
//! It holds what a controller may see and do (the sensor frame and actuator command in [`messages`]), the local
//! lockstep transport over iceoryx2 ([`transport`]) and the ptSCT [`player`], the experiment
//! configuration ([`config`]), the [`launcher`] behind `swarm run` and the grid runner behind `swarm
//! experiment` ([`experiment`]). It never depends on the world or on the robot
//! agent.

pub mod alloc_count;
pub mod bench;
pub mod config;
pub mod experiment;
pub mod launcher;
pub mod logging;
pub mod messages;
pub mod player;
pub mod remote;
pub mod transport;

/// The ptSCT toolchain's formats (compiled supervisor sets, models, synthesis), re-exported so that agents reach
/// them through the runtime contract only.
pub use supervisor_gen;
