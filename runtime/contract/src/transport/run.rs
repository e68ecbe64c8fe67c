//! The identity of one run on this host: its iceoryx2 prefix and root directory, and the cleanup of every file
//! the run created.
//!
//! Every run gets its own prefix (`/dev/shm/iox2_<name>_*`) and root directory, so parallel runs and tests never
//! see each other's services, and a run killed with SIGKILL can be wiped by name afterwards. Dead-node cleanup on
//! node creation is switched off (design.md: 1,000 agents connect in ~130 s with it, ~6 s without); the world
//! cleans dead nodes itself.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{SystemTime, UNIX_EPOCH};

use iceoryx2::prelude::{Config, FileName, SemanticString};

use super::TransportError;

/// Directory that holds the shared-memory files iceoryx2 (and the lockstep sync block) create.
const SHM_DIR: &str = "/dev/shm";
/// Where [`RunSpec::unique`] puts a run's iceoryx2 root directory (`iceoryx2-<name>`): the same tmpfs as the
/// shared memory. Every agent creates its node's files there when it joins; on a disk file system (ext4 under
/// `/tmp` here) creating those inodes was ~8 % of a 1,000-agent start-up.
pub const RUN_ROOTS_DIR: &str = SHM_DIR;
/// Longest run name; keeps every derived shared-memory file name far below the 255-byte limit.
const MAX_NAME_LEN: usize = 48;

/// Names one run: every process of the run must build the same `RunSpec` (the launcher passes it on the command line).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunSpec {
    name: String,
    root_dir: PathBuf,
}

impl RunSpec {
    /// A run with an explicit name (ASCII letters, digits, `-`; at most 48 bytes) and iceoryx2 root directory.
    pub fn new(name: &str, root_dir: impl Into<PathBuf>) -> Result<RunSpec, TransportError> {
        if name.is_empty()
            || name.len() > MAX_NAME_LEN
            || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-')
        {
            return Err(TransportError::InvalidRunName {
                name: name.to_owned(),
            });
        }
        let root_dir = root_dir.into();
        if !root_dir.is_absolute() {
            return Err(TransportError::RootDirNotAbsolute { path: root_dir });
        }
        Ok(RunSpec {
            name: name.to_owned(),
            root_dir,
        })
    }

    /// A fresh run name unique on this host (process id, time and a counter), rooted in the temp directory.
    pub fn unique() -> RunSpec {
        static COUNTER: AtomicU32 = AtomicU32::new(0);
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let name = format!(
            "sw{:x}-{:x}-{:x}",
            std::process::id(),
            nanos & 0xffff_ffff_ffff,
            COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let root_dir = Path::new(RUN_ROOTS_DIR).join(format!("iceoryx2-{name}"));
        RunSpec { name, root_dir }
    }

    /// The run name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The iceoryx2 root directory of the run (node and service descriptions).
    pub fn root_dir(&self) -> &Path {
        &self.root_dir
    }

    /// Start of the name of every file this run puts into `/dev/shm`.
    pub fn shm_prefix(&self) -> String {
        format!("iox2_{}_", self.name)
    }

    /// Path of the lockstep sync block (the futex words) of this run.
    pub(crate) fn sync_block_path(&self) -> PathBuf {
        Path::new(SHM_DIR).join(format!("{}lockstep", self.shm_prefix()))
    }

    /// Path of the run's command slots (`command_slots`).
    pub(crate) fn command_slots_path(&self) -> PathBuf {
        Path::new(SHM_DIR).join(format!("{}commands", self.shm_prefix()))
    }

    /// The iceoryx2 configuration of this run: its prefix and root, dead-node cleanup on creation off.
    pub(crate) fn iceoryx_config(&self) -> Result<Config, TransportError> {
        let mut config = Config::default();
        let prefix = self.shm_prefix();
        config.global.prefix = FileName::new(prefix.as_bytes())
            .map_err(|e| TransportError::iceoryx(format!("using the prefix '{prefix}'"), e))?;
        let mut root = self.root_dir.to_string_lossy().into_owned();
        if !root.ends_with('/') {
            root.push('/');
        }
        let root_path = iceoryx2::prelude::Path::new(root.as_bytes())
            .map_err(|e| TransportError::iceoryx(format!("using the root directory {root}"), e))?;
        config.global.set_root_path(&root_path);
        config.global.node.cleanup_dead_nodes_on_creation = false;
        config.global.node.cleanup_dead_nodes_on_destruction = false;
        config.global.service.cleanup_dead_nodes_on_open = false;
        Ok(config)
    }

    /// Removes every file of the run: `/dev/shm/iox2_<name>_*` and the root directory. Safe to call after any
    /// process of the run was killed, and when nothing is left. Returns the number of entries removed.
    pub fn cleanup(&self) -> Result<usize, TransportError> {
        let prefix = self.shm_prefix();
        let flat = std::fs::read_dir(SHM_DIR).map_err(|source| TransportError::Cleanup {
            path: PathBuf::from(SHM_DIR),
            source,
        })?;
        let mut doomed: Vec<Entry> = flat
            .flatten()
            .filter(|entry| entry.file_name().to_string_lossy().starts_with(&prefix))
            .map(Entry::of)
            .collect();
        // The root's subfolders (nodes, services) hold most of the entries: they are shared out entry by entry,
        // and removed themselves once empty.
        let (folders, files): (Vec<Entry>, Vec<Entry>) = entries_of(&self.root_dir)?
            .into_iter()
            .partition(|e| e.is_dir);
        for folder in &folders {
            doomed.extend(entries_of(&folder.path)?);
        }
        doomed.extend(files);
        let mut removed = remove_in_parallel(&doomed)?;
        let root = Entry {
            path: self.root_dir.clone(),
            is_dir: true,
        };
        for folder in folders.iter().chain([&root]) {
            removed += remove_entry(folder)?;
        }
        Ok(removed)
    }

    /// Removes the files of every run on this host whose launcher (or host daemon) is gone: a run named by
    /// [`RunSpec::unique`] carries its creator's process id, and a run whose creator no longer exists was killed
    /// before it could clean up (SIGKILL, power loss). Runs of a living process are left alone, whatever that
    /// process is, so a reused process id can only keep files, never remove a live run's. Logs and returns the
    /// number of entries removed.
    pub fn remove_dead_runs() -> usize {
        let mut dead: Vec<String> = std::fs::read_dir(SHM_DIR)
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|entry| {
                let file = entry.file_name().to_string_lossy().into_owned();
                let name = match file.strip_prefix("iox2_") {
                    Some(rest) => rest.split('_').next()?.to_owned(),
                    None => file.strip_prefix("iceoryx2-")?.to_owned(),
                };
                let creator = name.strip_prefix("sw")?.split('-').next()?;
                let pid = u32::from_str_radix(creator, 16).ok()?;
                let alive = Path::new("/proc").join(pid.to_string()).exists();
                (!alive).then_some(name)
            })
            .collect();
        dead.sort_unstable();
        dead.dedup();
        let mut removed = 0;
        for name in dead {
            let Ok(run) = RunSpec::new(
                &name,
                Path::new(RUN_ROOTS_DIR).join(format!("iceoryx2-{name}")),
            ) else {
                continue;
            };
            match run.cleanup() {
                Ok(n) => removed += n,
                Err(e) => tracing::warn!("removing the files of the dead run {name}: {e}"),
            }
        }
        if removed > 0 {
            tracing::info!(
                removed,
                "removed the shared memory of runs whose launcher or host daemon was killed"
            );
        }
        removed
    }

    /// Paths of every file of this run still present (empty after [`RunSpec::cleanup`]).
    pub fn leftovers(&self) -> Vec<PathBuf> {
        let prefix = self.shm_prefix();
        let mut found: Vec<PathBuf> = std::fs::read_dir(SHM_DIR)
            .into_iter()
            .flatten()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
            .map(|e| e.path())
            .collect();
        if self.root_dir.exists() {
            found.push(self.root_dir.clone());
        }
        found
    }
}

/// A file or folder to remove; a symbolic link counts as a file (it is removed, not followed).
struct Entry {
    path: PathBuf,
    is_dir: bool,
}

impl Entry {
    fn of(entry: std::fs::DirEntry) -> Entry {
        Entry {
            is_dir: entry.file_type().is_ok_and(|kind| kind.is_dir()),
            path: entry.path(),
        }
    }
}

/// The entries of folder `dir` (none if it does not exist).
fn entries_of(dir: &Path) -> Result<Vec<Entry>, TransportError> {
    match std::fs::read_dir(dir) {
        Ok(entries) => Ok(entries.flatten().map(Entry::of).collect()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(source) => Err(TransportError::Cleanup {
            path: dir.to_path_buf(),
            source,
        }),
    }
}

/// Removes `entries` (files, or folders with everything in them) from one thread per CPU; returns how many were
/// there. A run of 1,000 robots leaves about 15,000 entries, which one thread took 80 ms to remove, after the
/// run, while the user waits.
fn remove_in_parallel(entries: &[Entry]) -> Result<usize, TransportError> {
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let share = entries.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        let workers: Vec<_> = entries
            .chunks(share)
            .map(|chunk| {
                scope.spawn(move || chunk.iter().map(remove_entry).sum::<Result<usize, _>>())
            })
            .collect();
        workers
            .into_iter()
            .map(|worker| {
                worker
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .sum()
    })
}

/// Removes `entry`: 1 if it was there, 0 if it was gone already.
fn remove_entry(entry: &Entry) -> Result<usize, TransportError> {
    let path = &entry.path;
    let removed = if entry.is_dir {
        std::fs::remove_dir_all(path)
    } else {
        std::fs::remove_file(path)
    };
    match removed {
        Ok(()) => Ok(1),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(0),
        Err(source) => Err(TransportError::Cleanup {
            path: path.clone(),
            source,
        }),
    }
}
