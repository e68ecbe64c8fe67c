//! The exploration task's loop functions (paper A, docs/exploration.md): the task server and the judge of
//! exploration with task allocation. Robots of type 1 or 2 explore an arena with obstacles; tasks lie at fixed
//! positions that a robot only learns when it comes within its discovery radius. The robots report what they
//! find to a coordinator, which sends teams to the tasks; a team at a task executes it for `task_time`, and the
//! task is complete. A task completed after its time window is worth less, and nothing `decay` seconds later.
//!
//! ```xml
//! <loop_functions label="exploration_loop_functions">
//!   <exploration tasks="2.0,8.0,1,45,200; 8.0,2.0,2,20,220" robot_types="scout:1, hauler:2"
//!                task_time="10" decay="50" reach="0.3" discovery="sensor" coverage_cell="0.1" repeat="1"/>
//! </loop_functions>
//! ```
//!
//! - `tasks` (required): `x,y,type,value,window` entries separated by `;`: position (m), type (1 or 2), value
//!   u_j (>= 0) and time window W_j (seconds from the start of the run, > 0). Task numbers are the entries'
//!   places in the list, from 0. At most `wire::exploration::MAX_TASKS`.
//! - `robot_types` (required): `controller:type` pairs separated by commas or spaces: a robot's type comes from
//!   its controller's id; every robot's controller must be listed.
//! - `task_time`: seconds of continuous execution a task needs (default 10; at least one tick).
//! - `decay`: seconds over which a task's utility falls linearly to zero after its window (default 50; 0: no
//!   utility at all once the window is over).
//! - `reach`: a robot whose centre is this close to a task's position (m) is at the task (default 0.3).
//! - `discovery`: `sensor` (default: each robot's range-finder range; every robot needs a range finder) or a
//!   radius in metres.
//! - `coverage_cell`: side of the coverage grid's cells (m, default 0.1).
//! - `repeat`: seconds between re-sending every robot its `Setup` (default 1): robots may restart or join.
//!
//! `place` refuses a run without robots, a task no team of the swarm can do (a type-2 task needs a type-2 robot
//! or two type-1 robots), a task where no robot fits (off the arena, inside an obstacle or closer to one than
//! the largest robot's radius), and two tasks whose reach discs overlap.
//!
//! What is judged, every tick, from the robots' true positions and what they declare
//! (`swarm_navigation::wire::exploration`):
//!
//! - **Discovery.** A present, living robot within its discovery radius of a task it has not sensed gets a
//!   `Found` letter; the first robot to sense a task discovers it. A robot that leaves the run (dies or is
//!   removed) forgets what it sensed and loses its waiting letters: back in the run it senses anew.
//! - **Execution.** Robots send the world a `Status` when their mode changes and every second. A task is in
//!   progress in a tick when the present, living robots within `reach` of it that declare `Execute` with it
//!   include a feasible team by the world's types (`swarm_allocation::team::includes_feasible`); the team recorded is
//!   all those robots. Progress counts the ticks in progress and starts again from zero after a tick that is
//!   not. After `task_time` ticks the task is complete, with utility
//!   `wire::exploration::utility_at(value, window, decay, tick)`; robots travelling to or executing it, and any
//!   robot that declares it later, get a `Done` letter.
//! - **Expiry.** A task not complete when the tick passes its window plus `decay` has expired (recorded once; a
//!   later completion is recorded, with utility 0).
//! - **Distance and coverage.** Each robot's path (its steps while in the run) and its distance driven to tasks
//!   (its last `Status`); the fraction of free coverage cells whose centre has been within a robot's discovery
//!   radius (`coverage`: sight lines are not checked).
//!
//! The run is finished when every task is complete or expired.
//!
//! Letters from the world (`FROM_WORLD`, each to one robot in the run): `Setup` (the robot's type, the tick
//! rate, `reach`, and its range finder's range, or its discovery radius without one) at the first post and every
//! `repeat` seconds; `Found` and `Done` as they arise. At most [`LETTERS_PER_TICK`] go to one robot in one
//! tick; the rest wait for the next ticks. Letters to the world are decoded as hostile input: a `Status` counts
//! only from a robot and about a task of the run, an `Allocation` (the coordinator's allocator runs) only from a
//! participant that is no robot.
//!
//! Records: [`OUTPUT`] in the run folder, `tick,event,task,robots,utility,coverage` with the events
//! `discovered` (task, discovering robot, coverage), `started` (task, team: robot indices separated by spaces),
//! `completed` (task, team, utility), `expired` (task) and `coverage` (every second); cells that do not apply
//! are empty. Metrics (`summary.json`): `robots`, `tasks`, `tasks_discovered`, `tasks_completed`,
//! `tasks_expired` (expired and not completed with utility > 0), `utility`, `upper_bound` (the sum of the
//! values), `gap_percent` (`100 (upper_bound - utility) / upper_bound`, null for an upper bound of 0),
//! `distance_m`, `mean_distance_m`, `mean_distance_to_tasks_m` (per robot), `coverage` (fraction),
//! `coverage_90_s` (when coverage first reached 0.9, or null), `collisions`, `allocations`,
//! `allocation_us_mean` and `allocation_us_max` (wall time, machine-dependent; null without allocations).
//! Everything else is a function of the run alone.

use std::collections::VecDeque;
use std::fmt::Write as _;

use serde_json::json;
use swarm_allocation::Kind;
use swarm_allocation::team::includes_feasible;
use swarm_contract::mail::{Address, FROM_WORLD, Mail};
use swarm_contract::messages::ActuatorCommand;
use swarm_navigation::V2;
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::exploration::{
    Found, Letter, Mode, Setup, decode, encode_done, encode_found, encode_setup, utility_at,
};

use crate::arena::Arena;
use crate::error::WorldError;
use crate::geometry::Vec2;
use crate::loop_functions::params::ParamReader;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

mod config;
mod coverage;
use config::{TaskSpec, kind_number, parse_robot_types, parse_tasks};
use coverage::Coverage;

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "exploration_loop_functions";
/// The file, in the run folder, with one row per event and one per second of coverage.
pub const OUTPUT: &str = "exploration.csv";
/// Most letters the world posts to one robot in one tick (its inbox holds
/// [`swarm_contract::mail::MAILBOX_CAPACITY`] messages from everyone); the others wait for the next ticks.
pub const LETTERS_PER_TICK: usize = 8;
/// Coverage reached by `coverage_90_s`.
const COVERAGE_MARK: f64 = 0.9;
// The exploration letters must fit the messages medium.
const _: () = assert!(PAYLOAD <= swarm_contract::mail::MAIL_PAYLOAD_BYTES);

/// A letter waiting to be posted to one robot: about one task.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pending {
    Found(u16),
    Done(u16),
}

/// One task and what became of it.
#[derive(Debug, Clone)]
struct Task {
    spec: TaskSpec,
    /// The tick its window ends (from `place`).
    window_end: u32,
    discovered: bool,
    /// Consecutive ticks in progress.
    progress: u64,
    started: bool,
    /// The utility gained, once complete.
    completed: Option<f32>,
    expired: bool,
}

/// What the judge keeps of one robot.
#[derive(Debug, Clone)]
struct Member {
    kind: Kind,
    /// Discovery radius (m).
    radius: f32,
    /// Its range finder's range, for its `Setup` (the discovery radius for a robot without one).
    sensor_range: f32,
    /// Whether it was present and alive when last looked at (true at the start: a robot out of the run then
    /// leaves it at the first tick).
    in_run: bool,
    /// The tasks it has sensed, by number.
    sensed: Vec<bool>,
    /// Its last declared mode and task.
    mode: Mode,
    task: Option<u16>,
    /// Metres driven to tasks, from its last `Status`.
    to_tasks: f32,
    /// Where it was at the last tick in the run.
    last: Option<Vec2>,
    path: f64,
    pending: VecDeque<Pending>,
}

impl Member {
    fn queue(&mut self, letter: Pending) {
        if !self.pending.contains(&letter) {
            self.pending.push_back(letter);
        }
    }

    /// Out of the run: it forgets what it sensed and declared, and its waiting letters are dropped.
    fn leave(&mut self) {
        self.in_run = false;
        self.last = None;
        self.sensed.fill(false);
        self.pending.clear();
        self.mode = Mode::Explore;
        self.task = None;
    }
}

/// The sum of `values` from +0 (`Iterator::sum` of floats starts from -0, which an empty sum would show).
fn total(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(0.0, |a, b| a + b)
}

/// The exploration task server and judge.
pub struct Exploration {
    tasks: Vec<Task>,
    robot_types: Vec<(String, Kind)>,
    task_time_s: f64,
    decay_s: f64,
    reach: f32,
    /// The discovery radius, or `None` for each robot's range-finder range.
    discovery: Option<f32>,
    coverage_cell: f64,
    repeat_s: f64,
    /// Ticks, from the seconds above (`place`).
    task_time: u64,
    decay: u32,
    repeat: u64,
    ticks_per_second: u32,
    robots: Vec<Member>,
    coverage: Coverage,
    coverage_mark_tick: Option<u64>,
    last_setup: Option<u64>,
    allocations: u64,
    allocation_us_sum: u64,
    allocation_us_max: u32,
    tick: u64,
    /// The (task, robot) pairs executing this tick.
    executing: Vec<(u16, usize)>,
    location: String,
    output: String,
}

impl Exploration {
    /// The factory registered under [`LABEL`].
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        Ok(Box::new(Self::new(params)?))
    }

    fn new(params: &LoopFunctionsParams) -> Result<Self, WorldError> {
        let r = ParamReader::new(
            params,
            "exploration",
            &[
                "tasks",
                "robot_types",
                "task_time",
                "decay",
                "reach",
                "discovery",
                "coverage_cell",
                "repeat",
            ],
        )?;
        let error = |message: String| WorldError::Invalid {
            location: params.location.clone(),
            message: format!("<exploration>: {message}"),
        };
        let tasks = parse_tasks(r.required("tasks")?).map_err(error)?;
        let robot_types = parse_robot_types(r.required("robot_types")?).map_err(error)?;
        Ok(Exploration {
            tasks: tasks
                .into_iter()
                .map(|spec| Task {
                    spec,
                    window_end: 0,
                    discovered: false,
                    progress: 0,
                    started: false,
                    completed: None,
                    expired: false,
                })
                .collect(),
            robot_types,
            task_time_s: r.non_negative("task_time", 10.0)?,
            decay_s: r.non_negative("decay", 50.0)?,
            reach: r.positive("reach", 0.3)? as f32,
            discovery: r.positive_or_word("discovery", "sensor")?.map(|d| d as f32),
            coverage_cell: r.positive("coverage_cell", 0.1)?,
            repeat_s: r.positive("repeat", 1.0)?,
            task_time: 1,
            decay: 0,
            repeat: 1,
            ticks_per_second: 1,
            robots: Vec::new(),
            coverage: Coverage::default(),
            coverage_mark_tick: None,
            last_setup: None,
            allocations: 0,
            allocation_us_sum: 0,
            allocation_us_max: 0,
            tick: 0,
            executing: Vec::new(),
            location: params.location.clone(),
            output: String::from("tick,event,task,robots,utility,coverage\n"),
        })
    }

    fn error(&self, message: String) -> WorldError {
        WorldError::Invalid {
            location: self.location.clone(),
            message: format!("<exploration>: {message}"),
        }
    }

    /// `seconds` in ticks for the wire's 32-bit tick counts; `what` names them in the error.
    fn ticks_u32(&self, seconds: f64, what: &str) -> Result<u32, WorldError> {
        let ticks = (seconds * f64::from(self.ticks_per_second)).round();
        if ticks > f64::from(u32::MAX) {
            return Err(self.error(format!(
                "{what} of {seconds} s is {ticks} ticks at {} ticks per second; the letters carry at most {}",
                self.ticks_per_second,
                u32::MAX
            )));
        }
        Ok(ticks as u32)
    }

    /// Every robot's type and discovery radius.
    fn members(&self, arena: &Arena) -> Result<Vec<Member>, WorldError> {
        arena
            .robots
            .iter()
            .map(|r| {
                let Some(&(_, kind)) = self.robot_types.iter().find(|(c, _)| *c == r.controller)
                else {
                    return Err(self.error(format!(
                        "robot `{}` has controller `{}`, which `robot_types` does not list (it lists {})",
                        r.name,
                        r.controller,
                        self.robot_types
                            .iter()
                            .map(|(c, _)| format!("`{c}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                };
                let range = r
                    .devices
                    .range_finder
                    .map(|f| f.range)
                    .filter(|range| *range > 0.0);
                let radius = match (self.discovery, range) {
                    (Some(radius), _) | (None, Some(radius)) => radius,
                    (None, None) => {
                        return Err(self.error(format!(
                            "robot `{}` (controller `{}`) has no range finder, so `discovery=\"sensor\"` gives it no \
                             radius: give the controller a range finder or set `discovery` to a radius in metres",
                            r.name, r.controller
                        )));
                    }
                };
                Ok(Member {
                    kind,
                    radius,
                    sensor_range: range.unwrap_or(radius),
                    in_run: true,
                    sensed: vec![false; self.tasks.len()],
                    mode: Mode::Explore,
                    task: None,
                    to_tasks: 0.0,
                    last: None,
                    path: 0.0,
                    pending: VecDeque::new(),
                })
            })
            .collect()
    }

    /// Every task must have a team in the swarm and room for a robot, out of every other task's reach.
    fn check_tasks(&self, arena: &Arena, members: &[Member]) -> Result<(), WorldError> {
        let ones = members.iter().filter(|m| m.kind == Kind::One).count();
        let twos = members.len() - ones;
        let radius = arena
            .robots
            .iter()
            .map(|r| r.body.radius)
            .fold(0.0_f32, f32::max);
        for (n, task) in self.tasks.iter().enumerate() {
            let p = task.spec.position;
            let at = format!("task {n} at ({}, {})", p.x, p.y);
            if !includes_feasible(task.spec.kind, ones, twos) {
                return Err(self.error(format!(
                    "{at} is of type {}, which no team of this swarm can do: it needs one type-2 robot or two \
                     type-1 robots, and the swarm has {twos} type-2 and {ones} type-1",
                    kind_number(task.spec.kind)
                )));
            }
            let (lo, hi) = (arena.min, arena.max);
            if p.x - radius < lo.x
                || p.y - radius < lo.y
                || p.x + radius > hi.x
                || p.y + radius > hi.y
            {
                return Err(self.error(format!(
                    "{at} is off the arena: a robot of radius {radius} m there would not be inside ({}, {}) to \
                     ({}, {})",
                    lo.x, lo.y, hi.x, hi.y
                )));
            }
            for o in &arena.obstacles {
                let distance = o.placed.signed_distance(p);
                if distance <= 0.0 {
                    return Err(self.error(format!("{at} is inside obstacle `{}`", o.name)));
                }
                if distance < radius {
                    return Err(self.error(format!(
                        "{at} is {distance} m from obstacle `{}`, less than the largest robot radius {radius} m: \
                         no robot could stand there",
                        o.name
                    )));
                }
            }
        }
        // Tasks in order of x: only those less than two reaches apart along x can overlap.
        let apart = 2.0 * self.reach;
        let mut order: Vec<usize> = (0..self.tasks.len()).collect();
        order.sort_by(|&a, &b| {
            let (pa, pb) = (self.tasks[a].spec.position, self.tasks[b].spec.position);
            pa.x.total_cmp(&pb.x).then(a.cmp(&b))
        });
        for (k, &a) in order.iter().enumerate() {
            let pa = self.tasks[a].spec.position;
            for &b in &order[k + 1..] {
                let pb = self.tasks[b].spec.position;
                if pb.x - pa.x >= apart {
                    break;
                }
                let distance = (pa - pb).length();
                if distance < apart {
                    let (first, second) = (a.min(b), a.max(b));
                    let (p, q) = (
                        self.tasks[first].spec.position,
                        self.tasks[second].spec.position,
                    );
                    return Err(self.error(format!(
                        "tasks {first} at ({}, {}) and {second} at ({}, {}) are {distance} m apart, less than twice \
                         the reach ({apart} m): a robot could be at both",
                        p.x, p.y, q.x, q.y
                    )));
                }
            }
        }
        Ok(())
    }

    fn row(
        &mut self,
        event: &str,
        task: Option<usize>,
        robots: &str,
        utility: Option<f32>,
        coverage: bool,
    ) {
        let cell = |x: Option<String>| x.unwrap_or_default();
        let _ = writeln!(
            self.output,
            "{},{event},{},{robots},{},{}",
            self.tick,
            cell(task.map(|t| t.to_string())),
            cell(utility.map(|u| u.to_string())),
            cell(coverage.then(|| self.coverage.fraction().to_string())),
        );
    }

    /// Finds the tasks that robots in the run sense for the first time.
    fn discover(&mut self, arena: &Arena) {
        for (i, (member, robot)) in self.robots.iter_mut().zip(&arena.robots).enumerate() {
            if !member.in_run {
                continue;
            }
            for (t, task) in self.tasks.iter_mut().enumerate() {
                if member.sensed[t]
                    || (task.spec.position - robot.position).length() > member.radius
                {
                    continue;
                }
                member.sensed[t] = true;
                // `tasks` holds at most MAX_TASKS, so the number fits.
                member.queue(Pending::Found(t as u16));
                if !task.discovered {
                    task.discovered = true;
                    let _ = writeln!(
                        self.output,
                        "{},discovered,{t},{i},,{}",
                        self.tick,
                        self.coverage.fraction()
                    );
                }
            }
        }
    }

    /// Advances the tasks in progress and completes those done.
    fn execute(&mut self, arena: &Arena) {
        self.executing.clear();
        for (i, (member, robot)) in self.robots.iter().zip(&arena.robots).enumerate() {
            if let (true, Mode::Execute, Some(t)) = (member.in_run, member.mode, member.task)
                && let Some(task) = self.tasks.get(usize::from(t))
                && (robot.position - task.spec.position).length() <= self.reach
            {
                self.executing.push((t, i));
            }
        }
        self.executing.sort_unstable();
        let mut next = 0;
        for t in 0..self.tasks.len() {
            let first = next;
            while self
                .executing
                .get(next)
                .is_some_and(|&(task, _)| usize::from(task) == t)
            {
                next += 1;
            }
            let task = &mut self.tasks[t];
            if task.completed.is_some() {
                continue;
            }
            let team = &self.executing[first..next];
            let ones = team
                .iter()
                .filter(|&&(_, i)| self.robots[i].kind == Kind::One)
                .count();
            if !includes_feasible(task.spec.kind, ones, team.len() - ones) {
                task.progress = 0;
                continue;
            }
            task.progress += 1;
            let first_tick = !task.started;
            task.started = true;
            let complete = task.progress >= self.task_time;
            let utility = utility_at(task.spec.value, task.window_end, self.decay, self.tick);
            if complete {
                task.completed = Some(utility);
            }
            let robots = team
                .iter()
                .map(|(_, i)| i.to_string())
                .collect::<Vec<_>>()
                .join(" ");
            if first_tick {
                self.row("started", Some(t), &robots, None, false);
            }
            if complete {
                self.row("completed", Some(t), &robots, Some(utility), false);
                for member in &mut self.robots {
                    if member.task == Some(t as u16)
                        && matches!(member.mode, Mode::Travel | Mode::Execute)
                    {
                        member.queue(Pending::Done(t as u16));
                    }
                }
            }
        }
    }

    /// Records the tasks whose utility has run out before they were complete.
    fn expire(&mut self) {
        for t in 0..self.tasks.len() {
            let task = &mut self.tasks[t];
            if task.completed.is_none()
                && !task.expired
                && self.tick > u64::from(task.window_end) + u64::from(self.decay)
            {
                task.expired = true;
                self.row("expired", Some(t), "", None, false);
            }
        }
    }

    fn found(&self, t: u16) -> Option<Found> {
        let task = self.tasks.get(usize::from(t))?;
        Some(Found {
            task: t,
            position: V2::new(task.spec.position.x, task.spec.position.y),
            kind: task.spec.kind,
            value: task.spec.value,
            window_end: task.window_end,
            decay: self.decay,
            done: task.completed.is_some(),
        })
    }
}

impl LoopFunctions for Exploration {
    fn place(&mut self, arena: &mut Arena) -> Result<(), WorldError> {
        if arena.robots.is_empty() {
            return Err(self.error("exploration needs at least one robot".into()));
        }
        self.ticks_per_second = arena.ticks_per_second.max(1);
        let tps = f64::from(self.ticks_per_second);
        // Saturating casts: a task time or repeat beyond u64 ticks is as good as forever.
        self.task_time = ((self.task_time_s * tps).round() as u64).max(1);
        self.repeat = ((self.repeat_s * tps).round() as u64).max(1);
        self.decay = self.ticks_u32(self.decay_s, "`decay`")?;
        for t in 0..self.tasks.len() {
            self.tasks[t].window_end = self.ticks_u32(
                self.tasks[t].spec.window,
                &format!("the window of task {t}"),
            )?;
        }
        let members = self.members(arena)?;
        self.check_tasks(arena, &members)?;
        self.coverage = Coverage::new(arena.min, arena.max, self.coverage_cell, &arena.obstacles)
            .map_err(|message| self.error(message))?;
        self.robots = members;
        Ok(())
    }

    fn post_step(&mut self, arena: &mut Arena, _: &[ActuatorCommand], _: &[bool]) {
        self.tick = arena.tick;
        for (member, robot) in self.robots.iter_mut().zip(&arena.robots) {
            if !(robot.present && robot.alive) {
                if member.in_run {
                    member.leave();
                }
                continue;
            }
            member.in_run = true;
            if let Some(last) = member.last {
                member.path += f64::from((robot.position - last).length());
            }
            member.last = Some(robot.position);
            self.coverage.see(robot.position, member.radius);
        }
        if self.coverage_mark_tick.is_none() && self.coverage.fraction() >= COVERAGE_MARK {
            self.coverage_mark_tick = Some(self.tick);
        }
        self.discover(arena);
        self.execute(arena);
        self.expire();
        if self.tick.is_multiple_of(u64::from(self.ticks_per_second)) {
            self.row("coverage", None, "", None, true);
        }
    }

    fn post_mail(&mut self, arena: &Arena, letters: &mut Vec<Mail>) {
        let tick = arena.tick;
        let setup_due = self
            .last_setup
            .is_none_or(|sent| tick >= sent.saturating_add(self.repeat));
        if setup_due {
            self.last_setup = Some(tick);
        }
        let mut payload = [0u8; PAYLOAD];
        for i in 0..self.robots.len().min(arena.robots.len()) {
            let robot = &arena.robots[i];
            if !(robot.present && robot.alive) {
                if self.robots[i].in_run {
                    self.robots[i].leave();
                }
                continue;
            }
            let to = Address::To(i as u32);
            let mut send = |bytes: &[u8]| {
                if let Ok(mail) = Mail::new(FROM_WORLD, to, bytes) {
                    letters.push(mail);
                }
            };
            let mut budget = LETTERS_PER_TICK;
            if setup_due {
                let setup = Setup {
                    kind: self.robots[i].kind,
                    ticks_per_second: self.ticks_per_second,
                    reach: self.reach,
                    sensor_range: self.robots[i].sensor_range,
                };
                let len = encode_setup(&setup, &mut payload);
                send(&payload[..len]);
                budget -= 1;
            }
            for _ in 0..budget {
                let Some(letter) = self.robots[i].pending.pop_front() else {
                    break;
                };
                let len = match letter {
                    Pending::Found(t) => match self.found(t) {
                        Some(found) => encode_found(&found, &mut payload),
                        None => continue,
                    },
                    Pending::Done(t) => encode_done(t, &mut payload),
                };
                send(&payload[..len]);
            }
        }
    }

    fn read_mail(&mut self, _arena: &Arena, letters: &[Mail]) {
        for mail in letters {
            let from = mail.from as usize;
            match decode(mail.payload()) {
                Ok(Letter::Status(status)) => {
                    let Some(member) = self.robots.get_mut(from) else {
                        continue;
                    };
                    let task = match status.task {
                        Some(t) => match self.tasks.get(usize::from(t)) {
                            Some(task) => Some((t, task.completed.is_some())),
                            None => continue,
                        },
                        None => None,
                    };
                    member.mode = status.mode;
                    member.task = status.task;
                    member.to_tasks = status.to_tasks;
                    if let Some((t, true)) = task {
                        member.queue(Pending::Done(t));
                    }
                }
                Ok(Letter::Allocation(allocation)) if from >= self.robots.len() => {
                    self.allocations += 1;
                    self.allocation_us_sum = self
                        .allocation_us_sum
                        .saturating_add(u64::from(allocation.micros));
                    self.allocation_us_max = self.allocation_us_max.max(allocation.micros);
                }
                _ => {}
            }
        }
    }

    fn is_finished(&self, _arena: &Arena) -> bool {
        self.tick > 0
            && self
                .tasks
                .iter()
                .all(|t| t.completed.is_some() || t.expired)
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let robots = arena.robots.len();
        let per_robot = |total: f64| (robots > 0).then(|| total / robots as f64);
        let utility = total(self.tasks.iter().filter_map(|t| t.completed).map(f64::from));
        let upper_bound = total(self.tasks.iter().map(|t| f64::from(t.spec.value)));
        let distance = total(self.robots.iter().map(|m| m.path));
        let to_tasks = total(self.robots.iter().map(|m| f64::from(m.to_tasks)));
        json!({
            "robots": robots,
            "tasks": self.tasks.len(),
            "tasks_discovered": self.tasks.iter().filter(|t| t.discovered).count(),
            "tasks_completed": self.tasks.iter().filter(|t| t.completed.is_some()).count(),
            "tasks_expired": self
                .tasks
                .iter()
                .filter(|t| t.expired && !t.completed.is_some_and(|u| u > 0.0))
                .count(),
            "utility": utility,
            "upper_bound": upper_bound,
            "gap_percent": (upper_bound > 0.0).then(|| 100.0 * (upper_bound - utility) / upper_bound),
            "distance_m": distance,
            "mean_distance_m": per_robot(distance),
            "mean_distance_to_tasks_m": per_robot(to_tasks),
            "coverage": self.coverage.fraction(),
            "coverage_90_s": self
                .coverage_mark_tick
                .map(|tick| tick as f64 / f64::from(self.ticks_per_second)),
            "collisions": arena.robots.iter().map(|r| r.collisions).sum::<u64>(),
            "allocations": self.allocations,
            "allocation_us_mean": (self.allocations > 0)
                .then(|| self.allocation_us_sum as f64 / self.allocations as f64),
            "allocation_us_max": (self.allocations > 0).then_some(self.allocation_us_max),
        })
    }

    fn output_name(&self) -> Option<&str> {
        Some(OUTPUT)
    }

    fn drain_output(&mut self, out: &mut Vec<u8>) {
        out.extend_from_slice(self.output.as_bytes());
        self.output.clear();
    }
}

#[cfg(test)]
mod tests {
    use swarm_contract::mail::TO_WORLD;
    use swarm_navigation::wire::exploration::{
        Allocation, Status, encode_allocation, encode_status,
    };

    use super::*;
    use crate::devices::{Devices, RangeFinderOptions};
    use crate::geometry::{Placed, Shape};
    use crate::physics::Motion;
    use crate::{World, WorldBuilder};

    const LOCATION: &str = "e.argos:3:5";

    /// `<exploration>` with `attrs`; `tasks` and `robot_types` have defaults unless given (an empty value leaves
    /// the attribute out).
    fn params(attrs: &[(&str, &str)]) -> LoopFunctionsParams {
        let mut attributes: std::collections::BTreeMap<String, String> = [
            ("tasks", "5,5,1,40,100"),
            ("robot_types", "scout:1, hauler:2"),
            ("task_time", "0.5"),
        ]
        .iter()
        .chain(attrs)
        .map(|&(k, v)| (format!("exploration.{k}"), v.to_owned()))
        .collect();
        attributes.retain(|_, v| !v.is_empty());
        LoopFunctionsParams {
            label: LABEL.to_owned(),
            location: LOCATION.to_owned(),
            attributes,
            ..LoopFunctionsParams::default()
        }
    }

    fn range_finder(range: f32) -> Devices {
        Devices {
            range_finder: Some(RangeFinderOptions {
                rays: 8,
                range,
                noise_std_dev: 0.0,
            }),
            ..Devices::PROXIMITY_ONLY
        }
    }

    /// A 10 x 10 m arena at 10 ticks per second with robots (controller, position) that have 0.5 m range
    /// finders, and boxes (id, centre, half extents).
    fn world(robots: &[(&str, Vec2)], boxes: &[(&str, Vec2, Vec2)]) -> World {
        let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1);
        for (i, &(controller, p)) in robots.iter().enumerate() {
            b.robot(&format!("ep{i}"), controller, p, 0.0, range_finder(0.5));
        }
        for &(id, centre, half) in boxes {
            b.obstacle(
                id,
                Placed::new(Shape::Rect { half }, centre, 0.0),
                0.1,
                Motion::Fixed,
            );
        }
        b.build()
    }

    fn placed(attrs: &[(&str, &str)], robots: &[(&str, Vec2)]) -> (World, Exploration) {
        let mut w = world(robots, &[]);
        let mut lf = Exploration::new(&params(attrs)).unwrap();
        lf.place(&mut w.arena).unwrap();
        (w, lf)
    }

    fn place_error(attrs: &[(&str, &str)], w: &mut World) -> String {
        let mut lf = Exploration::new(&params(attrs)).unwrap();
        lf.place(&mut w.arena).unwrap_err().to_string()
    }

    fn step(w: &mut World, lf: &mut Exploration) {
        w.arena.tick += 1;
        lf.post_step(&mut w.arena, &[], &[]);
    }

    fn steps(w: &mut World, lf: &mut Exploration, n: usize) {
        for _ in 0..n {
            step(w, lf);
        }
    }

    fn declare(w: &World, lf: &mut Exploration, robot: u32, mode: Mode, task: Option<u16>) {
        let mut payload = [0u8; PAYLOAD];
        let status = Status {
            kind: Kind::One,
            mode,
            task,
            position: V2::ZERO,
            to_tasks: 1.5,
        };
        let len = encode_status(&status, &mut payload);
        let mail = Mail::new(robot, Address::To(TO_WORLD), &payload[..len]).unwrap();
        lf.read_mail(&w.arena, &[mail]);
    }

    /// The letters posted after this tick, as (recipient, letter) in words.
    fn posted(w: &World, lf: &mut Exploration) -> Vec<(u32, String)> {
        let mut letters = Vec::new();
        lf.post_mail(&w.arena, &mut letters);
        letters
            .iter()
            .map(|m| {
                assert_eq!(m.from, FROM_WORLD);
                let words = match decode(m.payload()) {
                    Ok(Letter::Setup(s)) => format!("setup {:?} {}", s.kind, s.sensor_range),
                    Ok(Letter::Found(f)) => format!("found {} done {}", f.task, f.done),
                    Ok(Letter::Done(t)) => format!("done {t}"),
                    other => format!("{other:?}"),
                };
                (m.to, words)
            })
            .collect()
    }

    fn drained(lf: &mut Exploration) -> String {
        let mut out = Vec::new();
        lf.drain_output(&mut out);
        String::from_utf8(out).unwrap()
    }

    fn error(message: &str) -> String {
        format!("{LOCATION}: <exploration>: {message}")
    }

    #[test]
    fn the_configuration_is_read_and_checked() {
        let (_, lf) = placed(
            &[
                ("task_time", "0.01"),
                ("decay", "2.5"),
                ("repeat", "0.25"),
                ("discovery", "0.7"),
                ("tasks", "2,8,1,45,200; 8,2,2,20,220.04"),
            ],
            &[
                ("scout", Vec2::new(1.0, 1.0)),
                ("hauler", Vec2::new(2.0, 1.0)),
            ],
        );
        assert_eq!((lf.task_time, lf.decay, lf.repeat), (1, 25, 3));
        assert_eq!(
            (lf.tasks[0].window_end, lf.tasks[1].window_end),
            (2000, 2200)
        );
        assert_eq!(
            lf.robots
                .iter()
                .map(|m| (m.kind, m.radius, m.sensor_range))
                .collect::<Vec<_>>(),
            vec![(Kind::One, 0.7, 0.5), (Kind::Two, 0.7, 0.5)]
        );
        let (_, lf) = placed(&[], &[("scout", Vec2::new(1.0, 1.0))]);
        assert_eq!(
            (lf.task_time, lf.decay, lf.reach, lf.robots[0].radius),
            (5, 500, 0.3, 0.5)
        );
        let err =
            |attrs: &[(&str, &str)]| Exploration::new(&params(attrs)).err().unwrap().to_string();
        assert!(
            err(&[("range", "1")])
                .starts_with("e.argos:3:5: <exploration> has no attribute 'range'"),
            "{}",
            err(&[("range", "1")])
        );
        assert_eq!(
            err(&[("tasks", "")]),
            "e.argos:3:5: <exploration> needs the attribute 'tasks'"
        );
        assert_eq!(
            err(&[("robot_types", "")]),
            "e.argos:3:5: <exploration> needs the attribute 'robot_types'"
        );
        assert_eq!(
            err(&[("tasks", "1,1,1,5,10; 8,2,3,20,220")]),
            error("`tasks` entry 2 (`8,2,3,20,220`): the type `3` must be 1 or 2")
        );
        assert_eq!(
            err(&[("robot_types", "scout:1 hauler:0")]),
            error("`robot_types` entry `hauler:0`: the type `0` must be 1 or 2")
        );
        assert_eq!(
            err(&[("discovery", "radar")]),
            "e.argos:3:5: <exploration discovery=\"radar\">: must be `sensor` or a number > 0"
        );
        assert_eq!(
            err(&[("reach", "0")]),
            "e.argos:3:5: <exploration reach=\"0\">: must be a number > 0"
        );
    }

    #[test]
    fn a_run_without_robots_or_with_an_unlisted_controller_is_refused() {
        assert_eq!(
            place_error(&[], &mut world(&[], &[])),
            error("exploration needs at least one robot")
        );
        assert_eq!(
            place_error(
                &[],
                &mut world(
                    &[("scout", Vec2::ONE), ("digger", Vec2::new(2.0, 1.0))],
                    &[]
                )
            ),
            error(
                "robot `ep1` has controller `digger`, which `robot_types` does not list (it lists `scout`, \
                 `hauler`)"
            )
        );
    }

    #[test]
    fn sensor_discovery_needs_a_range_finder() {
        let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1);
        b.robot("ep0", "scout", Vec2::ONE, 0.0, Devices::PROXIMITY_ONLY);
        let mut w = b.build();
        assert_eq!(
            place_error(&[], &mut w),
            error(
                "robot `ep0` (controller `scout`) has no range finder, so `discovery=\"sensor\"` gives it no \
                 radius: give the controller a range finder or set `discovery` to a radius in metres"
            )
        );
        let mut lf = Exploration::new(&params(&[("discovery", "0.8")])).unwrap();
        lf.place(&mut w.arena).unwrap();
        assert_eq!((lf.robots[0].radius, lf.robots[0].sensor_range), (0.8, 0.8));
    }

    #[test]
    fn a_type_2_task_needs_a_type_2_robot_or_two_type_1_robots_in_the_swarm() {
        let tasks = [("tasks", "5,5,1,40,100; 2,2,2,20,100")];
        let one = Vec2::ONE;
        assert_eq!(
            place_error(&tasks, &mut world(&[("scout", one)], &[])),
            error(
                "task 1 at (2, 2) is of type 2, which no team of this swarm can do: it needs one type-2 robot or \
                 two type-1 robots, and the swarm has 0 type-2 and 1 type-1"
            )
        );
        let two_scouts = [("scout", one), ("scout", Vec2::new(1.0, 2.0))];
        assert!(placed(&tasks, &two_scouts).1.robots.len() == 2);
        assert!(placed(&tasks, &[("hauler", one)]).1.robots.len() == 1);
    }

    #[test]
    fn a_task_where_no_robot_fits_is_refused() {
        let boxes = [("o1", Vec2::new(5.0, 5.0), Vec2::new(1.0, 0.5))];
        let mut w = world(&[("scout", Vec2::ONE)], &boxes);
        assert_eq!(
            place_error(&[("tasks", "8,8,1,1,10; 5.5,5.25,1,1,10")], &mut w),
            error("task 1 at (5.5, 5.25) is inside obstacle `o1`")
        );
        // 0.02 m from the box: an e-puck (radius 0.035 m) would overlap it.
        assert_eq!(
            place_error(&[("tasks", "5.5,5.52,1,1,10")], &mut w),
            error(
                "task 0 at (5.5, 5.52) is 0.01999998 m from obstacle `o1`, less than the largest robot radius \
                 0.035 m: no robot could stand there"
            )
        );
        assert_eq!(
            place_error(&[("tasks", "5,5.6,1,1,10; 9.98,3,1,1,10")], &mut w),
            error(
                "task 1 at (9.98, 3) is off the arena: a robot of radius 0.035 m there would not be inside (0, 0) \
                 to (10, 10)"
            )
        );
        let mut lf = Exploration::new(&params(&[("tasks", "5.5,5.54,1,1,10")])).unwrap();
        assert!(lf.place(&mut w.arena).is_ok());
    }

    #[test]
    fn tasks_whose_reach_discs_overlap_are_refused() {
        let mut w = world(&[("scout", Vec2::ONE)], &[]);
        assert_eq!(
            place_error(
                &[("tasks", "5,5,1,1,10; 2,2,1,1,10; 5.5,5.3,1,1,10")],
                &mut w
            ),
            error(
                "tasks 0 at (5, 5) and 2 at (5.5, 5.3) are 0.5830953 m apart, less than twice the reach (0.6 m): \
                 a robot could be at both"
            )
        );
        let mut lf = Exploration::new(&params(&[(
            "tasks",
            "5,5,1,1,10; 5,5.65,1,1,10; 5.65,5,1,1,10",
        )]))
        .unwrap();
        assert!(lf.place(&mut w.arena).is_ok());
        assert_eq!(
            place_error(
                &[("tasks", "5,5,1,1,10; 5,5.65,1,1,10"), ("reach", "0.33")],
                &mut w
            ),
            error(
                "tasks 0 at (5, 5) and 1 at (5, 5.65) are 0.6500001 m apart, less than twice the reach (0.66 m): \
                 a robot could be at both"
            )
        );
    }

    #[test]
    fn times_beyond_the_letters_and_grids_beyond_memory_are_refused() {
        let mut w = world(&[("scout", Vec2::ONE)], &[]);
        assert_eq!(
            place_error(&[("tasks", "5,5,1,1,1e9")], &mut w),
            error(
                "the window of task 0 of 1000000000 s is 10000000000 ticks at 10 ticks per second; the letters \
                 carry at most 4294967295"
            )
        );
        assert_eq!(
            place_error(&[("coverage_cell", "0.001")], &mut w),
            error("`coverage_cell` 0.001 m makes 100000000 cells over the arena; at most 10000000")
        );
    }

    #[test]
    fn a_task_is_found_once_per_robot_and_discovered_once() {
        let (mut w, mut lf) = placed(
            &[("tasks", "5,5,1,40,100; 8,8,1,10,100")],
            &[
                ("scout", Vec2::new(2.0, 2.0)),
                ("hauler", Vec2::new(3.0, 2.0)),
            ],
        );
        step(&mut w, &mut lf);
        assert_eq!(
            posted(&w, &mut lf),
            vec![(0, "setup One 0.5".into()), (1, "setup Two 0.5".into())]
        );
        w.arena.robots[0].position = Vec2::new(5.4, 5.0);
        step(&mut w, &mut lf);
        assert_eq!(posted(&w, &mut lf), vec![(0, "found 0 done false".into())]);
        steps(&mut w, &mut lf, 2);
        assert_eq!(posted(&w, &mut lf), vec![], "no repeat within the second");
        w.arena.robots[1].position = Vec2::new(5.0, 4.6);
        step(&mut w, &mut lf);
        assert_eq!(posted(&w, &mut lf), vec![(1, "found 0 done false".into())]);
        steps(&mut w, &mut lf, 6);
        // Tick 10: a second after the first Setup, and a coverage row.
        assert_eq!(posted(&w, &mut lf).len(), 2);
        let csv = drained(&mut lf);
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows[0], "tick,event,task,robots,utility,coverage");
        assert_eq!(
            rows.iter().filter(|r| r.contains(",discovered,")).count(),
            1
        );
        assert!(rows[1].starts_with("2,discovered,0,0,,0."), "{}", rows[1]);
        assert!(rows[2].starts_with("10,coverage,,,,0."), "{}", rows[2]);
        assert_eq!(rows.len(), 3);
        assert_eq!(lf.metrics(&w.arena)["tasks_discovered"], json!(1));
    }

    #[test]
    fn letters_wait_for_the_next_tick_and_a_robot_out_of_the_run_loses_them() {
        let many: Vec<String> = (0..12)
            .map(|k| format!("{},5,1,1,100", 1.0 + 0.7 * k as f32))
            .collect();
        let (mut w, mut lf) = placed(
            &[("tasks", &many.join(";")), ("discovery", "20")],
            &[
                ("scout", Vec2::new(5.0, 2.0)),
                ("scout", Vec2::new(5.0, 8.0)),
            ],
        );
        step(&mut w, &mut lf);
        let first = posted(&w, &mut lf);
        assert_eq!(
            first.iter().filter(|(to, _)| *to == 0).count(),
            LETTERS_PER_TICK
        );
        assert_eq!(first[1], (0, "found 0 done false".into()));
        w.arena.robots[1].alive = false;
        let second = posted(&w, &mut lf);
        assert_eq!(second.len(), 12 - (LETTERS_PER_TICK - 1));
        assert!(second.iter().all(|(to, _)| *to == 0));
        w.arena.robots[1].alive = true;
        step(&mut w, &mut lf);
        // Back in the run, it senses every task again.
        assert_eq!(posted(&w, &mut lf).len(), LETTERS_PER_TICK);
    }

    #[test]
    fn a_type_2_task_is_done_by_two_type_1_robots_not_by_one() {
        let at = Vec2::new(5.0, 5.0);
        let (mut w, mut lf) = placed(
            &[("tasks", "5,5,2,40,100")],
            &[
                ("scout", Vec2::new(5.2, 5.0)),
                ("scout", Vec2::new(2.0, 2.0)),
                ("hauler", Vec2::ONE),
            ],
        );
        declare(&w, &mut lf, 0, Mode::Execute, Some(0));
        steps(&mut w, &mut lf, 20);
        assert_eq!(lf.metrics(&w.arena)["tasks_completed"], json!(0));
        assert_eq!(posted(&w, &mut lf)[1], (0, "found 0 done false".into()));
        // The second one declares Execute but is not there yet.
        declare(&w, &mut lf, 1, Mode::Execute, Some(0));
        steps(&mut w, &mut lf, 3);
        w.arena.robots[1].position = at + Vec2::new(-0.25, 0.0);
        steps(&mut w, &mut lf, 4);
        assert_eq!(lf.tasks[0].progress, 4);
        assert_eq!(posted(&w, &mut lf), vec![(1, "found 0 done false".into())]);
        // Interrupted: robot 1 steps away for a tick, and execution starts again from zero.
        w.arena.robots[1].position = at + Vec2::new(-0.31, 0.0);
        step(&mut w, &mut lf);
        w.arena.robots[1].position = at + Vec2::new(-0.1, 0.0);
        steps(&mut w, &mut lf, 4);
        assert_eq!(lf.metrics(&w.arena)["tasks_completed"], json!(0));
        declare(&w, &mut lf, 2, Mode::Travel, Some(0));
        step(&mut w, &mut lf);
        let m = lf.metrics(&w.arena);
        assert_eq!(
            (m["tasks_completed"].clone(), m["utility"].clone()),
            (json!(1), json!(40.0))
        );
        assert!(lf.is_finished(&w.arena));
        let mut letters = posted(&w, &mut lf);
        letters.retain(|(_, l)| !l.starts_with("setup"));
        assert_eq!(
            letters,
            vec![
                (0, "done 0".into()),
                (1, "done 0".into()),
                (2, "done 0".into())
            ]
        );
        // Later declarations of the task are answered too, and a Found says it is done.
        declare(&w, &mut lf, 2, Mode::Travel, Some(0));
        w.arena.robots[2].position = Vec2::new(4.8, 5.0);
        step(&mut w, &mut lf);
        assert_eq!(
            posted(&w, &mut lf),
            vec![(2, "done 0".into()), (2, "found 0 done true".into())]
        );
        let csv = drained(&mut lf);
        let events: Vec<&str> = csv
            .lines()
            .filter(|r| !r.contains(",coverage,"))
            .skip(1)
            .collect();
        assert_eq!(
            events,
            vec![
                // Three robots' discs of 80 cells of 0.1 m out of 10,000.
                "1,discovered,0,0,,0.024",
                "24,started,0,0 1,,",
                "33,completed,0,0 1,40,",
            ]
        );
    }

    #[test]
    fn a_type_1_task_is_done_by_one_robot_in_task_time() {
        let (mut w, mut lf) = placed(&[], &[("scout", Vec2::new(5.0, 5.25))]);
        declare(&w, &mut lf, 0, Mode::Execute, Some(0));
        steps(&mut w, &mut lf, 4);
        assert!(!lf.is_finished(&w.arena));
        step(&mut w, &mut lf);
        assert!(lf.is_finished(&w.arena));
        assert_eq!(lf.metrics(&w.arena)["tasks_completed"], json!(1));
    }

    #[test]
    fn a_dead_robot_does_not_execute() {
        let (mut w, mut lf) = placed(&[], &[("scout", Vec2::new(5.0, 5.1))]);
        declare(&w, &mut lf, 0, Mode::Execute, Some(0));
        w.arena.robots[0].alive = false;
        steps(&mut w, &mut lf, 10);
        assert_eq!(lf.tasks[0].progress, 0);
        w.arena.robots[0].alive = true;
        steps(&mut w, &mut lf, 10);
        // It forgot its declaration when it died.
        assert_eq!(lf.tasks[0].progress, 0);
    }

    #[test]
    fn utility_decays_after_the_window_and_a_task_expires_once() {
        let (mut w, mut lf) = placed(
            &[("tasks", "5,5,1,40,1; 8,8,1,30,1"), ("decay", "1")],
            &[("scout", Vec2::new(5.0, 5.0))],
        );
        steps(&mut w, &mut lf, 10);
        declare(&w, &mut lf, 0, Mode::Execute, Some(0));
        steps(&mut w, &mut lf, 5);
        // Completed at tick 15: five ticks after the window of 10, half way through the decay.
        assert_eq!(lf.metrics(&w.arena)["utility"], json!(20.0));
        steps(&mut w, &mut lf, 5);
        assert!(!lf.is_finished(&w.arena));
        step(&mut w, &mut lf);
        assert!(lf.is_finished(&w.arena));
        steps(&mut w, &mut lf, 10);
        let csv = drained(&mut lf);
        assert!(csv.contains("\n15,completed,0,0,20,\n"), "{csv}");
        assert!(csv.contains("\n21,expired,1,,,\n"), "{csv}");
        assert_eq!(csv.matches("expired").count(), 1);
        let m = lf.metrics(&w.arena);
        assert_eq!(m["tasks_expired"], json!(1));
        assert_eq!(m["upper_bound"], json!(70.0));
        assert_eq!(m["gap_percent"], json!(100.0 * 50.0 / 70.0));
    }

    #[test]
    fn a_task_completed_after_it_expired_gains_nothing() {
        let (mut w, mut lf) = placed(
            &[("tasks", "5,5,1,40,1"), ("decay", "0")],
            &[("scout", Vec2::new(5.0, 5.0))],
        );
        steps(&mut w, &mut lf, 10);
        assert!(!lf.is_finished(&w.arena));
        step(&mut w, &mut lf);
        assert!(lf.is_finished(&w.arena));
        declare(&w, &mut lf, 0, Mode::Execute, Some(0));
        steps(&mut w, &mut lf, 5);
        let m = lf.metrics(&w.arena);
        assert_eq!(
            (m["tasks_completed"].clone(), m["utility"].clone()),
            (json!(1), json!(0.0))
        );
        assert_eq!(m["tasks_expired"], json!(1));
        assert!(drained(&mut lf).contains("\n16,completed,0,0,0,\n"));
    }

    #[test]
    fn coverage_grows_and_leaves_obstacle_cells_out() {
        // 0.5 m cells: 400, of which a 2 x 2 m box covers 16.
        let boxes = [("o1", Vec2::new(5.0, 5.0), Vec2::new(1.0, 1.0))];
        let mut w = world(&[("scout", Vec2::new(1.25, 1.25))], &boxes);
        let mut lf = Exploration::new(&params(&[
            ("tasks", "8,8,1,1,100"),
            ("coverage_cell", "0.5"),
        ]))
        .unwrap();
        lf.place(&mut w.arena).unwrap();
        // A 0.5 m radius from a cell centre: the cell and its four neighbours.
        step(&mut w, &mut lf);
        assert_eq!(lf.metrics(&w.arena)["coverage"], json!(5.0 / 384.0));
        // Next to the box: one of the five cells is the box's.
        w.arena.robots[0].position = Vec2::new(3.75, 4.25);
        step(&mut w, &mut lf);
        assert_eq!(lf.metrics(&w.arena)["coverage"], json!(9.0 / 384.0));
        assert_eq!(lf.metrics(&w.arena)["coverage_90_s"], json!(null));
        for k in 0..20 {
            for j in 0..20 {
                w.arena.robots[0].position =
                    Vec2::new(0.25 + 0.5 * j as f32, 0.25 + 0.5 * k as f32);
                step(&mut w, &mut lf);
            }
        }
        let m = lf.metrics(&w.arena);
        assert_eq!(m["coverage"], json!(1.0));
        // 346 of 384 cells is the first fraction >= 0.9: after the robot's 346th cell... at tick 2 + 400 * 0.9.
        assert!(
            m["coverage_90_s"]
                .as_f64()
                .is_some_and(|s| s > 30.0 && s < 40.2),
            "{m}"
        );
        let csv = drained(&mut lf);
        let coverage: Vec<f64> = csv
            .lines()
            .filter(|r| r.contains(",coverage,"))
            .map(|r| r.rsplit(',').next().unwrap().parse().unwrap())
            .collect();
        assert_eq!(coverage.len(), 40);
        assert!(
            coverage.windows(2).all(|p| p[0] < p[1] || p[1] == 1.0),
            "{coverage:?}"
        );
    }

    #[test]
    fn hostile_letters_are_ignored_and_allocator_runs_counted() {
        let (w, mut lf) = placed(&[], &[("scout", Vec2::new(5.0, 5.0))]);
        let mut payload = [0u8; PAYLOAD];
        let status = Status {
            kind: Kind::Two,
            mode: Mode::Execute,
            task: Some(0),
            position: V2::ZERO,
            to_tasks: 7.0,
        };
        let len = encode_status(&status, &mut payload);
        let out_of_range = {
            let mut p = [0u8; PAYLOAD];
            let len = encode_status(
                &Status {
                    task: Some(1),
                    ..status
                },
                &mut p,
            );
            Mail::new(0, Address::To(TO_WORLD), &p[..len]).unwrap()
        };
        let allocation = |from: u32, micros: u32| {
            let mut p = [0u8; PAYLOAD];
            let len = encode_allocation(
                &Allocation {
                    number: 1,
                    tasks: 1,
                    robots: 1,
                    micros,
                },
                &mut p,
            );
            Mail::new(from, Address::To(TO_WORLD), &p[..len]).unwrap()
        };
        let letters = [
            Mail::new(0, Address::To(TO_WORLD), &[]).unwrap(),
            Mail::new(0, Address::To(TO_WORLD), &payload[..len - 1]).unwrap(),
            Mail::new(0, Address::To(TO_WORLD), &[200, 1, 2]).unwrap(),
            // A status from the coordinator (participant 1), a task that does not exist, a robot's allocation.
            Mail::new(1, Address::To(TO_WORLD), &payload[..len]).unwrap(),
            out_of_range,
            allocation(0, 9999),
            allocation(1, 100),
            allocation(1, 300),
        ];
        lf.read_mail(&w.arena, &letters);
        assert_eq!(lf.robots[0].mode, Mode::Explore);
        let m = lf.metrics(&w.arena);
        assert_eq!(m["mean_distance_to_tasks_m"], json!(0.0));
        assert_eq!(
            (
                m["allocations"].clone(),
                m["allocation_us_mean"].clone(),
                m["allocation_us_max"].clone()
            ),
            (json!(2), json!(200.0), json!(300))
        );
        lf.read_mail(
            &w.arena,
            &[Mail::new(0, Address::To(TO_WORLD), &payload[..len]).unwrap()],
        );
        assert_eq!(
            (lf.robots[0].mode, lf.robots[0].task),
            (Mode::Execute, Some(0))
        );
        assert_eq!(lf.metrics(&w.arena)["mean_distance_to_tasks_m"], json!(7.0));
    }

    #[test]
    fn distances_are_summed_while_robots_are_in_the_run() {
        let (mut w, mut lf) = placed(
            &[],
            &[
                ("scout", Vec2::new(1.0, 1.0)),
                ("scout", Vec2::new(2.0, 1.0)),
            ],
        );
        step(&mut w, &mut lf);
        w.arena.robots[0].position = Vec2::new(1.0, 2.0);
        step(&mut w, &mut lf);
        w.arena.robots[0].alive = false;
        w.arena.robots[0].position = Vec2::new(1.0, 9.0);
        step(&mut w, &mut lf);
        w.arena.robots[0].alive = true;
        step(&mut w, &mut lf);
        w.arena.robots[0].position = Vec2::new(1.0, 8.0);
        step(&mut w, &mut lf);
        let m = lf.metrics(&w.arena);
        assert_eq!(
            (m["distance_m"].clone(), m["mean_distance_m"].clone()),
            (json!(2.0), json!(1.0))
        );
        assert_eq!(m["robots"], json!(2));
        assert_eq!(m["allocation_us_mean"], json!(null));
        assert_eq!(m["utility"].to_string(), "0.0");
        assert_eq!(m["gap_percent"], json!(100.0));
    }

    #[test]
    fn the_registry_knows_the_label() {
        let registry = crate::loop_functions::LoopFunctionsRegistry::default();
        let lf = registry.create(Some(&params(&[]))).unwrap();
        assert_eq!(lf.output_name(), Some(OUTPUT));
    }
}
