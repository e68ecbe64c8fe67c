//! The lockstep sync block: a small file in the run's shared memory holding the futex words of the tick protocol
//! and one slot per robot.
//!
//! Only control words live here (tick, per-chain wake words, acknowledgement counter, join and death flags);
//! frames travel through iceoryx2 blackboards, commands through the run's command slots (`command_slots`). The
//! world creates the block, agents map it. Every field is an atomic, so the mapping is shared freely between
//! threads and processes; a zero-filled block is a valid empty block.
//!
//! Agents are woken chain by chain: the robots form chains of consecutive indices, and every agent of a chain
//! sleeps on the chain's wake word. Once a chain's frames are in place the world sets the word to the tick and
//! wakes one of its agents; the first agent of the chain to run in the tick wakes all the others with one system
//! call ([`SyncBlock::spread`]). So neither the world nor an agent makes a system call per woken agent, and the
//! chain's agents, pinned to one CPU, queue there and run one after the other (measured in docs/transport.md).
//! No robot depends on another to be woken, so a dead or frozen agent holds up nobody; only when the world's one
//! wake-up went to a frozen agent does a chain wait, for the world's rescue (see [`SyncBlock::rescue`]).
//!
//! The acknowledgement word packs the tick it belongs to (top bits) with the number of robots accounted for in
//! that tick (bottom bits). An answer is counted only while the word still carries its tick, so a late answer
//! to an earlier tick can never be mistaken for an answer to the current one. Each robot is accounted for at
//! most once per tick: by its agent's answer or by a death notice, whichever claims it first.

use std::path::Path;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use super::TransportError;
use super::futex::{self, LineWord};
use super::shared_map::SharedMap;
use super::world_watch::WorldEndNotice;

/// Identifies a sync block file ("SWARMLCK").
const MAGIC: u64 = 0x5357_4152_4d4c_434b;
/// Layout version of the sync block.
const LAYOUT_VERSION: u32 = 11;
/// Bits of the acknowledgement word that count robots; the remaining top bits tag the tick.
const COUNT_BITS: u32 = 20;
/// Mask of the count bits.
const COUNT_MASK: u32 = (1 << COUNT_BITS) - 1;
/// How long an agent sleeps on its chain's wake word before it checks that the world still exists.
const WORLD_CHECK: Duration = Duration::from_secs(1);
/// How often a replacement agent re-checks a claim held by a dead agent while it waits for the death notice.
const CLAIM_POLL: Duration = Duration::from_millis(10);
/// Most robots one run can hold (the count field must not overflow into the tick tag).
pub const MAX_ROBOTS: u32 = COUNT_MASK;

/// Fixed part of the block.
#[repr(C)]
struct Header {
    magic: AtomicU64,
    version: AtomicU32,
    capacity: AtomicU32,
    /// Process id of the world, so that agents notice when it is gone.
    world_pid: AtomicU32,
    /// Robots per chain: chain `c` is robots `c * chain_len ..` up to the next chain's first robot.
    chain_len: AtomicU32,
    /// 1 when each agent pins itself to one CPU by its chain (`LinkConfig::pin_chains`).
    pin_chains: AtomicU32,
    /// 1 when each agent runs at real-time priority (`LinkConfig::realtime`).
    realtime: AtomicU32,
    /// 1 when the run carries mail: an inbox board and an outbox per robot (`LinkConfig::mail`).
    mail: AtomicU32,
    /// Current tick (full width), written before the tick's first chain starts; a chain's frames are in place
    /// once its wake word carries the tick.
    tick: AtomicU64,
    /// Tick tag and answer count; the world sleeps on it.
    acks: LineWord,
    /// Number of robots whose agent has joined; the world sleeps on it while waiting for agents.
    joined: LineWord,
    /// Non-zero once the world ends the run.
    stop: LineWord,
}

/// Per-robot control words, one cache line per robot: the robot's agent and the world write here from
/// different cores.
#[repr(C, align(64))]
struct RobotSlot {
    /// Last tick this robot was accounted for.
    answered: AtomicU64,
    /// 1 while an agent owns this robot.
    owner: AtomicU32,
    /// Process id of the agent that last claimed this robot: the only process whose commands count for it
    /// (`command_slots`), until another agent claims it.
    owner_pid: AtomicU32,
    /// 1 after a death notice, until a replacement agent joins.
    dead: AtomicU32,
    /// In the first robot of a chain only: the chain's wake word, the low 32 bits of the last tick whose frames
    /// of the chain are in place. Every agent of the chain sleeps on it.
    chain_go: AtomicU32,
    /// In the first robot of a chain only: the last tick in which an agent of the chain woke the others.
    chain_woken: AtomicU64,
}

/// Where and how the agents of a run run, and what they are given, as the world tells them in the block.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct AgentPlacement {
    /// Each agent pins itself to the CPU of its chain.
    pub(crate) pin_chains: bool,
    /// Each agent runs at real-time priority.
    pub(crate) realtime: bool,
    /// The run has an inbox board and an outbox per robot (`crate::mail`).
    pub(crate) mail: bool,
}

/// A mapping of a run's sync block.
pub(crate) struct SyncBlock {
    map: SharedMap,
    capacity: u32,
    /// Robots per chain (a copy of the header's, which never changes).
    chain_len: u32,
}

/// Whether a robot could be claimed by a new agent.
pub(crate) enum JoinClaim {
    /// The robot is now owned by the caller.
    Claimed,
    /// Another live agent already owns the robot.
    Taken,
}

impl SyncBlock {
    fn size_for(capacity: u32) -> usize {
        size_of::<Header>() + capacity as usize * size_of::<RobotSlot>()
    }

    /// Creates the block of a run for `capacity` robots woken in chains of `chain_len` robots, whose agents pin
    /// themselves to a CPU by chain if `placement.pin_chains` and run at real-time priority if
    /// `placement.realtime`; fails if it exists.
    pub(crate) fn create(
        path: &Path,
        capacity: u32,
        chain_len: u32,
        placement: AgentPlacement,
    ) -> Result<SyncBlock, TransportError> {
        let len = Self::size_for(capacity);
        let map = SharedMap::create(path, len).map_err(|source| TransportError::SyncBlock {
            path: path.to_path_buf(),
            source,
        })?;
        let block = SyncBlock {
            map,
            capacity,
            chain_len: chain_len.max(1),
        };
        let header = block.header();
        header.version.store(LAYOUT_VERSION, Ordering::Relaxed);
        header.capacity.store(capacity, Ordering::Relaxed);
        header.chain_len.store(block.chain_len, Ordering::Relaxed);
        header
            .pin_chains
            .store(u32::from(placement.pin_chains), Ordering::Relaxed);
        header
            .realtime
            .store(u32::from(placement.realtime), Ordering::Relaxed);
        header
            .mail
            .store(u32::from(placement.mail), Ordering::Relaxed);
        header
            .world_pid
            .store(std::process::id(), Ordering::Relaxed);
        header.magic.store(MAGIC, Ordering::Release);
        Ok(block)
    }

    /// Maps the existing block of a run.
    pub(crate) fn open(path: &Path) -> Result<SyncBlock, TransportError> {
        let io_err = |source| TransportError::SyncBlock {
            path: path.to_path_buf(),
            source,
        };
        let invalid = |reason: String| TransportError::InvalidSyncBlock {
            path: path.to_path_buf(),
            reason,
        };
        let (file, file_len) = SharedMap::open_file(path).map_err(io_err)?;
        if file_len < size_of::<Header>() as u64 {
            return Err(invalid(format!(
                "{file_len} bytes is too short for a header"
            )));
        }
        let mut block = SyncBlock {
            map: SharedMap::map(&file, file_len as usize).map_err(io_err)?,
            capacity: 0,
            chain_len: 1,
        };
        let header = block.header();
        if header.magic.load(Ordering::Acquire) != MAGIC {
            return Err(invalid("not a swarm lockstep block (bad magic)".into()));
        }
        let version = header.version.load(Ordering::Relaxed);
        if version != LAYOUT_VERSION {
            return Err(invalid(format!(
                "layout version {version}, this build speaks {LAYOUT_VERSION}"
            )));
        }
        let capacity = header.capacity.load(Ordering::Relaxed);
        let len = Self::size_for(capacity);
        if file_len < len as u64 {
            return Err(invalid(format!(
                "{file_len} bytes cannot hold {capacity} robots ({len} bytes)"
            )));
        }
        block.chain_len = header.chain_len.load(Ordering::Relaxed).max(1);
        block.capacity = capacity;
        Ok(block)
    }

    fn header(&self) -> &Header {
        // SAFETY: the mapping is at least one page-aligned header long and zero or validly initialised.
        unsafe { &*self.map.base().cast::<Header>() }
    }

    fn slot(&self, robot: u32) -> &RobotSlot {
        debug_assert!(robot < self.capacity);
        // SAFETY: robot < capacity, and the mapping holds `capacity` slots after the header.
        unsafe {
            &*self
                .map
                .base()
                .add(size_of::<Header>())
                .cast::<RobotSlot>()
                .add(robot as usize)
        }
    }

    /// Number of robots the block was created for.
    pub(crate) fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The current tick.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn tick(&self) -> u64 {
        self.header().tick.load(Ordering::Acquire)
    }

    /// Robots per chain.
    pub(crate) fn chain_len(&self) -> u32 {
        self.chain_len
    }

    /// Where and how the run's agents run.
    pub(crate) fn placement(&self) -> AgentPlacement {
        let header = self.header();
        AgentPlacement {
            pin_chains: header.pin_chains.load(Ordering::Relaxed) != 0,
            realtime: header.realtime.load(Ordering::Relaxed) != 0,
            mail: header.mail.load(Ordering::Relaxed) != 0,
        }
    }

    /// Whether the world has ended the run.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn stopped(&self) -> bool {
        self.header().stop.0.load(Ordering::Acquire) != 0
    }

    /// Opens tick `tick` for answers: resets the count, then accounts for every robot with a death notice.
    /// No agent runs before its chain starts ([`SyncBlock::start_chain`]); an agent woken earlier finds its
    /// frame still at the last tick and sleeps again.
    pub(crate) fn open_tick(&self, tick: u64) {
        let header = self.header();
        header
            .acks
            .0
            .store(tag(tick) << COUNT_BITS, Ordering::Release);
        // SeqCst pairs with `mark_dead`: either this scan sees the notice or the notice sees this tick.
        header.tick.store(tick, Ordering::SeqCst);
        for robot in 0..self.capacity {
            if self.slot(robot).dead.load(Ordering::SeqCst) != 0 {
                self.claim(robot, tick);
            }
        }
    }

    /// The chains, each as the range of its robots.
    pub(crate) fn chains(&self) -> impl Iterator<Item = std::ops::Range<u32>> + use<> {
        let (capacity, len) = (self.capacity, self.chain_len);
        (0..capacity)
            .step_by(len as usize)
            .map(move |first| first..(first + len).min(capacity))
    }

    /// Starts `tick` in the chain whose first robot is `first`: the chain's frames are in place. Wakes one of
    /// the chain's agents, which wakes the others ([`SyncBlock::spread`]).
    pub(crate) fn start_chain(&self, first: u32, tick: u64) {
        let go = &self.slot(first).chain_go;
        go.store(tick as u32, Ordering::Release);
        futex::wake(go, 1);
    }

    /// The first robot of `robot`'s chain.
    fn chain_of(&self, robot: u32) -> u32 {
        robot - robot % self.chain_len
    }

    /// Called by an agent that found its frame of `tick`: the first agent of the chain to do so wakes all the
    /// others of the chain with one system call. Returns whether this call did.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn spread(&self, robot: u32, tick: u64) -> bool {
        let first = self.slot(self.chain_of(robot));
        if first.chain_woken.swap(tick, Ordering::AcqRel) == tick {
            return false;
        }
        futex::wake(&first.chain_go, i32::MAX);
        true
    }

    /// The world's remedy for a chain whose one wake-up went to an agent that cannot run (frozen, or killed
    /// and not yet reported): wakes every agent of each started chain that still has robots not accounted for
    /// in `tick`. Returns how many chains it woke.
    pub(crate) fn rescue(&self, tick: u64) -> u32 {
        let mut woken = 0;
        for chain in self.chains() {
            let go = &self.slot(chain.start).chain_go;
            let waiting = chain
                .clone()
                .any(|robot| self.slot(robot).answered.load(Ordering::Acquire) != tick);
            if waiting && go.load(Ordering::Acquire) == tick as u32 {
                futex::wake(go, i32::MAX);
                woken += 1;
            }
        }
        woken
    }

    /// Ends the run: agents waiting for a tick return.
    pub(crate) fn stop(&self) {
        let header = self.header();
        header.stop.0.store(1, Ordering::Release);
        for chain in self.chains() {
            self.nudge(chain.start);
        }
    }

    /// Accounts for `robot` in `tick` unless it already was; returns whether this call counted it. The call
    /// that completes the count wakes the world.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn claim(&self, robot: u32, tick: u64) -> bool {
        if self.slot(robot).answered.swap(tick, Ordering::AcqRel) == tick {
            return false;
        }
        let acks = &self.header().acks.0;
        let mut current = acks.load(Ordering::Acquire);
        loop {
            if current >> COUNT_BITS != tag(tick) {
                return false;
            }
            match acks.compare_exchange_weak(
                current,
                current + 1,
                Ordering::AcqRel,
                Ordering::Acquire,
            ) {
                Ok(_) => {
                    if (current & COUNT_MASK) + 1 == self.capacity {
                        futex::wake(acks, 1);
                    }
                    return true;
                }
                Err(seen) => current = seen,
            }
        }
    }

    /// Waits until every robot is accounted for in `tick` or `deadline` passes, spinning for at most `spin`
    /// first. Whenever no answer arrives for `stall`, the chains still waiting are woken again
    /// ([`SyncBlock::rescue`]). Returns whether every robot was accounted for.
    pub(crate) fn wait_answers(
        &self,
        tick: u64,
        spin: Duration,
        stall: Duration,
        deadline: Instant,
    ) -> bool {
        let acks = &self.header().acks.0;
        let complete = tag(tick) << COUNT_BITS | self.capacity;
        let spin_until = Instant::now() + spin;
        let mut progress = (acks.load(Ordering::Acquire), Instant::now());
        loop {
            let current = acks.load(Ordering::Acquire);
            if current == complete {
                return true;
            }
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            if current != progress.0 {
                progress = (current, now);
            } else if now >= progress.1 + stall {
                let woken = self.rescue(tick);
                tracing::debug!(
                    tick,
                    woken,
                    "answers stalled; woke the chains still waiting"
                );
                progress.1 = now;
            }
            if now < spin_until {
                std::hint::spin_loop();
            } else {
                let wake_by = deadline.min(progress.1 + stall);
                futex::wait(acks, current, Some(wake_by.saturating_duration_since(now)));
            }
        }
    }

    /// Death notice: `robot` is accounted for in the current tick and every later one until an agent rejoins
    /// for it, and its ownership is released so that a replacement agent may join.
    pub(crate) fn mark_dead(&self, robot: u32) {
        let slot = self.slot(robot);
        slot.dead.store(1, Ordering::SeqCst);
        if slot.owner.swap(0, Ordering::AcqRel) == 1 {
            self.header().joined.0.fetch_sub(1, Ordering::AcqRel);
        }
        // A replacement may be waiting for the dead agent's claim to be released.
        futex::wake(&slot.owner, i32::MAX);
        let tick = self.header().tick.load(Ordering::SeqCst);
        self.claim(robot, tick);
    }

    /// Whether `robot` has a death notice and no replacement yet.
    pub(crate) fn is_dead(&self, robot: u32) -> bool {
        self.slot(robot).dead.load(Ordering::Acquire) != 0
    }

    /// Whether `robot` has a connected agent and no death notice.
    pub(crate) fn has_agent(&self, robot: u32) -> bool {
        let slot = self.slot(robot);
        slot.owner.load(Ordering::Acquire) == 1 && slot.dead.load(Ordering::Acquire) == 0
    }

    /// The process id of the agent that last claimed `robot` (0: none yet), whether or not it still owns it.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn claimer(&self, robot: u32) -> u32 {
        self.slot(robot).owner_pid.load(Ordering::Acquire)
    }

    /// The process id of `robot`'s agent, if one owns the robot.
    pub(crate) fn agent_pid(&self, robot: u32) -> Option<u32> {
        let slot = self.slot(robot);
        (slot.owner.load(Ordering::Acquire) == 1).then(|| slot.owner_pid.load(Ordering::Acquire))
    }

    /// Withdraws a death notice for a robot whose agent is still connected (it was frozen, or late): it owns
    /// the robot again and ticks wait for it again. `false` if another agent claimed the robot meanwhile.
    pub(crate) fn revive(&self, robot: u32) -> bool {
        let slot = self.slot(robot);
        if slot
            .owner
            .compare_exchange(0, 1, Ordering::AcqRel, Ordering::Acquire)
            .is_err()
        {
            return false;
        }
        slot.dead.store(0, Ordering::SeqCst);
        self.header().joined.0.fetch_add(1, Ordering::AcqRel);
        true
    }

    /// An agent claims `robot` before it connects, so that a second agent for the same robot fails fast. A
    /// claim held by a process that no longer exists is a dead agent whose death notice is still on its way
    /// (its replacement can start first): that one is waited for until `deadline`.
    pub(crate) fn claim_robot(&self, robot: u32, deadline: Instant) -> JoinClaim {
        let slot = self.slot(robot);
        loop {
            if slot
                .owner
                .compare_exchange(0, 1, Ordering::AcqRel, Ordering::Acquire)
                .is_ok()
            {
                slot.owner_pid.store(std::process::id(), Ordering::Release);
                return JoinClaim::Claimed;
            }
            let now = Instant::now();
            if now >= deadline || process_exists(slot.owner_pid.load(Ordering::Acquire)) {
                return JoinClaim::Taken;
            }
            futex::wait(&slot.owner, 1, Some((deadline - now).min(CLAIM_POLL)));
        }
    }

    /// The agent of `robot` is connected: its death notice (if any) is cleared, so ticks wait for it again, and
    /// a world waiting for joins is woken.
    pub(crate) fn announce_ready(&self, robot: u32) {
        self.slot(robot).dead.store(0, Ordering::SeqCst);
        let joined = &self.header().joined.0;
        joined.fetch_add(1, Ordering::AcqRel);
        futex::wake(joined, 1);
    }

    /// An agent that claimed `robot` but could not connect gives it back.
    pub(crate) fn release_claim(&self, robot: u32) {
        self.slot(robot).owner.store(0, Ordering::Release);
    }

    /// An agent leaving cleanly gives its robot back.
    pub(crate) fn leave(&self, robot: u32) {
        let slot = self.slot(robot);
        if slot
            .owner
            .compare_exchange(1, 0, Ordering::AcqRel, Ordering::Acquire)
            .is_ok()
        {
            self.header().joined.0.fetch_sub(1, Ordering::AcqRel);
        }
    }

    /// Waits until `count` agents have joined, `deadline` passes, 100 ms pass, or an agent joining wakes the
    /// join word; returns the number joined. Callers loop.
    pub(crate) fn wait_joined(&self, count: u32, deadline: Instant) -> u32 {
        let joined = &self.header().joined.0;
        let current = joined.load(Ordering::Acquire);
        let now = Instant::now();
        if current < count && now < deadline {
            futex::wait(
                joined,
                current,
                Some((deadline - now).min(Duration::from_millis(100))),
            );
        }
        joined.load(Ordering::Acquire)
    }

    /// The wake word of `robot`'s chain: read it before checking for an open tick, then
    /// [`SyncBlock::wait_chain`] on the value read, so that no wake-up between the check and the wait is missed.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn chain_word(&self, robot: u32) -> u32 {
        self.slot(self.chain_of(robot))
            .chain_go
            .load(Ordering::Acquire)
    }

    /// Waits until the wake word of `robot`'s chain differs from `seen` (a tick started, or the end of the run),
    /// polling `spin` times before blocking; `Err(pid)` when the world process is gone (killed without stopping
    /// the run), as far as `world_end` tells.
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn wait_chain(
        &self,
        robot: u32,
        seen: u32,
        spin: u32,
        world_end: &WorldEndNotice,
    ) -> Result<(), u32> {
        let go = &self.slot(self.chain_of(robot)).chain_go;
        for _ in 0..spin {
            if go.load(Ordering::Acquire) != seen {
                return Ok(());
            }
            std::hint::spin_loop();
        }
        while go.load(Ordering::Acquire) == seen {
            let gone = match world_end {
                WorldEndNotice::Thread(watch) if watch.gone().load(Ordering::Acquire) => true,
                WorldEndNotice::Thread(_) | WorldEndNotice::Parent => {
                    futex::wait(go, seen, None);
                    false
                }
                WorldEndNotice::Poll => {
                    futex::wait(go, seen, Some(WORLD_CHECK)) == futex::Waited::TimedOut
                        && !self.world_alive()
                }
            };
            if gone {
                return Err(self.world_pid());
            }
        }
        Ok(())
    }

    /// Wakes the agents of `robot`'s chain out of [`SyncBlock::wait_chain`] by changing the chain's wake word.
    /// Only for the end of a run (stopped, or the world gone), when the word's value means nothing any more.
    pub(crate) fn nudge(&self, robot: u32) {
        let go = &self.slot(self.chain_of(robot)).chain_go;
        go.fetch_add(1, Ordering::AcqRel);
        futex::wake(go, i32::MAX);
    }

    /// The pid of the process that created the block.
    pub(crate) fn world_pid(&self) -> u32 {
        self.header().world_pid.load(Ordering::Relaxed)
    }

    fn world_alive(&self) -> bool {
        process_exists(self.world_pid())
    }
}

/// Whether process `pid` exists (a zombie not yet reaped still does).
pub(crate) fn process_exists(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    // SAFETY: signal 0 only checks that the process exists; nothing is delivered.
    let result = unsafe { libc::kill(pid, 0) };
    result == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// The tick tag stored in the acknowledgement word.
fn tag(tick: u64) -> u32 {
    (tick as u32) & (u32::MAX >> COUNT_BITS)
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;
    use std::time::{Duration, Instant};

    use super::{AgentPlacement, JoinClaim, SyncBlock};

    /// A sync block in shared memory whose file is removed when the test ends, passed or not.
    struct TestBlock {
        block: SyncBlock,
        path: PathBuf,
    }

    impl TestBlock {
        /// `robots` robots in chains of `chain_len`, every robot with a joined agent.
        fn joined(name: &str, robots: u32, chain_len: u32) -> TestBlock {
            let path = PathBuf::from(format!("/dev/shm/swarm-test-{}-{name}", std::process::id()));
            let block = SyncBlock::create(&path, robots, chain_len, AgentPlacement::default())
                .expect("create the block");
            for robot in 0..robots {
                let deadline = Instant::now() + Duration::from_secs(1);
                assert!(matches!(
                    block.claim_robot(robot, deadline),
                    JoinClaim::Claimed
                ));
                block.announce_ready(robot);
            }
            TestBlock { block, path }
        }
    }

    impl Drop for TestBlock {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.path);
        }
    }

    #[test]
    fn a_started_chain_changes_only_its_own_wake_word_and_one_agent_spreads_it() {
        let test = TestBlock::joined("chain-start", 8, 4);
        let block = &test.block;
        block.open_tick(1);
        block.start_chain(0, 1);
        assert_eq!((block.chain_word(3), block.chain_word(4)), (1, 0));
        // The first agent of chain 0 to run wakes the others; later ones, and later calls, do not.
        assert!(block.spread(2, 1));
        assert!(!block.spread(0, 1));
        // A death notice wakes nobody: no robot waits for another one's answer.
        block.mark_dead(5);
        assert_eq!(block.chain_word(4), 0);
        block.start_chain(4, 1);
        assert_eq!(block.chain_word(7), 1);
        assert!(block.spread(7, 1));
        assert!(block.spread(1, 2), "a new tick is spread again");
    }

    #[test]
    fn the_rescue_wakes_started_chains_that_still_wait_for_answers() {
        let test = TestBlock::joined("chain-rescue", 8, 4);
        let block = &test.block;
        block.open_tick(1);
        block.start_chain(0, 1);
        assert_eq!(block.rescue(1), 1, "chain 0 started, chain 1 not yet");
        for robot in 0..4 {
            block.claim(robot, 1);
        }
        block.start_chain(4, 1);
        assert_eq!(block.rescue(1), 1, "chain 0 is done, chain 1 still waits");
        for robot in 4..8 {
            block.claim(robot, 1);
        }
        assert_eq!(block.rescue(1), 0);
    }
}
