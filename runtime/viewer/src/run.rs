//! One run directory as the viewer reads it: the scene, the summary, the indexed trajectory and events, and the
//! compiled supervisors, each refreshed on demand so that a run still being written shows what exists so far.
//! Whatever is missing or malformed becomes a readable problem, never an error that stops the server.

use std::fs::File;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use swarm_contract::run_dir::{
    FLOOR_IMAGE_FILE, OBJECTS_FILE, PHEROMONE_FILE, SCENE_FILE, SUMMARY_FILE,
};

use crate::events::EventsIndex;
use crate::frames::{self, FrameRobot};
use crate::objects::{ObjectPlaces, ObjectsIndex};
use crate::supervisors::Supervisors;
use crate::trajectory_source::TrajectorySource;

/// The `format` of `scene.json` this version reads.
pub const SCENE_FORMAT: u64 = 1;
/// Frames served by one request at most.
pub const MAX_FRAMES: u64 = 1024;
/// Bytes of frames served by one request at most (fewer frames for very large swarms).
pub const MAX_FRAME_BYTES: u64 = 32 << 20;
/// Events of a robot shown at most.
pub const RECENT_EVENTS: usize = 50;
/// Largest `scene.json` read, in bytes (a scene lists every robot and obstacle once).
const MAX_SCENE_BYTES: u64 = 64 << 20;

/// Why a request cannot be answered.
#[derive(Debug, PartialEq, Eq)]
pub enum Refusal {
    /// The request is malformed (400).
    BadRequest(String),
    /// No such robot (404).
    NotFound(String),
    /// The run has nothing to answer with yet (503).
    Unavailable(String),
}

/// A run directory being viewed.
pub struct RunRecord {
    dir: PathBuf,
    live: bool,
    scene: Option<Value>,
    scene_problem: Option<String>,
    robots: Vec<RobotInfo>,
    trajectory: TrajectorySource,
    events: EventsIndex,
    objects: ObjectsIndex,
    supervisors: Supervisors,
}

/// What the scene says of one robot.
#[derive(Clone, Debug, Default)]
struct RobotInfo {
    id: String,
    controller: String,
    body: String,
}

impl RunRecord {
    /// Opens `dir` (which must be a folder). `live`: the run may still be writing into it.
    pub fn open(dir: &Path, live: bool) -> Result<Self, String> {
        if !dir.is_dir() {
            return Err(format!(
                "{}: not a run directory (no such folder)",
                dir.display()
            ));
        }
        let mut record = Self {
            dir: dir.to_path_buf(),
            live,
            scene: None,
            scene_problem: None,
            robots: Vec::new(),
            trajectory: TrajectorySource::new(dir, None),
            events: EventsIndex::new(dir, None),
            objects: ObjectsIndex::new(&dir.join(OBJECTS_FILE), 0, 0),
            supervisors: Supervisors::new(dir),
        };
        record.refresh();
        Ok(record)
    }

    /// The run directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether the run may still be writing into the directory.
    pub fn live(&self) -> bool {
        self.live
    }

    /// Reads what was written since the last call.
    pub fn refresh(&mut self) {
        if self.scene.is_none() {
            self.load_scene();
        }
        self.trajectory.update();
        self.events.update();
        self.objects.update();
    }

    fn load_scene(&mut self) {
        let path = self.dir.join(SCENE_FILE);
        let scene = match read_scene(&path) {
            Ok(Some(scene)) => scene,
            Ok(None) if self.live => return,
            Ok(None) => {
                self.scene_problem = Some(format!(
                    "{} is missing: the run was recorded by a version before the viewer (or the world did not \
                     start), so there is no arena to draw",
                    path.display()
                ));
                return;
            }
            Err(problem) => {
                self.scene_problem = Some(problem);
                return;
            }
        };
        let robots: Vec<RobotInfo> = scene["robots"]
            .as_array()
            .map(|robots| {
                robots
                    .iter()
                    .map(|r| RobotInfo {
                        id: r["id"].as_str().unwrap_or_default().to_owned(),
                        controller: r["controller"].as_str().unwrap_or_default().to_owned(),
                        body: r["body"].as_str().unwrap_or_default().to_owned(),
                    })
                    .collect()
            })
            .unwrap_or_default();
        let participants = robots.len() + scene["coordinators"].as_array().map_or(0, Vec::len);
        self.trajectory = TrajectorySource::new(&self.dir, Some(robots.len()));
        self.events = EventsIndex::new(&self.dir, Some(participants));
        let count = |key: &str| scene[key].as_array().map_or(0, Vec::len);
        self.objects = ObjectsIndex::new(
            &self.dir.join(OBJECTS_FILE),
            count("targets"),
            count("obstacles"),
        );
        self.robots = robots;
        self.scene_problem = None;
        self.scene = Some(scene);
    }

    /// Everything wrong with the directory, as sentences naming the file.
    pub fn problems(&self) -> Vec<String> {
        let mut problems: Vec<String> = self.scene_problem.iter().cloned().collect();
        problems.extend(self.trajectory.problem().map(str::to_owned));
        problems.extend(self.events.problem().map(str::to_owned));
        problems.extend(self.objects.problem().map(str::to_owned));
        let finished = self.finished();
        if !self.trajectory.exists() && (finished || !self.live) {
            problems.push(format!(
                "{} is missing: the run recorded no poses",
                self.trajectory.path().display()
            ));
        } else if finished && self.trajectory.unfinished_bytes() > 0 {
            problems.push(format!(
                "{}: the last {} bytes are not a whole row (the file was cut short); the ticks before them are shown",
                self.trajectory.path().display(),
                self.trajectory.unfinished_bytes()
            ));
        }
        problems
    }

    /// Whether the run ended (its summary exists).
    pub fn finished(&self) -> bool {
        self.dir.join(SUMMARY_FILE).exists()
    }

    /// The answer of `/api/run`.
    pub fn overview(&self) -> Value {
        let summary = std::fs::read(self.dir.join(SUMMARY_FILE))
            .ok()
            .and_then(|bytes| serde_json::from_slice::<Value>(&bytes).ok());
        json!({
            "format": SCENE_FORMAT,
            "dir": self.dir.display().to_string(),
            "live": self.live,
            "finished": summary.is_some(),
            "problems": self.problems(),
            "scene": self.scene,
            "ticks": self.trajectory.complete_ticks().map(|(first, last)| json!({"first": first, "last": last})),
            "robots": self.robot_count(),
            "summary": summary,
        })
    }

    fn robot_count(&self) -> usize {
        if self.scene.is_some() {
            self.robots.len()
        } else {
            self.trajectory.robots().unwrap_or(0)
        }
    }

    /// The newest complete tick.
    pub fn last_tick(&self) -> Option<u64> {
        self.trajectory.complete_ticks().map(|(_, last)| last)
    }

    /// The floor image's path, when the scene has one.
    pub fn floor_image(&self) -> Option<PathBuf> {
        let scene = self.scene.as_ref()?;
        scene["floor"]
            .is_object()
            .then(|| self.dir.join(FLOOR_IMAGE_FILE))
    }

    /// The pheromone field's frame (tick, then the grid; docs/viewer.md) recorded last at or before `tick`, or
    /// `None` when the run has no field or no frame yet.
    pub fn pheromone(&self, tick: u64) -> Result<Option<Vec<u8>>, Refusal> {
        let Some(field) = self
            .scene
            .as_ref()
            .and_then(|s| PheromoneLayout::of(&s["pheromone"]))
        else {
            return Ok(None);
        };
        let path = self.dir.join(PHEROMONE_FILE);
        let unreadable =
            |e: std::io::Error| Refusal::Unavailable(format!("{}: {e}", path.display()));
        let file = match File::open(&path) {
            Ok(file) => file,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(unreadable(e)),
        };
        let whole_frames = file.metadata().map_err(unreadable)?.len() / field.frame_bytes;
        let Some(last_whole) = whole_frames.checked_sub(1) else {
            return Ok(None);
        };
        let index = (tick / field.every).min(last_whole);
        let mut frame = vec![0; field.frame_bytes as usize];
        std::os::unix::fs::FileExt::read_exact_at(&file, &mut frame, index * field.frame_bytes)
            .map_err(unreadable)?;
        let recorded = u64::from_le_bytes(frame[..8].try_into().unwrap_or_default());
        if recorded != index * field.every {
            return Err(Refusal::Unavailable(format!(
                "{}: frame {index} holds tick {recorded}, not {}: the file does not match scene.json",
                path.display(),
                index * field.every
            )));
        }
        Ok(Some(frame))
    }

    /// The frames of ticks `from, from + stride, ...` (at most `count`) in the layout of docs/viewer.md.
    pub fn frames(&self, from: u64, count: u64, stride: u64) -> Result<Vec<u8>, Refusal> {
        if stride == 0 || count == 0 {
            return Err(Refusal::BadRequest(
                "count and stride must be at least 1".to_owned(),
            ));
        }
        let frame_bytes = 4 + 16 * self.robot_count() as u64;
        let count = count
            .min(MAX_FRAMES)
            .min((MAX_FRAME_BYTES / frame_bytes).max(1));
        let (first, last) = self.readable_trajectory()?;
        let ticks: Vec<u64> = (0..count)
            .map_while(|i| {
                i.checked_mul(stride)
                    .and_then(|step| from.checked_add(step))
            })
            .filter(|tick| (first..=last).contains(tick))
            .collect();
        let robots = self.robot_count();
        let mut body = frames::header(robots, ticks.len());
        for tick in ticks {
            frames::push_frame(&mut body, tick, self.poses(tick)?.into_iter());
        }
        Ok(body)
    }

    /// Every robot of the complete tick `tick`, by robot index: its trajectory row with the frozen and carrying
    /// flags of the events up to it.
    pub fn poses(&self, tick: u64) -> Result<Vec<FrameRobot>, Refusal> {
        self.readable_trajectory()?;
        let poses = self
            .trajectory
            .read_tick(tick)
            .map_err(Refusal::Unavailable)?;
        Ok(poses
            .into_iter()
            .enumerate()
            .map(|(robot, pose)| {
                let (frozen, carrying) = self.events.flags_at(robot, tick);
                FrameRobot {
                    pose,
                    frozen,
                    carrying,
                }
            })
            .collect())
    }

    /// The first and last complete ticks, or why there is none.
    fn readable_trajectory(&self) -> Result<(u64, u64), Refusal> {
        match self.trajectory.complete_ticks() {
            Some(ticks) => Ok(ticks),
            None => Err(Refusal::Unavailable(
                self.problems()
                    .into_iter()
                    .next()
                    .unwrap_or_else(|| "no complete tick has been recorded yet".to_owned()),
            )),
        }
    }

    /// The answer of `/api/objects?tick=T`: where each target and movable obstacle is at `tick`.
    pub fn objects(&self, tick: u64) -> Value {
        self.objects.at(tick)
    }

    /// Where each target and movable obstacle is at `tick`, by scene index.
    pub fn object_places(&self, tick: u64) -> ObjectPlaces {
        self.objects.places_at(tick)
    }

    /// The answer of `/api/timeline`.
    pub fn timeline(&self) -> Value {
        let (markers, truncated) = self.events.markers();
        json!({"markers": markers, "truncated": truncated})
    }

    /// The answer of `/api/robot/{index}?at=tick`.
    pub fn robot(&mut self, index: usize, at: u64) -> Result<Value, Refusal> {
        let Some(info) = self.robots.get(index).cloned() else {
            return Err(Refusal::NotFound(format!(
                "robot {index} is not a robot of this run ({} robots)",
                self.robots.len()
            )));
        };
        let events: Vec<(u64, &str)> = self.events.events_until(index, at).collect();
        let recent: Vec<Value> = events[events.len().saturating_sub(RECENT_EVENTS)..]
            .iter()
            .map(|&(tick, name)| json!([tick, name]))
            .collect();
        let names: Vec<&str> = events.iter().map(|&(_, name)| name).collect();
        let (supervisors, problem) = match self.supervisors.replay(&info.controller, names) {
            Ok(states) => (states, None),
            Err(problem) => (Vec::new(), Some(problem)),
        };
        Ok(json!({
            "index": index,
            "id": info.id,
            "controller": info.controller,
            "body": info.body,
            "tick": at,
            "events": recent,
            "supervisors": supervisors,
            "problem": problem,
        }))
    }
}

/// The pheromone file's frame size and period, as `scene.json` gives them.
struct PheromoneLayout {
    frame_bytes: u64,
    every: u64,
}

impl PheromoneLayout {
    /// The layout of a scene's `pheromone` entry; `None` for `null` or an entry without sane numbers.
    fn of(entry: &Value) -> Option<Self> {
        let number = |key: &str| entry[key].as_u64().filter(|&n| (1..=1 << 16).contains(&n));
        let cells = number("nx")? * number("ny")? * number("channels")?;
        Some(Self {
            frame_bytes: 8 + cells,
            every: number("every")?,
        })
    }
}

/// `scene.json`, `None` when it does not exist; a problem sentence when it is unreadable, too large or of
/// another format.
fn read_scene(path: &Path) -> Result<Option<Value>, String> {
    let file = match File::open(path) {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let size = file.metadata().map(|m| m.len()).unwrap_or(0);
    if size > MAX_SCENE_BYTES {
        return Err(format!(
            "{}: {size} bytes, more than a scene can be ({MAX_SCENE_BYTES})",
            path.display()
        ));
    }
    let scene: Value = serde_json::from_reader(std::io::BufReader::new(file)).map_err(|e| {
        format!(
            "{}:{}:{}: not a scene: {e}",
            path.display(),
            e.line(),
            e.column()
        )
    })?;
    match scene["format"].as_u64() {
        Some(SCENE_FORMAT) if scene["robots"].is_array() && scene["arena"].is_object() => {
            Ok(Some(scene))
        }
        Some(SCENE_FORMAT) => Err(format!(
            "{}: a scene needs `arena` and `robots`",
            path.display()
        )),
        other => Err(format!(
            "{}: scene format {} is not the one this version reads ({SCENE_FORMAT}): view the run with the \
             version that recorded it",
            path.display(),
            other.map_or("(none)".to_owned(), |f| f.to_string())
        )),
    }
}
