//! The run's disk budget: a run stops cleanly, with its records complete, before it fills the disk of its run
//! folder (limit `disk_reserve_mb`) or grows its folder past `records_max_mb`.
//!
//! The launcher refuses to start a run on a disk already below its reserve ([`DiskBudget::check`]). During the
//! run the world looks at the budget about once per [`CHECK_PERIOD`] after a tick is recorded (free space by
//! `statvfs`, the folder's size by summing its files), never per tick: records grow by a few MB per second at
//! most. A run stopped by the budget ends like an interrupted one: the last tick is recorded whole and
//! `summary.json` says why it stopped (`stopped_early`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How often the budget is looked at.
const CHECK_PERIOD: Duration = Duration::from_secs(1);
const MIB: u64 = 1 << 20;

/// Watches the run folder's disk and size.
pub struct DiskBudget {
    dir: PathBuf,
    reserve_mb: u64,
    max_mb: u64,
    next_check: Instant,
}

impl DiskBudget {
    /// A budget for the run folder `dir`; the first look is one [`CHECK_PERIOD`] after its creation.
    pub fn new(dir: &Path, reserve_mb: u64, max_mb: u64) -> DiskBudget {
        DiskBudget {
            dir: dir.to_path_buf(),
            reserve_mb,
            max_mb,
            next_check: Instant::now() + CHECK_PERIOD,
        }
    }

    /// Why the run must stop now, if it must (looks at most once per [`CHECK_PERIOD`]).
    pub fn exceeded(&mut self) -> Option<String> {
        let now = Instant::now();
        if now < self.next_check {
            return None;
        }
        self.next_check = now + CHECK_PERIOD;
        self.check()
    }

    /// Why the run must stop (or not start), looking now.
    pub fn check(&self) -> Option<String> {
        match nix::sys::statvfs::statvfs(&self.dir) {
            Ok(stats) => {
                let free = stats.blocks_available() * stats.fragment_size();
                if free < self.reserve_mb.saturating_mul(MIB) {
                    return Some(format!(
                        "the disk of {} has {} MiB free, less than the reserve of {} MiB (limit disk_reserve_mb)",
                        self.dir.display(),
                        free / MIB,
                        self.reserve_mb
                    ));
                }
            }
            Err(e) => tracing::warn!(
                dir = %self.dir.display(),
                "cannot read the free space of the run folder's disk: {e}"
            ),
        }
        let size = folder_size(&self.dir);
        (size > self.max_mb.saturating_mul(MIB)).then(|| {
            format!(
                "the run folder {} holds {} MiB, more than the limit of {} MiB (limit records_max_mb)",
                self.dir.display(),
                size / MIB,
                self.max_mb
            )
        })
    }
}

/// Bytes in the files under `dir` (symbolic links not followed).
fn folder_size(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|entry| match entry.file_type() {
            Ok(kind) if kind.is_dir() => folder_size(&entry.path()),
            Ok(kind) if kind.is_file() => entry.metadata().map_or(0, |m| m.len()),
            _ => 0,
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_past_its_size_or_a_disk_below_its_reserve_stops_the_run() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        std::fs::create_dir(dir.path().join("logs")).expect("a subfolder");
        std::fs::write(dir.path().join("logs/a"), vec![0u8; 3 << 20]).expect("a file");
        assert_eq!(folder_size(dir.path()), 3 << 20);
        assert!(DiskBudget::new(dir.path(), 1, 1 << 20).check().is_none());
        let too_big = DiskBudget::new(dir.path(), 1, 2)
            .check()
            .expect("past 2 MiB");
        assert!(too_big.contains("records_max_mb"), "{too_big}");
        let no_room = DiskBudget::new(dir.path(), u64::MAX / MIB, 1 << 20)
            .check()
            .expect("no disk is that large");
        assert!(no_room.contains("disk_reserve_mb"), "{no_room}");
    }
}
