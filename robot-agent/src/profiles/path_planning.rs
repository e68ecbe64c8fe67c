//! Profile `path_planning`: one robot of the path-planning task (paper D, docs/planning.md), for the models in
//! `configs/planning/models`. The supervisor decides the robot's mode (waiting for a goal, planning, following
//! the plan, stopped to replan); the planners of `swarm_navigation::planning` are the action of `plan`.
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `task_new` | u | the task server sent a goal the robot has not taken up |
//! | `goal_reached` | u | the robot is within the goal's tolerance |
//! | `path_ready` | u | the last planner run found a path |
//! | `no_path` | u | the last planner run found none |
//! | `path_blocked` | u | an obstacle the map did not have lies on the rest of the path |
//! | `take_task` | c | the new goal becomes the current one; the path is dropped; the robot holds still |
//! | `plan` | c | one planner run from the current pose on the map and the obstacles found so far; holds still |
//! | `follow` | c | one step along the path; stops at once when the range finder shows the path blocked |
//! | `halt` | c | (v, w) = (0, 0) |
//!
//! Every action first reads the range finder: hits that neither a known obstacle nor the arena's edge explains
//! become found obstacles (`swarm_navigation::planning::discovery`). After each planner run the robot reports
//! its statistics for the task to the world (`wire::PlanReport`).
//!
//! Parameters: `planner` (`gsa` or `theta_star`), `shortcut` (true/false: follow the shortest free polyline
//! through the plan's own points, default true), `margin` (m kept from obstacles beyond the body, default
//! 0.1), the GSA's `agents`, `iterations`, `g0`, `alpha_g`, `kbest_final`, `initial_speed`, `max_step`,
//! `goal_anchor` (true/false), `arrive_fraction`, `penalty` (0 for 10 times the box's diagonal), the reference
//! planner's `resolution` (m, default 0.05), the follower's `lookahead`, `max_speed`, `max_turn_rate`, `k_w`,
//! `k_v`, and the sensing's `tolerance`, `linkage`, `max_hits` and `max_fit_radius` (defaults: docs/planning.md).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::mail::{Address, FROM_WORLD, Mailbox, TO_WORLD};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_navigation::V2;
use swarm_navigation::apf::Disc;
use swarm_navigation::planning::discovery::{Discoveries, Sensing};
use swarm_navigation::planning::follow::{Pursuit, pursue};
use swarm_navigation::planning::gsa::{self, GsaParams};
use swarm_navigation::planning::map::{path_length, segment_hits, shortcut};
use swarm_navigation::planning::{Bounds, Map, theta_star};
use swarm_navigation::wire::{self, Letter, PAYLOAD, PlanReport, Task};

use super::assembly::Assembly;
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

const DEFAULT_MAX_OBSTACLES: usize = 1024;
/// Room kept between the body and an obstacle (m): the follower cuts a path's corners by a few centimetres, and
/// the physics counts a contact a little before the bodies touch.
const DEFAULT_MARGIN: f32 = 0.1;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Planner {
    Gsa(GsaParams),
    ThetaStar { resolution: f32 },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Outcome {
    None,
    Ready,
    Failed,
}

/// Profile `path_planning`: one robot's map, plan and what it found on the way.
#[derive(Debug)]
pub struct PathPlanner {
    planner: Planner,
    cut_corners: bool,
    margin: f32,
    pursuit: Pursuit,
    sensing: Sensing,
    run_seed: u64,
    offered: Option<Task>,
    current: Option<Task>,
    known: Assembly<Disc>,
    bounds: Option<Bounds>,
    found: Discoveries,
    path: Vec<V2>,
    progress: usize,
    outcome: Outcome,
    blocked: bool,
    /// Planner runs since the robot started (seeds each run's random stream).
    runs: u64,
    stats: PlanReport,
    report_due: bool,
}

fn gsa_params(params: &Params) -> Result<GsaParams, ParamError> {
    let d = GsaParams::default();
    let penalty = params.non_negative_f32_or("penalty", 0.0)?;
    Ok(GsaParams {
        agents: params.whole_or("agents", d.agents)?,
        iterations: params.whole_or("iterations", d.iterations)?,
        g0: params.non_negative_f32_or("g0", d.g0)?,
        alpha_g: params.non_negative_f32_or("alpha_g", d.alpha_g)?,
        epsilon: d.epsilon,
        kbest_final: params.unit_f32_or("kbest_final", d.kbest_final)?,
        penalty: (penalty > 0.0).then_some(penalty),
        goal_tolerance: d.goal_tolerance,
        initial_speed: params.positive_f32_or("initial_speed", d.initial_speed)?,
        max_step: params.non_negative_f32_or("max_step", d.max_step)?,
        goal_anchor: params.flag_or("goal_anchor", d.goal_anchor)?,
        arrive_fraction: params.unit_f32_or("arrive_fraction", d.arrive_fraction)?,
    })
}

impl PathPlanner {
    fn position(frame: &SensorFrame) -> V2 {
        V2::new(frame.position[0], frame.position[1])
    }

    /// The map a point robot plans in: the known and found obstacles grown by the body and the margin, the box
    /// shrunk by the body.
    fn planning_map(&self, bounds: Bounds, radius: f32) -> Map {
        let discs: Vec<Disc> = self
            .known
            .items
            .iter()
            .chain(self.found.obstacles())
            .copied()
            .collect();
        Map::for_body(bounds, &discs, radius, self.margin)
    }

    /// Reads the range finder; returns whether an obstacle was found or grew.
    fn sense(&mut self, frame: &SensorFrame) -> bool {
        let Some(bounds) = self.bounds else {
            return false;
        };
        self.found.sense(
            &self.sensing,
            Self::position(frame),
            frame.heading,
            frame.range_readings(),
            &self.known.items,
            &bounds,
        )
    }

    fn near_goal(&self, frame: &SensorFrame) -> bool {
        self.current
            .is_some_and(|task| (task.goal - Self::position(frame)).length() < task.tolerance)
    }

    /// Whether the rest of the path, from the robot on, crosses a found obstacle (grown like the planner's).
    /// An obstacle the robot already stands in may be left, as the planner allows ([`Map::opened_at`]).
    fn rest_blocked(&self, here: V2, radius: f32, bounds: Bounds) -> bool {
        let found = Map::for_body(bounds, self.found.obstacles(), radius, self.margin);
        let rest = &self.path[self.progress.min(self.path.len())..];
        let blocked = |a: V2, b: V2| found.discs.iter().any(|d| segment_hits(a, b, d));
        rest.first().is_some_and(|&next| {
            found
                .opened_at(here)
                .discs
                .iter()
                .any(|d| segment_hits(here, next, d))
        }) || rest.windows(2).any(|w| blocked(w[0], w[1]))
    }

    /// One planner run; the result is in `path`/`outcome` and the task's statistics.
    fn run_planner(&mut self, frame: &SensorFrame) {
        self.blocked = false;
        self.progress = 0;
        self.path.clear();
        self.outcome = Outcome::Failed;
        let (Some(task), Some(bounds)) = (self.current, self.bounds) else {
            return;
        };
        let map = self.planning_map(bounds, task.radius);
        let start = map.bounds.clamp(Self::position(frame));
        self.runs += 1;
        self.stats.plans += 1;
        self.report_due = true;
        let planned = match self.planner {
            Planner::Gsa(params) => {
                let seed = self.run_seed
                    ^ u64::from(frame.robot).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    ^ self.runs.wrapping_mul(0xD1B5_4A32_D192_ED03);
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                self.stats.agents += params.agents as u32;
                match gsa::plan(start, task.goal, &map, &params, &mut rng) {
                    Ok(plan) => {
                        self.stats.collision_free += plan.collision_free as u32;
                        Some(plan.path)
                    }
                    Err(gsa::GsaError::NoPath { collision_free, .. }) => {
                        self.stats.collision_free += collision_free as u32;
                        None
                    }
                    Err(_) => None,
                }
            }
            Planner::ThetaStar { resolution } => {
                theta_star::shortest_path(start, task.goal, &map, resolution).ok()
            }
        };
        let Some(raw) = planned else {
            self.stats.failed += 1;
            return;
        };
        self.path = if self.cut_corners {
            shortcut(&raw, &map)
        } else {
            raw.clone()
        };
        if self.stats.first_planned == 0.0 {
            self.stats.first_planned = path_length(&raw);
            self.stats.first_followed = path_length(&self.path);
        }
        self.outcome = Outcome::Ready;
    }
}

fn stand_still(command: &mut ActuatorCommand) {
    command.set_twist(0.0, 0.0);
}

fn task_new(s: &PathPlanner, _: &SensorFrame) -> bool {
    s.offered.map(|t| t.seq) > s.current.map(|t| t.seq)
}

fn goal_reached(s: &PathPlanner, frame: &SensorFrame) -> bool {
    s.near_goal(frame)
}

fn path_ready(s: &PathPlanner, _: &SensorFrame) -> bool {
    s.outcome == Outcome::Ready
}

fn no_path(s: &PathPlanner, _: &SensorFrame) -> bool {
    s.outcome == Outcome::Failed
}

fn path_blocked(s: &PathPlanner, _: &SensorFrame) -> bool {
    s.blocked
}

fn take_task(s: &mut PathPlanner, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.sense(frame);
    s.current = s.offered;
    s.path.clear();
    s.outcome = Outcome::None;
    s.blocked = false;
    s.stats = PlanReport {
        seq: s.current.map_or(0, |t| t.seq),
        ..PlanReport::default()
    };
    stand_still(command);
}

fn plan(s: &mut PathPlanner, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.sense(frame);
    s.run_planner(frame);
    stand_still(command);
}

fn follow(s: &mut PathPlanner, frame: &SensorFrame, command: &mut ActuatorCommand) {
    let (Some(task), Some(bounds)) = (s.current, s.bounds) else {
        return stand_still(command);
    };
    if s.sense(frame) && s.rest_blocked(PathPlanner::position(frame), task.radius, bounds) {
        // Paper D: stop as soon as a new obstacle is seen on the way; `path_blocked` replans next tick.
        s.blocked = true;
        s.stats.replans += 1;
        s.report_due = true;
        return stand_still(command);
    }
    let twist = pursue(
        &s.pursuit,
        &s.path,
        &mut s.progress,
        PathPlanner::position(frame),
        frame.heading,
    );
    command.set_twist(twist.v, twist.w);
}

fn halt(s: &mut PathPlanner, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.sense(frame);
    stand_still(command);
}

impl Profile for PathPlanner {
    const NAME: &'static str = "path_planning";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("task_new", Procedure::Check(task_new)),
        ("goal_reached", Procedure::Check(goal_reached)),
        ("path_ready", Procedure::Check(path_ready)),
        ("no_path", Procedure::Check(no_path)),
        ("path_blocked", Procedure::Check(path_blocked)),
        ("take_task", Procedure::Act(take_task)),
        ("plan", Procedure::Act(plan)),
        ("follow", Procedure::Act(follow)),
        ("halt", Procedure::Act(halt)),
    ];
    const TALKS: bool = true;

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        let planner = match params.choice_or("planner", &["gsa", "theta_star"], "gsa")? {
            "gsa" => Planner::Gsa(gsa_params(params)?),
            _ => Planner::ThetaStar {
                resolution: params.positive_f32_or("resolution", 0.05)?,
            },
        };
        let p = Pursuit::default();
        let d = Sensing::default();
        Ok(PathPlanner {
            planner,
            cut_corners: params.flag_or("shortcut", true)?,
            margin: params.non_negative_f32_or("margin", DEFAULT_MARGIN)?,
            pursuit: Pursuit {
                lookahead: params.positive_f32_or("lookahead", p.lookahead)?,
                max_speed: params.non_negative_f32_or("max_speed", p.max_speed)?,
                max_turn_rate: params.non_negative_f32_or("max_turn_rate", p.max_turn_rate)?,
                k_w: params.non_negative_f32_or("k_w", p.k_w)?,
                k_v: params.non_negative_f32_or("k_v", p.k_v)?,
            },
            sensing: Sensing {
                tolerance: params.non_negative_f32_or("tolerance", d.tolerance)?,
                spacing: d.spacing,
                linkage: params.non_negative_f32_or("linkage", d.linkage)?,
                capacity: params.capacity_or("max_hits", d.capacity)?,
                max_radius: params.positive_f32_or("max_fit_radius", d.max_radius)?,
            },
            run_seed: params.run_seed(),
            offered: None,
            current: None,
            known: Assembly::with_capacity(
                params.capacity_or("max_obstacles", DEFAULT_MAX_OBSTACLES)?,
            ),
            bounds: None,
            found: Discoveries::default(),
            path: Vec::new(),
            progress: 0,
            outcome: Outcome::None,
            blocked: false,
            runs: 0,
            stats: PlanReport::default(),
            report_due: false,
        })
    }

    fn receive(&mut self, inbox: &Mailbox) {
        for mail in inbox.messages().iter().filter(|m| m.from == FROM_WORLD) {
            match wire::decode(mail.payload()) {
                Ok(Letter::Task(task)) => self.offered = Some(task),
                Ok(Letter::Map(chunk)) => {
                    self.known.add(&chunk, chunk.discs());
                }
                Ok(Letter::Bounds(bounds)) => self.bounds = Some(bounds),
                // Anything else is not for this robot.
                _ => {}
            }
        }
    }

    fn send(&mut self, outbox: &mut Mailbox) {
        if !self.report_due {
            return;
        }
        let mut payload = [0u8; PAYLOAD];
        let len = wire::encode_plan_report(&self.stats, &mut payload);
        // A full outbox only delays the report to the next tick.
        if outbox.send(Address::To(TO_WORLD), &payload[..len]).is_ok() {
            self.report_due = false;
        }
    }
}
