//! The programs of a run and their child processes: where the world and agent programs are
//! ([`binaries`]), starting, signalling and reaping children ([`children`]), and the open-file limit a run
//! needs ([`open_files`]).

pub mod binaries;
pub mod children;
pub mod open_files;
