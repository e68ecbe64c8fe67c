//! Logging setup shared by the run's programs (`swarm`, `swarm-world`, `robot-agent`).
//!
//! Logs go to standard error through `tracing`, filtered by `RUST_LOG` when it is set and by the program's default
//! otherwise. Standard output stays free for machine-read output (the world's progress reports, the agent's
//! `--check` event table).

/// Installs the stderr subscriber with `default_filter` (e.g. `"info"`) unless `RUST_LOG` says otherwise.
pub fn init(default_filter: &str) {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default_filter)),
        )
        .with_writer(std::io::stderr)
        .init();
}
