//! swarm-world: the simulator every robot process senses and acts in.
//!
//! A 2-D e-puck arena (`docs/epuck-and-world.md`): rigid-body physics, the e-puck sensors and
//! actuators, LED / range-and-bearing / pheromone media, loop functions for task metrics, and the recorder.
//! It implements the control interface defined in `swarm_contract::messages`; it never depends on robot-agent.

#![warn(missing_docs)]

pub mod actuators;
pub mod arena;
pub mod arrivals;
pub mod devices;
pub mod distribute;
pub mod entities;
pub mod error;
pub mod from_config;
pub mod geometry;
pub mod gripper;
pub mod in_process;
pub mod loop_functions;
pub mod media;
pub mod physics;
pub mod recorder;
pub mod rng;
pub mod scene;
pub mod sensors;
pub mod spatial;
pub mod world;

pub use arena::Arena;
pub use error::WorldError;
pub use loop_functions::{LoopFunctions, LoopFunctionsRegistry};
pub use recorder::Recorder;
pub use world::{World, WorldBuilder};
