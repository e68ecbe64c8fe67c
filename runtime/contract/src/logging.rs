//! Logging setup shared by the run's programs (`swarm`, `swarm-world`, `robot-agent`).
//!
//! Logs go to standard error through `tracing`, filtered by `RUST_LOG` when it is set and by the program's default
//! otherwise. Standard output stays free for machine-read output (the world's progress reports, the agent's
//! `--check` event table). Colour codes only on a terminal.

/// Installs the stderr subscriber with `default_filter` (e.g. `"info"`) unless `RUST_LOG` says otherwise.
pub fn init(default_filter: &str) {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new(default_filter)),
        )
        .with_writer(std::io::stderr)
        .with_ansi(colour_on_stderr())
        .init();
}

/// Colour only on a terminal, and never when `NO_COLOR` is set (no-color.org): log files and pipes get plain
/// text.
fn colour_on_stderr() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty())
}

/// An error and its causes on one line, `outer: cause: cause`, each text once: library errors often quote their
/// source in their own message, and printing the whole chain as well would say it twice.
pub fn error_chain(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let part = cause.to_string();
        if !text.contains(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
        source = cause.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("reading x.argos: {0}")]
    struct Quoting(#[source] std::io::Error);

    #[derive(Debug, thiserror::Error)]
    #[error("running the experiment")]
    struct Silent(#[source] Quoting);

    #[test]
    fn each_cause_is_said_once() {
        let inner = || std::io::Error::other("no such file");
        assert_eq!(
            error_chain(&Quoting(inner())),
            "reading x.argos: no such file"
        );
        assert_eq!(
            error_chain(&Silent(Quoting(inner()))),
            "running the experiment: reading x.argos: no such file"
        );
    }
}
