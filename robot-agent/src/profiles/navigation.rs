//! Profile `navigation`: one robot of the navigation task (docs/navigation.md), for the models in
//! `configs/navigation/models`. The supervisor decides the robot's mode (waiting for a goal, taking one up,
//! driving, holding still while the coordinator is silent); the planner of `swarm_navigation::apf` is the
//! action of `drive`.
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `task_new` | u | the task server sent a goal the robot has not taken up |
//! | `goal_reached` | u | the robot is within the goal's tolerance |
//! | `coordinator_lost` | u | no complete snapshot from the coordinator for `stale` ticks (or none yet) |
//! | `coordinator_back` | u | a snapshot came within `stale` ticks |
//! | `take_task` | c | the new goal becomes the current one; the robot holds still this tick |
//! | `drive` | c | one planner step: the (v, w) of the total force of `method` |
//! | `halt` | c | (v, w) = (0, 0) |
//!
//! Every tick the robot reports its pose, radius, status (moving when its last action was `drive`) and goal to
//! the coordinator it heard last. Parameters: `method` (`amr_apf`, `dapf`, `apf`), the switches
//! `adaptive_obstacles`, `adaptive_robots`, `gap_plugs`, `clusters` (true/false), `turn_rule`
//! (`described`/`literal`), `plug_radius` (`enclosing`/`published`), the numbers `attraction`, `caution`,
//! `robot_caution`, `influence`, `threshold_angle` (degrees), `cluster_radius`, `linkage`, `k_v`, `k_w`,
//! `max_speed`, `max_turn_rate`, `min_distance` (defaults: docs/navigation.md), `stale` (ticks, default 10), and the buffer
//! sizes `max_robots` and `max_obstacles` (default 1,024 each; entries beyond them are ignored).

use swarm_contract::mail::{Address, FROM_WORLD, Mailbox};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_navigation::V2;
use swarm_navigation::apf::planner::{Scratch, plan};
use swarm_navigation::apf::{
    Disc, Me, Method, Neighbour, Params as ApfParams, Parts, PlugRadius, Status, TurnRule,
};
use swarm_navigation::wire::{self, Letter, PAYLOAD, Report, Task};

use super::assembly::Assembly;
use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

/// Default number of ticks without a snapshot after which the coordinator counts as lost.
pub const DEFAULT_STALE_TICKS: u64 = 10;
const DEFAULT_CAPACITY: usize = 1024;

/// Profile `navigation`: one robot's planner, its view of the others, its map and its task.
#[derive(Debug)]
pub struct Navigator {
    params: ApfParams,
    stale: u64,
    /// The latest task the server sent.
    offered: Option<Task>,
    /// The task taken up (the goal being driven to).
    current: Option<Task>,
    map: Assembly<Disc>,
    snapshot: Assembly<Neighbour>,
    /// Tick of the last complete snapshot.
    heard: Option<u64>,
    coordinator: Option<u32>,
    priority: f32,
    position: V2,
    heading: f32,
    moving: bool,
    scratch: Scratch,
}

/// The planner parameters of a controller's `<params>`.
fn apf_params(params: &Params) -> Result<ApfParams, ParamError> {
    let d = ApfParams::default();
    Ok(ApfParams {
        method: match params.choice_or("method", &["amr_apf", "dapf", "apf"], "amr_apf")? {
            "amr_apf" => Method::AmrApf,
            "dapf" => Method::Dapf,
            _ => Method::Apf,
        },
        parts: Parts {
            adaptive_obstacles: params.flag_or("adaptive_obstacles", true)?,
            adaptive_robots: params.flag_or("adaptive_robots", true)?,
            gap_plugs: params.flag_or("gap_plugs", true)?,
            clusters: params.flag_or("clusters", true)?,
        },
        attraction: params.positive_f32_or("attraction", d.attraction)?,
        caution: params.non_negative_f32_or("caution", d.caution)?,
        robot_caution: params.non_negative_f32_or("robot_caution", d.robot_caution)?,
        influence: params.positive_f32_or("influence", d.influence)?,
        threshold_angle: params
            .non_negative_f32_or("threshold_angle", d.threshold_angle.to_degrees())?
            .to_radians(),
        cluster_radius: params.non_negative_f32_or("cluster_radius", d.cluster_radius)?,
        linkage: params.non_negative_f32_or("linkage", d.linkage)?,
        k_v: params.non_negative_f32_or("k_v", d.k_v)?,
        k_w: params.non_negative_f32_or("k_w", d.k_w)?,
        max_speed: params.non_negative_f32_or("max_speed", d.max_speed)?,
        max_turn_rate: params.non_negative_f32_or("max_turn_rate", d.max_turn_rate)?,
        min_distance: params.positive_f32_or("min_distance", d.min_distance)?,
        turn_rule: match params.choice_or("turn_rule", &["described", "literal"], "described")? {
            "described" => TurnRule::Described,
            _ => TurnRule::Literal,
        },
        plug_radius: match params.choice_or(
            "plug_radius",
            &["enclosing", "published"],
            "enclosing",
        )? {
            "enclosing" => PlugRadius::Enclosing,
            _ => PlugRadius::Published,
        },
    })
}

impl Navigator {
    fn near_goal(&self, frame: &SensorFrame) -> bool {
        self.current.is_some_and(|task| {
            (task.goal - V2::new(frame.position[0], frame.position[1])).length() < task.tolerance
        })
    }

    fn linked(&self, frame: &SensorFrame) -> bool {
        self.heard
            .is_some_and(|t| frame.tick.saturating_sub(t) <= self.stale)
    }

    fn see(&mut self, frame: &SensorFrame) {
        self.position = V2::new(frame.position[0], frame.position[1]);
        self.heading = frame.heading;
    }
}

fn task_new(s: &Navigator, _: &SensorFrame) -> bool {
    s.offered.map(|t| t.seq) > s.current.map(|t| t.seq)
}

fn goal_reached(s: &Navigator, frame: &SensorFrame) -> bool {
    s.near_goal(frame)
}

fn coordinator_lost(s: &Navigator, frame: &SensorFrame) -> bool {
    !s.linked(frame)
}

fn coordinator_back(s: &Navigator, frame: &SensorFrame) -> bool {
    s.linked(frame)
}

fn stand_still(s: &mut Navigator, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.see(frame);
    s.moving = false;
    command.set_twist(0.0, 0.0);
}

fn take_task(s: &mut Navigator, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.current = s.offered;
    stand_still(s, frame, command);
}

fn halt(s: &mut Navigator, frame: &SensorFrame, command: &mut ActuatorCommand) {
    stand_still(s, frame, command);
}

fn drive(s: &mut Navigator, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.see(frame);
    let Some(task) = s.current else {
        return stand_still(s, frame, command);
    };
    let me = Me {
        id: frame.robot,
        position: s.position,
        heading: s.heading,
        radius: task.radius,
        goal: task.goal,
        priority: s.priority,
    };
    let twist = plan(
        &s.params,
        &me,
        &s.snapshot.items,
        &s.map.items,
        &mut s.scratch,
    );
    s.moving = true;
    command.set_twist(twist.v, twist.w);
}

impl Profile for Navigator {
    const NAME: &'static str = "navigation";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("task_new", Procedure::Check(task_new)),
        ("goal_reached", Procedure::Check(goal_reached)),
        ("coordinator_lost", Procedure::Check(coordinator_lost)),
        ("coordinator_back", Procedure::Check(coordinator_back)),
        ("take_task", Procedure::Act(take_task)),
        ("drive", Procedure::Act(drive)),
        ("halt", Procedure::Act(halt)),
    ];
    const TALKS: bool = true;

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        let robots = params.capacity_or("max_robots", DEFAULT_CAPACITY)?;
        let obstacles = params.capacity_or("max_obstacles", DEFAULT_CAPACITY)?;
        Ok(Navigator {
            params: apf_params(params)?,
            stale: params.whole_or("stale", DEFAULT_STALE_TICKS)?,
            offered: None,
            current: None,
            map: Assembly::with_capacity(obstacles),
            snapshot: Assembly::with_capacity(robots),
            heard: None,
            coordinator: None,
            priority: 0.0,
            position: V2::ZERO,
            heading: 0.0,
            moving: false,
            scratch: Scratch::with_capacity(robots.min(64), obstacles.min(64)),
        })
    }

    fn receive(&mut self, inbox: &Mailbox) {
        for mail in inbox.messages() {
            match wire::decode(mail.payload()) {
                Ok(Letter::Task(task)) if mail.from == FROM_WORLD => self.offered = Some(task),
                Ok(Letter::Map(chunk)) if mail.from == FROM_WORLD => {
                    self.map.add(&chunk, chunk.discs());
                }
                Ok(Letter::Snapshot(chunk))
                    if mail.from != FROM_WORLD && self.snapshot.add(&chunk, chunk.neighbours()) =>
                {
                    self.heard = Some(inbox.tick);
                    self.coordinator = Some(mail.from);
                    let me = inbox.owner;
                    if let Some(mine) = self.snapshot.items.iter().find(|n| n.id == me) {
                        self.priority = mine.priority;
                    }
                }
                // Anything else (a report meant for a coordinator, a forged letter, garbage) is not for a robot.
                _ => {}
            }
        }
    }

    fn send(&mut self, outbox: &mut Mailbox) {
        let Some(coordinator) = self.coordinator else {
            return;
        };
        let report = Report {
            position: self.position,
            heading: self.heading,
            radius: self.current.or(self.offered).map_or(0.1, |t| t.radius),
            status: if self.moving {
                Status::Moving
            } else {
                Status::Stopped
            },
            goal: self.current.map_or(self.position, |t| t.goal),
        };
        let mut payload = [0u8; PAYLOAD];
        let len = wire::encode_report(&report, &mut payload);
        // A full outbox only delays the report to the next tick.
        let _ = outbox.send(Address::To(coordinator), &payload[..len]);
    }
}
