//! Where a run's poses are read from: `trajectory.parquet` once the run has ended and its records were converted
//! (the default), else `trajectory.csv` as the world appends it (a live run, or a `--records csv` run). A live
//! run's viewer moves from the one to the other when the Parquet file appears.

use std::fs::File;
use std::path::{Path, PathBuf};

use swarm_records::Table;

use crate::parquet_trajectory::ParquetTrajectory;
use crate::trajectory::{Pose, TrajectoryIndex};

/// The trajectory of a run folder, from whichever file holds it.
pub struct TrajectorySource {
    csv_path: PathBuf,
    parquet_path: PathBuf,
    robots: Option<usize>,
    csv: TrajectoryIndex,
    csv_file: Option<File>,
    parquet: Option<ParquetTrajectory>,
    /// Why `trajectory.parquet` cannot be shown (it is not opened again).
    parquet_problem: Option<String>,
}

impl TrajectorySource {
    /// The trajectory of the run folder `dir` of `robots` robots (`None`: learn it from the file).
    pub fn new(dir: &Path, robots: Option<usize>) -> Self {
        let csv_path = dir.join(Table::Trajectory.csv_name());
        TrajectorySource {
            csv: TrajectoryIndex::new(&csv_path, robots),
            csv_path,
            parquet_path: dir.join(Table::Trajectory.parquet_name()),
            robots,
            csv_file: None,
            parquet: None,
            parquet_problem: None,
        }
    }

    /// Reads what was written since the last call.
    pub fn update(&mut self) {
        if self.parquet.is_some() || self.parquet_problem.is_some() {
            return;
        }
        if self.parquet_path.exists() {
            match ParquetTrajectory::open(&self.parquet_path, self.robots) {
                Ok(parquet) => {
                    self.parquet = Some(parquet);
                    self.csv_file = None;
                }
                Err(problem) => self.parquet_problem = Some(problem),
            }
            return;
        }
        if self.csv.update() && self.csv_file.is_none() {
            self.csv_file = File::open(&self.csv_path).ok();
        }
    }

    /// Whether a trajectory file exists.
    pub fn exists(&self) -> bool {
        self.parquet_path.exists() || self.csv_path.exists()
    }

    /// The file the poses are read from (or would be), for messages.
    pub fn path(&self) -> &Path {
        if self.parquet.is_some() || self.parquet_problem.is_some() {
            &self.parquet_path
        } else {
            &self.csv_path
        }
    }

    /// Why the file cannot be read (further), if it cannot.
    pub fn problem(&self) -> Option<&str> {
        self.parquet_problem
            .as_deref()
            .or_else(|| self.parquet.is_none().then(|| self.csv.problem()).flatten())
    }

    /// Bytes at the end of `trajectory.csv` that are not a whole row (none for Parquet).
    pub fn unfinished_bytes(&self) -> usize {
        match self.parquet {
            Some(_) => 0,
            None => self.csv.unfinished_bytes(),
        }
    }

    /// Robots per tick, once known.
    pub fn robots(&self) -> Option<usize> {
        match &self.parquet {
            Some(parquet) => Some(parquet.robots()),
            None => self.csv.robots(),
        }
    }

    /// The first and last ticks whose every row can be read.
    pub fn complete_ticks(&self) -> Option<(u64, u64)> {
        match (&self.parquet, &self.csv_file) {
            (Some(parquet), _) => parquet.ticks(),
            (None, Some(_)) => self.csv.complete_ticks(),
            (None, None) => None,
        }
    }

    /// Every robot's pose at `tick` (a complete tick), by robot index.
    pub fn read_tick(&self, tick: u64) -> Result<Vec<Pose>, String> {
        match (&self.parquet, &self.csv_file) {
            (Some(parquet), _) => parquet.read_tick(tick),
            (None, Some(file)) => self.csv.read_tick(file, tick),
            (None, None) => Err("no trajectory file".to_owned()),
        }
    }
}
