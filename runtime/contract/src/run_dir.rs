//! The run directory: everything a run leaves behind, and the one place that names its files.
//!
//! `summary.json`, `trajectory.csv`, `events.csv` and `snapshot_<tick>.png` are written by the world; the launcher
//! adds `config.argos` (the configuration as used), `logs/` (one log per agent, kept so a failed start can be
//! explained), `supervisors/` (each controller's compiled supervisor set), `event_tables.json`, `resume/` (the
//! resume points of restarted agents), `control.sock` (`swarm ctl`) and its own fields in `summary.json`. A batch
//! of `swarm experiment` marks each finished run with `run.json`. Every process takes these names from here.

use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

/// The run's summary: the world's figures and the launcher's fields.
pub const SUMMARY_FILE: &str = "summary.json";
/// Pose, LED and alive flag of every robot at every tick.
pub const TRAJECTORY_FILE: &str = "trajectory.csv";
/// Every event every robot fired.
pub const EVENTS_FILE: &str = "events.csv";
/// Each controller's event names by id, for the world's `events.csv`.
pub const EVENT_TABLES_FILE: &str = "event_tables.json";
/// The configuration as the run used it.
pub const CONFIG_COPY_FILE: &str = "config.argos";
/// Folder of the agents' logs.
pub const LOGS_DIR: &str = "logs";
/// Folder holding each controller's compiled supervisor set.
pub const COMPILED_SUPERVISORS_DIR: &str = "supervisors";
/// Folder of the resume points of restarted agents.
pub const RESUME_DIR: &str = "resume";
/// The launcher's control socket (`swarm ctl`).
pub const CONTROL_SOCKET: &str = "control.sock";
/// The marker of a finished run in a `swarm experiment` batch.
pub const RUN_MARKER: &str = "run.json";

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
    std::fs::copy(config, dir.join(CONFIG_COPY_FILE))?;
    Ok(dir)
}

/// The folder of the agents' logs.
pub fn logs_dir(run_dir: &Path) -> PathBuf {
    run_dir.join(LOGS_DIR)
}

/// The log file of one robot's agent.
pub fn agent_log(run_dir: &Path, robot: u32) -> PathBuf {
    logs_dir(run_dir).join(format!("robot-{robot}.log"))
}

/// The snapshot image of `tick`.
pub fn snapshot(run_dir: &Path, tick: u64) -> PathBuf {
    run_dir.join(format!("snapshot_{tick:06}.png"))
}

/// The compiled supervisor set of controller `controller`.
pub fn compiled_supervisors(run_dir: &Path, controller: &str) -> PathBuf {
    run_dir
        .join(COMPILED_SUPERVISORS_DIR)
        .join(format!("{controller}.ptsct"))
}

/// The last `lines` non-empty lines of a log, for error messages.
pub fn tail(path: &Path, lines: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let kept: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    kept[kept.len().saturating_sub(lines)..].join("\n")
}
