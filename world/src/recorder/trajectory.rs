//! `trajectory.csv`: `tick,robot,x,y,heading,led_r,led_g,led_b,alive`, one row per robot per recorded tick,
//! positions in metres and headings in radians, `robot` being the id from the configuration.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::arena::Arena;
use crate::error::WorldError;

/// Name of the trajectory file in the run directory.
pub const TRAJECTORY_FILE: &str = "trajectory.csv";
/// The header line.
pub const TRAJECTORY_HEADER: &str = "tick,robot,x,y,heading,led_r,led_g,led_b,alive";

/// A buffered trajectory file.
pub struct TrajectoryWriter {
    path: PathBuf,
    out: BufWriter<File>,
}

impl TrajectoryWriter {
    /// Creates (truncates) the file and writes the header.
    pub fn create(path: &Path) -> Result<Self, WorldError> {
        let file = File::create(path).map_err(|source| WorldError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut writer = Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 16, file),
        };
        writeln!(writer.out, "{TRAJECTORY_HEADER}").map_err(|source| writer.error(source))?;
        Ok(writer)
    }

    fn error(&self, source: std::io::Error) -> WorldError {
        WorldError::Io {
            path: self.path.clone(),
            source,
        }
    }

    /// Writes every robot's row for the arena's current tick and flushes.
    pub fn write_tick(&mut self, arena: &Arena) -> Result<(), WorldError> {
        for r in &arena.robots {
            writeln!(
                self.out,
                "{},{},{},{},{},{},{},{},{}",
                arena.tick,
                r.name,
                r.position.x,
                r.position.y,
                r.heading,
                r.led.r,
                r.led.g,
                r.led.b,
                u8::from(r.alive)
            )
            .map_err(|source| self.error(source))?;
        }
        self.flush()
    }

    /// Flushes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.out.flush().map_err(|source| self.error(source))
    }
}
