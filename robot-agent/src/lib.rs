//! robot-agent: one robot's process. It loads the robot's controller (a supervisor set plus an operational-procedure
//! profile, or a native controller), binds every supervisor event to its callback by name, and runs one control
//! step per tick.
//!
//! It sees only `swarm_contract`: the sensor frame, the actuator command, the player and the transport. It never
//! depends on the world.

#![warn(missing_docs)]

pub mod binding;
pub mod control;
pub mod controller;
pub mod from_config;
pub mod huge_text;
pub mod native;
pub mod params;
pub mod profile;
pub mod profiles;
pub mod resume;
pub mod supervisors;
pub mod zygote;
