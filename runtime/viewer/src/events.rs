//! A run's events held per participant in a compact form (tick and an interned name, 12 bytes a row), with what
//! the viewer derives from them: the faults, joins and leaves of the timeline, and when each robot was frozen or
//! held something in its gripper. They are read from `events.parquet` when the run's records have been
//! converted, else from `events.csv`, whose index grows as the file does (a live run).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use swarm_records::{ParquetTable, Table as RecordTable, Value};

use crate::lines::GrowingLines;

/// The header this version writes (docs/records.md).
pub const HEADER: &str = "tick,robot,robot_id,event";
/// Timeline markers kept at most; a run with more faults and joins than this shows the first ones.
pub const MAX_MARKERS: usize = 5000;
/// Participant indices accepted at most when the scene does not say how many there are.
const MAX_PARTICIPANTS: usize = 1 << 20;
/// Rows of `events.parquet` held at most (12 bytes each: 1.6 GB). Parquet's run-length encoding lets a small
/// file claim billions of rows, so a file claiming more is refused rather than loaded; a 1,000-robot,
/// 10,000-tick run has 6.5 million.
const MAX_PARQUET_ROWS: u64 = 1 << 27;
/// Distinct event names at most (they are interned as `u16`).
const MAX_NAMES: usize = u16::MAX as usize;

/// Whether an `events.csv` row is the world's (a fault, join, leave, gripper or item row) rather than an event a
/// robot's supervisors fired.
pub fn written_by_the_world(event: &str) -> bool {
    ["fault:", "gripper:", "item:", "join"]
        .iter()
        .any(|prefix| event.starts_with(prefix))
        || event == "leave"
}

/// A fault, join or leave on the timeline.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Marker {
    /// The tick.
    pub tick: u64,
    /// The participant index.
    pub robot: usize,
    /// Its id.
    pub id: String,
    /// `fault:kill`, `join`, ...
    pub what: String,
}

/// A state that a robot enters and leaves, as (tick, now on) changes in tick order.
#[derive(Default)]
struct Toggles(Vec<(u64, bool)>);

impl Toggles {
    fn push(&mut self, tick: u64, on: bool) {
        let at = self.0.partition_point(|&(t, _)| t <= tick);
        self.0.insert(at, (tick, on));
    }

    fn at(&self, tick: u64) -> bool {
        let at = self.0.partition_point(|&(t, _)| t <= tick);
        at > 0 && self.0[at - 1].1
    }
}

/// What one participant did.
#[derive(Default)]
struct Participant {
    id: String,
    /// (tick, interned event name), in file order (ticks ascending but for faults stamped ahead).
    events: Vec<(u64, u16)>,
    frozen: Toggles,
    carrying: Toggles,
}

/// The events of one run.
pub struct EventsIndex {
    lines: GrowingLines,
    /// `events.parquet` beside the CSV file, read whole once it exists.
    parquet: PathBuf,
    parquet_read: bool,
    table: Table,
    problem: Option<String>,
}

struct Table {
    header_seen: bool,
    participants_limit: usize,
    names: Vec<String>,
    name_ids: HashMap<String, u16>,
    participants: Vec<Participant>,
    markers: Vec<Marker>,
    markers_truncated: bool,
}

impl EventsIndex {
    /// An index of the run folder `dir`'s events, of a run with `participants` robots and coordinators (`None`:
    /// unknown).
    pub fn new(dir: &Path, participants: Option<usize>) -> Self {
        Self {
            lines: GrowingLines::new(&dir.join(RecordTable::Events.csv_name())),
            parquet: dir.join(RecordTable::Events.parquet_name()),
            parquet_read: false,
            table: Table::new(participants.unwrap_or(MAX_PARTICIPANTS)),
            problem: None,
        }
    }

    /// Why the file cannot be read further, if it cannot.
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }

    /// Reads the rows written since the last call: all of `events.parquet` once it exists (the run's records were
    /// converted when it ended), else the new lines of `events.csv`. Returns whether either file exists.
    pub fn update(&mut self) -> bool {
        if self.parquet_read {
            return true;
        }
        if self.parquet.exists() {
            self.parquet_read = true;
            let (table, problem) = load_parquet(
                &self.parquet,
                self.table.participants_limit,
                MAX_PARQUET_ROWS,
            );
            self.table = table;
            self.problem = problem;
            return true;
        }
        let table = &mut self.table;
        self.lines
            .read_until_problem(&mut self.problem, |line| table.add(line.text))
    }

    /// The faults, joins and leaves, and whether more were left out.
    pub fn markers(&self) -> (&[Marker], bool) {
        (&self.table.markers, self.table.markers_truncated)
    }

    /// Whether `robot` was frozen, and whether it held something in its gripper, at `tick`.
    pub fn flags_at(&self, robot: usize, tick: u64) -> (bool, bool) {
        self.table
            .participants
            .get(robot)
            .map_or((false, false), |p| (p.frozen.at(tick), p.carrying.at(tick)))
    }

    /// `robot`'s events up to and including `tick`, as (tick, name), in file order.
    pub fn events_until(&self, robot: usize, tick: u64) -> impl Iterator<Item = (u64, &str)> {
        self.table
            .participants
            .get(robot)
            .map(|p| p.events.as_slice())
            .unwrap_or_default()
            .iter()
            .filter(move |&&(t, _)| t <= tick)
            .map(|&(t, name)| (t, self.table.names[usize::from(name)].as_str()))
    }
}

impl Table {
    fn new(participants_limit: usize) -> Table {
        Table {
            header_seen: false,
            participants_limit,
            names: Vec::new(),
            name_ids: HashMap::new(),
            participants: Vec::new(),
            markers: Vec::new(),
            markers_truncated: false,
        }
    }

    /// Adds a row of `events.parquet` (the reader has checked the columns' types).
    fn add_row(&mut self, values: &[Value<'_>]) -> Result<(), String> {
        match values {
            [
                Value::Int64(tick),
                Value::Int32(robot),
                Value::Text(id),
                Value::Text(event),
            ] => {
                let robot = *robot as u32 as usize;
                let robot = (robot < self.participants_limit)
                    .then_some(robot)
                    .ok_or_else(|| format!("robot {robot} is not a participant of this run"))?;
                self.add_event(*tick as u64, robot, utf8(id)?, utf8(event)?)
            }
            _ => Err("the row is not an events row".to_owned()),
        }
    }

    /// Adds a line of `events.csv` (the first is its header).
    fn add(&mut self, text: &[u8]) -> Result<(), String> {
        let text = std::str::from_utf8(text).map_err(|_| "the row is not UTF-8".to_owned())?;
        if !self.header_seen {
            if text != HEADER {
                return Err(format!(
                    "the header `{text}` is not the one this version writes (`{HEADER}`): the file is not an \
                     events record, or an older version recorded it"
                ));
            }
            self.header_seen = true;
            return Ok(());
        }
        // An event name holds no comma; an id from the configuration might, so the event is the last field.
        let (front, event) = text
            .rsplit_once(',')
            .ok_or_else(|| "the row has no `event` column".to_owned())?;
        let mut fields = front.splitn(3, ',');
        let mut next = |name: &str| {
            fields
                .next()
                .ok_or_else(|| format!("the row ends before its `{name}` column"))
        };
        let tick_text = next("tick")?;
        let tick: u64 = tick_text
            .parse()
            .map_err(|_| format!("`{tick_text}` in the `tick` column is not a tick"))?;
        let robot_text = next("robot")?;
        let robot: usize = robot_text
            .parse()
            .ok()
            .filter(|&r| r < self.participants_limit)
            .ok_or_else(|| {
                format!("`{robot_text}` in the `robot` column is not a participant of this run")
            })?;
        let id = next("robot_id")?;
        self.add_event(tick, robot, id, event)
    }

    fn add_event(&mut self, tick: u64, robot: usize, id: &str, event: &str) -> Result<(), String> {
        let name = self.intern(event)?;
        if self.participants.len() <= robot {
            self.participants
                .resize_with(robot + 1, Participant::default);
        }
        let participant = &mut self.participants[robot];
        if participant.id.is_empty() {
            participant.id = id.to_owned();
        }
        participant.events.push((tick, name));
        match event {
            "fault:freeze" => participant.frozen.push(tick, true),
            "fault:thaw" | "fault:up" => participant.frozen.push(tick, false),
            "gripper:grip" | "item:picked" => participant.carrying.push(tick, true),
            "gripper:release" | "gripper:lost" | "gripper:release_on_death" | "item:dropped" => {
                participant.carrying.push(tick, false)
            }
            _ => {}
        }
        if event.starts_with("fault:") || event.starts_with("join") || event == "leave" {
            if self.markers.len() < MAX_MARKERS {
                self.markers.push(Marker {
                    tick,
                    robot,
                    id: id.to_owned(),
                    what: event.to_owned(),
                });
            } else {
                self.markers_truncated = true;
            }
        }
        Ok(())
    }

    fn intern(&mut self, name: &str) -> Result<u16, String> {
        if let Some(&id) = self.name_ids.get(name) {
            return Ok(id);
        }
        if self.names.len() >= MAX_NAMES {
            return Err(format!("more than {MAX_NAMES} distinct event names"));
        }
        let id = self.names.len() as u16;
        self.names.push(name.to_owned());
        self.name_ids.insert(name.to_owned(), id);
        Ok(id)
    }
}

/// The events of the Parquet file at `path`, and why not all of them when some are missing.
fn load_parquet(path: &Path, participants_limit: usize, max_rows: u64) -> (Table, Option<String>) {
    let mut table = Table::new(participants_limit);
    table.header_seen = true;
    let file = match ParquetTable::open(RecordTable::Events, path) {
        Ok(file) => file,
        Err(e) => return (table, Some(e.to_string())),
    };
    let rows: u64 = (0..file.row_groups()).map(|group| file.rows(group)).sum();
    if rows > max_rows {
        let problem = format!(
            "{}: {rows} rows, more than the viewer holds ({max_rows}): the events are not shown",
            path.display()
        );
        return (table, Some(problem));
    }
    let read = (0..file.row_groups()).try_for_each(|group| {
        file.read_row_group(group, |_, values| table.add_row(values))
            .map(drop)
    });
    (table, read.err().map(|e| e.to_string()))
}

fn utf8(value: &[u8]) -> Result<&str, String> {
    std::str::from_utf8(value).map_err(|_| "a text column is not UTF-8".to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derives_markers_and_frozen_spans() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("events.csv");
        std::fs::write(
            &path,
            format!(
                "{HEADER}\n1,0,ep0,go\n3,1,ep1,fault:freeze\n4,0,ep0,gripper:grip\n7,1,ep1,fault:thaw\n7,1,ep1,fault:up\n"
            ),
        )
        .expect("written");
        let mut index = EventsIndex::new(dir.path(), Some(2));
        assert!(index.update());
        assert_eq!(index.problem(), None);
        let (markers, truncated) = index.markers();
        let whats: Vec<_> = markers.iter().map(|m| (m.tick, m.what.as_str())).collect();
        assert_eq!(
            whats,
            vec![(3, "fault:freeze"), (7, "fault:thaw"), (7, "fault:up")]
        );
        assert!(!truncated);
        assert_eq!(index.flags_at(1, 2), (false, false));
        assert_eq!(index.flags_at(1, 3), (true, false));
        assert_eq!(index.flags_at(1, 7), (false, false));
        assert_eq!(index.flags_at(0, 5), (false, true));
        let until: Vec<_> = index.events_until(0, 3).collect();
        assert_eq!(until, vec![(1, "go")]);
    }

    #[test]
    fn an_id_with_a_comma_keeps_its_event() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("events.csv");
        std::fs::write(&path, format!("{HEADER}\n4,0,ep,0,fault:kill\n")).expect("written");
        let mut index = EventsIndex::new(dir.path(), Some(1));
        index.update();
        assert_eq!(index.problem(), None);
        let (markers, _) = index.markers();
        assert_eq!(
            (markers[0].id.as_str(), markers[0].what.as_str()),
            ("ep,0", "fault:kill")
        );
    }

    #[test]
    fn a_robot_outside_the_run_names_its_line() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("events.csv");
        std::fs::write(&path, format!("{HEADER}\n1,0,ep0,go\n1,9,ep9,go\n")).expect("written");
        let mut index = EventsIndex::new(dir.path(), Some(2));
        index.update();
        let problem = index.problem().expect("a problem");
        assert!(
            problem.ends_with(
                "events.csv:3: `9` in the `robot` column is not a participant of this run"
            ),
            "{problem}"
        );
    }

    #[test]
    fn parquet_events_are_read_whole_unless_they_claim_too_many_rows() {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::write(
            dir.path().join("events.csv"),
            format!("{HEADER}\n1,0,ep0,go\n3,1,ep1,fault:freeze\n7,1,ep1,fault:thaw\n"),
        )
        .expect("written");
        swarm_records::export(dir.path(), swarm_records::Format::Parquet).expect("exported");
        std::fs::remove_file(dir.path().join("events.csv")).expect("removed");
        let mut index = EventsIndex::new(dir.path(), Some(2));
        assert!(index.update());
        assert_eq!(index.problem(), None);
        assert_eq!(index.flags_at(1, 4), (true, false));
        assert_eq!(
            index.events_until(0, 9).collect::<Vec<_>>(),
            vec![(1, "go")]
        );
        let path = dir.path().join("events.parquet");
        let (table, problem) = load_parquet(&path, 2, 2);
        assert!(table.participants.is_empty());
        assert!(problem.is_some_and(|p| {
            p.ends_with("3 rows, more than the viewer holds (2): the events are not shown")
        }));
    }
}
