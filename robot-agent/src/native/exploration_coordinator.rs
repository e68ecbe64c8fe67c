//! Native controller `exploration_coordinator`: level 2 of exploration with task allocation (paper A,
//! docs/exploration.md), run as a coordinator process. It is the central memory of every task the robots report
//! and the allocator that assigns the available robots to the open tasks with the fast genetic allocator
//! (`swarm_allocation::fga`) whenever something changed: a task was reported, a robot became available, a robot
//! failed, a task was completed.
//!
//! - **Memory.** Tasks by number, each open, allocated to a team or complete. What a robot reports is merged in:
//!   a task reported complete stays complete, and every robot is told (`Done` to all).
//! - **Liveliness.** Every robot sends its status every tick. A robot not heard from for `stale` ticks has
//!   failed: the rest of its team is told to drop the task (`Cancel`), and the task is open again.
//! - **Acknowledgement.** An assigned robot must report the task as its own within `ack` ticks; until then the
//!   assignment is sent again every `ack` ticks while the robot is available; a robot that took something else
//!   meanwhile loses the assignment and its task is opened again.
//! - **Restart.** A coordinator starts with an empty memory and asks every participant to report again
//!   (`Recall`): the robots send every task they know, complete or not, and their status says which task each
//!   one is travelling to or executing, so a restarted coordinator rebuilds what the killed one knew.
//!
//! The allocator's run time is reported to the task server (`Allocation`), for the run's summary. Parameters:
//! `population`, `generations`, `crossover`, `mutation` (FGA; defaults P 50, G 40, Pc 0.95, Pm 0.3), `w_utility`,
//! `w_distance`, `w_value` (1, 0.5, 0.2), `diagonal` (m, the workspace's diagonal for normalising distances,
//! default 14.142), `stale` (ticks, default 20), `ack` (ticks, default 5), `max_per_tick` (letters sent per
//! tick, default 8: the messages medium's default), `max_robots` and `max_tasks` (1,024 each: the highest
//! participant index and task number kept, plus one). Allocating allocates memory; it happens only on events.

use std::collections::VecDeque;
use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use swarm_allocation::fga::{self, FgaParams};
use swarm_allocation::{Kind, Problem, Robot, Task, Weights};
use swarm_contract::mail::{Address, Mailbox, TO_WORLD};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_navigation::V2;
use swarm_navigation::wire::PAYLOAD;
use swarm_navigation::wire::exploration::{
    self as wire, Allocation, Assign, Found, Letter, Status,
};

use crate::params::{ParamError, Params};

use super::NativeController;

const DEFAULT_STALE_TICKS: u64 = 20;
const DEFAULT_ACK_TICKS: u64 = 5;
const DEFAULT_CAPACITY: usize = 1024;

/// What the coordinator knows of a task.
#[derive(Debug, Clone, PartialEq)]
enum TaskState {
    Open,
    /// Assigned to these robots (participant indices).
    Allocated(Vec<u32>),
    Done,
}

#[derive(Debug, Clone)]
struct KnownTask {
    found: Found,
    state: TaskState,
}

/// An assignment sent and not yet taken up.
#[derive(Debug, Clone, Copy)]
struct Pending {
    assign: Assign,
    sent: u64,
}

#[derive(Debug, Clone)]
struct KnownRobot {
    status: Status,
    heard: u64,
    failed: bool,
    pending: Option<Pending>,
}

/// The coordinator.
#[derive(Debug)]
pub struct ExplorationCoordinator {
    fga: FgaParams,
    weights: Weights,
    diagonal: f32,
    stale: u64,
    ack: u64,
    max_per_tick: usize,
    seed: u64,
    started: bool,
    tasks: Vec<Option<KnownTask>>,
    robots: Vec<Option<KnownRobot>>,
    allocations: u32,
    /// Something changed since the last allocation.
    changed: bool,
    outgoing: VecDeque<(Address, [u8; PAYLOAD], usize)>,
}

impl ExplorationCoordinator {
    /// Registry name.
    pub const NAME: &'static str = "exploration_coordinator";

    /// Reads the parameters above.
    pub fn from_params(params: &Params) -> Result<Self, ParamError> {
        let d = FgaParams::default();
        let w = Weights::default();
        let positive_whole = |name: &str, default: usize| params.capacity_or(name, default);
        Ok(Self {
            fga: FgaParams {
                population: positive_whole("population", d.population)?.max(2),
                generations: params.whole_or("generations", d.generations)?,
                crossover: f64::from(params.unit_f32_or("crossover", d.crossover as f32)?),
                mutation: f64::from(params.unit_f32_or("mutation", d.mutation as f32)?),
            },
            weights: Weights {
                utility: f64::from(params.non_negative_f32_or("w_utility", w.utility as f32)?),
                distance: f64::from(params.non_negative_f32_or("w_distance", w.distance as f32)?),
                value: f64::from(params.non_negative_f32_or("w_value", w.value as f32)?),
            },
            diagonal: params.positive_f32_or("diagonal", 200f32.sqrt())?,
            stale: positive_whole("stale", DEFAULT_STALE_TICKS as usize)? as u64,
            ack: positive_whole("ack", DEFAULT_ACK_TICKS as usize)? as u64,
            max_per_tick: positive_whole("max_per_tick", 8)?,
            seed: params.run_seed(),
            started: false,
            tasks: vec![None; positive_whole("max_tasks", DEFAULT_CAPACITY)?],
            robots: vec![None; positive_whole("max_robots", DEFAULT_CAPACITY)?],
            allocations: 0,
            changed: false,
            outgoing: VecDeque::new(),
        })
    }

    fn queue(&mut self, to: Address, encode: impl FnOnce(&mut [u8; PAYLOAD]) -> usize) {
        let mut payload = [0u8; PAYLOAD];
        let len = encode(&mut payload);
        self.outgoing.push_back((to, payload, len));
    }

    fn task_mut(&mut self, task: u16) -> Option<&mut KnownTask> {
        self.tasks.get_mut(usize::from(task))?.as_mut()
    }

    /// A task reported by a robot: new ones are remembered, and completion is final.
    fn learn(&mut self, found: Found) {
        let Some(slot) = self.tasks.get_mut(usize::from(found.task)) else {
            return;
        };
        match slot {
            None => {
                *slot = Some(KnownTask {
                    found: Found {
                        done: false,
                        ..found
                    },
                    state: TaskState::Open,
                });
                self.changed = true;
                if found.done {
                    self.complete(found.task);
                }
            }
            Some(_) if found.done => self.complete(found.task),
            Some(_) => {}
        }
    }

    /// A task is complete: its team is free again and every participant is told.
    fn complete(&mut self, task: u16) {
        let Some(known) = self.task_mut(task) else {
            return;
        };
        if known.state == TaskState::Done {
            return;
        }
        known.state = TaskState::Done;
        known.found.done = true;
        self.changed = true;
        self.queue(Address::All, |p| wire::encode_done(task, p));
    }

    /// Drops `task`'s assignment: the rest of the team is told to drop it, and it is open again.
    fn reopen(&mut self, task: u16) {
        let Some(known) = self.task_mut(task) else {
            return;
        };
        let TaskState::Allocated(team) = std::mem::replace(&mut known.state, TaskState::Open)
        else {
            return;
        };
        for robot in team {
            if let Some(Some(r)) = self.robots.get_mut(robot as usize) {
                r.pending = None;
            }
            self.queue(Address::To(robot), |p| wire::encode_cancel(task, p));
        }
        self.changed = true;
    }

    /// A robot's status: it may be travelling to or executing a task the coordinator did not know it had (after a
    /// restart), or have taken up its assignment, or be free.
    fn heard(&mut self, robot: u32, status: Status, tick: u64) {
        let Some(slot) = self.robots.get_mut(robot as usize) else {
            return;
        };
        let was_available = slot
            .as_ref()
            .is_none_or(|r| r.failed || !r.status.mode.is_available());
        let pending = slot.as_ref().and_then(|r| r.pending);
        *slot = Some(KnownRobot {
            status,
            heard: tick,
            failed: false,
            pending,
        });
        if status.mode.is_available() && was_available {
            self.changed = true;
        }
        let Some(task) = status.task else {
            return;
        };
        if let Some(Some(r)) = self.robots.get_mut(robot as usize)
            && r.pending.is_some_and(|p| p.assign.task == task)
        {
            r.pending = None;
        }
        let Some(known) = self.task_mut(task) else {
            return;
        };
        match &mut known.state {
            TaskState::Done => self.queue(Address::To(robot), |p| wire::encode_done(task, p)),
            TaskState::Open => known.state = TaskState::Allocated(vec![robot]),
            TaskState::Allocated(team) => {
                if !team.contains(&robot) {
                    team.push(robot);
                }
            }
        }
    }

    /// Robots silent for too long have failed; assignments not taken up are sent again or dropped.
    fn check_robots(&mut self, tick: u64) {
        for index in 0..self.robots.len() {
            let Some(robot) = self.robots[index].as_mut() else {
                continue;
            };
            if robot.failed {
                continue;
            }
            let task = robot.status.task;
            if tick.saturating_sub(robot.heard) > self.stale {
                robot.failed = true;
                let pending = robot.pending.take().map(|p| p.assign.task);
                tracing::info!(robot = index, "exploration coordinator: robot failed");
                for task in task.into_iter().chain(pending) {
                    self.drop_from_team(task, index as u32);
                    self.reopen(task);
                }
                self.changed = true;
                continue;
            }
            let Some(pending) = robot.pending else {
                continue;
            };
            if tick < pending.sent + self.ack {
                continue;
            }
            if robot.status.mode.is_available() {
                robot.pending = Some(Pending {
                    sent: tick,
                    ..pending
                });
                let assign = pending.assign;
                self.queue(Address::To(index as u32), |p| {
                    wire::encode_assign(&assign, p)
                });
            } else {
                robot.pending = None;
                self.drop_from_team(pending.assign.task, index as u32);
                self.reopen(pending.assign.task);
            }
        }
    }

    fn drop_from_team(&mut self, task: u16, robot: u32) {
        if let Some(KnownTask {
            state: TaskState::Allocated(team),
            ..
        }) = self.task_mut(task)
        {
            team.retain(|&r| r != robot);
        }
    }

    /// Runs the allocator over the open tasks that still have a utility and the available robots, and sends the
    /// assignments.
    fn allocate(&mut self, tick: u64) {
        let open: Vec<Found> = self
            .tasks
            .iter()
            .flatten()
            .filter(|t| t.state == TaskState::Open && t.found.utility_at(tick) > 0.0)
            .map(|t| t.found)
            .collect();
        let free: Vec<(u32, Status)> = self
            .robots
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.as_ref().map(|r| (i as u32, r)))
            .filter(|(_, r)| !r.failed && r.pending.is_none() && r.status.mode.is_available())
            .map(|(i, r)| (i, r.status))
            .collect();
        if open.is_empty() || free.is_empty() {
            return;
        }
        let v = |p: V2| (p.x, p.y);
        let problem = Problem {
            robots: free
                .iter()
                .map(|(_, s)| Robot {
                    kind: s.kind,
                    position: v(s.position),
                    value: if s.kind == Kind::One { 1.0 } else { 2.0 },
                })
                .collect(),
            tasks: open
                .iter()
                .map(|t| Task {
                    kind: t.kind,
                    position: v(t.position),
                    utility: t.utility_at(tick),
                    window: (u64::from(t.window_end).saturating_sub(tick)).max(1) as f32,
                })
                .collect(),
            weights: self.weights,
            diagonal: self.diagonal,
        };
        self.allocations += 1;
        let mut rng = ChaCha8Rng::seed_from_u64(
            self.seed ^ u64::from(self.allocations).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        );
        let began = Instant::now();
        let result = fga::allocate(&problem, &self.fga, &mut rng);
        let micros = u32::try_from(began.elapsed().as_micros()).unwrap_or(u32::MAX);
        let report = Allocation {
            number: self.allocations,
            tasks: open.len().min(usize::from(u16::MAX)) as u16,
            robots: free.len().min(usize::from(u16::MAX)) as u16,
            micros,
        };
        self.queue(Address::To(TO_WORLD), |p| {
            wire::encode_allocation(&report, p)
        });
        for (slot, task) in result.assignment.iter().enumerate() {
            let Some(task) = *task else { continue };
            let (robot, found) = (free[slot].0, open[task]);
            let assign = Assign {
                task: found.task,
                position: found.position,
                allocation: self.allocations,
            };
            if let Some(known) = self.task_mut(found.task) {
                match &mut known.state {
                    TaskState::Allocated(team) => team.push(robot),
                    state => *state = TaskState::Allocated(vec![robot]),
                }
            }
            if let Some(Some(r)) = self.robots.get_mut(robot as usize) {
                r.pending = Some(Pending { assign, sent: tick });
            }
            self.queue(Address::To(robot), |p| wire::encode_assign(&assign, p));
        }
    }

    fn take_in(&mut self, inbox: &Mailbox) {
        // Tasks and completions first, so that a robot's status of the same tick finds them.
        for mail in inbox.messages() {
            match wire::decode(mail.payload()) {
                Ok(Letter::Found(found)) => self.learn(found),
                Ok(Letter::Done(task)) => self.complete(task),
                _ => {}
            }
        }
        for mail in inbox.messages() {
            if let Ok(Letter::Status(status)) = wire::decode(mail.payload()) {
                self.heard(mail.from, status, inbox.tick);
            }
        }
    }
}

impl NativeController for ExplorationCoordinator {
    fn step(&mut self, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        command.wheels = [0.0, 0.0];
    }

    fn step_with_mail(
        &mut self,
        frame: &SensorFrame,
        inbox: &Mailbox,
        outbox: &mut Mailbox,
        command: &mut ActuatorCommand,
    ) {
        self.step(frame, command);
        if !self.started {
            self.started = true;
            self.queue(Address::All, wire::encode_recall);
        }
        self.take_in(inbox);
        self.check_robots(frame.tick);
        if self.changed {
            self.changed = false;
            self.allocate(frame.tick);
        }
        for _ in 0..self.max_per_tick {
            let Some((to, payload, len)) = self.outgoing.front() else {
                break;
            };
            if outbox.send(*to, &payload[..*len]).is_err() {
                break;
            }
            self.outgoing.pop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use swarm_contract::mail::Mail;
    use swarm_navigation::wire::exploration::Mode;

    use super::*;

    const ME: u32 = 9;

    fn found(task: u16, kind: Kind, x: f32) -> Found {
        Found {
            task,
            position: V2::new(x, 1.0),
            kind,
            value: 50.0,
            window_end: 1000,
            decay: 100,
            done: false,
        }
    }

    fn status(kind: Kind, mode: Mode, task: Option<u16>, x: f32) -> Status {
        Status {
            kind,
            mode,
            task,
            position: V2::new(x, 0.0),
            to_tasks: 0.0,
        }
    }

    fn free(kind: Kind, x: f32) -> Status {
        status(kind, Mode::Explore, None, x)
    }

    /// One step at `tick` with the letters `(from, payload)`; returns what was sent, decoded, with addresses.
    fn step(
        c: &mut ExplorationCoordinator,
        tick: u64,
        letters: &[(u32, Vec<u8>)],
    ) -> Vec<(Address, Letter<'static>)> {
        let mut inbox = Mailbox::empty(ME);
        inbox.tick = tick;
        for (from, payload) in letters {
            inbox
                .push(Mail::new(*from, Address::To(ME), payload).unwrap())
                .unwrap();
        }
        let mut frame = SensorFrame::empty(ME);
        frame.tick = tick;
        let mut outbox = Mailbox::empty(ME);
        c.step_with_mail(
            &frame,
            &inbox,
            &mut outbox,
            &mut ActuatorCommand::idle(ME, tick),
        );
        outbox
            .messages()
            .iter()
            .filter_map(|m| {
                let payload: &'static [u8] = Box::leak(m.payload().to_vec().into_boxed_slice());
                wire::decode(payload).ok().map(|l| (m.address(), l))
            })
            .collect()
    }

    fn encoded(encode: impl FnOnce(&mut [u8; PAYLOAD]) -> usize) -> Vec<u8> {
        let mut p = [0u8; PAYLOAD];
        let len = encode(&mut p);
        p[..len].to_vec()
    }

    fn st(s: Status) -> Vec<u8> {
        encoded(|p| wire::encode_status(&s, p))
    }

    fn fd(f: Found) -> Vec<u8> {
        encoded(|p| wire::encode_found(&f, p))
    }

    fn assignments(sent: &[(Address, Letter<'_>)]) -> Vec<(u32, u16)> {
        sent.iter()
            .filter_map(|(to, l)| match (to, l) {
                (Address::To(r), Letter::Assign(a)) => Some((*r, a.task)),
                _ => None,
            })
            .collect()
    }

    fn coordinator() -> ExplorationCoordinator {
        ExplorationCoordinator::from_params(&Params::default()).unwrap()
    }

    #[test]
    fn it_recalls_first_then_assigns_a_reported_task_to_the_near_free_robot() {
        let mut c = coordinator();
        let first = step(&mut c, 0, &[]);
        assert!(matches!(first[..], [(Address::All, Letter::Recall)]));
        let sent = step(
            &mut c,
            1,
            &[
                (0, st(free(Kind::One, 0.0))),
                (1, st(free(Kind::One, 8.0))),
                (0, fd(found(0, Kind::One, 0.5))),
            ],
        );
        assert_eq!(assignments(&sent), vec![(0, 0)]);
        assert!(sent.iter().any(|(to, l)| *to == Address::To(TO_WORLD)
            && matches!(l, Letter::Allocation(a) if a.tasks == 1 && a.robots == 2)));
        // Not taken up within `ack` ticks: sent again; taken up: nothing more.
        let again = step(
            &mut c,
            1 + DEFAULT_ACK_TICKS,
            &[(0, st(free(Kind::One, 0.0)))],
        );
        assert_eq!(assignments(&again), vec![(0, 0)]);
        let taken = step(
            &mut c,
            2 + 2 * DEFAULT_ACK_TICKS,
            &[(0, st(status(Kind::One, Mode::Travel, Some(0), 0.1)))],
        );
        assert!(assignments(&taken).is_empty());
    }

    #[test]
    fn a_silent_robot_fails_its_teammate_is_cancelled_and_the_task_goes_to_others() {
        let mut c = coordinator();
        step(&mut c, 0, &[]);
        // A type-2 task, two type-1 robots free: both go.
        let sent = step(
            &mut c,
            1,
            &[
                (0, st(free(Kind::One, 0.0))),
                (1, st(free(Kind::One, 1.0))),
                (0, fd(found(0, Kind::Two, 0.5))),
            ],
        );
        let mut team = assignments(&sent);
        team.sort();
        assert_eq!(team, vec![(0, 0), (1, 0)]);
        step(
            &mut c,
            2,
            &[
                (0, st(status(Kind::One, Mode::Travel, Some(0), 0.1))),
                (1, st(status(Kind::One, Mode::Travel, Some(0), 0.9))),
                (2, st(free(Kind::Two, 5.0))),
            ],
        );
        // Robot 0 falls silent; robots 1 and 2 keep reporting.
        let mut cancelled = false;
        let mut reassigned = Vec::new();
        for tick in 3..3 + DEFAULT_STALE_TICKS + 3 {
            let sent = step(
                &mut c,
                tick,
                &[
                    (1, st(status(Kind::One, Mode::Travel, Some(0), 0.9))),
                    (2, st(free(Kind::Two, 5.0))),
                ],
            );
            cancelled |= sent
                .iter()
                .any(|(to, l)| *to == Address::To(1) && *l == Letter::Cancel(0));
            reassigned.extend(assignments(&sent));
        }
        assert!(cancelled, "the surviving teammate is told to drop the task");
        assert!(
            reassigned.contains(&(2, 0)),
            "the free type-2 robot takes the task: {reassigned:?}"
        );
    }

    #[test]
    fn a_fresh_coordinator_rebuilds_its_memory_from_what_robots_report() {
        let mut c = coordinator();
        step(&mut c, 0, &[]);
        let done = Found {
            done: true,
            ..found(1, Kind::One, 3.0)
        };
        // Robot 0 travels to task 0; robot 1 reports task 1 as complete and task 2 as open; robot 2 is free.
        let sent = step(
            &mut c,
            1,
            &[
                (0, fd(found(0, Kind::One, 0.5))),
                (0, st(status(Kind::One, Mode::Travel, Some(0), 0.2))),
                (1, fd(done)),
                (1, fd(found(2, Kind::One, 6.0))),
                (1, st(free(Kind::One, 5.0))),
                (2, st(free(Kind::Two, 9.0))),
            ],
        );
        assert!(
            sent.iter()
                .any(|(to, l)| *to == Address::All && *l == Letter::Done(1))
        );
        let assigned = assignments(&sent);
        assert!(
            !assigned.iter().any(|&(_, t)| t == 0 || t == 1),
            "{assigned:?}"
        );
        assert!(assigned.iter().any(|&(_, t)| t == 2), "{assigned:?}");
        // A robot travelling to a task the coordinator knows is complete is told so.
        let told = step(
            &mut c,
            2,
            &[(2, st(status(Kind::Two, Mode::Travel, Some(1), 9.0)))],
        );
        assert!(
            told.iter()
                .any(|(to, l)| *to == Address::To(2) && *l == Letter::Done(1))
        );
    }

    #[test]
    fn capacities_are_bounded() {
        let params = Params::new([("max_robots", "1000000000000")]);
        let err = ExplorationCoordinator::from_params(&params).unwrap_err();
        assert!(
            err.to_string().contains("must be from 1 to 1048576"),
            "{err}"
        );
    }

    #[test]
    fn garbage_and_out_of_range_numbers_are_ignored() {
        let mut c = coordinator();
        step(&mut c, 0, &[]);
        let sent = step(
            &mut c,
            1,
            &[
                (0, vec![17, 1, 2]),
                (0, vec![]),
                (5000, st(free(Kind::One, 0.0))),
                (0, fd(found(2000, Kind::One, 0.0))),
            ],
        );
        assert!(sent.is_empty(), "{sent:?}");
    }
}
