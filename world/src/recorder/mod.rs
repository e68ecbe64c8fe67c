//! The run record: `trajectory.csv` (one row per robot per tick), `summary.json` (the loop functions' metrics
//! and run facts) and PNG snapshots at chosen ticks.
//!
//! Rows go through a buffered writer that is flushed at the end of every tick, so a crash loses at most the tick
//! being written. Recording reads the world and never changes it.

pub mod snapshot;
pub mod trajectory;

pub use trajectory::{TRAJECTORY_FILE, TrajectoryWriter};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::error::WorldError;
use crate::world::World;

/// Name of the summary file in the run directory.
pub const SUMMARY_FILE: &str = "summary.json";

/// Records one run into a directory.
pub struct Recorder {
    dir: PathBuf,
    trajectory: TrajectoryWriter,
    snapshot_ticks: BTreeSet<u64>,
}

impl Recorder {
    /// Creates `dir` (if needed) and its `trajectory.csv`; snapshots are drawn after each tick in `snapshot_ticks`
    /// (tick 0 is the initial placement, drawn by [`Recorder::record_initial`]).
    pub fn create(dir: &Path, snapshot_ticks: &[u64]) -> Result<Self, WorldError> {
        std::fs::create_dir_all(dir).map_err(|source| WorldError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        Ok(Self {
            dir: dir.to_path_buf(),
            trajectory: TrajectoryWriter::create(&dir.join(TRAJECTORY_FILE))?,
            snapshot_ticks: snapshot_ticks.iter().copied().collect(),
        })
    }

    /// Records the initial placement (tick 0).
    pub fn record_initial(&mut self, world: &World) -> Result<(), WorldError> {
        self.record(world)
    }

    /// Records the world's current tick: trajectory rows (flushed), and a snapshot if this tick is scheduled.
    pub fn record(&mut self, world: &World) -> Result<(), WorldError> {
        self.trajectory.write_tick(&world.arena)?;
        let tick = world.tick();
        if self.snapshot_ticks.contains(&tick) {
            snapshot::render(world, &self.dir.join(format!("snapshot_{tick:06}.png")))?;
        }
        Ok(())
    }

    /// Writes `summary.json`: the metrics of the loop functions under `metrics`, the run facts, and `extra`
    /// merged in at the top level. Returns the file's path.
    pub fn finish(
        &mut self,
        world: &World,
        extra: serde_json::Value,
    ) -> Result<PathBuf, WorldError> {
        self.trajectory.flush()?;
        let mut summary = serde_json::json!({
            "ticks": world.tick(),
            "ticks_per_second": world.arena.ticks_per_second,
            "robots": world.robot_count(),
            "metrics": world.metrics(),
        });
        if let (Some(map), serde_json::Value::Object(extra)) = (summary.as_object_mut(), extra) {
            map.extend(extra);
        }
        let path = self.dir.join(SUMMARY_FILE);
        let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
        std::fs::write(&path, text).map_err(|source| WorldError::Io {
            path: path.clone(),
            source,
        })?;
        Ok(path)
    }
}
