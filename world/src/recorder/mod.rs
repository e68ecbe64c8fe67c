//! The run record: `trajectory.csv` (one row per robot per tick), `events.csv` (every fired event and fault),
//! `messages.csv` (every addressed message's fate, in runs with a messages medium), `scene.json` (what a viewer
//! draws the run over, [`scene_file`]), `summary.json` (the loop functions' metrics and run facts) and PNG snapshots at chosen ticks.
//!
//! The tick loop only copies plain rows; a thread of the recorder's own formats, writes and flushes them, one
//! batch per tick ([`background`], [`files`]). Recording reads the world and never changes it.

pub mod background;
mod csv_line;
pub mod events;
pub mod files;
pub mod messages;
pub mod objects_file;
mod parquet_twin;
pub mod pheromone_file;
pub mod scene_file;
pub mod snapshot;
mod snapshot_labels;
mod trail_lines;
pub mod trails;
pub mod trajectory;

use swarm_contract::run_dir::SUMMARY_FILE;

pub use background::{Background, RowWriter};
pub use events::{EventRow, EventsWriter};
pub use files::{RecordFiles, RecordRow};
pub use trajectory::{PoseRow, TrajectoryWriter};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use swarm_contract::messages::ActuatorCommand;
pub use swarm_contract::protocol::launcher_to_world::Records;

use crate::arena::GripperEvent;
use crate::error::WorldError;
use crate::media::mail::MessageRecord;
use crate::world::World;

/// Records one run into a directory.
pub struct Recorder {
    dir: PathBuf,
    /// The record tables' writing thread; `None` with [`Records::Off`].
    files: Option<Background<RecordFiles>>,
    snapshot_ticks: BTreeSet<u64>,
    loop_output: Option<LoopOutput>,
    object_moves: Option<objects_file::ObjectMoves>,
    pheromone: Option<pheromone_file::PheromoneFile>,
    trails: trails::Trails,
}

/// The loop functions' own output file, written on the tick thread: a short line per tick at most, and only for
/// loop functions that keep one (ARGoS' foraging example), never on the thesis tasks' path.
struct LoopOutput {
    path: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
    buffer: Vec<u8>,
}

impl LoopOutput {
    fn write(&mut self, world: &mut World) -> Result<(), WorldError> {
        use std::io::Write;
        world.drain_loop_output(&mut self.buffer);
        let io = |source| WorldError::Io {
            path: self.path.clone(),
            source,
        };
        self.file.write_all(&self.buffer).map_err(io)?;
        self.buffer.clear();
        self.file.flush().map_err(io)
    }
}

impl Recorder {
    /// Creates `dir` (if needed) and its `trajectory.csv` and `events.csv` for `world`'s robots (event names
    /// from the launcher's event tables in `dir`, if any); snapshots are drawn after each tick in
    /// `snapshot_ticks` (tick 0 is the initial placement: record it before the first tick), and of the final
    /// state by [`Recorder::finish`]. With [`Records::Parquet`] the record tables are also written as Parquet
    /// files, which [`Recorder::finish`] completes; with [`Records::Off`] there are no record tables (nor
    /// `objects.csv`), only the scene, the pheromone field, the snapshots and the summary.
    pub fn create(
        dir: &Path,
        world: &World,
        snapshot_ticks: &[u64],
        records: Records,
    ) -> Result<Self, WorldError> {
        std::fs::create_dir_all(dir).map_err(|source| WorldError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let parquet = records == Records::Parquet;
        let (object_moves, files) = if records == Records::Off {
            (None, None)
        } else {
            let (object_moves, objects) =
                objects_file::ObjectsWriter::create(dir, &world.arena)?.unzip();
            let files = RecordFiles {
                events: EventsWriter::create(dir, &world.arena, world.coordinators(), parquet)?,
                trajectory: TrajectoryWriter::create(dir, &world.arena, parquet)?,
                messages: world
                    .has_mail()
                    .then(|| messages::MessagesWriter::create(dir, parquet))
                    .transpose()?,
                objects,
            };
            (object_moves, Some(Background::spawn(dir, files)?))
        };
        let pheromone = pheromone_file::PheromoneFile::create(dir, &world.arena)?;
        let pheromone_entry = pheromone
            .as_ref()
            .map_or(serde_json::Value::Null, |p| p.describe(&world.arena));
        scene_file::write(dir, world, pheromone_entry)?;
        let loop_output = match world.loop_output_name() {
            None => None,
            Some(name) => {
                let path = dir.join(name);
                let file = std::fs::File::create(&path).map_err(|source| WorldError::Io {
                    path: path.clone(),
                    source,
                })?;
                Some(LoopOutput {
                    path,
                    file: std::io::BufWriter::new(file),
                    buffer: Vec::new(),
                })
            }
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            files,
            snapshot_ticks: snapshot_ticks.iter().copied().collect(),
            loop_output,
            object_moves,
            pheromone,
            trails: trails::Trails::default(),
        })
    }

    /// Hands `row` to the writing thread (nothing with [`Records::Off`]).
    fn push(&mut self, row: RecordRow) {
        if let Some(files) = &mut self.files {
            files.push(row);
        }
    }

    /// Records the events `robot`'s command reports as fired.
    pub fn record_command(&mut self, robot: usize, command: &ActuatorCommand) {
        for &event in command.fired_events() {
            self.push(RecordRow::Event(EventRow::Fired {
                tick: command.tick,
                robot: robot as u32,
                event,
            }));
        }
    }

    /// Records the messages medium's decisions of a tick (`messages.csv`).
    pub fn record_messages(&mut self, records: &[MessageRecord]) {
        for &record in records {
            self.push(RecordRow::Message(record));
        }
    }

    /// Records a fault row: `name` (e.g. `fault:kill`) in the event column, taking effect at `tick`.
    pub fn record_fault(&mut self, tick: u64, robot: usize, name: &'static str) {
        self.push(RecordRow::Event(EventRow::Fault {
            tick,
            robot: robot as u32,
            name,
        }));
    }

    /// Ends the world's current tick: the loop functions' output of the tick goes to its file; the physical
    /// grippers' events of the tick (`gripper:grip`, `gripper:lifted`, `gripper:lowered`, `gripper:release`,
    /// `gripper:lost`, `gripper:release_on_death`) and the items picked up and put down (`item:picked`,
    /// `item:dropped`), its trajectory rows and the events recorded since the last
    /// tick go to the writing thread; and a snapshot is drawn if this tick is scheduled.
    pub fn record(&mut self, world: &mut World) -> Result<(), WorldError> {
        if let Some(output) = &mut self.loop_output {
            output.write(world)?;
        }
        if let Some(pheromone) = &mut self.pheromone {
            pheromone.record(&world.arena)?;
        }
        if let (Some(moves), Some(files)) = (&mut self.object_moves, &mut self.files) {
            moves.changes(&world.arena, |row| files.push(RecordRow::Object(row)));
        }
        let tick = world.tick();
        for event in &world.arena.gripper_events {
            let (robot, name) = match *event {
                GripperEvent::Gripped { robot, .. } => (robot, "gripper:grip"),
                GripperEvent::Lifted { robot, .. } => (robot, "gripper:lifted"),
                GripperEvent::Lowered { robot, .. } => (robot, "gripper:lowered"),
                GripperEvent::Released { robot, cause, .. } => (robot, cause.event_name()),
                GripperEvent::Picked { robot, .. } => (robot, "item:picked"),
                GripperEvent::Dropped { robot, .. } => (robot, "item:dropped"),
            };
            self.record_fault(tick, robot.index(), name);
        }
        if let Some(files) = &mut self.files {
            PoseRow::capture(&world.arena, |row| files.push(RecordRow::Pose(row)));
            files.end_batch()?;
        }
        let positions = world
            .arena
            .robots
            .iter()
            .map(|r| (r.present && r.alive && !r.removed).then_some(r.position));
        self.trails.sample(tick, positions);
        if self.snapshot_ticks.contains(&world.tick()) {
            self.snapshot(world)?;
        }
        Ok(())
    }

    fn snapshot(&self, world: &World) -> Result<(), WorldError> {
        let tick = world.tick();
        let path = swarm_contract::run_dir::snapshot(&self.dir, tick);
        snapshot::render(world, &self.trails, &path)
    }

    /// Returns once every row recorded so far is in its file. The world calls it before it reports a scheduled
    /// world kill (the launcher kills it on that report) and before the launcher applies any other fault, so a
    /// world killed by its schedule leaves every earlier tick recorded.
    pub fn sync(&mut self) -> Result<(), WorldError> {
        self.files.as_mut().map_or(Ok(()), Background::sync)
    }

    /// Writes the rest of the record tables and completes their files (the Parquet files get their footers and
    /// their names). Later rows are not recorded. [`Recorder::finish`] does this too if it has not been done.
    ///
    /// The world calls it after the last tick and before it ends the run for the agents: the recording thread
    /// runs at normal priority, and 1,000 agents exiting at real-time priority kept it from its last 5 ms of
    /// work for 70-110 ms.
    pub fn complete_records(&mut self) -> Result<(), WorldError> {
        if let Some(files) = self.files.take() {
            let started = std::time::Instant::now();
            files.finish()?;
            tracing::debug!(took = ?started.elapsed(), "record files completed");
        }
        Ok(())
    }

    /// Completes the record files (unless [`Recorder::complete_records`] did), draws a snapshot of the final state
    /// (unless that tick was drawn already), then writes `summary.json`: the metrics of the loop functions under
    /// `metrics`, the run facts, the final pose of every movable box and cylinder under `movable_objects`, the
    /// participants without a body under `coordinators` (index, id, controller), and `extra` merged in at the top
    /// level. Returns the summary's path.
    ///
    /// The final snapshot is drawn here rather than in the last tick: drawing it there counted as tick time and
    /// made the last tick of a 2,000-robot real-time run 50 ms late.
    pub fn finish(
        mut self,
        world: &World,
        extra: serde_json::Value,
    ) -> Result<PathBuf, WorldError> {
        self.complete_records()?;
        let started = std::time::Instant::now();
        if !self.snapshot_ticks.contains(&world.tick()) {
            self.snapshot(world)?;
        }
        tracing::debug!(snapshot = ?started.elapsed(), "final snapshot drawn");
        let movable: Vec<serde_json::Value> = world
            .arena
            .obstacles
            .iter()
            .enumerate()
            .filter(|(_, o)| matches!(o.motion, crate::physics::Motion::Movable { .. }))
            .map(|(index, o)| {
                serde_json::json!({
                    "id": o.name,
                    "index": index,
                    "x": o.placed.position.x,
                    "y": o.placed.position.y,
                    "angle": o.placed.angle(),
                    "lifted": o.lifted,
                })
            })
            .collect();
        let coordinators: Vec<serde_json::Value> = (world.robot_count()..)
            .zip(world.coordinators())
            .map(|(index, c)| serde_json::json!({"index": index, "id": c.id, "controller": c.controller}))
            .collect();
        let mut summary = serde_json::json!({
            "ticks": world.tick(),
            "ticks_per_second": world.arena.ticks_per_second,
            "robots": world.robot_count(),
            "coordinators": coordinators,
            "metrics": world.metrics(),
            "movable_objects": movable,
        });
        if let (Some(map), serde_json::Value::Object(extra)) = (summary.as_object_mut(), extra) {
            map.extend(extra);
        }
        let path = self.dir.join(SUMMARY_FILE);
        let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
        swarm_contract::run_dir::write_atomically(&path, text.as_bytes()).map_err(|source| {
            WorldError::Io {
                path: path.clone(),
                source,
            }
        })?;
        Ok(path)
    }
}
