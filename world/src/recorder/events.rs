//! `events.csv`: every event each robot fired, tick by tick, as its agent reported it in its command.
//!
//! Event ids are global per controller's supervisor set; names come from the event tables the launcher wrote
//! into the run directory (`event_tables.json`: controller id -> event names by id). Faults are rows too, with
//! `fault:<what>` in the event column (docs/faults.md).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use swarm_contract::run_dir::{EVENT_TABLES_FILE, EVENTS_FILE};

use super::csv_line::CsvLine;
use crate::arena::Arena;
use crate::error::WorldError;
use crate::world::Coordinator;

/// One row of `events.csv`, before formatting.
#[derive(Clone, Copy, Debug)]
pub enum EventRow {
    /// `robot` fired event `event` (an id of its controller's table) at `tick`.
    Fired {
        /// The tick.
        tick: u64,
        /// The robot index.
        robot: u32,
        /// The event id.
        event: u8,
    },
    /// A fault (`fault:kill`, ...) took effect for `robot` at `tick`.
    Fault {
        /// The tick.
        tick: u64,
        /// The robot index.
        robot: u32,
        /// The event column's text.
        name: &'static str,
    },
}

/// Writes `events.csv`.
pub struct EventsWriter {
    path: PathBuf,
    out: BufWriter<File>,
    /// Per participant (robots, then coordinators): its id and its controller's event names by event id.
    robots: Vec<(String, Vec<String>)>,
}

impl EventsWriter {
    /// Creates `events.csv` in `dir` for the arena's robots and the run's `coordinators` (the participants after
    /// the robots), naming events from the event tables the launcher left there (a controller without a table,
    /// or a run without tables, gets numeric event names).
    pub fn create(
        dir: &Path,
        arena: &Arena,
        coordinators: &[Coordinator],
    ) -> Result<EventsWriter, WorldError> {
        let tables_path = dir.join(EVENT_TABLES_FILE);
        let tables: BTreeMap<String, Vec<String>> = match std::fs::read_to_string(&tables_path) {
            Ok(text) => serde_json::from_str(&text).map_err(|e| WorldError::Io {
                path: tables_path.clone(),
                source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
            })?,
            Err(_) => BTreeMap::new(),
        };
        let path = dir.join(EVENTS_FILE);
        let io_error = |source| WorldError::Io {
            path: path.clone(),
            source,
        };
        let mut out = BufWriter::new(File::create(&path).map_err(io_error)?);
        writeln!(out, "tick,robot,robot_id,event").map_err(io_error)?;
        let named = |id: &str, controller: &str| {
            (
                id.to_owned(),
                tables.get(controller).cloned().unwrap_or_default(),
            )
        };
        let robots = arena
            .robots
            .iter()
            .map(|r| named(&r.name, &r.controller))
            .chain(coordinators.iter().map(|c| named(&c.id, &c.controller)))
            .collect();
        Ok(EventsWriter { path, out, robots })
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &EventRow) -> Result<(), WorldError> {
        self.format(row).map_err(|source| self.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.out.flush().map_err(|source| self.error(source))
    }

    fn error(&self, source: std::io::Error) -> WorldError {
        WorldError::Io {
            path: self.path.clone(),
            source,
        }
    }

    fn format(&mut self, row: &EventRow) -> std::io::Result<()> {
        let (tick, robot) = match *row {
            EventRow::Fired { tick, robot, .. } | EventRow::Fault { tick, robot, .. } => {
                (tick, robot)
            }
        };
        let robot_entry = self.robots.get(robot as usize);
        let start = |out| CsvLine::new(out).int(tick)?.int(robot);
        match (*row, robot_entry) {
            (EventRow::Fault { name, .. }, _) => {
                let id = robot_entry.map_or("", |(id, _)| id.as_str());
                start(&mut self.out)?.text(id)?.text(name)?.end()
            }
            (EventRow::Fired { event, .. }, Some((id, names))) => {
                let line = start(&mut self.out)?.text(id)?;
                match names.get(usize::from(event)) {
                    Some(name) => line.text(name)?.end(),
                    None => line.prefixed_int("#", event)?.end(),
                }
            }
            // Not a robot of this run: nothing to name it by.
            (EventRow::Fired { .. }, None) => Ok(()),
        }
    }
}
