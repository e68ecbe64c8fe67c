//! `trajectory.csv` indexed by tick: where each tick's rows start, so that any tick is read with one positioned
//! read and nothing else of the file is held in memory. The index grows as the file does (a live run).

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::Path;

use crate::lines::GrowingLines;

/// The header this version writes (docs/records.md).
pub const HEADER: &str = "tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive";

/// One robot's row of a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Metres; `NaN` while the robot is not in the run.
    pub x: f32,
    /// Metres; `NaN` while the robot is not in the run.
    pub y: f32,
    /// Radians; `NaN` while the robot is not in the run.
    pub heading: f32,
    /// LED colour.
    pub led: [u8; 3],
    /// The `alive` column.
    pub alive: bool,
}

impl Pose {
    /// A robot without a row (never shown as present).
    pub const ABSENT: Pose = Pose {
        x: f32::NAN,
        y: f32::NAN,
        heading: f32::NAN,
        led: [0; 3],
        alive: false,
    };
}

/// Where one tick's rows start.
#[derive(Clone, Copy, Debug)]
struct TickStart {
    offset: u64,
    line: u64,
}

/// The tick index of one trajectory file.
pub struct TrajectoryIndex {
    lines: GrowingLines,
    ticks: Ticks,
    /// Offset just past the last indexed line.
    end: u64,
    /// Why indexing stopped: a malformed line (`file:line: what`).
    problem: Option<String>,
}

/// The ticks seen so far.
struct Ticks {
    /// Rows per tick; `None` until known (from the scene, or from the first tick once the second starts).
    robots: Option<usize>,
    header_seen: bool,
    first_tick: Option<u64>,
    /// `starts[i]` is where tick `first_tick + i` starts.
    starts: Vec<TickStart>,
    rows_in_last: usize,
}

impl TrajectoryIndex {
    /// An index of the file at `path` for `robots` robots per tick (`None`: learn it from the file).
    pub fn new(path: &Path, robots: Option<usize>) -> Self {
        Self {
            lines: GrowingLines::new(path),
            ticks: Ticks {
                robots,
                header_seen: false,
                first_tick: None,
                starts: Vec::new(),
                rows_in_last: 0,
            },
            end: 0,
            problem: None,
        }
    }

    /// Robots per tick, once known.
    pub fn robots(&self) -> Option<usize> {
        self.ticks.robots
    }

    /// Why the file cannot be read further, if it cannot.
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }

    /// Bytes at the end of the file that are not a whole line (a run still writing, or a truncated file).
    pub fn unfinished_bytes(&self) -> usize {
        self.lines.unfinished_bytes()
    }

    /// Indexes the lines written since the last call. Returns whether the file exists.
    pub fn update(&mut self) -> bool {
        let (ticks, end) = (&mut self.ticks, &mut self.end);
        self.lines.read_until_problem(&mut self.problem, |line| {
            ticks.index_line(line.number, line.offset, line.text)?;
            *end = line.offset + line.text.len() as u64 + 1;
            Ok(())
        })
    }

    /// The first and last ticks whose every row is in the file.
    pub fn complete_ticks(&self) -> Option<(u64, u64)> {
        self.ticks.complete()
    }

    /// Every robot's pose at `tick` (a complete tick), by robot index.
    pub fn read_tick(&self, file: &File, tick: u64) -> Result<Vec<Pose>, String> {
        let (first, last) = self
            .complete_ticks()
            .ok_or_else(|| "no complete tick yet".to_owned())?;
        if !(first..=last).contains(&tick) {
            return Err(format!("tick {tick} is outside {first}..={last}"));
        }
        let i = (tick - first) as usize;
        let start = self.ticks.starts[i];
        let end = self.ticks.starts.get(i + 1).map_or(self.end, |s| s.offset);
        let mut bytes = vec![0; (end - start.offset) as usize];
        let path = self.lines.path().display();
        file.read_exact_at(&mut bytes, start.offset)
            .map_err(|e| format!("{path}: {e}"))?;
        let robots = self.ticks.robots.unwrap_or(0);
        let mut poses = vec![Pose::ABSENT; robots];
        for (row, text) in bytes
            .split(|&b| b == b'\n')
            .filter(|l| !l.is_empty())
            .enumerate()
        {
            let line = start.line + row as u64;
            let (robot, pose) = parse_row(text).map_err(|what| format!("{path}:{line}: {what}"))?;
            if let Some(slot) = poses.get_mut(robot) {
                *slot = pose;
            }
        }
        Ok(poses)
    }
}

impl Ticks {
    fn index_line(&mut self, number: u64, offset: u64, text: &[u8]) -> Result<(), String> {
        if !self.header_seen {
            let header = String::from_utf8_lossy(text);
            if header != HEADER {
                return Err(format!(
                    "the header `{header}` is not the one this version writes (`{HEADER}`): the file is not a \
                     trajectory, or an older version recorded it"
                ));
            }
            self.header_seen = true;
            return Ok(());
        }
        let (tick, robot) = tick_and_robot(text)?;
        let Some(first) = self.first_tick else {
            self.first_tick = Some(tick);
            self.starts.push(TickStart {
                offset,
                line: number,
            });
            self.rows_in_last = 1;
            return self.check_robot(robot);
        };
        let last = first + self.starts.len() as u64 - 1;
        if tick == last {
            self.rows_in_last += 1;
        } else if tick == last + 1 {
            let robots = *self.robots.get_or_insert(self.rows_in_last);
            if self.rows_in_last != robots {
                return Err(format!(
                    "tick {last} has {} rows, not one per robot ({robots})",
                    self.rows_in_last
                ));
            }
            self.starts.push(TickStart {
                offset,
                line: number,
            });
            self.rows_in_last = 1;
        } else {
            return Err(format!("tick {tick} follows tick {last}"));
        }
        self.check_robot(robot)
    }

    fn check_robot(&self, robot: usize) -> Result<(), String> {
        match self.robots {
            Some(robots) if robot >= robots || self.rows_in_last > robots => Err(format!(
                "robot {robot} in row {} of a tick of a {robots}-robot run",
                self.rows_in_last
            )),
            _ => Ok(()),
        }
    }

    fn complete(&self) -> Option<(u64, u64)> {
        let first = self.first_tick?;
        let indexed = self.starts.len() as u64;
        let last_complete = self.robots == Some(self.rows_in_last);
        let count = if last_complete { indexed } else { indexed - 1 };
        (count > 0).then(|| (first, first + count - 1))
    }
}

fn field<'a>(fields: &mut impl Iterator<Item = &'a str>, name: &str) -> Result<&'a str, String> {
    fields
        .next()
        .ok_or_else(|| format!("the row ends before its `{name}` column"))
}

/// `text` read as a number of the record column `name`, or a sentence saying it is not one.
pub(crate) fn number<T: std::str::FromStr>(text: &str, name: &str) -> Result<T, String> {
    text.parse().map_err(|_| {
        format!("`{text}` in the `{name}` column is not a number of that column's kind")
    })
}

fn tick_and_robot(text: &[u8]) -> Result<(u64, usize), String> {
    let text = std::str::from_utf8(text).map_err(|_| "the row is not UTF-8".to_owned())?;
    let mut fields = text.splitn(3, ',');
    let tick = number(field(&mut fields, "tick")?, "tick")?;
    let robot = number(field(&mut fields, "robot")?, "robot")?;
    Ok((tick, robot))
}

/// A row's robot index and pose: tick and robot from the left, the seven numbers from the right, so that an id
/// with a comma in it (the configuration does not forbid one) is read right too.
fn parse_row(text: &[u8]) -> Result<(usize, Pose), String> {
    let text = std::str::from_utf8(text).map_err(|_| "the row is not UTF-8".to_owned())?;
    let mut left = text.splitn(3, ',');
    field(&mut left, "tick")?;
    let robot = number(field(&mut left, "robot")?, "robot")?;
    let mut right = text.rsplitn(8, ',');
    let alive: u8 = number(field(&mut right, "alive")?, "alive")?;
    let b = number(field(&mut right, "led_b")?, "led_b")?;
    let g = number(field(&mut right, "led_g")?, "led_g")?;
    let r = number(field(&mut right, "led_r")?, "led_r")?;
    let heading = number(field(&mut right, "heading")?, "heading")?;
    let y = number(field(&mut right, "y")?, "y")?;
    let x = number(field(&mut right, "x")?, "x")?;
    Ok((
        robot,
        Pose {
            x,
            y,
            heading,
            led: [r, g, b],
            alive: alive != 0,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn row(tick: u64, robot: usize) -> String {
        format!("{tick},{robot},r{robot},{}.5,-1.25,0.5,255,0,0,1\n", robot)
    }

    #[test]
    fn indexes_ticks_and_reads_any_of_them() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("trajectory.csv");
        let mut file = std::fs::File::create(&path).expect("created");
        writeln!(file, "{HEADER}").expect("written");
        for tick in 0..3 {
            for robot in 0..2 {
                file.write_all(row(tick, robot).as_bytes())
                    .expect("written");
            }
        }
        file.write_all(row(3, 0).as_bytes()).expect("written");
        let mut index = TrajectoryIndex::new(&path, None);
        assert!(index.update());
        assert_eq!(index.complete_ticks(), Some((0, 2)), "tick 3 lacks a row");
        let reader = std::fs::File::open(&path).expect("opened");
        let poses = index.read_tick(&reader, 2).expect("tick 2");
        assert_eq!(poses.len(), 2);
        assert_eq!(poses[1].x, 1.5);
        assert_eq!(poses[1].led, [255, 0, 0]);
        file.write_all(row(3, 1).as_bytes()).expect("written");
        index.update();
        assert_eq!(index.complete_ticks(), Some((0, 3)));
    }

    #[test]
    fn a_malformed_row_names_its_line_and_stops_indexing() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("trajectory.csv");
        std::fs::write(&path, format!("{HEADER}\n{}x,1,r1\n", row(0, 0))).expect("written");
        let mut index = TrajectoryIndex::new(&path, Some(2));
        index.update();
        let problem = index.problem().expect("a problem");
        assert!(problem.contains("trajectory.csv:3:"), "{problem}");
        assert!(problem.contains("`x` in the `tick` column"), "{problem}");
    }

    #[test]
    fn another_header_is_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("trajectory.csv");
        std::fs::write(&path, "tick,robot,x,y\n0,0,1,1\n").expect("written");
        let mut index = TrajectoryIndex::new(&path, None);
        index.update();
        assert!(
            index
                .problem()
                .expect("a problem")
                .contains(":1: the header")
        );
        assert_eq!(index.complete_ticks(), None);
    }
}
