//! The navigation task's loop functions (docs/navigation.md): the task server and the judge of multi-robot
//! navigation. They place the robots at their starts, send each robot its goal and the obstacle map as
//! messages from the world, decide from the robots' true poses when a goal is reached (giving the next one in
//! continuous tasking), and measure the run: makespan, path lengths, flowtime, separation, collisions, stalls.
//!
//! ```xml
//! <loop_functions label="navigation_loop_functions">
//!   <navigation layout="circle" center="4.9,4.9" radius="4.5" goal_tolerance="0.1" tasks="single"/>
//! </loop_functions>
//! ```
//!
//! - `layout`: `circle` (robot i of N on the circle `center`/`radius` at angle 360 i / N, facing the centre),
//!   `random` (starts drawn in the area, clear of obstacles and of each other) or `as_placed` (where the
//!   configuration put them).
//! - `goals`: `antipodal` (the start's mirror image through `center`; the default for `circle`), `random` (the
//!   default otherwise) or a list `x,y; x,y; ...`, one per robot in index order.
//! - `area_min`, `area_max`: where random starts and goals are drawn (default: the arena inset by 0.5 m).
//! - `clearance`: free space kept around a drawn or given start or goal, beyond the robot's body, in metres
//!   (default 0.1).
//! - `goal_tolerance` (0.1 m), `tasks` (`single`: the run ends when every robot has arrived once;
//!   `continuous`: a new random goal on every arrival), `repeat` (seconds between re-sending a robot its task
//!   and map, default 1), `stall_speed` (m/s under which a robot on its way counts as stopped, default 0.01).
//! - `hidden`: cylinders left out of the map the robots get (ids separated by spaces or commas; `h*` for every
//!   id starting with `h`): obstacles a path-planning robot only finds with its range finder (docs/planning.md).
//!
//! The map is the arena's cylinders; walls and boxes are not part of the method's map. With the map the robots
//! get the arena's rectangle (a planner's box). A robot that plans paths reports its planner's statistics to the
//! world (`wire::PlanReport`); each trip is also measured against the reference optimum of `planning`.

use std::fmt::Write as _;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde_json::json;
use swarm_contract::mail::{Address, Mail};
use swarm_contract::messages::ActuatorCommand;
use swarm_navigation::V2;
use swarm_navigation::apf::Disc;
use swarm_navigation::planning::Bounds;
use swarm_navigation::planning::theta_star::SearchError;
use swarm_navigation::wire::{self, Letter, PAYLOAD, PlanReport, Task};

use crate::arena::Arena;
use crate::entities::RobotId;
use crate::error::WorldError;
use crate::geometry::{Shape, Vec2};
use crate::loop_functions::params::ParamReader;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};
use crate::rng::{Purpose, stream};

pub(crate) mod planning;
use planning::{Totals, TripFigures, reference};

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "navigation_loop_functions";
// The navigation letters must fit the messages medium.
const _: () = assert!(PAYLOAD <= swarm_contract::mail::MAIL_PAYLOAD_BYTES);

/// The file, in the run folder, with one row per goal reached.
pub const OUTPUT: &str = "navigation.csv";
const ATTEMPTS: usize = 10_000;
/// Random goals drawn for one robot before giving up on finding one it can reach.
const REACHABLE_ATTEMPTS: usize = 100;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    Circle,
    Random,
    AsPlaced,
}

#[derive(Debug, Clone, PartialEq)]
enum Goals {
    Antipodal,
    Random,
    Given(Vec<V2>),
}

/// One robot's current task and what it did so far.
#[derive(Debug, Clone, Default)]
struct Trip {
    /// Task number (1, 2, ...).
    seq: u32,
    goal: V2,
    /// Where the robot was when the task started.
    start: V2,
    /// The reference optimum of the task when its goal was drawn (continuous tasking), else worked out on arrival.
    optimum: Option<f32>,
    started: u64,
    path: f64,
    last: Option<V2>,
    /// Heading at the last tick it was in the run.
    last_heading: Option<f32>,
    /// Sum of the heading changes on this task (rad): how much the robot turned.
    turning: f64,
    /// Reached in single tasking: no further task.
    done: bool,
    /// Whether the robot has been in the run (a robot joining later starts its task when it joins).
    seen: bool,
    stalled: bool,
    last_sent: Option<u64>,
    /// The robot's last planner statistics for this task.
    report: Option<PlanReport>,
}

/// The navigation task server and judge.
pub struct Navigation {
    layout: Layout,
    goals: Goals,
    center: V2,
    radius: f32,
    area: (V2, V2),
    clearance: f32,
    tolerance: f32,
    continuous: bool,
    repeat_seconds: f64,
    /// Converted from `repeat_seconds` once the tick rate is known (`place`).
    repeat_ticks: u64,
    stall_speed: f32,
    rng: ChaCha8Rng,
    trips: Vec<Trip>,
    /// Every cylinder of the arena.
    map: Vec<Disc>,
    /// The cylinders the robots are told about (all but the hidden ones).
    known: Vec<Disc>,
    /// Ids (or `prefix*` patterns) of hidden cylinders.
    hidden: Vec<String>,
    bounds: Bounds,
    totals: Totals,
    /// The known map's chunks and the bounds, as sent with every task.
    map_letters: Vec<Vec<u8>>,
    arrivals: u64,
    last_arrival_tick: u64,
    flowtime_ticks: u64,
    completed_path: f64,
    completed_turning: f64,
    peak_turn_rate: f32,
    min_separation: f32,
    min_clearance: f32,
    stop_events: u64,
    tick: u64,
    ticks_per_second: u32,
    location: String,
    output: String,
}

/// Whether entity id `name` matches `pattern`: the id itself, or `prefix*` for every id starting with `prefix`.
fn id_matches(pattern: &str, name: &str) -> bool {
    match pattern.strip_suffix('*') {
        Some(prefix) => name.starts_with(prefix),
        None => pattern == name,
    }
}

fn v(p: (f64, f64)) -> V2 {
    V2::new(p.0 as f32, p.1 as f32)
}

fn to_v2(p: Vec2) -> V2 {
    V2::new(p.x, p.y)
}

impl Navigation {
    /// The factory registered under [`LABEL`].
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        let r = ParamReader::new(
            params,
            "navigation",
            &[
                "layout",
                "goals",
                "center",
                "radius",
                "area_min",
                "area_max",
                "clearance",
                "goal_tolerance",
                "tasks",
                "repeat",
                "stall_speed",
                "hidden",
            ],
        )?;
        let layout = match r.choice("layout", &["circle", "random", "as_placed"], "circle")? {
            "circle" => Layout::Circle,
            "random" => Layout::Random,
            _ => Layout::AsPlaced,
        };
        let goals = match r.points("goals") {
            Ok(Some(points)) => Goals::Given(points.into_iter().map(v).collect()),
            Ok(None) if layout == Layout::Circle => Goals::Antipodal,
            Ok(None) => Goals::Random,
            Err(not_points) => match r.choice("goals", &["antipodal", "random"], "random") {
                Ok("antipodal") => Goals::Antipodal,
                Ok(_) => Goals::Random,
                Err(_) => return Err(not_points),
            },
        };
        let area_min = r.point("area_min", (f64::NAN, f64::NAN))?;
        let area_max = r.point("area_max", (f64::NAN, f64::NAN))?;
        Ok(Box::new(Navigation {
            layout,
            goals,
            center: v(r.point("center", (0.0, 0.0))?),
            radius: r.positive("radius", 1.0)? as f32,
            area: (v(area_min), v(area_max)),
            clearance: r.non_negative("clearance", 0.1)? as f32,
            tolerance: r.positive("goal_tolerance", 0.1)? as f32,
            continuous: r.choice("tasks", &["single", "continuous"], "single")? == "continuous",
            repeat_ticks: 0,
            stall_speed: r.non_negative("stall_speed", 0.01)? as f32,
            rng: stream(params.seed, Purpose::LoopFunctions, 0),
            trips: Vec::new(),
            map: Vec::new(),
            known: Vec::new(),
            hidden: r.words("hidden"),
            bounds: Bounds {
                min: V2::ZERO,
                max: V2::ZERO,
            },
            totals: Totals::default(),
            map_letters: Vec::new(),
            arrivals: 0,
            last_arrival_tick: 0,
            flowtime_ticks: 0,
            completed_path: 0.0,
            completed_turning: 0.0,
            peak_turn_rate: 0.0,
            min_separation: f32::INFINITY,
            min_clearance: f32::INFINITY,
            stop_events: 0,
            tick: 0,
            ticks_per_second: 1,
            repeat_seconds: r.positive("repeat", 1.0)?,
            location: params.location.clone(),
            output: String::from(
                "tick,robot,task,goal_x,goal_y,duration_s,path_m,turning_rad,optimum_m,plans,failed_plans,replans,\
                 collision_free_fraction,planned_m,followed_m\n",
            ),
        }))
    }

    /// Whether a robot of `radius` at `p` keeps the clearance from every obstacle of the map.
    fn is_free(&self, p: V2, radius: f32) -> bool {
        self.map
            .iter()
            .all(|o| (p - o.centre).length() >= o.radius + radius + self.clearance)
    }

    /// A random point of the area free of obstacles and at least `apart` from every point of `taken`.
    fn draw(&mut self, radius: f32, taken: &[V2], apart: f32) -> Option<V2> {
        let (lo, hi) = self.area;
        for _ in 0..ATTEMPTS {
            let p = V2::new(
                self.rng.random_range(lo.x..=hi.x),
                self.rng.random_range(lo.y..=hi.y),
            );
            if self.is_free(p, radius) && taken.iter().all(|&q| (p - q).length() >= apart) {
                return Some(p);
            }
        }
        None
    }

    /// The reference search from `start` to `goal` for a robot of `radius` on the whole map.
    fn reference(&self, start: V2, goal: V2, radius: f32) -> Result<f32, SearchError> {
        reference(start, goal, &self.map, self.bounds, radius)
    }

    /// A random goal as [`Navigation::draw`] gives, that obstacles do not wall off from `start`, with the
    /// reference optimum the search that decided it found (if it could tell).
    fn draw_reachable(
        &mut self,
        start: V2,
        radius: f32,
        taken: &[V2],
        apart: f32,
    ) -> Option<(V2, Option<f32>)> {
        for _ in 0..REACHABLE_ATTEMPTS {
            let goal = self.draw(radius, taken, apart)?;
            match self.reference(start, goal, radius) {
                Err(SearchError::Unreachable) => continue,
                found => return Some((goal, found.ok())),
            }
        }
        None
    }

    fn starts(&mut self, arena: &mut Arena) -> Result<(), WorldError> {
        let n = arena.robots.len();
        for i in 0..n {
            let radius = arena.robots[i].body.radius;
            let (position, heading) = match self.layout {
                Layout::AsPlaced => continue,
                Layout::Circle => {
                    let angle = std::f32::consts::TAU * i as f32 / n as f32;
                    let p = self.center + V2::from_angle(angle) * self.radius;
                    (p, angle + std::f32::consts::PI)
                }
                Layout::Random => {
                    let taken: Vec<V2> = (0..i).map(|j| to_v2(arena.robots[j].position)).collect();
                    let apart = 2.0 * radius + 2.0 * self.clearance;
                    let p = self.draw(radius, &taken, apart).ok_or_else(|| {
                        self.error(format!(
                            "no free start for robot `{}` in the area after {ATTEMPTS} draws: too many robots or \
                             obstacles for the area",
                            arena.robots[i].name
                        ))
                    })?;
                    (
                        p,
                        self.rng
                            .random_range(-std::f32::consts::PI..std::f32::consts::PI),
                    )
                }
            };
            arena.place_robot(
                RobotId(i as u32),
                Vec2::new(position.x, position.y),
                heading,
            );
        }
        for i in 0..n {
            let a = &arena.robots[i];
            if !self.is_free(to_v2(a.position), a.body.radius - self.clearance) {
                return Err(self.error(format!(
                    "the start ({}, {}) of robot `{}` is inside an obstacle",
                    a.position.x, a.position.y, a.name
                )));
            }
            for b in &arena.robots[i + 1..] {
                if (a.position - b.position).length() < a.body.radius + b.body.radius {
                    return Err(self.error(format!(
                        "the start positions of robots `{}` and `{}` overlap",
                        a.name, b.name
                    )));
                }
            }
        }
        Ok(())
    }

    fn first_goals(&mut self, arena: &Arena) -> Result<(), WorldError> {
        let n = arena.robots.len();
        if let Goals::Given(points) = &self.goals
            && points.len() != n
        {
            return Err(self.error(format!(
                "`goals` lists {} points for {n} robots",
                points.len()
            )));
        }
        let mut goals = Vec::with_capacity(n);
        for i in 0..n {
            let robot = &arena.robots[i];
            let radius = robot.body.radius;
            let goal = match &self.goals {
                Goals::Given(points) => points[i],
                Goals::Antipodal => self.center * 2.0 - to_v2(robot.position),
                Goals::Random => {
                    let apart = 2.0 * radius + 2.0 * self.clearance;
                    let start = to_v2(robot.position);
                    self.draw_reachable(start, radius, &goals, apart)
                        .map(|(goal, _)| goal)
                        .ok_or_else(|| {
                            self.error(format!(
                                "no free goal for robot `{}` in the area that it can reach",
                                robot.name
                            ))
                        })?
                }
            };
            self.check_goal(arena, i, goal)?;
            goals.push(goal);
        }
        self.trips = goals
            .into_iter()
            .map(|goal| Trip {
                seq: 1,
                goal,
                ..Trip::default()
            })
            .collect();
        Ok(())
    }

    /// A goal must lie in the arena with room for the robot, outside every obstacle's clearance, and not be walled
    /// off from the robot's start by obstacles (the reference search of `planning` decides).
    fn check_goal(&self, arena: &Arena, robot: usize, goal: V2) -> Result<(), WorldError> {
        let r = &arena.robots[robot];
        let radius = r.body.radius;
        let (lo, hi) = (arena.min, arena.max);
        if goal.x - radius < lo.x
            || goal.y - radius < lo.y
            || goal.x + radius > hi.x
            || goal.y + radius > hi.y
        {
            return Err(self.error(format!(
                "the goal ({}, {}) of robot `{}` is unreachable: a robot there would not be inside the arena",
                goal.x, goal.y, r.name
            )));
        }
        if let Some(o) = self
            .map
            .iter()
            .position(|o| (goal - o.centre).length() < o.radius + radius + self.clearance)
        {
            let name = &arena
                .obstacles
                .iter()
                .filter(|o| matches!(o.placed.shape, Shape::Disc { .. }))
                .nth(o)
                .map_or("?", |o| o.name.as_str());
            return Err(self.error(format!(
                "the goal ({}, {}) of robot `{}` is inside obstacle `{name}` (or within {} m of it)",
                goal.x, goal.y, r.name, self.clearance
            )));
        }
        let start = to_v2(r.position);
        if self.reference(start, goal, radius) == Err(SearchError::Unreachable) {
            return Err(self.error(format!(
                "the goal ({}, {}) of robot `{}` cannot be reached from its start ({}, {}): obstacles wall it off",
                goal.x, goal.y, r.name, start.x, start.y
            )));
        }
        Ok(())
    }

    /// The known map as the payloads of its chunks, then the bounds (they never change, so they are encoded
    /// once).
    fn map_payloads(&self) -> Vec<Vec<u8>> {
        let mut payload = [0u8; PAYLOAD];
        let mut chunks = Vec::new();
        let mut first = 0;
        loop {
            let (len, next) = wire::encode_map(&self.known, first, &mut payload);
            chunks.push(payload[..len].to_vec());
            if next >= self.known.len() {
                break;
            }
            first = next;
        }
        let len = wire::encode_bounds(&self.bounds, &mut payload);
        chunks.push(payload[..len].to_vec());
        chunks
    }

    fn is_hidden(&self, name: &str) -> bool {
        self.hidden.iter().any(|h| id_matches(h, name))
    }

    fn error(&self, message: String) -> WorldError {
        WorldError::Invalid {
            location: self.location.clone(),
            message: format!("<navigation>: {message}"),
        }
    }

    fn arrive(&mut self, arena: &Arena, robot: usize, here: V2) {
        let tps = f64::from(self.ticks_per_second);
        let radius = arena.robots[robot].body.radius;
        let trip = &self.trips[robot];
        let figures = TripFigures {
            // The trip ends on entering the goal's tolerance, so the reference ends there too.
            optimum: trip
                .optimum
                .or_else(|| self.reference(trip.start, trip.goal, radius).ok())
                .map(|o| (o - self.tolerance).max(0.0)),
            known_optimum: trip
                .report
                .and(reference(trip.start, trip.goal, &self.known, self.bounds, radius).ok()),
            driven: trip.path,
            report: trip.report,
        };
        self.totals.add(&figures);
        let trip = &mut self.trips[robot];
        self.arrivals += 1;
        self.last_arrival_tick = self.tick;
        self.flowtime_ticks += self.tick - trip.started;
        self.completed_path += trip.path;
        self.completed_turning += trip.turning;
        let cell = |x: Option<String>| x.unwrap_or_default();
        let report = trip.report;
        let _ = writeln!(
            self.output,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            self.tick,
            robot,
            trip.seq,
            trip.goal.x,
            trip.goal.y,
            (self.tick - trip.started) as f64 / tps,
            trip.path,
            trip.turning,
            cell(figures.optimum.map(|o| o.to_string())),
            cell(report.map(|r| r.plans.to_string())),
            cell(report.map(|r| r.failed.to_string())),
            cell(report.map(|r| r.replans.to_string())),
            cell(
                report
                    .filter(|r| r.agents > 0)
                    .map(|r| (f64::from(r.collision_free) / f64::from(r.agents)).to_string())
            ),
            cell(report.map(|r| r.first_planned.to_string())),
            cell(report.map(|r| r.first_followed.to_string())),
        );
        if !self.continuous {
            trip.done = true;
            return;
        }
        let radius = arena.robots[robot].body.radius;
        let next = self.draw_reachable(here, radius, &[], 0.0);
        let trip = &mut self.trips[robot];
        match next {
            Some((goal, optimum)) => {
                trip.goal = goal;
                trip.start = here;
                trip.optimum = optimum;
                trip.report = None;
                trip.seq += 1;
                trip.started = self.tick;
                trip.path = 0.0;
                trip.turning = 0.0;
                trip.last_sent = None;
            }
            None => trip.done = true,
        }
    }
}

impl LoopFunctions for Navigation {
    fn place(&mut self, arena: &mut Arena) -> Result<(), WorldError> {
        self.ticks_per_second = arena.ticks_per_second;
        self.repeat_ticks =
            ((self.repeat_seconds * f64::from(arena.ticks_per_second)).round() as u64).max(1);
        if !self.area.0.is_finite() {
            self.area.0 = V2::new(arena.min.x + 0.5, arena.min.y + 0.5);
        }
        if !self.area.1.is_finite() {
            self.area.1 = V2::new(arena.max.x - 0.5, arena.max.y - 0.5);
        }
        if !(self.area.0.x < self.area.1.x && self.area.0.y < self.area.1.y) {
            return Err(self.error("`area_min` must lie below and left of `area_max`".into()));
        }
        self.map = arena
            .obstacles
            .iter()
            .filter_map(|o| match o.placed.shape {
                Shape::Disc { radius } => Some(Disc {
                    centre: to_v2(o.placed.position),
                    radius,
                }),
                Shape::Rect { .. } => None,
            })
            .collect();
        if self.map.len() > usize::from(u16::MAX) {
            return Err(self.error("the map holds at most 65,535 cylinders".into()));
        }
        let cylinders: Vec<&str> = arena
            .obstacles
            .iter()
            .filter(|o| matches!(o.placed.shape, Shape::Disc { .. }))
            .map(|o| o.name.as_str())
            .collect();
        if let Some(unknown) = self
            .hidden
            .iter()
            .find(|h| !cylinders.iter().any(|c| id_matches(h, c)))
        {
            return Err(self.error(format!(
                "`hidden` names `{unknown}`, which matches no cylinder of the arena"
            )));
        }
        self.known = self
            .map
            .iter()
            .zip(&cylinders)
            .filter(|(_, name)| !self.is_hidden(name))
            .map(|(disc, _)| *disc)
            .collect();
        self.bounds = Bounds {
            min: to_v2(arena.min),
            max: to_v2(arena.max),
        };
        self.starts(arena)?;
        self.first_goals(arena)?;
        self.map_letters = self.map_payloads();
        Ok(())
    }

    fn post_step(&mut self, arena: &mut Arena, _: &[ActuatorCommand], _: &[bool]) {
        self.tick = arena.tick;
        let dt = arena.dt();
        for i in 0..arena.robots.len() {
            let r = &arena.robots[i];
            let here = to_v2(r.position);
            let in_run = r.present && r.alive;
            let trip = &mut self.trips[i];
            if !in_run {
                trip.last = None;
                trip.last_heading = None;
                continue;
            }
            if !trip.seen {
                trip.seen = true;
                trip.started = self.tick;
                trip.start = here;
            }
            let step = trip.last.map_or(0.0, |last| (here - last).length());
            let turn = trip.last_heading.map_or(0.0, |last| {
                swarm_navigation::vec2::wrap(r.heading - last).abs()
            });
            trip.last = Some(here);
            trip.last_heading = Some(r.heading);
            if trip.done {
                continue;
            }
            trip.path += f64::from(step);
            trip.turning += f64::from(turn);
            self.peak_turn_rate = self.peak_turn_rate.max(turn / dt);
            let stalled = step / dt < self.stall_speed;
            if stalled && !trip.stalled && trip.path > 0.0 {
                self.stop_events += 1;
            }
            trip.stalled = stalled;
            if (trip.goal - here).length() < self.tolerance {
                self.arrive(arena, i, here);
            }
        }
        let robots = &arena.robots;
        for (i, a) in robots
            .iter()
            .enumerate()
            .filter(|(_, r)| r.present && r.alive)
        {
            for b in robots[i + 1..].iter().filter(|r| r.present && r.alive) {
                let d = (a.position - b.position).length();
                self.min_separation = self.min_separation.min(d);
                self.min_clearance = self.min_clearance.min(d - a.body.radius - b.body.radius);
            }
        }
    }

    fn post_mail(&mut self, arena: &Arena, letters: &mut Vec<Mail>) {
        let mut payload = [0u8; PAYLOAD];
        for (i, trip) in self.trips.iter_mut().enumerate() {
            let r = &arena.robots[i];
            if !(r.present && r.alive) || trip.done && trip.last_sent.is_some() {
                continue;
            }
            if trip
                .last_sent
                .is_some_and(|sent| self.tick < sent + self.repeat_ticks)
            {
                continue;
            }
            trip.last_sent = Some(self.tick);
            let to = Address::To(i as u32);
            let mut send = |bytes: &[u8]| {
                if let Ok(mail) = Mail::new(swarm_contract::mail::FROM_WORLD, to, bytes) {
                    letters.push(mail);
                }
            };
            let task = Task {
                seq: trip.seq,
                goal: trip.goal,
                tolerance: self.tolerance,
                radius: r.body.radius,
            };
            let len = wire::encode_task(&task, &mut payload);
            send(&payload[..len]);
            for chunk in &self.map_letters {
                send(chunk);
            }
        }
    }

    fn read_mail(&mut self, _arena: &Arena, letters: &[Mail]) {
        for mail in letters {
            if let Ok(Letter::PlanReport(report)) = wire::decode(mail.payload())
                && let Some(trip) = self.trips.get_mut(mail.from as usize)
                && trip.seq == report.seq
                && !trip.done
            {
                trip.report = Some(report);
            }
        }
    }

    fn is_finished(&self, _arena: &Arena) -> bool {
        !self.continuous && !self.trips.is_empty() && self.trips.iter().all(|t| t.done)
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let tps = f64::from(self.ticks_per_second);
        let robots = self.trips.len();
        let arrived = self.trips.iter().filter(|t| t.done).count();
        let finite = |x: f32| x.is_finite().then_some(f64::from(x));
        let mut metrics = json!({
            "robots": robots,
            "tasks_completed": self.arrivals,
            "failures": if self.continuous { 0 } else { robots - arrived },
            "makespan_s": (!self.continuous && arrived == robots && robots > 0)
                .then(|| self.last_arrival_tick as f64 / tps),
            "mean_path_length_m": (self.arrivals > 0).then(|| self.completed_path / self.arrivals as f64),
            "mean_turning_rad": (self.arrivals > 0).then(|| self.completed_turning / self.arrivals as f64),
            "peak_turn_rate_rad_s": self.peak_turn_rate,
            "flowtime_s": self.flowtime_ticks as f64 / tps,
            "min_separation_m": finite(self.min_separation),
            "min_clearance_m": finite(self.min_clearance),
            "collisions": arena.robots.iter().map(|r| r.collisions).sum::<u64>(),
            "stop_events": self.stop_events,
        });
        if let Some(object) = metrics.as_object_mut() {
            self.totals.metrics(object);
        }
        metrics
    }

    fn output_name(&self) -> Option<&str> {
        Some(OUTPUT)
    }

    fn drain_output(&mut self, out: &mut Vec<u8>) {
        out.extend_from_slice(self.output.as_bytes());
        self.output.clear();
    }
}
