//! The contract's integration tests in one binary (one link instead of one per file): the configuration
//! parser against every error path and the shipped configurations, and the player against the rules of
//! docs/ptsct.md. `player_no_alloc` stays a binary of its own: it installs a counting global allocator.

mod config_errors;
mod config_examples;
mod config_robustness;
mod config_warnings;
mod player_rules;
