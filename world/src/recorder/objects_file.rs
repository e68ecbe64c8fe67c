//! `objects.csv`: where the targets and the movable obstacles are, for replays. A row for every such object at
//! tick 0, then one whenever an object moved (more than half a millimetre or a milliradian) or entered or left the
//! arena (a target picked up, put down or removed), so that still objects cost nothing.
//!
//! The tick loop only compares poses and hands the changed ones over as plain rows ([`ObjectMoves`]); the
//! recorder's thread formats and writes them ([`ObjectsWriter`]), as it does the other per-tick files.

use std::path::Path;

use swarm_contract::run_dir::OBJECTS_FILE;

use super::csv_line::CsvFile;
use crate::arena::Arena;
use crate::entities::TargetState;
use crate::error::WorldError;
use crate::geometry::Placed;
use crate::physics::Motion;

/// The header line.
pub const OBJECTS_HEADER: &str = "tick,kind,index,id,x,y,angle,in_arena";

/// Movement below these is not written again.
const MIN_MOVE_M: f32 = 5e-4;
const MIN_TURN_RAD: f32 = 1e-3;

/// Which list of the scene an object is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjectKind {
    /// A target.
    Target,
    /// A movable obstacle.
    Obstacle,
}

/// An object's pose and presence.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Place {
    x: f32,
    y: f32,
    angle: f32,
    in_arena: bool,
}

impl Place {
    fn of(placed: &Placed, in_arena: bool) -> Self {
        Self {
            x: placed.position.x,
            y: placed.position.y,
            angle: placed.angle(),
            in_arena,
        }
    }

    fn differs(&self, other: &Place) -> bool {
        self.in_arena != other.in_arena
            || (self.x - other.x).hypot(self.y - other.y) > MIN_MOVE_M
            || (self.angle - other.angle).abs() > MIN_TURN_RAD
    }
}

/// One row of `objects.csv`, before formatting.
#[derive(Clone, Copy, Debug)]
pub struct ObjectRow {
    tick: u64,
    kind: ObjectKind,
    index: u32,
    place: Place,
}

/// What was last written of each object; finds the objects that changed in a tick.
pub struct ObjectMoves {
    targets: Vec<Option<Place>>,
    obstacles: Vec<Option<Place>>,
}

impl ObjectMoves {
    /// Hands a row to `rows` for every object that changed since its last row (every object at the first call).
    pub fn changes(&mut self, arena: &Arena, mut rows: impl FnMut(ObjectRow)) {
        let targets = arena
            .targets
            .iter()
            .map(|t| Some(Place::of(&t.placed, t.state == TargetState::InArena)));
        changed(
            &mut self.targets,
            targets,
            ObjectKind::Target,
            arena.tick,
            &mut rows,
        );
        let obstacles = arena.obstacles.iter().map(|o| {
            matches!(o.motion, Motion::Movable { .. }).then(|| Place::of(&o.placed, true))
        });
        changed(
            &mut self.obstacles,
            obstacles,
            ObjectKind::Obstacle,
            arena.tick,
            &mut rows,
        );
    }
}

/// Compares each object's place now (`None`: not tracked) with its last row and records the changes.
fn changed(
    last: &mut [Option<Place>],
    now: impl Iterator<Item = Option<Place>>,
    kind: ObjectKind,
    tick: u64,
    rows: &mut impl FnMut(ObjectRow),
) {
    for (index, (last, now)) in last.iter_mut().zip(now).enumerate() {
        let Some(now) = now else { continue };
        if last.is_none_or(|l| l.differs(&now)) {
            *last = Some(now);
            rows(ObjectRow {
                tick,
                kind,
                index: index as u32,
                place: now,
            });
        }
    }
}

/// Writes `objects.csv` on the recorder's thread.
pub struct ObjectsWriter {
    file: CsvFile,
    target_ids: Vec<String>,
    obstacle_ids: Vec<String>,
}

impl ObjectsWriter {
    /// Creates the file in `dir` and the tracker of its rows, when the arena has targets or movable obstacles.
    pub fn create(dir: &Path, arena: &Arena) -> Result<Option<(ObjectMoves, Self)>, WorldError> {
        let movable = arena
            .obstacles
            .iter()
            .any(|o| matches!(o.motion, Motion::Movable { .. }));
        if arena.targets.is_empty() && !movable {
            return Ok(None);
        }
        let moves = ObjectMoves {
            targets: vec![None; arena.targets.len()],
            obstacles: vec![None; arena.obstacles.len()],
        };
        let writer = Self {
            file: CsvFile::create(&dir.join(OBJECTS_FILE), OBJECTS_HEADER, 1 << 12)?,
            target_ids: arena.targets.iter().map(|t| t.name.clone()).collect(),
            obstacle_ids: arena.obstacles.iter().map(|o| o.name.clone()).collect(),
        };
        Ok(Some((moves, writer)))
    }

    /// Formats `row` into the file's buffer.
    pub fn write_row(&mut self, row: &ObjectRow) -> Result<(), WorldError> {
        let (kind, ids) = match row.kind {
            ObjectKind::Target => ("target", &self.target_ids),
            ObjectKind::Obstacle => ("obstacle", &self.obstacle_ids),
        };
        let id = ids.get(row.index as usize).map_or("", String::as_str);
        let place = row.place;
        let written = self
            .file
            .line()
            .int(row.tick)
            .and_then(|l| l.text(kind))
            .and_then(|l| l.int(row.index))
            .and_then(|l| l.text(id))
            .and_then(|l| l.float(place.x))
            .and_then(|l| l.float(place.y))
            .and_then(|l| l.float(place.angle))
            .and_then(|l| l.int(u8::from(place.in_arena)))
            .and_then(|l| l.end());
        written.map_err(|source| self.file.error(source))
    }

    /// Writes the buffer to the file.
    pub fn flush(&mut self) -> Result<(), WorldError> {
        self.file.flush()
    }
}
