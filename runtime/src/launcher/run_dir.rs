//! The run directory: everything a run leaves behind.
//!
//! `summary.json`, `trajectory.csv`, `events.csv` and `snapshot*.png` are written by the world; the launcher adds
//! `config.argos` (the configuration as used), `logs/` (one log per agent, kept so a failed start can be explained)
//! and its own fields in `summary.json`.

use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// Folder under which runs go when `--out` is not given.
pub const DEFAULT_RUNS_DIR: &str = "runs";

/// Creates the run directory (`out`, or `runs/<config name>-<unix seconds>`), its `logs/` folder, and a copy of
/// the configuration.
pub fn create(out: Option<&Path>, config: &Path) -> std::io::Result<PathBuf> {
    let dir = match out {
        Some(dir) => dir.to_path_buf(),
        None => {
            let stem = config
                .file_stem()
                .map_or_else(|| "run".to_owned(), |s| s.to_string_lossy().into_owned());
            let secs = SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_secs());
            Path::new(DEFAULT_RUNS_DIR).join(format!("{stem}-{secs}"))
        }
    };
    std::fs::create_dir_all(logs_dir(&dir))?;
    std::fs::copy(config, dir.join("config.argos"))?;
    Ok(dir)
}

/// The folder of the agents' logs.
pub fn logs_dir(run_dir: &Path) -> PathBuf {
    run_dir.join("logs")
}

/// The log file of one robot's agent.
pub fn agent_log(run_dir: &Path, robot: u32) -> PathBuf {
    logs_dir(run_dir).join(format!("robot-{robot}.log"))
}

/// The last `lines` non-empty lines of a log, for error messages.
pub fn tail(path: &Path, lines: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let kept: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    kept[kept.len().saturating_sub(lines)..].join("\n")
}
