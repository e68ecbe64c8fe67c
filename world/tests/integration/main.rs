//! The world library's integration tests in one binary (one link instead of one per file). `hot_path` stays a
//! binary of its own: it installs a counting global allocator.

#[path = "../common/mod.rs"]
mod common;

mod actuators;
mod config;
mod disc;
mod distance_scanner;
mod footbot;
mod gripping;
mod run;
mod sensors;
mod shipped_configs;
