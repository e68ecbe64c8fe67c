//! `objects.csv`: where the targets and the movable obstacles are, for replays. A row for every such object at
//! tick 0, then one whenever an object moved (more than half a millimetre or a milliradian) or entered or left the
//! arena (a target picked up, put down or removed), so that still objects cost nothing.

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

/// An object's last written pose and presence.
#[derive(Clone, Copy, PartialEq)]
struct Written {
    x: f32,
    y: f32,
    angle: f32,
    in_arena: bool,
}

impl Written {
    fn of(placed: &Placed, in_arena: bool) -> Self {
        Self {
            x: placed.position.x,
            y: placed.position.y,
            angle: placed.angle(),
            in_arena,
        }
    }

    fn differs(&self, other: &Written) -> bool {
        self.in_arena != other.in_arena
            || (self.x - other.x).hypot(self.y - other.y) > MIN_MOVE_M
            || (self.angle - other.angle).abs() > MIN_TURN_RAD
    }
}

/// The open file and what it last said of each object.
pub struct ObjectsFile {
    file: CsvFile,
    targets: Vec<Option<Written>>,
    obstacles: Vec<Option<Written>>,
}

impl ObjectsFile {
    /// Creates the file in `dir` when the arena has targets or movable obstacles.
    pub fn create(dir: &Path, arena: &Arena) -> Result<Option<Self>, WorldError> {
        let movable = arena
            .obstacles
            .iter()
            .any(|o| matches!(o.motion, Motion::Movable { .. }));
        if arena.targets.is_empty() && !movable {
            return Ok(None);
        }
        Ok(Some(Self {
            file: CsvFile::create(&dir.join(OBJECTS_FILE), OBJECTS_HEADER, 1 << 12)?,
            targets: vec![None; arena.targets.len()],
            obstacles: vec![None; arena.obstacles.len()],
        }))
    }

    /// Writes the rows of the objects that changed since they were last written, and flushes.
    pub fn record(&mut self, arena: &Arena) -> Result<(), WorldError> {
        let tick = arena.tick;
        for (index, target) in arena.targets.iter().enumerate() {
            let now = Written::of(&target.placed, target.state == TargetState::InArena);
            if let Some(last) = self.targets.get_mut(index)
                && last.is_none_or(|l| l.differs(&now))
            {
                *last = Some(now);
                write_row(&mut self.file, tick, "target", index, &target.name, &now)?;
            }
        }
        for (index, obstacle) in arena.obstacles.iter().enumerate() {
            if !matches!(obstacle.motion, Motion::Movable { .. }) {
                continue;
            }
            let now = Written::of(&obstacle.placed, true);
            if let Some(last) = self.obstacles.get_mut(index)
                && last.is_none_or(|l| l.differs(&now))
            {
                *last = Some(now);
                write_row(
                    &mut self.file,
                    tick,
                    "obstacle",
                    index,
                    &obstacle.name,
                    &now,
                )?;
            }
        }
        self.file.flush()
    }
}

fn write_row(
    file: &mut CsvFile,
    tick: u64,
    kind: &str,
    index: usize,
    id: &str,
    at: &Written,
) -> Result<(), WorldError> {
    let written = file
        .line()
        .int(tick)
        .and_then(|l| l.text(kind))
        .and_then(|l| l.int(index))
        .and_then(|l| l.text(id))
        .and_then(|l| l.float(at.x))
        .and_then(|l| l.float(at.y))
        .and_then(|l| l.float(at.angle))
        .and_then(|l| l.int(u8::from(at.in_arena)))
        .and_then(|l| l.end());
    written.map_err(|source| file.error(source))
}
