//! Profile `transport`: one foot-bot of a team that carries a box (paper B, docs/cooperative_transport.md), for
//! the models in `configs/transport/models`. The supervisor decides the robot's phase (approach its face, hold,
//! carry to the next waypoint, wait for the others, put down); TangentBug with the potential-field correction
//! is the action of `approach`, the drive to the next waypoint the action of `carry`, and the team's protocol
//! ([`protocol`]) runs in the messages the robot sends and receives.
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `task_known` | u | the supervisor's `Object` letter came |
//! | `at_face` | u | the gripper holds the box |
//! | `take` | u | the team took the box (the coordinator's `Take`) |
//! | `path_ready` | u | the waypoints are known and the team has settled for `settle` ticks since `Take` |
//! | `at_waypoint` | u | the robot is where its grip must be for the current waypoint |
//! | `go` | u | the coordinator released the current waypoint |
//! | `put` | u | the coordinator said `Put` |
//! | `stop` | u | the team stopped (a teammate lost, the box dropped, no path) |
//! | `released` | u | the gripper is open after a put-down |
//! | `approach` | c | TangentBug + field to a point `standoff` out from its face, turn to the face, creep in gripping |
//! | `hold` | c | stand still (gripping, the turret free) |
//! | `carry` | c | drive its grip point to where the next waypoint puts it |
//! | `put_down` | c | open the gripper, stand still |
//! | `halt` | c | stand still |
//!
//! Each robot holds the box by a free turret pinned at its centre, so turning on the spot does not move the box:
//! a robot only drives its centre to its place on the box at the next waypoint (the place it gripped, in the box's
//! frame). When every robot is at its place the box is at the waypoint, so the formation needs no force model.
//!
//! Parameters (times in ticks; the configs run at 10 ticks per second): `radius` (m, the body's, default the
//! foot-bot's 0.085), `standoff` (m out from the face where the approach ends, 0.35), `approach_speed` (0.15
//! m/s), `creep_speed` (0.02 m/s), `carry_speed` (0.05 m/s), `max_turn_rate` (1 rad/s), `k_w` (2),
//! `waypoint_tolerance` (m, 0.02), `final_tolerance` (m, 0.008), `settle` (30: the method's 3 s after `Take`),
//! `stagger` (10 per participant index), `repeat` (10), `step_timeout` (150), `global_threshold` (m: a longer
//! way asks the supervisor for the path, 3), `step` (m, 0.2) and `angle_step` (degrees, 10) of the local path,
//! `clearance` (m, 0.25), and the field's `range1` (0.3), `range2` (0.6), `alpha` (1.5), `beta` (0.5).

mod formation;
pub mod protocol;

use swarm_contract::mail::{Address, FROM_WORLD, Mailbox, TO_WORLD};
use swarm_contract::messages::{ActuatorCommand, GripperAction, SensorFrame, Turret};
use swarm_navigation::V2;
use swarm_navigation::planning::follow::{Pursuit, pursue};
use swarm_navigation::planning::tangent_bug::{Bug, BugParams, Correction, Scan};
use swarm_navigation::vec2::wrap;
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::transport::{self as wire, Ending, Letter, Object, Outcome};

use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};
use formation::{MAX_STEPS, Pose, along, face_point, straight};
use protocol::{PathMode, Team, Timing};

/// The foot-bot's radius (m).
const FOOTBOT_RADIUS: f32 = 0.085_036_76;
/// The gripper grips within 1 cm of the box; the approach aims a little short of contact.
const GRIP_GAP: f32 = 0.005;
/// Ticks a robot that should hold a lifted box may see it not lifted before it calls the box dropped.
const DROP_TICKS: u32 = 5;
/// Waypoints over which a shift of the path fades out.
const SHIFT_FADE: u32 = 5;
/// Heading error under which a robot at its standoff point stops turning and creeps in (rad).
const ALIGNED: f32 = 0.05;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Approach {
    Travel,
    Turn,
    Creep,
}

/// A path arriving in chunks.
#[derive(Debug, Default)]
struct Incoming {
    plan: u32,
    total: usize,
    points: Vec<V2>,
}

/// Profile `transport`: one carrier's view of the box, the path and the team.
#[derive(Debug)]
pub struct Carrier {
    radius: f32,
    standoff: f32,
    approach: Pursuit,
    creep_speed: f32,
    carry: Pursuit,
    waypoint_tolerance: f32,
    final_tolerance: f32,
    settle: u64,
    timing: Timing,
    global_threshold: f32,
    step: f32,
    angle_step: f32,
    bug_params: BugParams,
    correction: Correction,
    team: Option<Team>,
    object: Option<(Object, u64)>,
    gripped_at: Option<u64>,
    phase: Approach,
    bug: Bug,
    incoming: Incoming,
    waypoints: Vec<Pose>,
    shifts: Vec<(u32, V2)>,
    offset: Option<V2>,
    start: Option<Pose>,
    k: u32,
    deviated: u32,
    not_lifted: u32,
    path_requested: bool,
    put_issued: bool,
    outcome_sent: bool,
    tick: u64,
}

impl Carrier {
    fn position(frame: &SensorFrame) -> V2 {
        V2::new(frame.position[0], frame.position[1])
    }

    fn object(&self) -> Option<Object> {
        self.object.map(|(o, _)| o)
    }

    fn team(&mut self, me: u32) -> &mut Team {
        let timing = self.timing;
        self.team.get_or_insert_with(|| Team::new(me, timing))
    }

    fn last(&self) -> u32 {
        self.waypoints.len().saturating_sub(1) as u32
    }

    /// Where this robot's centre belongs at waypoint `k`. A shift announced from waypoint `from` on moves the
    /// box aside there and fades out over the next [`SHIFT_FADE`] waypoints: the box goes round the obstacle and
    /// back to its path, and the goal never moves.
    fn target(&self, k: u32) -> Option<V2> {
        let pose = self.waypoints.get(k as usize)?;
        let shift = if k >= self.last() {
            V2::ZERO
        } else {
            self.shifts
                .iter()
                .filter(|(from, _)| *from <= k)
                .fold(V2::ZERO, |sum, (from, by)| {
                    let weight = 1.0 - (k - from) as f32 / SHIFT_FADE as f32;
                    sum + *by * weight.max(0.0)
                })
        };
        Some(pose.to_world(self.offset?) + shift)
    }

    fn at_target(&self, frame: &SensorFrame) -> bool {
        let tolerance = if self.k >= self.last() {
            self.final_tolerance
        } else {
            self.waypoint_tolerance
        };
        self.target(self.k)
            .is_some_and(|t| (t - Self::position(frame)).length() < tolerance)
    }

    fn scan<'a>(frame: &'a SensorFrame, range: f32) -> Scan<'a> {
        Scan {
            position: Self::position(frame),
            heading: frame.heading,
            ranges: frame.range_readings(),
            range,
        }
    }

    /// After `Take`: the robot's place on the box, and (the coordinator) how the path is made.
    fn settle_in(&mut self, frame: &SensorFrame) {
        let (Some(object), Some(took)) =
            (self.object(), self.team.as_ref().and_then(Team::took_at))
        else {
            return;
        };
        if self.offset.is_none() {
            let pose = Pose {
                centre: object.centre,
                angle: object.angle,
            };
            self.offset = Some(pose.to_local(Self::position(frame)));
            self.start = Some(pose);
            let me = frame.robot;
            let far = (object.goal - object.centre).length() > self.global_threshold;
            let team = self.team(me);
            if team.coordinator() == Some(me) && team.path_mode().is_none() {
                let mode = if far || blocked_towards(frame, object) {
                    PathMode::Global
                } else {
                    PathMode::Local
                };
                team.decide_path(mode, took);
            }
        }
        if !self.waypoints.is_empty() {
            return;
        }
        let start = self.start.unwrap_or(Pose {
            centre: object.centre,
            angle: object.angle,
        });
        match self.team.as_ref().and_then(Team::path_mode) {
            Some(PathMode::Local) => {
                self.waypoints = straight(
                    start,
                    object.goal,
                    object.goal_angle,
                    self.step,
                    self.angle_step,
                );
            }
            Some(PathMode::Global) => {
                let whole =
                    self.incoming.plan > 0 && self.incoming.points.len() == self.incoming.total;
                if whole && self.incoming.total == 0 {
                    self.team(frame.robot).stop(Ending::NoPath);
                } else if whole {
                    self.waypoints = along(&self.incoming.points, start.angle, object.goal_angle);
                }
            }
            None => {}
        }
        if !self.waypoints.is_empty() {
            self.k = 1.min(self.last());
            let last = self.last();
            self.team(frame.robot).set_last(last);
        }
    }

    /// While the box should be lifted: a box not lifted for a few ticks was dropped.
    fn watch_the_box(&mut self, frame: &SensorFrame) {
        let Some(team) = self.team.as_mut() else {
            return;
        };
        if team.took_at().is_none() || team.put() || team.stopped().is_some() {
            return;
        }
        if frame.gripper_holding == 2 {
            self.not_lifted = 0;
        } else {
            self.not_lifted += 1;
            if self.not_lifted > DROP_TICKS {
                tracing::info!("transport: the box is down while it should be carried");
                team.stop(Ending::Dropped);
            }
        }
    }

    /// Keeps the tick, the box's watch and the team's own state current; called by every action.
    fn observe(&mut self, frame: &SensorFrame) {
        self.tick = frame.tick;
        if frame.gripper_holding > 0 && self.gripped_at.is_none() {
            self.gripped_at = Some(frame.tick);
            self.team(frame.robot).gripped(frame.tick);
        }
        let able = self
            .gripped_at
            .zip(self.object.map(|(_, at)| at))
            .is_some_and(|(gripped, heard)| heard > gripped && frame.gripper_holding > 0);
        self.team(frame.robot).able = able;
        self.watch_the_box(frame);
        let shifts = self.team(frame.robot).take_shifts();
        self.shifts.extend(shifts);
    }
}

/// Whether the range finder sees something in the way of the box's straight line to its goal (beyond the box
/// itself): the method's "target not visible".
fn blocked_towards(frame: &SensorFrame, object: Object) -> bool {
    let here = Carrier::position(frame);
    let direction = object.goal - object.centre;
    let n = frame.range_readings().len();
    let reach = object.half.length() + 0.3;
    frame.range_readings().iter().enumerate().any(|(k, &r)| {
        let angle = frame.heading + std::f32::consts::TAU * k as f32 / n as f32;
        let hit = here + V2::from_angle(angle) * r;
        r.is_finite()
            && (hit - object.centre).length() > reach
            && wrap(angle - direction.angle()).abs() < 0.3
    })
}

fn still(command: &mut ActuatorCommand) {
    command.set_twist(0.0, 0.0);
}

fn task_known(s: &Carrier, _: &SensorFrame) -> bool {
    s.object.is_some()
}

fn at_face(s: &Carrier, frame: &SensorFrame) -> bool {
    s.object.is_some() && frame.gripper_holding > 0
}

fn take(s: &Carrier, _: &SensorFrame) -> bool {
    s.team.as_ref().is_some_and(|t| t.took_at().is_some())
}

fn path_ready(s: &Carrier, frame: &SensorFrame) -> bool {
    let settled = s
        .team
        .as_ref()
        .and_then(Team::took_at)
        .is_some_and(|at| frame.tick >= at + s.settle);
    settled && s.offset.is_some() && !s.waypoints.is_empty()
}

fn at_waypoint(s: &Carrier, frame: &SensorFrame) -> bool {
    s.at_target(frame)
}

fn go(s: &Carrier, _: &SensorFrame) -> bool {
    s.team
        .as_ref()
        .is_some_and(|t| t.released() >= s.k && s.k < s.last())
}

fn put(s: &Carrier, _: &SensorFrame) -> bool {
    s.team.as_ref().is_some_and(Team::put)
}

fn stop(s: &Carrier, _: &SensorFrame) -> bool {
    s.team.as_ref().is_some_and(|t| t.stopped().is_some())
}

fn released(s: &Carrier, frame: &SensorFrame) -> bool {
    s.put_issued && frame.gripper_holding == 0
}

fn approach(s: &mut Carrier, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.observe(frame);
    command.turret_mode = Turret::Position;
    command.turret = 0.0;
    let Some(object) = s.object() else {
        return still(command);
    };
    let here = Carrier::position(frame);
    let (face, facing) = face_point(&object, s.radius, GRIP_GAP);
    let (outside, _) = face_point(&object, s.radius, s.standoff);
    if s.phase == Approach::Travel && (outside - here).length() < 0.03 {
        s.phase = Approach::Turn;
    }
    if s.phase == Approach::Turn && wrap(facing - frame.heading).abs() < ALIGNED {
        s.phase = Approach::Creep;
    }
    match s.phase {
        Approach::Travel => {
            let scan = Carrier::scan(frame, 1.0);
            let direction = s.bug.step(&s.bug_params, &scan, outside);
            let direction = s.correction.apply(direction, &scan);
            let remaining = (outside - here).length();
            let aim = here + direction * remaining.min(0.5);
            let mut progress = 0;
            let twist = pursue(&s.approach, &[aim], &mut progress, here, frame.heading);
            command.set_twist(twist.v, twist.w);
        }
        Approach::Turn => {
            let error = wrap(facing - frame.heading);
            command.set_twist(0.0, (s.approach.k_w * error).clamp(-0.5, 0.5));
        }
        Approach::Creep => {
            command.gripper = GripperAction::Pick;
            let error = wrap((face - here).angle() - frame.heading);
            let ahead = (face - here).dot(V2::from_angle(frame.heading));
            let v = if ahead > -0.01 { s.creep_speed } else { 0.0 };
            command.set_twist(v, (s.approach.k_w * error).clamp(-0.3, 0.3));
        }
    }
}

fn hold(s: &mut Carrier, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.observe(frame);
    still(command);
    command.turret_mode = Turret::Passive;
    command.gripper = GripperAction::Hold;
    s.settle_in(frame);
    if s.offset.is_some() && s.at_target(frame) {
        let (k, tick) = (s.k, frame.tick);
        s.team(frame.robot).arrive(k, tick);
    }
}

fn carry(s: &mut Carrier, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.observe(frame);
    command.turret_mode = Turret::Passive;
    command.gripper = GripperAction::Hold;
    if s.team.as_ref().is_some_and(|t| t.released() >= s.k) && s.k < s.last() {
        s.k += 1;
    }
    let Some(target) = s.target(s.k) else {
        return still(command);
    };
    let here = Carrier::position(frame);
    let scan = Carrier::scan(frame, 1.0);
    if let Some(by) = s.deviation(&scan) {
        let k = s.k;
        s.deviated = k;
        s.team(frame.robot).deviate(k, by);
    }
    let mut progress = 0;
    let twist = pursue(&s.carry, &[target], &mut progress, here, frame.heading);
    command.set_twist(twist.v, twist.w);
}

impl Carrier {
    /// The method's "I moved aside, follow": an obstacle within the field's `range2` that is neither the box nor
    /// a teammate (both near the box's outline: the box itself, and a robot at the centre of a face) pushes the
    /// rest of the path away from it by the bounded field of B.4, once per waypoint.
    fn deviation(&self, scan: &Scan<'_>) -> Option<V2> {
        if self.deviated >= self.k {
            return None;
        }
        let (object, offset) = (self.object()?, self.offset?);
        let pose = *self.waypoints.get(self.k as usize)?;
        // The box now, from where this robot holds it.
        let now = Pose {
            centre: scan.position - (pose.to_world(offset) - pose.centre),
            angle: pose.angle,
        };
        let margin = 0.05;
        let faces = [
            V2::new(object.half.x + self.radius, 0.0),
            V2::new(-object.half.x - self.radius, 0.0),
            V2::new(0.0, object.half.y + self.radius),
            V2::new(0.0, -object.half.y - self.radius),
        ];
        let ours = |hit: V2| {
            let local = now.to_local(hit);
            let on_box =
                local.x.abs() <= object.half.x + margin && local.y.abs() <= object.half.y + margin;
            on_box
                || faces
                    .iter()
                    .any(|f| (local - *f).length() <= self.radius + margin)
        };
        let n = scan.ranges.len();
        let c = self.correction;
        let (d, hit) = (0..n)
            .filter(|&k| scan.ranges[k].is_finite() && scan.ranges[k] < c.range2)
            .map(|k| {
                let angle = scan.heading + std::f32::consts::TAU * k as f32 / n as f32;
                (
                    scan.ranges[k],
                    scan.position + V2::from_angle(angle) * scan.ranges[k],
                )
            })
            .filter(|(_, hit)| !ours(*hit))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        let strength = if d < c.range1 {
            c.alpha * (c.range1 - d) / c.range1
        } else {
            c.beta * (c.range2 - d) / (c.range2 - c.range1)
        };
        let away = scan.position - hit;
        Some(away * (strength * self.step * 0.5 / away.length().max(1e-6)))
    }
}

fn put_down(s: &mut Carrier, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.observe(frame);
    still(command);
    command.turret_mode = Turret::Passive;
    command.gripper = GripperAction::Drop;
    s.put_issued = true;
}

fn halt(s: &mut Carrier, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.observe(frame);
    still(command);
}

impl Profile for Carrier {
    const NAME: &'static str = "transport";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("task_known", Procedure::Check(task_known)),
        ("at_face", Procedure::Check(at_face)),
        ("take", Procedure::Check(take)),
        ("path_ready", Procedure::Check(path_ready)),
        ("at_waypoint", Procedure::Check(at_waypoint)),
        ("go", Procedure::Check(go)),
        ("put", Procedure::Check(put)),
        ("stop", Procedure::Check(stop)),
        ("released", Procedure::Check(released)),
        ("approach", Procedure::Act(approach)),
        ("hold", Procedure::Act(hold)),
        ("carry", Procedure::Act(carry)),
        ("put_down", Procedure::Act(put_down)),
        ("halt", Procedure::Act(halt)),
    ];
    const TALKS: bool = true;

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        let c = Correction::default();
        let pursuit = |speed: f32| -> Result<Pursuit, ParamError> {
            Ok(Pursuit {
                lookahead: 0.01,
                max_speed: speed,
                max_turn_rate: params.positive_f32_or("max_turn_rate", 1.0)?,
                k_w: params.positive_f32_or("k_w", 2.0)?,
                k_v: 1.0,
            })
        };
        let ticks = |name: &str, default: u64| params.whole_or(name, default);
        Ok(Carrier {
            radius: params.positive_f32_or("radius", FOOTBOT_RADIUS)?,
            standoff: params.positive_f32_or("standoff", 0.35)?,
            approach: pursuit(params.positive_f32_or("approach_speed", 0.15)?)?,
            creep_speed: params.positive_f32_or("creep_speed", 0.02)?,
            carry: pursuit(params.positive_f32_or("carry_speed", 0.05)?)?,
            waypoint_tolerance: params.positive_f32_or("waypoint_tolerance", 0.02)?,
            final_tolerance: params.positive_f32_or("final_tolerance", 0.008)?,
            settle: ticks("settle", 30)?,
            timing: Timing {
                stagger: ticks("stagger", 10)?,
                repeat: ticks("repeat", 10)?.max(1),
                step_timeout: ticks("step_timeout", 150)?.max(1),
            },
            global_threshold: params.non_negative_f32_or("global_threshold", 3.0)?,
            step: params.positive_f32_or("step", 0.2)?,
            angle_step: params.positive_f32_or("angle_step", 10.0)?.to_radians(),
            bug_params: BugParams {
                clearance: params.positive_f32_or("clearance", 0.25)?,
                ..BugParams::default()
            },
            correction: Correction {
                range1: params.positive_f32_or("range1", c.range1)?,
                range2: params.positive_f32_or("range2", c.range2)?,
                alpha: params.non_negative_f32_or("alpha", c.alpha)?,
                beta: params.non_negative_f32_or("beta", c.beta)?,
                weight: c.weight,
            },
            team: None,
            object: None,
            gripped_at: None,
            phase: Approach::Travel,
            bug: Bug::new(),
            incoming: Incoming::default(),
            waypoints: Vec::new(),
            shifts: Vec::new(),
            offset: None,
            start: None,
            k: 0,
            deviated: 0,
            not_lifted: 0,
            path_requested: false,
            put_issued: false,
            outcome_sent: false,
            tick: 0,
        })
    }

    fn receive(&mut self, inbox: &Mailbox) {
        let me = inbox.owner;
        let tick = self.tick;
        for mail in inbox.messages() {
            let Ok(letter) = wire::decode(mail.payload()) else {
                continue;
            };
            match letter {
                Letter::Object(object) if mail.from == FROM_WORLD => {
                    self.team(me)
                        .set_task(usize::from(object.team), usize::from(object.lift_by));
                    self.object = Some((object, tick));
                }
                Letter::Path(chunk) if mail.from == FROM_WORLD => {
                    if chunk.plan != self.incoming.plan || chunk.first == 0 {
                        self.incoming = Incoming {
                            plan: chunk.plan,
                            total: usize::from(chunk.total).min(MAX_STEPS + 1),
                            points: Vec::new(),
                        };
                    }
                    if usize::from(chunk.first) == self.incoming.points.len() {
                        let room = self.incoming.total - self.incoming.points.len();
                        self.incoming.points.extend(chunk.points().take(room));
                    }
                }
                Letter::Signal(signal) if mail.from != FROM_WORLD => {
                    self.team(me).hear(mail.from, mail.address(), signal, tick);
                }
                _ => {}
            }
        }
    }

    fn send(&mut self, outbox: &mut Mailbox) {
        let tick = self.tick;
        let mut payload = [0u8; PAYLOAD];
        let Some(team) = self.team.as_mut() else {
            return;
        };
        for (to, signal) in team.outgoing(tick) {
            let len = wire::encode_signal(&signal, &mut payload);
            let _ = outbox.send(to, &payload[..len]);
        }
        let leads = team.coordinator() == Some(outbox.owner);
        if leads && team.path_mode() == Some(PathMode::Global) && !self.path_requested {
            let len = wire::encode_path_request(&mut payload);
            self.path_requested = outbox.send(Address::To(TO_WORLD), &payload[..len]).is_ok();
        }
        let ended = self.put_issued && self.gripped_at.is_some();
        if ended && !self.outcome_sent {
            let outcome = Outcome {
                ending: team.stopped().unwrap_or(Ending::Delivered),
                step: self.k,
            };
            let len = wire::encode_outcome(&outcome, &mut payload);
            self.outcome_sent = outbox.send(Address::To(TO_WORLD), &payload[..len]).is_ok();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_in_the_way_of_the_straight_line_does_not_count_as_an_obstacle() {
        let object = Object {
            centre: V2::new(1.0, 0.0),
            angle: 0.0,
            half: V2::new(0.3, 0.4),
            goal: V2::new(5.0, 0.0),
            goal_angle: 0.0,
            team: 2,
            lift_by: 2,
            face: 2,
            tolerance: 0.02,
            angle_tolerance: 0.05,
            plans: 0,
        };
        let mut frame = SensorFrame::empty(0);
        // The robot at the box's front face (+x), facing the goal.
        frame.position = [1.4, 0.0];
        frame.ranges_len = 24;
        for r in frame.ranges.iter_mut() {
            *r = f32::INFINITY;
        }
        // Ray 12 (behind) hits the box.
        frame.ranges[12] = 0.1;
        assert!(!blocked_towards(&frame, object));
        // A hit 1 m ahead, beyond the box, on the way to the goal.
        frame.ranges[0] = 1.0;
        assert!(blocked_towards(&frame, object));
    }
}
