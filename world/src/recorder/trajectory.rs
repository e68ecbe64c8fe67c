//! `trajectory.csv`: `tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive`, one row per robot per recorded
//! tick, positions in metres and headings in radians in (-pi, pi]. As in `events.csv`, `robot` is the robot's index
//! (the number `--fault`, `swarm ctl` and `summary.json` use) and `robot_id` its id from the configuration. A robot
//! that is not in the run at that tick (it joins later, or it left) has `NaN` for its pose and `alive` 0.

use std::path::Path;

use swarm_contract::messages::Rgb;

use super::csv_line::CsvFile;
use crate::arena::Arena;
use crate::error::WorldError;

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
                // A robot that is not in the run (yet, or any more) has no pose.
                x: if r.present { r.position.x } else { f32::NAN },
                y: if r.present { r.position.y } else { f32::NAN },
                heading: if r.present { r.heading } else { f32::NAN },
                led: r.led,
                alive: r.alive,
            })
            .for_each(rows);
    }
}

/// `angle` in (-pi, pi]: placed robots keep the orientation the configuration gave them until physics moves them.
fn wrapped(angle: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let a = angle.rem_euclid(TAU);
    if a > PI { a - TAU } else { a }
}

/// A buffered trajectory file.
pub struct TrajectoryWriter {
    file: CsvFile,
    /// The configuration's robot ids, by robot index.
    names: Vec<String>,
}

impl TrajectoryWriter {
    /// Creates (truncates) the run folder `dir`'s file for the arena's robots and writes the header; with
    /// `parquet`, also the table's Parquet file.
    pub fn create(dir: &Path, arena: &Arena, parquet: bool) -> Result<Self, WorldError> {
        Ok(Self {
            file: CsvFile::for_table(dir, swarm_records::Table::Trajectory, 1 << 16, parquet)?,
            names: arena.robots.iter().map(|r| r.name.clone()).collect(),
        })
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &PoseRow) -> Result<(), WorldError> {
        self.format(row).map_err(|source| self.file.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.file.flush()
    }

    /// Flushes the file and completes its Parquet file.
    pub fn close(&mut self) -> Result<(), WorldError> {
        self.file.close()
    }

    fn format(&mut self, row: &PoseRow) -> std::io::Result<()> {
        let name = self
            .names
            .get(row.robot as usize)
            .map_or("", String::as_str);
        self.file
            .line()
            .int(row.tick)?
            .int(row.robot)?
            .text(name)?
            .float(row.x)?
            .float(row.y)?
            .float(wrapped(row.heading))?
            .int(row.led.r)?
            .int(row.led.g)?
            .int(row.led.b)?
            .int(u8::from(row.alive))?
            .end()
    }
}

#[cfg(test)]
mod tests {
    use super::wrapped;
    use std::f32::consts::PI;

    #[test]
    fn headings_are_written_in_minus_pi_to_pi() {
        for (angle, expected) in [
            (0.0, 0.0),
            (PI, PI),
            (-PI, PI),
            (1.5 * PI, -0.5 * PI),
            (-6.807, -0.5239),
        ] {
            assert!(
                (wrapped(angle) - expected).abs() < 1e-3,
                "{angle} -> {}",
                wrapped(angle)
            );
        }
    }
}
