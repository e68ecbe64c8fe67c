//! The system tests in one binary (one link instead of one per file): real processes, real shared memory, real
//! files, real zenoh sessions.

mod experiment;
mod faults;
mod host_security;
mod hosts;
mod swarm_run;
mod tasks_a;
mod tasks_b;
