//! The cooperative transport task's loop functions (paper B, docs/cooperative_transport.md): the task server, the
//! global planner and the judge of two to four foot-bots that grip a box together, lift it, carry it along a
//! planned path to a goal pose and put it down.
//!
//! ```xml
//! <loop_functions label="transport_loop_functions">
//!   <transport object="crate" goal="2,2,195" tolerance="0.02" angle_tolerance="3" planner="ort"
//!              step="0.2" failures="5" iterations="20000" reach="1.0" margin="0.1" repeat="1"/>
//! </loop_functions>
//! ```
//!
//! - `object` (required): the id of a movable box of the arena with `lift_by`: the object to carry.
//! - `goal` (required): `x,y,angle`: where the box's centre must end (m) and its heading there (degrees).
//! - `tolerance` (m, default 0.02) and `angle_tolerance` (degrees, default 3; sent in radians): how close counts.
//! - `planner`: `ort` (default) or `rrt`, the global planner (`swarm_navigation::planning::tree`), with `step`
//!   gamma (m, default 0.2), `failures` (ORT's f, default 5), `iterations` (most samples, default 20,000, at most
//!   1,000,000) and `reach` (RRT, m, default 1).
//! - `margin` (m, default 0.1): room kept beyond the formation.
//! - `repeat` (s, default 1): how often every robot is sent the `Object` letter again.
//!
//! **The team and the formation.** Every robot of the run is in the team, at most four. Faces are numbered in
//! the box's own frame, 0 +x, 1 +y, 2 -x, 3 -y; the front face is the one whose outward normal at the box's
//! start pose points most towards the goal (the lowest number on a tie). Robots by index take the front face f,
//! the opposite face (f + 2) % 4, the face clockwise from the front (f + 3) % 4, then (f + 1) % 4. The formation's
//! radius is `R = max(half-diagonal of the box, max over the faces in use of (distance from the box's centre to
//! the face + 2 x the largest robot radius)) + margin`. The planner plans for the box's centre as a point on the
//! map of `transport::map` (static obstacles as discs grown by R; walls along the arena's edge as its bounds).
//!
//! `place` refuses (located errors): an `object` that is no box, a box that is not movable or has no `lift_by`;
//! a run without robots or with more than four; a `lift_by` above the number of robots with a `footbot_gripper`;
//! a goal where the formation would overlap a static obstacle (naming it) or leave the arena; and a goal the
//! formation cannot reach from the box's start, as the Theta* reference search of `navigation::planning`
//! (`reference`, 5 cm grid) decides on the same map (a map too large for its grid is not checked).
//!
//! **Letters** (`swarm_navigation::wire::transport`). From the world, each to one present, living robot: `Object`
//! (the box's pose now, its half size, the goal pose, the team's size, `lift_by`, the robot's face, the
//! tolerances and the number of plans made so far) at the first post and every `repeat` seconds; after a
//! `PathRequest`, in the same tick's post, the plan's path as chunks to every robot (a failed plan is a path of
//! no points: one chunk of total 0). To the world, decoded as hostile input and counted only from a robot:
//! `PathRequest` (one plan per tick at most, whatever the number of requests: from the box's centre now to the
//! goal, drawing from the run seed's loop-functions stream numbered by the plan, so that a run is a function of
//! its seed) and `Outcome` (the team's report; the first counts). Other letters are ignored.
//!
//! **What is judged** (`transport::judge`): the box's path (the sum of its centre's steps), its lifts and
//! lowerings, and the end: the first tick after which the box is on the ground and either the team has reported
//! an `Outcome` or the box has been carried and every gripper has been open for two seconds' worth of ticks
//! (`judge::SILENT_TICKS`, a grace for the report). Then the position error (distance from the
//! box's centre to the goal), the heading error `|wrap(angle - goal angle)|` in degrees, and success: delivered
//! (put down that way with no report other than `Delivered`) within both tolerances. The run is finished then;
//! a run that never gets there stops at its configured length (the world never waits for robots).
//!
//! Records: [`OUTPUT`], `tick,event,x,y,angle_deg,detail` with the box's pose in every row, for the events
//! `start` (at `place`; detail `front_face=F formation_radius_m=R`), `lifted`, `lowered`, `plan` (detail `ort
//! nodes=N length_m=L`, `rrt ...` or `failed`), `pose` (every whole second while the box is lifted), `outcome`
//! (detail `delivered`, `teammate_lost`, `dropped` or `no_path`) and `final` (detail `position_error_m=E
//! angle_error_deg=A`). Metrics: `outcome` (or null), `success`, `position_error_m` and `angle_error_deg` (null
//! before the end), `time_s` (the end's tick over the tick rate, null before the end), `object_path_m`,
//! `planned_path_m` and `planner_nodes` (of the last plan), `plans`, `planning_ms` (summed wall time,
//! machine-dependent: the only figure that is not a function of the run), `lifted_s` and `collisions` (summed
//! over robots).

use serde_json::json;
use swarm_contract::mail::{Address, FROM_WORLD, Mail};
use swarm_contract::messages::ActuatorCommand;
use swarm_navigation::V2;
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::transport::{Letter, Object, decode, encode_object};

use crate::arena::Arena;
use crate::entities::Obstacle;
use crate::error::WorldError;
use crate::loop_functions::{LoopFunctions, LoopFunctionsParams};

mod config;
mod formation;
mod judge;
mod map;
mod planner;
mod records;
mod site;
#[cfg(test)]
mod tests;

use config::Settings;
use judge::{Goal, Judge, Seen, ending_name};
use planner::Plan;
use records::{Pose, Records};
use site::Site;

/// The label under which the configuration selects these loop functions.
pub const LABEL: &str = "transport_loop_functions";
/// The file, in the run folder, with one row per event of the box.
pub const OUTPUT: &str = "transport.csv";
// The transport letters must fit the messages medium.
const _: () = assert!(PAYLOAD <= swarm_contract::mail::MAIL_PAYLOAD_BYTES);

/// The cooperative transport task server, global planner and judge.
pub struct Transport {
    settings: Settings,
    goal: Goal,
    seed: u64,
    location: String,
    /// The task as laid out in the arena (`place`).
    site: Option<Site>,
    judge: Judge,
    records: Records,
    /// Plans made so far.
    plans: u32,
    /// The last plan.
    last_plan: Option<Plan>,
    /// Wall time of all plans (µs).
    planning_us: u64,
    /// The tick of the last plan: one per tick at most.
    planned_tick: Option<u64>,
    /// The last plan's chunks, when they are to be posted this tick.
    path_letters: Vec<Vec<u8>>,
    /// The tick of the last `Object` letters.
    last_object: Option<u64>,
    /// Ticks between `Object` letters (`place`).
    repeat: u64,
    ticks_per_second: u32,
}

fn pose_of(o: &Obstacle) -> Pose {
    Pose {
        centre: V2::new(o.placed.position.x, o.placed.position.y),
        angle: o.placed.angle(),
    }
}

impl Transport {
    /// The factory registered under [`LABEL`].
    pub fn factory(params: &LoopFunctionsParams) -> Result<Box<dyn LoopFunctions>, WorldError> {
        Ok(Box::new(Self::new(params)?))
    }

    fn new(params: &LoopFunctionsParams) -> Result<Self, WorldError> {
        let settings = Settings::read(params)?;
        Ok(Transport {
            goal: Goal {
                pose: Pose {
                    centre: settings.goal,
                    angle: settings.goal_angle,
                },
                tolerance: settings.tolerance,
                angle_tolerance: settings.angle_tolerance,
            },
            settings,
            seed: params.seed,
            location: params.location.clone(),
            site: None,
            judge: Judge::default(),
            records: Records::new(),
            plans: 0,
            last_plan: None,
            planning_us: 0,
            planned_tick: None,
            path_letters: Vec::new(),
            last_object: None,
            repeat: 1,
            ticks_per_second: 1,
        })
    }

    fn error(&self, message: String) -> WorldError {
        WorldError::Invalid {
            location: self.location.clone(),
            message: format!("<transport>: {message}"),
        }
    }

    /// The box's pose now, once placed.
    fn object_pose(&self, arena: &Arena) -> Option<Pose> {
        let site = self.site.as_ref()?;
        arena.obstacles.get(site.object).map(pose_of)
    }

    /// Makes the next plan from the box's pose `from` and queues its chunks for this tick's post.
    fn plan(&mut self, tick: u64, from: Pose) {
        let Some(site) = &self.site else {
            return;
        };
        self.planned_tick = Some(tick);
        self.plans = self.plans.saturating_add(1);
        let plan = Plan::make(
            &self.settings,
            &site.area.map,
            from.centre,
            self.seed,
            self.plans,
        );
        self.planning_us = self.planning_us.saturating_add(plan.micros);
        let detail = match (plan.length, plan.nodes) {
            (Some(length), Some(nodes)) => format!(
                "{} nodes={nodes} length_m={length}",
                self.settings.planner_name()
            ),
            _ => "failed".to_owned(),
        };
        self.records.row(tick, "plan", from, &detail);
        self.path_letters = plan.chunks();
        self.last_plan = Some(plan);
    }
}

impl LoopFunctions for Transport {
    fn place(&mut self, arena: &mut Arena) -> Result<(), WorldError> {
        self.ticks_per_second = arena.ticks_per_second.max(1);
        // A saturating cast: a repeat beyond u64 ticks is as good as never.
        self.repeat =
            ((self.settings.repeat_s * f64::from(self.ticks_per_second)).round() as u64).max(1);
        let site = Site::new(&self.settings, arena).map_err(|message| self.error(message))?;
        if let Some(pose) = arena.obstacles.get(site.object).map(pose_of) {
            let detail = format!(
                "front_face={} formation_radius_m={}",
                site.faces.first().copied().unwrap_or_default(),
                site.radius
            );
            self.records.row(arena.tick, "start", pose, &detail);
        }
        self.site = Some(site);
        Ok(())
    }

    fn post_step(&mut self, arena: &mut Arena, _: &[ActuatorCommand], _: &[bool]) {
        let (Some(site), Some(pose)) = (&self.site, self.object_pose(arena)) else {
            return;
        };
        let seen = Seen {
            tick: arena.tick,
            whole_second: arena.tick.is_multiple_of(u64::from(self.ticks_per_second)),
            pose,
            lifted: arena.obstacles.get(site.object).is_some_and(|o| o.lifted),
            grips_open: arena.robots.iter().all(|r| r.gripper.holding.is_none()),
        };
        self.judge.step(seen, &self.goal, &mut self.records);
    }

    fn post_mail(&mut self, arena: &Arena, letters: &mut Vec<Mail>) {
        let (Some(site), Some(pose)) = (&self.site, self.object_pose(arena)) else {
            return;
        };
        let tick = arena.tick;
        let object_due = self
            .last_object
            .is_none_or(|sent| tick >= sent.saturating_add(self.repeat));
        if object_due {
            self.last_object = Some(tick);
        }
        let path = std::mem::take(&mut self.path_letters);
        let team = u8::try_from(arena.robots.len()).unwrap_or(u8::MAX);
        let mut payload = [0u8; PAYLOAD];
        for (i, robot) in arena.robots.iter().enumerate() {
            if !(robot.present && robot.alive) {
                continue;
            }
            let to = Address::To(i as u32);
            let mut send = |bytes: &[u8]| {
                if let Ok(mail) = Mail::new(FROM_WORLD, to, bytes) {
                    letters.push(mail);
                }
            };
            if object_due && let Some(&face) = site.faces.get(i) {
                let object = Object {
                    centre: pose.centre,
                    angle: swarm_navigation::vec2::wrap(pose.angle),
                    half: site.half,
                    goal: self.goal.pose.centre,
                    goal_angle: self.goal.pose.angle,
                    team,
                    lift_by: site.lift_by,
                    face,
                    tolerance: self.goal.tolerance,
                    angle_tolerance: self.goal.angle_tolerance,
                    plans: self.plans,
                };
                let len = encode_object(&object, &mut payload);
                send(&payload[..len]);
            }
            for chunk in &path {
                send(chunk);
            }
        }
    }

    fn read_mail(&mut self, arena: &Arena, letters: &[Mail]) {
        let Some(pose) = self.object_pose(arena) else {
            return;
        };
        let mut requested = false;
        for mail in letters {
            if mail.from as usize >= arena.robots.len() {
                continue;
            }
            match decode(mail.payload()) {
                Ok(Letter::PathRequest) => requested = true,
                Ok(Letter::Outcome(outcome)) => {
                    self.judge
                        .report(arena.tick, outcome.ending, pose, &mut self.records);
                }
                _ => {}
            }
        }
        if requested && self.judge.end.is_none() && self.planned_tick != Some(arena.tick) {
            self.plan(arena.tick, pose);
        }
    }

    fn is_finished(&self, _arena: &Arena) -> bool {
        self.judge.end.is_some()
    }

    fn metrics(&self, arena: &Arena) -> serde_json::Value {
        let tps = f64::from(self.ticks_per_second);
        let end = self.judge.end;
        let last = self.last_plan.as_ref();
        json!({
            "outcome": self.judge.outcome.map(ending_name),
            "success": end.is_some_and(|e| e.success),
            "position_error_m": end.map(|e| f64::from(e.position_error)),
            "angle_error_deg": end.map(|e| f64::from(e.angle_error_deg)),
            "time_s": end.map(|e| e.tick as f64 / tps),
            "object_path_m": self.judge.path_m,
            "planned_path_m": last.and_then(|p| p.length).map(f64::from),
            "plans": self.plans,
            "planner_nodes": last.and_then(|p| p.nodes),
            "planning_ms": self.planning_us as f64 / 1000.0,
            "lifted_s": self.judge.lifted_ticks as f64 / tps,
            "collisions": arena.robots.iter().map(|r| r.collisions).sum::<u64>(),
        })
    }

    fn output_name(&self) -> Option<&str> {
        Some(OUTPUT)
    }

    fn drain_output(&mut self, out: &mut Vec<u8>) {
        self.records.drain(out);
    }
}
