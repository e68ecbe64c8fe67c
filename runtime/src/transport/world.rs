//! The world's side of the lockstep: creates every service of the run with explicit limits, publishes each
//! tick's frames, wakes the agents, waits on one counter and reads each robot's command from its own service.
//!
//! It must never let a dead or frozen robot block a tick (death notices and the tick deadline), never accept a
//! command into a slot other than its robot's, and never let arrival order change what it reads.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::ipc;
use iceoryx2::sample::Sample;

use super::TransportError;
use super::run::RunSpec;
use super::services::{self, CommandService, FrameService};
use super::sync_block::{MAX_ROBOTS, SyncBlock};
use crate::messages::{ActuatorCommand, SensorFrame};

/// Default time the world waits for the commands of one tick (see [`LinkConfig::tick_deadline`]).
pub const DEFAULT_TICK_DEADLINE: Duration = Duration::from_millis(500);
/// Default time the world spins before it blocks on the answer counter (see [`LinkConfig::spin`]).
pub const DEFAULT_SPIN: Duration = Duration::from_micros(20);
/// Default number of ticks between two dead-node cleanups (see [`LinkConfig::cleanup_interval`]).
pub const DEFAULT_CLEANUP_INTERVAL: u64 = 1000;

/// Limits and timing of a run's local transport.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinkConfig {
    /// Number of robots (agents) of the run; every service is created for exactly this many.
    pub robots: u32,
    /// How long one tick waits for missing commands before it goes on without them (default 500 ms: far above
    /// a healthy tick, which takes microseconds to a few milliseconds, so only a frozen agent ever hits it).
    pub tick_deadline: Duration,
    /// How long the world busy-waits for answers before it sleeps on the counter (default 20 us). Spinning
    /// saves a wake-up when agents answer fast; longer spins steal the CPU the agents need on small machines.
    pub spin: Duration,
    /// Ticks between two removals of dead nodes' iceoryx2 resources (default 1000); a death notice triggers
    /// one at the next tick as well.
    pub cleanup_interval: u64,
}

impl LinkConfig {
    /// The default configuration for `robots` robots.
    pub fn new(robots: u32) -> LinkConfig {
        LinkConfig {
            robots,
            tick_deadline: DEFAULT_TICK_DEADLINE,
            spin: DEFAULT_SPIN,
            cleanup_interval: DEFAULT_CLEANUP_INTERVAL,
        }
    }
}

/// What the world got from one robot in the last tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandStatus {
    /// The robot's agent answered this tick.
    Answered,
    /// The agent did not answer before the deadline.
    Missing,
    /// The robot has a death notice (and no command this tick).
    Dead,
}

/// Summary of one tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TickOutcome {
    /// The tick.
    pub tick: u64,
    /// Robots whose command arrived.
    pub answered: u32,
    /// Robots that missed the deadline.
    pub missing: u32,
    /// Robots with a death notice.
    pub dead: u32,
}

/// A handle that delivers death notices to the world from any thread (for the launcher, which learns of a death
/// from the OS). Cheap to clone.
#[derive(Clone)]
pub struct DeathNotices {
    sync: Arc<SyncBlock>,
    notices: Arc<AtomicU64>,
}

impl DeathNotices {
    /// `robot` is dead: the current tick stops waiting for it at once and later ticks do not wait for it until
    /// a replacement agent joins.
    pub fn mark_dead(&self, robot: u32) -> Result<(), TransportError> {
        let capacity = self.sync.capacity();
        if robot >= capacity {
            return Err(TransportError::RobotOutOfRange { robot, capacity });
        }
        self.sync.mark_dead(robot);
        self.notices.fetch_add(1, Ordering::Release);
        Ok(())
    }
}

/// The world's end of a run's local transport.
pub struct WorldLink {
    config: LinkConfig,
    tick: u64,
    frame_publisher: Publisher<ipc::Service, [SensorFrame], ()>,
    command_subscribers: Vec<Subscriber<ipc::Service, ActuatorCommand, ()>>,
    commands: Vec<Option<Sample<ipc::Service, ActuatorCommand, ()>>>,
    status: Vec<CommandStatus>,
    deaths: DeathNotices,
    notices_handled: u64,
    last_cleanup: u64,
    _command_services: Vec<CommandService>,
    _frame_service: FrameService,
    node: Node<ipc::Service>,
}

impl WorldLink {
    /// Creates every service and the sync block of `run` for `config.robots` robots. Agents can join afterwards.
    pub fn create(run: &RunSpec, config: LinkConfig) -> Result<WorldLink, TransportError> {
        let robots = config.robots;
        if robots == 0 || robots > MAX_ROBOTS {
            return Err(TransportError::RobotCount {
                robots,
                max: MAX_ROBOTS,
            });
        }
        let node = services::node(run, "world")?;
        let frame_service = services::create_frame_service(&node, robots)?;
        let frame_publisher = frame_service
            .publisher_builder()
            .initial_max_slice_len(robots as usize)
            .max_loaned_samples(1)
            .create()
            .map_err(|e| TransportError::iceoryx("creating the frame publisher", e))?;
        let mut command_services = Vec::with_capacity(robots as usize);
        let mut command_subscribers = Vec::with_capacity(robots as usize);
        for robot in 0..robots {
            let service = services::create_command_service(&node, robot)?;
            let subscriber = service.subscriber_builder().create().map_err(|e| {
                TransportError::iceoryx(format!("subscribing to robot {robot}'s commands"), e)
            })?;
            command_services.push(service);
            command_subscribers.push(subscriber);
        }
        // Last, so that a failure above leaves no sync block behind (iceoryx2 removes its own resources on drop).
        let sync = Arc::new(SyncBlock::create(&run.sync_block_path(), robots)?);
        tracing::debug!(run = run.name(), robots, "world link created");
        Ok(WorldLink {
            tick: 0,
            commands: (0..robots).map(|_| None).collect(),
            status: vec![CommandStatus::Missing; robots as usize],
            deaths: DeathNotices {
                sync,
                notices: Arc::new(AtomicU64::new(0)),
            },
            notices_handled: 0,
            last_cleanup: 0,
            frame_publisher,
            command_subscribers,
            _command_services: command_services,
            _frame_service: frame_service,
            node,
            config,
        })
    }

    /// The configuration the link was created with.
    pub fn config(&self) -> &LinkConfig {
        &self.config
    }

    /// The last tick run (0 before the first).
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Blocks until every robot has an agent or `timeout` passes.
    pub fn wait_for_agents(&self, timeout: Duration) -> Result<(), TransportError> {
        let start = Instant::now();
        let expected = self.config.robots;
        let joined = self.deaths.sync.wait_joined(expected, start + timeout);
        if joined >= expected {
            Ok(())
        } else {
            Err(TransportError::JoinTimeout {
                joined,
                expected,
                waited_ms: start.elapsed().as_millis(),
            })
        }
    }

    /// A handle for death notices from other threads.
    pub fn death_notices(&self) -> DeathNotices {
        self.deaths.clone()
    }

    /// Death notice from the world's own thread; see [`DeathNotices::mark_dead`].
    pub fn mark_dead(&self, robot: u32) -> Result<(), TransportError> {
        self.deaths.mark_dead(robot)
    }

    /// Whether `robot` has a connected agent without a death notice (e.g. a replacement agent has joined).
    pub fn agent_present(&self, robot: u32) -> bool {
        robot < self.config.robots && self.deaths.sync.has_agent(robot)
    }

    /// Withdraws the death notice of `robot`, whose agent is still connected (thawed, or answering again after
    /// missing deadlines): from the next tick on, ticks wait for it again. `false` when the robot is out of
    /// range or another agent has claimed it meanwhile.
    pub fn revive(&self, robot: u32) -> bool {
        robot < self.config.robots && self.deaths.sync.revive(robot)
    }

    /// Runs one tick: `sense` fills every robot's frame (pre-set to [`SensorFrame::empty`] with this tick;
    /// `tick` and `robot` are enforced afterwards), the frames go out, and the call returns when every robot
    /// answered, is dead, or the deadline passed. Read the commands with [`WorldLink::command`].
    pub fn tick_with(
        &mut self,
        sense: impl FnOnce(u64, &mut [SensorFrame]),
    ) -> Result<TickOutcome, TransportError> {
        let tick = self.tick + 1;
        let robots = self.config.robots as usize;
        for held in &mut self.commands {
            *held = None;
        }
        let uninit = self
            .frame_publisher
            .loan_slice_uninit(robots)
            .map_err(|e| {
                TransportError::iceoryx(format!("loaning the frames of tick {tick}"), e)
            })?;
        let mut frames = uninit.write_from_fn(|i| {
            let mut frame = SensorFrame::empty(i as u32);
            frame.tick = tick;
            frame
        });
        sense(tick, frames.payload_mut());
        for (i, frame) in frames.payload_mut().iter_mut().enumerate() {
            frame.tick = tick;
            frame.robot = i as u32;
        }
        frames.send().map_err(|e| {
            TransportError::iceoryx(format!("publishing the frames of tick {tick}"), e)
        })?;

        let sync = &self.deaths.sync;
        sync.open_tick(tick);
        self.tick = tick;
        sync.wake_agents(tick);
        let deadline = Instant::now() + self.config.tick_deadline;
        if !sync.wait_answers(tick, self.config.spin, deadline) {
            tracing::debug!(tick, "tick deadline passed with answers missing");
        }
        let outcome = self.collect(tick)?;
        self.cleanup_if_due(tick);
        Ok(outcome)
    }

    /// Reads each robot's command for `tick` from its own service into its slot.
    fn collect(&mut self, tick: u64) -> Result<TickOutcome, TransportError> {
        let mut outcome = TickOutcome {
            tick,
            answered: 0,
            missing: 0,
            dead: 0,
        };
        for (robot, subscriber) in self.command_subscribers.iter().enumerate() {
            let slot = &mut self.commands[robot];
            loop {
                let received = subscriber.receive().map_err(|e| {
                    TransportError::iceoryx(format!("receiving robot {robot}'s command"), e)
                })?;
                let Some(sample) = received else { break };
                let command = sample.payload();
                // Late answers to earlier ticks are dropped; the service has a single publisher, the robot's agent.
                if slot.is_none() && command.tick == tick && command.robot == robot as u32 {
                    *slot = Some(sample);
                }
            }
            self.status[robot] = if slot.is_some() {
                outcome.answered += 1;
                CommandStatus::Answered
            } else if self.deaths.sync.is_dead(robot as u32) {
                outcome.dead += 1;
                CommandStatus::Dead
            } else {
                outcome.missing += 1;
                CommandStatus::Missing
            };
        }
        Ok(outcome)
    }

    fn cleanup_if_due(&mut self, tick: u64) {
        let notices = self.deaths.notices.load(Ordering::Acquire);
        if notices != self.notices_handled
            || tick - self.last_cleanup >= self.config.cleanup_interval
        {
            self.notices_handled = notices;
            self.last_cleanup = tick;
            let state = self.node.try_cleanup_dead_nodes();
            tracing::debug!(tick, ?state, "dead-node cleanup");
        }
    }

    /// The command `robot` sent in the last tick, read in place from shared memory; `None` if it did not answer.
    pub fn command(&self, robot: u32) -> Option<&ActuatorCommand> {
        self.commands
            .get(robot as usize)
            .and_then(|held| held.as_ref())
            .map(|sample| sample.payload())
    }

    /// What the world got from each robot in the last tick, indexed by robot.
    pub fn statuses(&self) -> &[CommandStatus] {
        &self.status
    }
}

impl Drop for WorldLink {
    fn drop(&mut self) {
        self.deaths.sync.stop();
    }
}
