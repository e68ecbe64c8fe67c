//! `events.csv`: every event each robot fired, tick by tick, as its agent reported it in its command.
//!
//! Event ids are global per controller's supervisor set; names come from the event tables the launcher wrote
//! into the run directory (`event_tables.json`: controller id -> event names by id). Faults are rows too, with
//! `fault:<what>` in the event column (docs/faults.md).

use std::collections::BTreeMap;
use std::path::Path;

use swarm_contract::run_dir::EVENT_TABLES_FILE;

use super::csv_line::CsvFile;
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
    file: CsvFile,
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
        parquet: bool,
    ) -> Result<EventsWriter, WorldError> {
        let tables_path = dir.join(EVENT_TABLES_FILE);
        let tables: BTreeMap<String, Vec<String>> = match std::fs::read_to_string(&tables_path) {
            Ok(text) => serde_json::from_str(&text).map_err(|e| WorldError::Io {
                path: tables_path.clone(),
                source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
            })?,
            Err(_) => BTreeMap::new(),
        };
        let file = CsvFile::for_table(dir, swarm_records::Table::Events, 1 << 13, parquet)?;
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
        Ok(EventsWriter { file, robots })
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &EventRow) -> Result<(), WorldError> {
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

    fn format(&mut self, row: &EventRow) -> std::io::Result<()> {
        let (tick, robot) = match *row {
            EventRow::Fired { tick, robot, .. } | EventRow::Fault { tick, robot, .. } => {
                (tick, robot)
            }
        };
        let robot_entry = self.robots.get(robot as usize);
        if let (EventRow::Fired { .. }, None) = (row, robot_entry) {
            // Not a robot of this run: nothing to name it by.
            return Ok(());
        }
        let line = self.file.line().int(tick)?.int(robot)?;
        match (*row, robot_entry) {
            (EventRow::Fault { name, .. }, _) => {
                let id = robot_entry.map_or("", |(id, _)| id.as_str());
                line.text(id)?.text(name)?.end()
            }
            (EventRow::Fired { event, .. }, Some((id, names))) => {
                let line = line.text(id)?;
                match names.get(usize::from(event)) {
                    Some(name) => line.text(name)?.end(),
                    None => line.prefixed_int("#", event)?.end(),
                }
            }
            (EventRow::Fired { .. }, None) => Ok(()),
        }
    }
}
