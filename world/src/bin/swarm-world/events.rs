//! `events.csv`: every event each robot fired, tick by tick, as its agent reported it in its command.
//!
//! Event ids are global per controller's supervisor set; names come from the event tables the launcher wrote
//! into the run directory (`event_tables.json`: controller id -> event names by id). Rows are buffered and
//! flushed at the end of every tick, so a crash loses at most the tick being written. Faults are rows too, with
//! `fault:<what>` in the event column (docs/faults.md).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use anyhow::Context;
use swarm_runtime::launcher::EVENT_TABLES_FILE;
use swarm_runtime::messages::ActuatorCommand;

/// File name of the event record in the run directory.
pub const EVENTS_FILE: &str = "events.csv";

/// Writes `events.csv`.
pub struct EventsWriter {
    out: BufWriter<File>,
    /// Per robot: its id and its controller's event names by event id.
    robots: Vec<(String, Vec<String>)>,
}

impl EventsWriter {
    /// Creates `events.csv` in `dir` for robots given as (robot id, controller id), reading the event tables the
    /// launcher left there (a robot whose controller has no table gets numeric event names).
    pub fn create(dir: &Path, robots: &[(String, String)]) -> anyhow::Result<EventsWriter> {
        let tables_path = dir.join(EVENT_TABLES_FILE);
        let tables: BTreeMap<String, Vec<String>> = match std::fs::read_to_string(&tables_path) {
            Ok(text) => serde_json::from_str(&text)
                .with_context(|| format!("reading {}", tables_path.display()))?,
            Err(_) => BTreeMap::new(),
        };
        let path = dir.join(EVENTS_FILE);
        let file = File::create(&path).with_context(|| format!("creating {}", path.display()))?;
        let mut out = BufWriter::new(file);
        writeln!(out, "tick,robot,robot_id,event")?;
        let robots = robots
            .iter()
            .map(|(id, controller)| {
                (
                    id.clone(),
                    tables.get(controller).cloned().unwrap_or_default(),
                )
            })
            .collect();
        Ok(EventsWriter { out, robots })
    }

    /// Writes the events of one robot's command.
    pub fn record(&mut self, robot: usize, command: &ActuatorCommand) -> std::io::Result<()> {
        let Some((id, names)) = self.robots.get(robot) else {
            return Ok(());
        };
        for &event in command.fired_events() {
            match names.get(usize::from(event)) {
                Some(name) => writeln!(self.out, "{},{robot},{id},{name}", command.tick)?,
                None => writeln!(self.out, "{},{robot},{id},#{event}", command.tick)?,
            }
        }
        Ok(())
    }

    /// Writes a fault row: `name` (e.g. `fault:kill`) in the event column, taking effect at `tick`.
    pub fn record_fault(&mut self, tick: u64, robot: usize, name: &str) -> std::io::Result<()> {
        let id = self.robots.get(robot).map_or("", |(id, _)| id.as_str());
        writeln!(self.out, "{tick},{robot},{id},{name}")
    }

    /// Ends a tick: everything recorded so far reaches the file.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}
