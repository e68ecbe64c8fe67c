//! Profile `exploration`: level 1 of exploration with task allocation (paper A, docs/exploration.md), one robot,
//! for the models in `configs/exploration/models`. The supervisor decides the robot's mode (explore, take up an
//! assignment, travel to the task, execute it); Multi-SRT exploration and TangentBug of
//! `swarm_navigation::planning` are the actions of `explore` and `travel`.
//!
//! | event | kind | procedure |
//! |---|---|---|
//! | `assigned` | u | the coordinator assigned the robot, which is free, to a task not known to be complete |
//! | `at_task` | u | the robot's centre is within the task server's reach of its task |
//! | `task_done` | u | its task is complete (the task server or the coordinator said so) |
//! | `cancelled` | u | the coordinator cancelled its task (a teammate failed) |
//! | `take_task` | c | the assignment becomes the robot's task (mode 1); holds still |
//! | `travel` | c | one TangentBug step towards the task |
//! | `execute` | c | holds still at the task (mode 2) until the task server judges it complete |
//! | `explore` | c | one step of Multi-SRT; a robot back from a task starts a new tree where it stands (mode 3) |
//!
//! **Messages.** From the task server: `Setup` (type, tick rate, reach, sensor range; nothing moves before it),
//! `Found` for each task the robot senses, `Done` when its task is complete. From the coordinator: `Recall`,
//! `Assign`, `Cancel`, `Done`. From other robots: `Region`, the local safe regions of their trees. The robot
//! sends its `Status` to the coordinator every tick (its heartbeat) and to the task server on every change of
//! mode and every second; every task it learns of, and every completion, to the coordinator (all of them again
//! on a `Recall`); and each new node's region to every participant.
//!
//! Parameters: `memory` (s an explored region is remembered, default 10), `alpha` (0.8), `d_min` (m, 0.3),
//! `attempts` (30), `clearance` (m kept from what the rays hit, default 0.2), `max_speed` (m/s, default 0.15;
//! the body's own limit applies too), `max_turn_rate` (rad/s, 2), `k_w` (3), `arrive` (m: an SRT node is
//! reached this close, default 0.05), `max_regions` (regions of other robots kept, default 4,096), `max_tasks`
//! (tasks remembered, default 1,024), `max_per_tick` (letters sent per tick, default 8).

use std::collections::VecDeque;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_contract::mail::{Address, FROM_WORLD, Mailbox, TO_WORLD};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_navigation::V2;
use swarm_navigation::planning::follow::{Pursuit, pursue};
use swarm_navigation::planning::srt::{Lsr, Move, Srt, SrtParams};
use swarm_navigation::planning::tangent_bug::{Bug, BugParams, Scan};
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::exploration::{
    self as wire, Assign, Found, Letter, Mode, Setup, Status,
};

use crate::params::{ParamError, Params};
use crate::profile::{Procedure, Profile};

const DEFAULT_MAX_REGIONS: usize = 4096;
const DEFAULT_MAX_TASKS: usize = 1024;
/// Slowest progress (m/s) before an exploration move is given up (another robot in the way).
const GIVE_UP_SPEED: f32 = 0.03;
/// How far ahead of the robot a TangentBug direction is pursued (m).
const BUG_AIM: f32 = 0.5;
/// Half-angle of the cone ahead in which a hit closer than the clearance stops an exploration move (rad).
const AHEAD: f32 = std::f32::consts::FRAC_PI_4;

/// The exploration move under way.
#[derive(Debug, Clone, Copy)]
struct Heading {
    to: V2,
    back: bool,
    deadline: u64,
}

/// Profile `exploration`: one robot's tree, task memory and assignment.
#[derive(Debug)]
pub struct Explorer {
    srt_params: SrtParams,
    memory_seconds: f32,
    bug_params: BugParams,
    pursuit: Pursuit,
    arrive: f32,
    max_per_tick: usize,
    run_seed: u64,
    rng: Option<ChaCha8Rng>,
    setup: Option<Setup>,
    coordinator: Option<u32>,
    known: Vec<Found>,
    others: Vec<Lsr>,
    srt: Srt,
    heading: Option<Heading>,
    bug: Bug,
    offered: Option<Assign>,
    taken: u32,
    current: Option<Assign>,
    done: bool,
    cancelled: bool,
    mode: Mode,
    to_tasks: f32,
    last_position: Option<V2>,
    tick: u64,
    position: V2,
    to_coordinator: VecDeque<Letter<'static>>,
    /// The newest node's region, to share.
    region: Option<Lsr>,
    world_status_due: bool,
    world_status_sent: Option<u64>,
}

impl Explorer {
    fn position(frame: &SensorFrame) -> V2 {
        V2::new(frame.position[0], frame.position[1])
    }

    fn scan<'a>(&self, frame: &'a SensorFrame) -> Option<Scan<'a>> {
        self.setup.map(|s| Scan {
            position: Self::position(frame),
            heading: frame.heading,
            ranges: frame.range_readings(),
            range: s.sensor_range,
        })
    }

    fn knows_done(&self, task: u16) -> bool {
        self.known.iter().any(|f| f.task == task && f.done)
    }

    /// A task learnt of (sensed, or reported complete): remembered, and passed on to the coordinator when new.
    fn learn(&mut self, found: Found) {
        let room = self.known.len() < self.known.capacity();
        match self.known.iter_mut().find(|f| f.task == found.task) {
            Some(known) if found.done && !known.done => {
                known.done = true;
                self.to_coordinator.push_back(Letter::Done(found.task));
            }
            Some(_) => {}
            None if room => {
                self.known.push(found);
                self.to_coordinator.push_back(Letter::Found(found));
            }
            None => {}
        }
    }

    fn complete(&mut self, task: u16) {
        if let Some(known) = self.known.iter_mut().find(|f| f.task == task) {
            known.done = true;
        }
        if self.current.is_some_and(|a| a.task == task) {
            self.done = true;
        }
        if self.offered.is_some_and(|a| a.task == task) {
            self.offered = None;
        }
    }

    fn set_mode(&mut self, mode: Mode) {
        if self.mode != mode {
            self.mode = mode;
            self.world_status_due = true;
        }
    }

    /// Keeps track of the distance driven to tasks; called by every action.
    fn moved(&mut self, frame: &SensorFrame) {
        let here = Self::position(frame);
        if self.mode == Mode::Travel
            && let Some(last) = self.last_position
        {
            self.to_tasks += (here - last).length();
        }
        self.last_position = Some(here);
        self.tick = frame.tick;
        self.position = here;
    }

    fn status(&self) -> Option<Status> {
        let setup = self.setup?;
        Some(Status {
            kind: setup.kind,
            mode: self.mode,
            task: self
                .current
                .filter(|_| matches!(self.mode, Mode::Travel | Mode::Execute))
                .map(|a| a.task),
            position: self.position,
            to_tasks: self.to_tasks,
        })
    }

    /// Adds a node where the robot stands and shares its region.
    fn add_node(&mut self, frame: &SensorFrame, range: f32) {
        let lsr = Lsr::new(
            Self::position(frame),
            frame.heading,
            frame.range_readings(),
            range,
            frame.tick,
        );
        self.region = Some(lsr);
        self.srt.arrive(lsr);
    }

    /// Forgets the other robots' regions older than the memory.
    fn forget(&mut self, now: u64) {
        let memory = self.srt_params.memory;
        self.others.retain(|l| now.saturating_sub(l.time) <= memory);
    }

    /// Twist towards `to`, held back when something is closer than the clearance ahead.
    fn drive_to(&self, frame: &SensorFrame, to: V2, command: &mut ActuatorCommand) {
        let mut progress = 0;
        let twist = pursue(
            &self.pursuit,
            &[to],
            &mut progress,
            Self::position(frame),
            frame.heading,
        );
        let n = frame.range_readings().len();
        let blocked = frame.range_readings().iter().enumerate().any(|(k, &r)| {
            let angle = swarm_navigation::vec2::wrap(std::f32::consts::TAU * k as f32 / n as f32);
            angle.abs() < AHEAD && r < self.bug_params.clearance
        });
        command.set_twist(if blocked { 0.0 } else { twist.v }, twist.w);
    }
}

fn hold(command: &mut ActuatorCommand) {
    command.set_twist(0.0, 0.0);
}

fn assigned(s: &Explorer, _: &SensorFrame) -> bool {
    s.mode.is_available()
        && s.offered
            .is_some_and(|a| a.allocation > s.taken && !s.knows_done(a.task))
}

fn at_task(s: &Explorer, frame: &SensorFrame) -> bool {
    match (s.current, s.setup) {
        (Some(task), Some(setup)) => {
            (task.position - Explorer::position(frame)).length() < setup.reach
        }
        _ => false,
    }
}

fn task_done(s: &Explorer, _: &SensorFrame) -> bool {
    s.current.is_some() && s.done
}

fn cancelled(s: &Explorer, _: &SensorFrame) -> bool {
    s.current.is_some() && s.cancelled
}

fn take_task(s: &mut Explorer, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.moved(frame);
    if let Some(offer) = s.offered.take() {
        s.taken = offer.allocation;
        s.current = Some(offer);
        s.done = false;
        s.cancelled = false;
        s.bug = Bug::new();
        s.heading = None;
        s.set_mode(Mode::Travel);
    }
    hold(command);
}

fn travel(s: &mut Explorer, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.moved(frame);
    let (Some(task), Some(scan)) = (s.current, s.scan(frame)) else {
        return hold(command);
    };
    let direction = s.bug.step(&s.bug_params, &scan, task.position);
    if direction == V2::ZERO {
        return hold(command);
    }
    let mut progress = 0;
    let aim = scan.position + direction * BUG_AIM;
    let twist = pursue(
        &s.pursuit,
        &[aim],
        &mut progress,
        scan.position,
        frame.heading,
    );
    command.set_twist(twist.v, twist.w);
}

fn execute(s: &mut Explorer, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.moved(frame);
    s.set_mode(Mode::Execute);
    hold(command);
}

fn explore(s: &mut Explorer, frame: &SensorFrame, command: &mut ActuatorCommand) {
    s.moved(frame);
    let Some(setup) = s.setup else {
        return hold(command);
    };
    if s.current.take().is_some() {
        // Back from a task: the old tree is far behind; explore afresh from here.
        s.set_mode(if s.done {
            Mode::Finished
        } else {
            Mode::Explore
        });
        s.done = false;
        s.cancelled = false;
        s.srt = Srt::default();
        s.heading = None;
    }
    s.forget(frame.tick);
    let here = Explorer::position(frame);
    if s.srt.regions().next().is_none() {
        s.add_node(frame, setup.sensor_range);
    }
    if let Some(h) = s.heading {
        let arrived = (h.to - here).length() < s.arrive;
        if arrived && h.back {
            s.srt.back();
        } else if arrived {
            s.add_node(frame, setup.sensor_range);
        } else if frame.tick > h.deadline {
            // Someone stands in the way: start a new tree here rather than push.
            s.srt = Srt::default();
            s.add_node(frame, setup.sensor_range);
        } else {
            return s.drive_to(frame, h.to, command);
        }
        s.heading = None;
    }
    let robot = frame.robot;
    let seed = s.run_seed ^ u64::from(robot).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let rng = s.rng.get_or_insert_with(|| ChaCha8Rng::seed_from_u64(seed));
    let (to, back) = match s.srt.step(&s.srt_params, frame.tick, s.others.iter(), rng) {
        Move::Forward(to) => (to, false),
        Move::Back(to) => (to, true),
        Move::Done => {
            // Everything around is remembered as explored: a new root here, tried again next tick.
            s.srt = Srt::default();
            s.add_node(frame, setup.sensor_range);
            return hold(command);
        }
    };
    let ticks = setup.ticks_per_second as f32 * (1.0 + (to - here).length() / GIVE_UP_SPEED);
    s.heading = Some(Heading {
        to,
        back,
        deadline: frame.tick + ticks as u64,
    });
    s.drive_to(frame, to, command);
}

impl Profile for Explorer {
    const NAME: &'static str = "exploration";
    const PROCEDURES: &'static [(&'static str, Procedure<Self>)] = &[
        ("assigned", Procedure::Check(assigned)),
        ("at_task", Procedure::Check(at_task)),
        ("task_done", Procedure::Check(task_done)),
        ("cancelled", Procedure::Check(cancelled)),
        ("take_task", Procedure::Act(take_task)),
        ("travel", Procedure::Act(travel)),
        ("execute", Procedure::Act(execute)),
        ("explore", Procedure::Act(explore)),
    ];
    const TALKS: bool = true;

    fn from_params(params: &Params) -> Result<Self, ParamError> {
        let d = SrtParams::default();
        let b = BugParams::default();
        let p = Pursuit::default();
        let clearance = params.positive_f32_or("clearance", b.clearance)?;
        // Task numbers are 16 bits: more could never be told apart.
        let max_tasks = params
            .capacity_or("max_tasks", DEFAULT_MAX_TASKS)?
            .min(wire::MAX_TASKS);
        Ok(Explorer {
            srt_params: SrtParams {
                alpha: params.unit_f32_or("alpha", d.alpha)?,
                d_min: params.non_negative_f32_or("d_min", d.d_min)?,
                attempts: params.whole_or("attempts", d.attempts)?,
                memory: 0,
            },
            memory_seconds: params.non_negative_f32_or("memory", 10.0)?,
            bug_params: BugParams { clearance, ..b },
            pursuit: Pursuit {
                lookahead: p.lookahead,
                max_speed: params.positive_f32_or("max_speed", 0.15)?,
                max_turn_rate: params.positive_f32_or("max_turn_rate", p.max_turn_rate)?,
                k_w: params.positive_f32_or("k_w", p.k_w)?,
                k_v: p.k_v,
            },
            arrive: params.positive_f32_or("arrive", 0.05)?,
            max_per_tick: params.whole_or("max_per_tick", 8usize)?.max(2),
            run_seed: params.run_seed(),
            rng: None,
            setup: None,
            coordinator: None,
            known: Vec::with_capacity(max_tasks),
            others: Vec::with_capacity(params.capacity_or("max_regions", DEFAULT_MAX_REGIONS)?),
            srt: Srt::default(),
            heading: None,
            bug: Bug::new(),
            offered: None,
            taken: 0,
            current: None,
            done: false,
            cancelled: false,
            mode: Mode::Explore,
            to_tasks: 0.0,
            last_position: None,
            tick: 0,
            position: V2::ZERO,
            to_coordinator: VecDeque::with_capacity(max_tasks + 16),
            region: None,
            world_status_due: true,
            world_status_sent: None,
        })
    }

    fn receive(&mut self, inbox: &Mailbox) {
        for mail in inbox.messages() {
            let Ok(letter) = wire::decode(mail.payload()) else {
                continue;
            };
            let from_coordinator = self.coordinator == Some(mail.from);
            match letter {
                Letter::Setup(setup) if mail.from == FROM_WORLD => {
                    self.srt_params.memory =
                        (self.memory_seconds * setup.ticks_per_second as f32).round() as u64;
                    self.setup = Some(setup);
                }
                Letter::Found(found) if mail.from == FROM_WORLD => self.learn(found),
                Letter::Done(task) if mail.from == FROM_WORLD || from_coordinator => {
                    if let Some(known) = self.known.iter().find(|f| f.task == task).copied() {
                        self.learn(Found {
                            done: true,
                            ..known
                        });
                    }
                    self.complete(task);
                }
                Letter::Recall if mail.from != FROM_WORLD => {
                    self.coordinator = Some(mail.from);
                    self.to_coordinator.clear();
                    self.to_coordinator
                        .extend(self.known.iter().map(|&f| Letter::Found(f)));
                }
                Letter::Assign(assign) if mail.from != FROM_WORLD => {
                    self.coordinator = Some(mail.from);
                    if assign.allocation > self.taken {
                        self.offered = Some(assign);
                    }
                }
                Letter::Cancel(task) if from_coordinator => {
                    if self.current.is_some_and(|a| a.task == task) {
                        self.cancelled = true;
                    }
                    if self.offered.is_some_and(|a| a.task == task) {
                        self.offered = None;
                    }
                }
                Letter::Region(region) if mail.from != FROM_WORLD => {
                    let lsr = Lsr::from_rays(
                        region.centre,
                        region.heading,
                        region.rays(),
                        u64::from(region.tick),
                    );
                    if self.others.len() < self.others.capacity() && !lsr.rays().is_empty() {
                        self.others.push(lsr);
                    }
                }
                _ => {}
            }
        }
    }

    fn send(&mut self, outbox: &mut Mailbox) {
        let Some(status) = self.status() else {
            return;
        };
        let mut payload = [0u8; PAYLOAD];
        let mut budget = self.max_per_tick;
        let mut post = |to: Address, len: usize, payload: &[u8; PAYLOAD], budget: &mut usize| {
            let sent = *budget > 0 && outbox.send(to, &payload[..len]).is_ok();
            *budget -= usize::from(sent);
            sent
        };
        let ticks_per_second = self.setup.map_or(1, |s| u64::from(s.ticks_per_second));
        let world_due = self.world_status_due
            || self
                .world_status_sent
                .is_none_or(|sent| self.tick >= sent + ticks_per_second);
        // The same status goes to the world and to the coordinator: encoded once.
        let mut status_payload = [0u8; PAYLOAD];
        let status_len = wire::encode_status(&status, &mut status_payload);
        if world_due
            && post(
                Address::To(TO_WORLD),
                status_len,
                &status_payload,
                &mut budget,
            )
        {
            self.world_status_due = false;
            self.world_status_sent = Some(self.tick);
        }
        if let Some(lsr) = &self.region {
            let tick = lsr.time.min(u64::from(u32::MAX)) as u32;
            let len = wire::encode_region(tick, lsr.centre, lsr.heading, lsr.rays(), &mut payload);
            if post(Address::All, len, &payload, &mut budget) {
                self.region = None;
            }
        }
        let Some(coordinator) = self.coordinator else {
            return;
        };
        let to = Address::To(coordinator);
        post(to, status_len, &status_payload, &mut budget);
        while let Some(letter) = self.to_coordinator.front() {
            let len = match letter {
                Letter::Found(found) => wire::encode_found(found, &mut payload),
                Letter::Done(task) => wire::encode_done(*task, &mut payload),
                _ => 0,
            };
            if len > 0 && !post(to, len, &payload, &mut budget) {
                break;
            }
            self.to_coordinator.pop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use swarm_allocation::Kind;
    use swarm_contract::mail::Mail;

    use super::*;

    const ME: u32 = 1;
    const COORDINATOR: u32 = 5;

    fn inbox(letters: &[(u32, Vec<u8>)]) -> Mailbox {
        let mut inbox = Mailbox::empty(ME);
        for (from, payload) in letters {
            inbox
                .push(Mail::new(*from, Address::To(ME), payload).unwrap())
                .unwrap();
        }
        inbox
    }

    fn encoded(encode: impl FnOnce(&mut [u8; PAYLOAD]) -> usize) -> Vec<u8> {
        let mut p = [0u8; PAYLOAD];
        let len = encode(&mut p);
        p[..len].to_vec()
    }

    fn setup() -> Vec<u8> {
        let setup = Setup {
            kind: Kind::One,
            ticks_per_second: 10,
            reach: 0.3,
            sensor_range: 1.0,
        };
        encoded(|p| wire::encode_setup(&setup, p))
    }

    fn found(task: u16) -> Found {
        Found {
            task,
            position: V2::new(2.0, 0.0),
            kind: Kind::One,
            value: 10.0,
            window_end: 100,
            decay: 10,
            done: false,
        }
    }

    /// What the robot sends this tick, decoded, with addresses.
    fn sent(robot: &mut Explorer) -> Vec<(Address, Vec<u8>)> {
        let mut outbox = Mailbox::empty(ME);
        robot.send(&mut outbox);
        outbox
            .messages()
            .iter()
            .map(|m| (m.address(), m.payload().to_vec()))
            .collect()
    }

    fn founds(sent: &[(Address, Vec<u8>)]) -> Vec<u16> {
        sent.iter()
            .filter_map(|(to, p)| match wire::decode(p) {
                Ok(Letter::Found(f)) if *to == Address::To(COORDINATOR) => Some(f.task),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn tasks_go_to_the_coordinator_once_and_all_again_on_a_recall() {
        let mut robot = Explorer::from_params(&Params::default()).unwrap();
        let (t0, t1) = (found(0), found(1));
        robot.receive(&inbox(&[
            (FROM_WORLD, setup()),
            (COORDINATOR, encoded(wire::encode_recall)),
            (FROM_WORLD, encoded(|p| wire::encode_found(&t0, p))),
            (FROM_WORLD, encoded(|p| wire::encode_found(&t1, p))),
        ]));
        let first = sent(&mut robot);
        assert_eq!(founds(&first), vec![0, 1]);
        // The heartbeat goes to the coordinator and the status to the world.
        assert!(first.iter().any(|(to, _)| *to == Address::To(TO_WORLD)));
        robot.receive(&inbox(&[(
            FROM_WORLD,
            encoded(|p| wire::encode_found(&t0, p)),
        )]));
        assert!(
            founds(&sent(&mut robot)).is_empty(),
            "a task is reported once"
        );
        robot.receive(&inbox(&[(COORDINATOR, encoded(wire::encode_recall))]));
        assert_eq!(founds(&sent(&mut robot)), vec![0, 1]);
    }

    #[test]
    fn an_assignment_is_taken_once_and_dropped_when_cancelled_or_known_done() {
        let mut robot = Explorer::from_params(&Params::default()).unwrap();
        let frame = SensorFrame::empty(ME);
        let assign = |task: u16, allocation: u32| {
            let a = Assign {
                task,
                position: V2::new(2.0, 0.0),
                allocation,
            };
            encoded(|p| wire::encode_assign(&a, p))
        };
        robot.receive(&inbox(&[
            (FROM_WORLD, setup()),
            (COORDINATOR, assign(0, 1)),
        ]));
        assert!(assigned(&robot, &frame));
        take_task(&mut robot, &frame, &mut ActuatorCommand::idle(ME, 0));
        assert!(!assigned(&robot, &frame) && !at_task(&robot, &frame));
        // The same letter again (a resend) is no new assignment.
        robot.receive(&inbox(&[(COORDINATOR, assign(0, 1))]));
        assert!(!assigned(&robot, &frame));
        // A cancel from someone else than the coordinator is ignored; from the coordinator it counts.
        robot.receive(&inbox(&[(3, encoded(|p| wire::encode_cancel(0, p)))]));
        assert!(!cancelled(&robot, &frame));
        robot.receive(&inbox(&[(
            COORDINATOR,
            encoded(|p| wire::encode_cancel(0, p)),
        )]));
        assert!(cancelled(&robot, &frame));
        // An offer of a task known to be complete is no assignment.
        let mut robot = Explorer::from_params(&Params::default()).unwrap();
        let done = Found {
            done: true,
            ..found(4)
        };
        robot.receive(&inbox(&[
            (FROM_WORLD, setup()),
            (FROM_WORLD, encoded(|p| wire::encode_found(&done, p))),
            (COORDINATOR, assign(4, 2)),
        ]));
        assert!(!assigned(&robot, &frame));
    }
}
