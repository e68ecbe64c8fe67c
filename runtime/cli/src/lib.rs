//! swarm-cli: the `swarm` program.
//!
//! The [`launcher`] behind `swarm run` (starts the world and one agent per robot, supervises them, applies faults,
//! writes the summary), the grid runner behind `swarm experiment` with its results, plots and report
//! ([`experiment`]), and `swarm bench` ([`bench`](mod@bench)). `swarm host` and the cross-host link are in `swarm-remote`;
//! everything the processes of a run share is in `swarm-contract`.

#![warn(missing_docs)]

pub mod bench;
pub mod experiment;
pub mod launcher;
