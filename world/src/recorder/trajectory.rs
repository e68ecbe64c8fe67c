//! `trajectory.csv`: `tick,robot,x,y,heading,led_r,led_g,led_b,alive`, one row per robot per recorded tick,
//! positions in metres and headings in radians, `robot` being the id from the configuration.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use swarm_contract::messages::Rgb;

use super::csv_line::CsvLine;
use crate::arena::Arena;
use crate::error::WorldError;

/// The header line.
pub const TRAJECTORY_HEADER: &str = "tick,robot,x,y,heading,led_r,led_g,led_b,alive";

/// One robot's row of one tick, before formatting.
#[derive(Clone, Copy, Debug)]
pub struct PoseRow {
    tick: u64,
    robot: u32,
    x: f32,
    y: f32,
    heading: f32,
    led: Rgb,
    alive: bool,
}

impl PoseRow {
    /// Hands every robot's row for the arena's current tick to `rows`, in robot order.
    pub fn capture(arena: &Arena, rows: impl FnMut(PoseRow)) {
        arena
            .robots
            .iter()
            .enumerate()
            .map(|(robot, r)| PoseRow {
                tick: arena.tick,
                robot: robot as u32,
                x: r.position.x,
                y: r.position.y,
                heading: r.heading,
                led: r.led,
                alive: r.alive,
            })
            .for_each(rows);
    }
}

/// A buffered trajectory file.
pub struct TrajectoryWriter {
    path: PathBuf,
    out: BufWriter<File>,
    /// The configuration's robot ids, by robot index.
    names: Vec<String>,
}

impl TrajectoryWriter {
    /// Creates (truncates) the file for the arena's robots and writes the header.
    pub fn create(path: &Path, arena: &Arena) -> Result<Self, WorldError> {
        let file = File::create(path).map_err(|source| WorldError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut writer = Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 16, file),
            names: arena.robots.iter().map(|r| r.name.clone()).collect(),
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

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &PoseRow) -> Result<(), WorldError> {
        self.format(row).map_err(|source| self.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.out.flush().map_err(|source| self.error(source))
    }

    fn format(&mut self, row: &PoseRow) -> std::io::Result<()> {
        let name = self
            .names
            .get(row.robot as usize)
            .map_or("", String::as_str);
        CsvLine::new(&mut self.out)
            .int(row.tick)?
            .text(name)?
            .float(row.x)?
            .float(row.y)?
            .float(row.heading)?
            .int(row.led.r)?
            .int(row.led.g)?
            .int(row.led.b)?
            .int(u8::from(row.alive))?
            .end()
    }
}
