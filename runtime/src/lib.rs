//! swarm-runtime: the contract every process of a run shares.
//!
//! It holds what a controller may see and do (the sensor frame and actuator command in [`messages`]), the local
//! lockstep transport over iceoryx2 ([`transport`]) and the ptSCT [`player`]; it will hold the zenoh transport and the
//! launcher behind `swarm`. It never depends on the world or on the robot agent.

pub mod config;
pub mod messages;
pub mod player;
pub mod transport;
