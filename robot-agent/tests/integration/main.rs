//! The agent's integration tests in one binary (one link instead of one per file). `step_no_alloc` stays a
//! binary of its own: it installs a counting global allocator.

mod lockstep_agents;
mod obstacle_avoidance_models;
mod player_run;
mod startup;
