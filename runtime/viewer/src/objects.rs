//! `objects.csv`: where each target and movable obstacle is at any tick, from the rows the world writes when one
//! moves or enters or leaves the arena. Held in memory per object (a row is 13 bytes here); grows as the file does.

use std::path::Path;

use serde_json::{Value, json};

use crate::lines::GrowingLines;
use crate::trajectory::number;

/// The header this version writes (docs/records.md).
pub const HEADER: &str = "tick,kind,index,id,x,y,angle,in_arena";

/// Where an object is from a tick on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectPlace {
    /// Centre x in metres.
    pub x: f32,
    /// Centre y in metres.
    pub y: f32,
    /// Radians, counter-clockwise.
    pub angle: f32,
    /// False for a target carried or taken out of the run.
    pub in_arena: bool,
}

/// Every target and obstacle by scene index: where its last row at or before a tick put it (`None`: no row, so
/// where the scene placed it).
pub struct ObjectPlaces {
    /// By index in the scene's `targets`.
    pub targets: Vec<Option<ObjectPlace>>,
    /// By index in the scene's `obstacles`.
    pub obstacles: Vec<Option<ObjectPlace>>,
}

/// Every object's rows, in tick order.
struct Table {
    header_seen: bool,
    targets: Vec<Vec<(u64, ObjectPlace)>>,
    obstacles: Vec<Vec<(u64, ObjectPlace)>>,
}

/// The objects of one run.
pub struct ObjectsIndex {
    lines: GrowingLines,
    table: Table,
    problem: Option<String>,
}

impl ObjectsIndex {
    /// An index of the file at `path` for a scene of `targets` targets and `obstacles` obstacles.
    pub fn new(path: &Path, targets: usize, obstacles: usize) -> Self {
        Self {
            lines: GrowingLines::new(path),
            table: Table {
                header_seen: false,
                targets: vec![Vec::new(); targets],
                obstacles: vec![Vec::new(); obstacles],
            },
            problem: None,
        }
    }

    /// Why the file cannot be read further, if it cannot.
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }

    /// Reads the rows written since the last call.
    pub fn update(&mut self) {
        let table = &mut self.table;
        self.lines
            .read_until_problem(&mut self.problem, |line| table.add(line.text));
    }

    /// Where every object is at `tick`.
    pub fn places_at(&self, tick: u64) -> ObjectPlaces {
        let at = |objects: &[Vec<(u64, ObjectPlace)>]| -> Vec<Option<ObjectPlace>> {
            objects
                .iter()
                .map(|rows| {
                    let seen = rows.partition_point(|&(t, _)| t <= tick);
                    rows.get(seen.checked_sub(1)?).map(|&(_, place)| place)
                })
                .collect()
        };
        ObjectPlaces {
            targets: at(&self.table.targets),
            obstacles: at(&self.table.obstacles),
        }
    }

    /// Every object with a row at or before `tick`: `{"targets": [[index, x, y, angle, in_arena], ...],
    /// "obstacles": [...]}`.
    pub fn at(&self, tick: u64) -> Value {
        let list = |places: Vec<Option<ObjectPlace>>| -> Vec<Value> {
            places
                .into_iter()
                .enumerate()
                .filter_map(|(index, place)| {
                    let p = place?;
                    Some(json!([index, p.x, p.y, p.angle, p.in_arena]))
                })
                .collect()
        };
        let places = self.places_at(tick);
        json!({"targets": list(places.targets), "obstacles": list(places.obstacles)})
    }
}

impl Table {
    fn add(&mut self, text: &[u8]) -> Result<(), String> {
        let text = std::str::from_utf8(text).map_err(|_| "the row is not UTF-8".to_owned())?;
        if !self.header_seen {
            if text != HEADER {
                return Err(format!(
                    "the header `{text}` is not the one this version writes (`{HEADER}`)"
                ));
            }
            self.header_seen = true;
            return Ok(());
        }
        // The id may hold commas: the first three columns are counted from the left, the last four from the right.
        let fields: Vec<&str> = text.split(',').collect();
        let n = fields.len();
        if n < 8 {
            return Err(format!("the row has {n} columns, not 8"));
        }
        let tick: u64 = number(fields[0], "tick")?;
        let kind = fields[1];
        let index: usize = number(fields[2], "index")?;
        let (x, y, angle) = (
            number(fields[n - 4], "x")?,
            number(fields[n - 3], "y")?,
            number(fields[n - 2], "angle")?,
        );
        let in_arena = fields[n - 1] == "1";
        let objects = match kind {
            "target" => &mut self.targets,
            "obstacle" => &mut self.obstacles,
            other => {
                return Err(format!(
                    "`{other}` in the `kind` column is not `target` or `obstacle`"
                ));
            }
        };
        let rows = objects
            .get_mut(index)
            .ok_or_else(|| format!("{kind} {index} is not in the scene"))?;
        let at = rows.partition_point(|&(t, _)| t <= tick);
        rows.insert(
            at,
            (
                tick,
                ObjectPlace {
                    x,
                    y,
                    angle,
                    in_arena,
                },
            ),
        );
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_object_is_where_its_last_row_put_it() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("objects.csv");
        std::fs::write(
            &path,
            format!("{HEADER}\n0,target,0,t0,1.0,2.0,0.0,1\n0,obstacle,1,box,0.0,0.0,0.0,1\n5,target,0,t0,1.0,2.0,0.0,0\n7,obstacle,1,box,0.5,0.0,0.25,1\n"),
        )
        .expect("written");
        let mut index = ObjectsIndex::new(&path, 1, 2);
        index.update();
        assert_eq!(index.problem(), None);
        assert_eq!(index.at(4)["targets"], json!([[0, 1.0, 2.0, 0.0, true]]));
        assert_eq!(index.at(5)["targets"], json!([[0, 1.0, 2.0, 0.0, false]]));
        assert_eq!(index.at(6)["obstacles"], json!([[1, 0.0, 0.0, 0.0, true]]));
        assert_eq!(index.at(7)["obstacles"], json!([[1, 0.5, 0.0, 0.25, true]]));
    }

    #[test]
    fn an_object_outside_the_scene_names_its_line() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("objects.csv");
        std::fs::write(&path, format!("{HEADER}\n0,target,3,t3,1,2,0,1\n")).expect("written");
        let mut index = ObjectsIndex::new(&path, 1, 0);
        index.update();
        let problem = index.problem().expect("a problem");
        assert!(
            problem.ends_with("objects.csv:2: target 3 is not in the scene"),
            "{problem}"
        );
    }
}
