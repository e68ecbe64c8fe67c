//! The run directory: everything a run leaves behind, and the one place that names its files.
//!
//! `summary.json`, `trajectory.csv`, `events.csv`, `snapshot_<tick>.png` and `resume/` (the resume point of every
//! robot the world marks down, for its replacement if one is started) are written by the world; the launcher adds
//! the record tables' Parquet files when the run ends (replacing their CSV files unless the run keeps CSV),
//! `config.argos` (the configuration as run), `logs/` (one log per local agent, kept so a failed start can be
//! explained), `supervisors/` (each controller's compiled supervisor set), `event_tables.json`, `control.sock`
//! (`swarm ctl`) and its own fields in `summary.json`. A batch of `swarm experiment` marks each finished run with
//! `run.json`. Every process takes these names from here; docs/records.md describes every file and column.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

/// The run's summary: the world's figures and the launcher's fields.
pub const SUMMARY_FILE: &str = "summary.json";
/// Pose, LED and alive flag of every robot at every tick.
pub const TRAJECTORY_FILE: &str = "trajectory.csv";
/// Every event every robot fired.
pub const EVENTS_FILE: &str = "events.csv";
/// Every addressed message's fate (runs with a `<messages>` medium).
pub const MESSAGES_FILE: &str = "messages.csv";
/// [`TRAJECTORY_FILE`] as Apache Parquet, converted when the run ended.
pub const TRAJECTORY_PARQUET_FILE: &str = "trajectory.parquet";
/// [`EVENTS_FILE`] as Apache Parquet, converted when the run ended.
pub const EVENTS_PARQUET_FILE: &str = "events.parquet";
/// [`MESSAGES_FILE`] as Apache Parquet, converted when the run ended.
pub const MESSAGES_PARQUET_FILE: &str = "messages.parquet";
/// What does not move with the robots: the arena, obstacles, targets and lights as placed, each robot's id,
/// controller and body (`swarm view` draws the run over it).
pub const SCENE_FILE: &str = "scene.json";
/// The floor's grey levels as an image over the arena (runs whose floor is not all white).
pub const FLOOR_IMAGE_FILE: &str = "floor.png";
/// Where the targets and movable obstacles are, a row whenever one moved (runs with any): for replays.
pub const OBJECTS_FILE: &str = "objects.csv";
/// The pheromone field once a second (runs with a pheromone medium): for replays.
pub const PHEROMONE_FILE: &str = "pheromone.bin";
/// Each controller's event names by id, for the world's `events.csv`.
pub const EVENT_TABLES_FILE: &str = "event_tables.json";
/// The configuration as the run used it.
pub const CONFIG_COPY_FILE: &str = "config.argos";
/// Folder of the agents' logs.
pub const LOGS_DIR: &str = "logs";
/// Folder holding each controller's compiled supervisor set.
pub const COMPILED_SUPERVISORS_DIR: &str = "supervisors";
/// Folder of the resume points of robots the world marked down (read by their replacements).
pub const RESUME_DIR: &str = "resume";
/// The launcher's control socket (`swarm ctl`).
pub const CONTROL_SOCKET: &str = "control.sock";
/// The marker of a finished run in a `swarm experiment` batch.
pub const RUN_MARKER: &str = "run.json";

/// Folder under which runs go when `--out` is not given.
pub const DEFAULT_RUNS_DIR: &str = "runs";
/// The lock file of a run directory: the launcher of the run holds an exclusive lock on it for the whole run, so
/// no second launcher writes into the same folder.
pub const LOCK_FILE: &str = ".swarm.lock";

/// Why a run directory cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum RunDirError {
    /// Another launcher holds the folder's lock.
    #[error("{}: another swarm run or experiment is writing into it (it holds {LOCK_FILE})", path.display())]
    InUse {
        /// The folder.
        path: PathBuf,
    },
    /// The folder already holds something and `--overwrite` was not given.
    #[error(
        "{}: already holds files of an earlier run; pass --overwrite to empty it first, or choose another --out",
        path.display()
    )]
    NotEmpty {
        /// The folder.
        path: PathBuf,
    },
    /// A file operation failed.
    #[error("{what} {}: {source}", path.display())]
    Io {
        /// What was being done.
        what: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

fn io_error(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> RunDirError {
    let path = path.to_path_buf();
    move |source| RunDirError::Io { what, path, source }
}

/// A run directory held by this process: its lock is released when the value is dropped (or the process dies).
#[derive(Debug)]
pub struct RunDir {
    /// The folder.
    pub path: PathBuf,
    _lock: File,
}

/// Creates the run directory, locked for this process, with its `logs/` folder and a copy of the configuration.
///
/// Without `out` the folder is `runs/<config name>-<YYYYMMDD-HHMMSS>-<4 hex digits>`, created exclusively (never
/// an existing one, even for runs started in the same second). With `out` an existing folder is used only if no
/// other run holds it and it is empty, or `overwrite` is set: then it is emptied first.
pub fn create(out: Option<&Path>, overwrite: bool, config: &Path) -> Result<RunDir, RunDirError> {
    let run_dir = match out {
        Some(dir) => claim(dir, overwrite)?,
        None => create_fresh(Path::new(DEFAULT_RUNS_DIR), config)?,
    };
    let logs = logs_dir(&run_dir.path);
    std::fs::create_dir_all(&logs).map_err(io_error("creating", &logs))?;
    std::fs::copy(config, run_dir.path.join(CONFIG_COPY_FILE))
        .map_err(io_error("copying the configuration into", &run_dir.path))?;
    Ok(run_dir)
}

/// A new folder under `parent`, named after the configuration and the time, with a random suffix.
fn create_fresh(parent: &Path, config: &Path) -> Result<RunDir, RunDirError> {
    std::fs::create_dir_all(parent).map_err(io_error("creating", parent))?;
    let stem = config
        .file_stem()
        .map_or_else(|| "run".to_owned(), |s| s.to_string_lossy().into_owned());
    let stamp = folder_time(SystemTime::now());
    loop {
        let path = parent.join(format!("{stem}-{stamp}-{:04x}", rand::random::<u16>()));
        match std::fs::create_dir(&path) {
            Ok(()) => return lock(path),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(io_error("creating", &path)(e)),
        }
    }
}

/// `YYYYMMDD-HHMMSS` in UTC.
fn folder_time(now: SystemTime) -> String {
    let text = humantime::format_rfc3339_seconds(now).to_string();
    text.chars()
        .filter(|c| c.is_ascii_digit() || *c == 'T')
        .map(|c| if c == 'T' { '-' } else { c })
        .collect()
}

/// Takes `dir` (creating it if needed) for a run: locked, and empty unless refused.
fn claim(dir: &Path, overwrite: bool) -> Result<RunDir, RunDirError> {
    std::fs::create_dir_all(dir).map_err(io_error("creating", dir))?;
    let run_dir = lock(dir.to_path_buf())?;
    let entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io_error("reading", dir))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.file_name().is_none_or(|n| n != LOCK_FILE))
        .collect();
    if !entries.is_empty() && !overwrite {
        return Err(RunDirError::NotEmpty {
            path: dir.to_path_buf(),
        });
    }
    for entry in entries {
        let removed = if entry.is_dir() && !entry.is_symlink() {
            std::fs::remove_dir_all(&entry)
        } else {
            std::fs::remove_file(&entry)
        };
        removed.map_err(io_error("removing", &entry))?;
    }
    Ok(run_dir)
}

/// Creates `dir` if needed and locks it for this process (e.g. a batch folder of `swarm experiment`), or says
/// that another process holds it.
pub fn lock_folder(dir: &Path) -> Result<RunDir, RunDirError> {
    std::fs::create_dir_all(dir).map_err(io_error("creating", dir))?;
    lock(dir.to_path_buf())
}

/// Locks `path`'s lock file for this process, or says who has it.
fn lock(path: PathBuf) -> Result<RunDir, RunDirError> {
    let lock_path = path.join(LOCK_FILE);
    let file = File::options()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(io_error("opening", &lock_path))?;
    match file.try_lock() {
        Ok(()) => Ok(RunDir { path, _lock: file }),
        Err(std::fs::TryLockError::WouldBlock) => Err(RunDirError::InUse { path }),
        Err(std::fs::TryLockError::Error(e)) => Err(io_error("locking", &lock_path)(e)),
    }
}

/// Writes `bytes` to `path` atomically: into a temporary file beside it, flushed to disk, then renamed over it,
/// so a crash or a full disk leaves the old file or the new one, never a part of either.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path
        .file_name()
        .map_or_else(|| "file".into(), |n| n.to_string_lossy().into_owned());
    let temporary = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let written = (|| {
        let mut file = File::create(&temporary)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temporary, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    written
}

/// The folder of the agents' logs.
pub fn logs_dir(run_dir: &Path) -> PathBuf {
    run_dir.join(LOGS_DIR)
}

/// The log file of one robot's agent.
pub fn agent_log(run_dir: &Path, robot: u32) -> PathBuf {
    agent_log_in(&logs_dir(run_dir), robot)
}

/// The log file of one robot's agent in the logs folder `logs` (a run's `logs/`, or a host's own folder).
pub fn agent_log_in(logs: &Path, robot: u32) -> PathBuf {
    logs.join(format!("robot-{robot}.log"))
}

/// The snapshot image of `tick`.
pub fn snapshot(run_dir: &Path, tick: u64) -> PathBuf {
    run_dir.join(format!("snapshot_{tick:06}.png"))
}

/// The compiled supervisor set of controller `controller`; refused for an id that is not a plain file name (one
/// that would name a file outside the folder, such as `../x`), since ids also arrive from hosts' peers.
pub fn compiled_supervisors(run_dir: &Path, controller: &str) -> std::io::Result<PathBuf> {
    let plain = !controller.is_empty()
        && !controller.starts_with('.')
        && !controller.contains(['/', '\\', '\0']);
    if !plain {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("controller id {controller:?} is not a plain file name"),
        ));
    }
    Ok(run_dir
        .join(COMPILED_SUPERVISORS_DIR)
        .join(format!("{controller}.ptsct")))
}

/// The last `lines` non-empty lines of a log, for error messages (bytes that are not UTF-8 shown as U+FFFD).
pub fn tail(path: &Path, lines: usize) -> String {
    let bytes = std::fs::read(path).unwrap_or_default();
    let text = String::from_utf8_lossy(&bytes);
    let kept: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    kept[kept.len().saturating_sub(lines)..].join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(dir: &Path) -> PathBuf {
        let path = dir.join("exp.argos");
        std::fs::write(&path, "<argos-configuration/>").expect("write");
        path
    }

    #[test]
    fn runs_started_in_the_same_second_get_their_own_folders() {
        let dir = tempfile::tempdir().expect("temp dir");
        let config = config(dir.path());
        let runs = dir.path().join("runs");
        let first = create_fresh(&runs, &config).expect("first");
        let second = create_fresh(&runs, &config).expect("second");
        assert_ne!(first.path, second.path);
        let name = first
            .path
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let parts: Vec<&str> = name.split('-').collect();
        assert_eq!(parts[0], "exp", "{name}");
        assert_eq!(
            (parts[1].len(), parts[2].len(), parts[3].len()),
            (8, 6, 4),
            "{name}"
        );
    }

    #[test]
    fn a_used_folder_is_refused_unless_overwritten_and_then_emptied() {
        let dir = tempfile::tempdir().expect("temp dir");
        let config = config(dir.path());
        let out = dir.path().join("out");
        let first = create(Some(&out), false, &config).expect("an empty folder is taken");
        std::fs::write(out.join(SUMMARY_FILE), "{}").expect("write");
        drop(first);
        assert!(matches!(
            create(Some(&out), false, &config),
            Err(RunDirError::NotEmpty { .. })
        ));
        assert!(out.join(SUMMARY_FILE).exists(), "a refusal loses nothing");
        let _second = create(Some(&out), true, &config).expect("overwrite");
        assert!(
            !out.join(SUMMARY_FILE).exists(),
            "--overwrite empties the folder"
        );
        assert!(out.join(CONFIG_COPY_FILE).exists());
    }

    #[test]
    fn a_folder_another_run_writes_into_is_refused_even_with_overwrite() {
        let dir = tempfile::tempdir().expect("temp dir");
        let config = config(dir.path());
        let out = dir.path().join("out");
        let _running = create(Some(&out), false, &config).expect("first run");
        assert!(matches!(
            create(Some(&out), true, &config),
            Err(RunDirError::InUse { .. })
        ));
        assert!(
            out.join(CONFIG_COPY_FILE).exists(),
            "the running run keeps its files"
        );
    }

    #[test]
    fn an_atomic_write_replaces_the_whole_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join(SUMMARY_FILE);
        std::fs::write(&path, "old").expect("write");
        write_atomically(&path, b"new").expect("written");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, [SUMMARY_FILE]);
    }
}
