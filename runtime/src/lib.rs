//! swarm-runtime: the contract every process of a run shares.
//!
//! It holds what a controller may see and do (the sensor frame and actuator command in [`messages`]), and will
//! hold the ptSCT player, the transports (iceoryx2 locally, zenoh across hosts) and the launcher behind `swarm`.
//! It never depends on the world or on the robot agent.

pub mod config;
pub mod messages;
