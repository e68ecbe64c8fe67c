//! The programs of a run and their child processes: where the world and agent programs are
//! ([`binaries`]), and starting, signalling and reaping children ([`children`]).

pub mod binaries;
pub mod children;
