//! `pheromone.bin`: the pheromone field at tick 0 and then once per simulated second, for replays (the viewer
//! draws it under the robots). Only runs with a pheromone medium have one.
//!
//! The file is a sequence of equal frames: the tick (`u64`, little-endian), then per channel, per row from the
//! arena's minimum y up, per column one byte, the concentration clamped to [0, 1] times 255. The grid's size, the
//! period and the channel colours are in `scene.json` (`pheromone`). A frame is written whole and flushed, so a
//! cut file ends with whole frames plus at most one partial one, which readers ignore. It is written on the tick
//! thread, as the loop functions' output is: once a simulated second, a frame's copy would cost what its write does.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use swarm_contract::messages::PHEROMONE_CHANNELS;
use swarm_contract::run_dir::PHEROMONE_FILE;

use super::scene_file::short;
use super::snapshot::PHEROMONE_COLOURS;
use crate::arena::Arena;
use crate::error::WorldError;

/// Bytes before a frame's grid: its tick.
pub const FRAME_HEADER: usize = 8;

/// The open file of a run.
pub struct PheromoneFile {
    path: PathBuf,
    file: BufWriter<File>,
    /// Ticks between frames.
    every: u64,
    frame: Vec<u8>,
}

impl PheromoneFile {
    /// Creates the file in `dir` when the arena has a pheromone medium.
    pub fn create(dir: &Path, arena: &Arena) -> Result<Option<Self>, WorldError> {
        if !arena.pheromone.is_active() {
            return Ok(None);
        }
        let path = dir.join(PHEROMONE_FILE);
        let file = File::create(&path).map_err(|source| WorldError::Io {
            path: path.clone(),
            source,
        })?;
        let (nx, ny, _) = arena.pheromone.dimensions();
        Ok(Some(Self {
            path,
            file: BufWriter::new(file),
            every: u64::from(arena.ticks_per_second.max(1)),
            frame: Vec::with_capacity(FRAME_HEADER + PHEROMONE_CHANNELS * nx * ny),
        }))
    }

    /// The file's entry of `scene.json`.
    pub fn describe(&self, arena: &Arena) -> Value {
        let (nx, ny, cell) = arena.pheromone.dimensions();
        let origin = arena.pheromone.origin();
        json!({
            "file": PHEROMONE_FILE,
            "min": [short(origin.x), short(origin.y)],
            "cell": short(cell),
            "nx": nx,
            "ny": ny,
            "channels": PHEROMONE_CHANNELS,
            "every": self.every,
            "colours": PHEROMONE_COLOURS.map(|(r, g, b)| [r, g, b]),
        })
    }

    /// Writes the field if the arena's tick is a multiple of the period.
    pub fn record(&mut self, arena: &Arena) -> Result<(), WorldError> {
        if !arena.tick.is_multiple_of(self.every) {
            return Ok(());
        }
        let (nx, ny, _) = arena.pheromone.dimensions();
        self.frame.clear();
        self.frame.extend_from_slice(&arena.tick.to_le_bytes());
        for channel in 0..PHEROMONE_CHANNELS {
            for y in 0..ny {
                for x in 0..nx {
                    let value = arena.pheromone.cell_value(channel, x, y).clamp(0.0, 1.0);
                    self.frame.push((value * 255.0).round() as u8);
                }
            }
        }
        let io = |source| WorldError::Io {
            path: self.path.clone(),
            source,
        };
        self.file.write_all(&self.frame).map_err(io)?;
        self.file.flush().map_err(io)
    }
}
