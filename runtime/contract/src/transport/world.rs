//! The world's side of the lockstep: creates every service of the run with explicit limits, writes each tick's
//! frames into the frame board, wakes the agents, waits on one counter and reads each robot's command from its
//! own command slot.
//!
//! It must never let a dead or frozen robot block a tick (death notices and the tick deadline), never accept a
//! command into a slot other than its robot's, and never let arrival order change what it reads.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::writer::{EntryHandleMut, Writer};
use iceoryx2::prelude::{ZeroCopySend, ipc};

use super::TransportError;
use super::cleaner::Cleaner;
use super::command_slots::CommandSlots;
use super::placement;
use super::run::RunSpec;
use super::services::{self, Board};
use super::sync_block::{AgentPlacement, MAX_ROBOTS, SyncBlock};
use crate::mail::Mailbox;
use crate::messages::{ActuatorCommand, SensorFrame};

/// Default time the world waits for the commands of one tick (see [`LinkConfig::tick_deadline`]).
pub const DEFAULT_TICK_DEADLINE: Duration = Duration::from_millis(500);
/// Default time the world spins before it blocks on the answer counter (see [`LinkConfig::spin`]).
pub const DEFAULT_SPIN: Duration = Duration::from_micros(20);
/// Default time without any answer after which the world wakes the chains still waiting again (see
/// [`LinkConfig::chain_stall`]).
pub const DEFAULT_CHAIN_STALL: Duration = Duration::from_millis(5);
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
    /// Ticks between two removals of dead nodes' iceoryx2 resources (default 1000); a death notice triggers one
    /// at once as well. Removals run on a thread of their own.
    pub cleanup_interval: u64,
    /// Number of chains the robots are woken in (0: chosen from the robot count, see
    /// [`LinkConfig::chain_len`]). The world wakes one agent of each chain once its frames are written; that
    /// agent wakes the rest of the chain.
    pub chains: u32,
    /// How long a tick may go without any answer before the world wakes the agents of every chain still
    /// waiting (default 5 ms): a chain whose one wake-up went to a frozen agent, or to one killed before its
    /// death notice, waits until then.
    pub chain_stall: Duration,
    /// Whether each agent pins itself to one CPU by its chain, the chains taking the CPUs in turn
    /// (default true; see `transport::placement`).
    pub pin_chains: bool,
    /// Whether each agent runs at real-time priority [`AGENT_PRIORITY`](super::priority::AGENT_PRIORITY)
    /// (default false). Set it once the thread that ticks the link runs at
    /// [`WORLD_PRIORITY`](super::priority::WORLD_PRIORITY): see [`priority`](super::priority).
    pub realtime: bool,
    /// Whether the run carries addressed messages (`crate::mail`): an inbox board and an outbox beside every
    /// command slot (default false: a run without a `<messages>` medium pays nothing for them).
    pub mail: bool,
}

impl LinkConfig {
    /// The default configuration for `robots` robots.
    pub fn new(robots: u32) -> LinkConfig {
        LinkConfig {
            robots,
            tick_deadline: DEFAULT_TICK_DEADLINE,
            spin: DEFAULT_SPIN,
            cleanup_interval: DEFAULT_CLEANUP_INTERVAL,
            chains: 0,
            chain_stall: DEFAULT_CHAIN_STALL,
            pin_chains: true,
            realtime: false,
            mail: false,
        }
    }

    /// Robots per chain. Unless [`LinkConfig::chains`] says otherwise, one chain per 100 robots, at least 2 and
    /// at most 16: enough chains to spread over the CPUs, each woken with one system call
    /// (docs/transport.md).
    pub fn chain_len(&self) -> u32 {
        let robots = self.robots.max(1);
        let chains = match self.chains {
            0 => (robots / 100).clamp(2, 16),
            chosen => chosen,
        };
        robots.div_ceil(chains.min(robots))
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
        self.mark_agent_dead(robot, 0).map(drop)
    }

    /// The agent with process id `agent` (0: whichever) of `robot` is dead: as [`DeathNotices::mark_dead`],
    /// unless another agent has claimed the robot since, which keeps it (a notice read after the robot's
    /// replacement joined). Returns whether the notice took effect.
    pub fn mark_agent_dead(&self, robot: u32, agent: u32) -> Result<bool, TransportError> {
        let capacity = self.sync.capacity();
        if robot >= capacity {
            return Err(TransportError::RobotOutOfRange { robot, capacity });
        }
        if agent != 0
            && self
                .sync
                .agent_pid(robot)
                .is_some_and(|owner| owner != agent)
        {
            return Ok(false);
        }
        self.sync.mark_dead(robot);
        self.notices.fetch_add(1, Ordering::Release);
        Ok(true)
    }
}

/// The world's writing end of the inbox board (runs with mail only). Fields drop in declaration order.
struct InboxBoard {
    entries: Vec<EntryHandleMut<ipc::Service, u32, Mailbox>>,
    _writer: Writer<ipc::Service, u32>,
    _board: Board,
}

/// The world's iceoryx2 ports: one frame-board entry per robot, indexed by robot, and the inbox board in runs
/// with mail. Entry handles keep their ports and services alive; the other fields are only held, in drop order.
struct Boards {
    frame_entries: Vec<EntryHandleMut<ipc::Service, u32, SensorFrame>>,
    inboxes: Option<InboxBoard>,
    _frame_writer: Writer<ipc::Service, u32>,
    _frame_board: Board,
}

/// The world's end of a run's local transport.
pub struct WorldLink {
    config: LinkConfig,
    tick: u64,
    boards: Boards,
    /// Every robot's command slot.
    slots: CommandSlots,
    /// This tick's frames, filled by the caller and then written to the board.
    frames: Vec<SensorFrame>,
    /// The last tick's commands, valid where `status` says `Answered`.
    commands: Vec<ActuatorCommand>,
    /// The state word of each robot's slot the last tick's command was read under (for its outbox).
    read_states: Vec<u64>,
    status: Vec<CommandStatus>,
    deaths: DeathNotices,
    notices_handled: u64,
    last_cleanup: u64,
    cleaner: Cleaner,
    /// The world's iceoryx2 node, held for the boards.
    _node: Node<ipc::Service>,
    /// The CPU of each chain's agents, when they pin themselves ([`LinkConfig::pin_chains`]); empty otherwise.
    chain_cpus: Vec<usize>,
    /// Messages posted to each robot's inbox for the next tick ([`WorldLink::post`]); its frame says how many.
    posted: Vec<u8>,
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
        let boards = Self::create_boards(&node, robots, config.mail)?;
        let cleaner = Cleaner::start(run.iceoryx_config()?)?;
        // Last, so that a failure above leaves no file of ours behind (iceoryx2 removes its own resources on
        // drop); the sync block after the slots, since agents that find it open the slots.
        let slots = CommandSlots::create(&run.command_slots_path(), robots, config.mail)?;
        let sync = SyncBlock::create(
            &run.sync_block_path(),
            robots,
            config.chain_len(),
            AgentPlacement {
                pin_chains: config.pin_chains,
                realtime: config.realtime,
                mail: config.mail,
            },
        )
        .inspect_err(|_| {
            let _ = std::fs::remove_file(run.command_slots_path());
        })?;
        let sync = Arc::new(sync);
        let chain_cpus = if config.pin_chains {
            placement::chain_cpus(sync.chains().count()).unwrap_or_default()
        } else {
            Vec::new()
        };
        tracing::debug!(run = run.name(), robots, "world link created");
        Ok(WorldLink {
            tick: 0,
            boards,
            slots,
            frames: (0..robots).map(SensorFrame::empty).collect(),
            commands: (0..robots).map(|r| ActuatorCommand::idle(r, 0)).collect(),
            read_states: vec![0; robots as usize],
            status: vec![CommandStatus::Missing; robots as usize],
            deaths: DeathNotices {
                sync,
                notices: Arc::new(AtomicU64::new(0)),
            },
            notices_handled: 0,
            last_cleanup: 0,
            cleaner,
            _node: node,
            config,
            chain_cpus,
            posted: vec![0; robots as usize],
        })
    }

    fn create_boards(
        node: &Node<ipc::Service>,
        robots: u32,
        mail: bool,
    ) -> Result<Boards, TransportError> {
        let frame_board = services::create_frame_board(node, robots)?;
        let (frame_writer, frame_entries) =
            every_entry::<SensorFrame>(&frame_board, robots, "frame")?;
        let inboxes = mail
            .then(|| Self::create_inboxes(node, robots))
            .transpose()?;
        Ok(Boards {
            frame_entries,
            inboxes,
            _frame_writer: frame_writer,
            _frame_board: frame_board,
        })
    }

    fn create_inboxes(
        node: &Node<ipc::Service>,
        robots: u32,
    ) -> Result<InboxBoard, TransportError> {
        let board = services::create_inbox_board(node, robots)?;
        let (writer, entries) = every_entry::<Mailbox>(&board, robots, "inbox")?;
        Ok(InboxBoard {
            entries,
            _writer: writer,
            _board: board,
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

    /// Numbers the first tick `first` instead of 1, so a host that joins a run mid-way gives its agents the
    /// world's tick numbers (their timers and random streams are positioned by tick). No effect once a tick ran.
    pub fn start_at(&mut self, first: u64) {
        if self.tick == 0 {
            self.tick = first.saturating_sub(1);
        }
    }

    /// Blocks until every robot has an agent or `timeout` passes. Death notices meanwhile have the dead agents'
    /// iceoryx2 resources removed, which frees their places in the frame board for their replacements.
    pub fn wait_for_agents(&mut self, timeout: Duration) -> Result<(), TransportError> {
        let start = Instant::now();
        let deadline = start + timeout;
        let expected = self.config.robots;
        loop {
            if self.take_new_notices() {
                self.cleaner.request();
            }
            let joined = self.deaths.sync.wait_joined(expected, deadline);
            if joined >= expected {
                return Ok(());
            }
            if Instant::now() >= deadline {
                return Err(TransportError::JoinTimeout {
                    joined,
                    expected,
                    waited_ms: start.elapsed().as_millis(),
                });
            }
        }
    }

    /// Whether death notices arrived since the last call: their dead agents' iceoryx2 resources are to be
    /// removed.
    fn take_new_notices(&mut self) -> bool {
        let notices = self.deaths.notices.load(Ordering::Acquire);
        if notices == self.notices_handled {
            return false;
        }
        tracing::debug!(
            notices = notices - self.notices_handled,
            "dead-node cleanup requested"
        );
        self.notices_handled = notices;
        true
    }

    /// A handle for death notices from other threads.
    pub fn death_notices(&self) -> DeathNotices {
        self.deaths.clone()
    }

    /// Death notice from the world's own thread; see [`DeathNotices::mark_dead`].
    pub fn mark_dead(&self, robot: u32) -> Result<(), TransportError> {
        self.deaths.mark_dead(robot)
    }

    /// Every robot starts without an agent: it counts as present only once its agent has connected. Unlike a
    /// death notice this asks for no dead-node cleanup, as no agent has lived yet (at 1,000 robots a cleanup scan
    /// takes half a second of a core, which the first ticks would otherwise share).
    pub fn start_without_agents(&self) {
        for robot in 0..self.config.robots {
            self.deaths.sync.mark_dead(robot);
        }
    }

    /// Whether `robot` has a connected agent without a death notice (e.g. a replacement agent has joined).
    pub fn agent_present(&self, robot: u32) -> bool {
        robot < self.config.robots && self.deaths.sync.has_agent(robot)
    }

    /// The process ids of the robots' agents (robots without one are left out).
    pub fn agent_pids(&self) -> Vec<u32> {
        (0..self.config.robots)
            .filter_map(|robot| self.deaths.sync.agent_pid(robot))
            .collect()
    }

    /// Withdraws the death notice of `robot`, whose agent is still connected (thawed, or answering again after
    /// missing deadlines): from the next tick on, ticks wait for it again. `false` when the robot is out of
    /// range or another agent has claimed it meanwhile.
    pub fn revive(&self, robot: u32) -> bool {
        robot < self.config.robots && self.deaths.sync.revive(robot)
    }

    /// Runs one tick, chain by chain: `sense(tick, first, frames)` fills the frames of the robots `first..`
    /// (pre-set to [`SensorFrame::empty`] with this tick; `tick` and `robot` are enforced afterwards), those
    /// frames go out and that chain's agents start while the next chain is sensed. The call returns when every
    /// robot answered, is dead, or the deadline passed. Read the commands with [`WorldLink::command`].
    ///
    /// Sensing chain by chain overlaps the world's sensing with the first chains' agents (on a second core);
    /// `sense` must therefore fill a robot's frame from the world's state alone, never from another frame.
    pub fn tick_with(
        &mut self,
        mut sense: impl FnMut(u64, usize, &mut [SensorFrame]),
    ) -> Result<TickOutcome, TransportError> {
        let tick = self.tick + 1;
        let sync = &self.deaths.sync;
        sync.open_tick(tick);
        self.tick = tick;
        // The chains whose agents share this thread's CPU go last and start together once every frame is out:
        // under the normal scheduler the first agent woken on this CPU would preempt the world's sensing, and
        // hold up the chains of the other CPUs with it.
        let here = if self.chain_cpus.is_empty() {
            None
        } else {
            placement::current_cpu()
        };
        let on_this_cpu =
            |chain: usize| here.is_some() && self.chain_cpus.get(chain).copied() == here;
        let elsewhere = sync
            .chains()
            .enumerate()
            .filter(|&(index, _)| !on_this_cpu(index));
        let here_last = sync
            .chains()
            .enumerate()
            .filter(|&(index, _)| on_this_cpu(index));
        for (index, chain) in elsewhere.chain(here_last) {
            let robots = chain.start as usize..chain.end as usize;
            let frames = &mut self.frames[robots.clone()];
            SensorFrame::sense_into(tick, robots.start, frames, &mut sense);
            if self.config.mail {
                for (frame, &posted) in frames.iter_mut().zip(&self.posted[robots.clone()]) {
                    frame.inbox_len = posted;
                }
            }
            for (frame, entry) in frames.iter().zip(&self.boards.frame_entries[robots]) {
                entry.update_with_copy(*frame);
            }
            if !on_this_cpu(index) {
                sync.start_chain(chain.start, tick);
            }
        }
        for (index, chain) in sync.chains().enumerate() {
            if on_this_cpu(index) {
                sync.start_chain(chain.start, tick);
            }
        }
        let deadline = Instant::now() + self.config.tick_deadline;
        if !sync.wait_answers(tick, self.config.spin, self.config.chain_stall, deadline) {
            tracing::debug!(tick, "tick deadline passed with answers missing");
        }
        let outcome = self.collect(tick);
        if self.config.mail {
            self.posted.fill(0);
        }
        self.cleanup_if_due(tick);
        Ok(outcome)
    }

    /// Puts `inbox` into `robot`'s inbox for the next tick, whose frame then says how many messages wait
    /// (`inbox.tick` and `inbox.owner` are set here). Without mail (see [`LinkConfig::mail`]), or for a robot out
    /// of range, nothing is posted and the call says so.
    pub fn post(&mut self, robot: u32, inbox: &mut Mailbox) -> bool {
        let Some(entry) = self
            .boards
            .inboxes
            .as_ref()
            .and_then(|inboxes| inboxes.entries.get(robot as usize))
        else {
            return false;
        };
        inbox.tick = self.tick + 1;
        inbox.owner = robot;
        entry.update_with_copy(*inbox);
        self.posted[robot as usize] = inbox.messages().len() as u8;
        true
    }

    /// The messages `robot` sent in the last tick, read from its outbox; `None` when it did not answer, sent
    /// nothing, or its outbox does not belong to the tick (an agent that died between writing its outbox and
    /// its command).
    pub fn outbox(&self, robot: u32) -> Option<Mailbox> {
        let command = self.command(robot)?;
        if command.outbox_len == 0 {
            return None;
        }
        let outbox = self
            .slots
            .read_outbox(robot, self.read_states[robot as usize])?;
        (outbox.tick == command.tick && outbox.owner == robot).then_some(outbox)
    }

    /// Reads each robot's command for `tick` from its own command slot.
    fn collect(&mut self, tick: u64) -> TickOutcome {
        let mut outcome = TickOutcome {
            tick,
            answered: 0,
            missing: 0,
            dead: 0,
        };
        for robot in 0..self.config.robots {
            let r = robot as usize;
            // A late answer to an earlier tick is not this tick's answer; only the robot's agent writes its slot,
            // so `robot` can only be wrong if the agent is broken. A slot being written has no answer yet.
            self.status[r] = match self.slots.read(robot) {
                Some((command, state)) if command.tick == tick && command.robot == robot => {
                    self.commands[r] = command;
                    self.read_states[r] = state;
                    outcome.answered += 1;
                    CommandStatus::Answered
                }
                _ if self.deaths.sync.is_dead(robot) => {
                    outcome.dead += 1;
                    CommandStatus::Dead
                }
                _ => {
                    outcome.missing += 1;
                    CommandStatus::Missing
                }
            };
        }
        outcome
    }

    /// Has dead nodes removed after death notices, and every [`LinkConfig::cleanup_interval`] ticks.
    fn cleanup_if_due(&mut self, tick: u64) {
        if self.take_new_notices() || tick - self.last_cleanup >= self.config.cleanup_interval {
            self.cleaner.request();
            self.last_cleanup = tick;
        }
    }

    /// The command `robot` sent in the last tick; `None` if it did not answer.
    pub fn command(&self, robot: u32) -> Option<&ActuatorCommand> {
        match self.status.get(robot as usize) {
            Some(CommandStatus::Answered) => self.commands.get(robot as usize),
            _ => None,
        }
    }

    /// What the world got from each robot in the last tick, indexed by robot.
    pub fn statuses(&self) -> &[CommandStatus] {
        &self.status
    }
}

/// The world's writer of a board with one entry per robot (the frame board, the inbox board), and every robot's
/// entry handle, in robot order.
type Entries<T> = (
    Writer<ipc::Service, u32>,
    Vec<EntryHandleMut<ipc::Service, u32, T>>,
);

/// Opens the world's writer of `board` (one entry per robot of `robots`) and every robot's entry.
fn every_entry<T: Copy + ZeroCopySend>(
    board: &Board,
    robots: u32,
    what: &str,
) -> Result<Entries<T>, TransportError> {
    let writer = board
        .writer_builder()
        .create()
        .map_err(|e| TransportError::iceoryx(format!("writing the {what} board"), e))?;
    let entries = (0..robots)
        .map(|robot| {
            writer
                .entry::<T>(&robot)
                .map_err(|e| TransportError::iceoryx(format!("robot {robot}'s {what} entry"), e))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((writer, entries))
}

impl WorldLink {
    /// Ends the run for the agents (as dropping the link does) without taking down the run's services one by
    /// one: the process is about to exit, and whoever created the run removes its shared memory as a whole
    /// ([`RunSpec::cleanup`]). At 1,000 robots the orderly teardown took 0.4 s of the world's exit.
    pub fn end_run(self) {
        self.deaths.sync.stop();
        std::mem::forget(self);
    }
}

impl Drop for WorldLink {
    fn drop(&mut self) {
        self.deaths.sync.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::LinkConfig;

    fn chain_len(robots: u32, chains: u32) -> u32 {
        LinkConfig {
            chains,
            ..LinkConfig::new(robots)
        }
        .chain_len()
    }

    #[test]
    fn chains_follow_the_robot_count_unless_chosen() {
        assert_eq!(chain_len(1, 0), 1);
        assert_eq!(chain_len(10, 0), 5);
        assert_eq!(chain_len(100, 0), 50);
        assert_eq!(chain_len(1000, 0), 100);
        assert_eq!(chain_len(2000, 0), 125);
        assert_eq!(chain_len(5000, 0), 313);
        assert_eq!(chain_len(8, 3), 3);
        assert_eq!(chain_len(4, 9), 1);
    }
}
