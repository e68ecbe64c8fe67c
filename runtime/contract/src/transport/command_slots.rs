//! The run's command slots: one slot per robot in one shared-memory file of the run
//! (`/dev/shm/iox2_<run>_commands`), where the robot's agent writes its answer to a tick and the world reads it.
//!
//! Commands used to travel through one iceoryx2 blackboard per robot. A blackboard admits one writer, so N
//! writers took N services: at 1,000 robots the world created 1,000 services before the first tick (0.2-0.3 s of
//! a core), every agent opened one with a writer port and an entry (about 140 us each), and the run's clean-up
//! removed their files again. One file, created once by the world and mapped by every agent, costs none of that
//! (docs/transport.md, "Command slots").
//!
//! Each slot begins with a state word: the process id of the agent writing the slot in its upper half (0 while
//! nobody is), the number of finished writes in its lower half. A writer takes the slot by putting its pid there,
//! checks that it is still its robot's agent, copies the command (and the outbox) in, and frees the slot with the
//! count advanced. A reader copies the command out between two loads of the state word and keeps the copy only
//! when both loads are equal and show no writer (a sequence lock). Because writers exclude each other, an agent
//! that lost its robot (frozen, then replaced) can neither mix its bytes into its successor's nor have a command
//! of its own counted.

use std::mem::{MaybeUninit, size_of};
use std::path::Path;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering, fence};
use std::time::{Duration, Instant};

use super::TransportError;
use super::shared_map::SharedMap;
use super::sync_block::process_exists;
use crate::mail::Mailbox;
use crate::messages::{ActuatorCommand, MESSAGE_VERSION};

/// Identifies a command slots file ("SWARMCMD").
const MAGIC: u64 = 0x5357_4152_4d43_4d44;
/// Layout version of the file.
const LAYOUT_VERSION: u32 = 1;
/// A cache line: the header and every slot start on one, so that no two robots' slots share a line.
const LINE: usize = 64;
/// How often a joining agent looks again at a slot held by a predecessor stopped in the middle of a write.
const HOLDER_POLL: Duration = Duration::from_millis(10);
/// Bytes from the start of one robot's command slot to the next.
const COMMAND_STRIDE: usize =
    (size_of::<SlotHead>() + size_of::<ActuatorCommand>()).div_ceil(LINE) * LINE;
/// Bytes from the start of one robot's outbox to the next (runs with mail only).
const OUTBOX_STRIDE: usize = size_of::<Mailbox>().div_ceil(LINE) * LINE;

/// The first line of the file.
#[repr(C)]
struct Header {
    magic: AtomicU64,
    version: AtomicU32,
    /// The `MESSAGE_VERSION` of the commands in the slots.
    message_version: AtomicU32,
    capacity: AtomicU32,
    /// 1 when every robot has an outbox after the command slots.
    mail: AtomicU32,
}

const _: () = assert!(size_of::<Header>() <= LINE);

/// The line a command slot begins with; the command follows it.
#[repr(C, align(64))]
struct SlotHead {
    /// The writer's pid (upper 32 bits, 0: none) and the number of finished writes (lower 32 bits).
    state: AtomicU64,
}

/// The state word of a slot taken by `writer`, from the free state `state`.
fn taken(state: u64, writer: u32) -> u64 {
    (u64::from(writer) << 32) | (state & u64::from(u32::MAX))
}

/// The state word of a slot freed after a write, from the free state `state` before it.
fn written(state: u64) -> u64 {
    u64::from((state as u32).wrapping_add(1))
}

/// The pid of the process writing a slot in state `state`, 0 if none.
fn holder(state: u64) -> u32 {
    (state >> 32) as u32
}

/// A mapping of a run's command slots file.
pub(crate) struct CommandSlots {
    map: SharedMap,
    capacity: u32,
    mail: bool,
}

impl CommandSlots {
    fn size_for(capacity: u32, mail: bool) -> usize {
        let outboxes = if mail { OUTBOX_STRIDE } else { 0 };
        LINE + capacity as usize * (COMMAND_STRIDE + outboxes)
    }

    /// World side: creates the file at `path` with one slot for each of `capacity` robots, each holding an idle
    /// command, and an outbox per robot if the run has `mail`; fails if it exists.
    pub(crate) fn create(
        path: &Path,
        capacity: u32,
        mail: bool,
    ) -> Result<CommandSlots, TransportError> {
        let map = SharedMap::create(path, Self::size_for(capacity, mail)).map_err(|source| {
            TransportError::RunFile {
                path: path.to_path_buf(),
                source,
            }
        })?;
        let slots = CommandSlots {
            map,
            capacity,
            mail,
        };
        for robot in 0..capacity {
            // SAFETY: robot < capacity; nobody else has the file yet.
            unsafe { slots.command(robot).write(ActuatorCommand::idle(robot, 0)) };
            if let Some(outbox) = slots.outbox(robot) {
                // SAFETY: as above.
                unsafe { outbox.write(Mailbox::empty(robot)) };
            }
        }
        let header = slots.header();
        header.version.store(LAYOUT_VERSION, Ordering::Relaxed);
        header
            .message_version
            .store(MESSAGE_VERSION, Ordering::Relaxed);
        header.capacity.store(capacity, Ordering::Relaxed);
        header.mail.store(u32::from(mail), Ordering::Relaxed);
        header.magic.store(MAGIC, Ordering::Release);
        Ok(slots)
    }

    /// Agent side: maps the existing file at `path`, checking that this build can read it.
    pub(crate) fn open(path: &Path) -> Result<CommandSlots, TransportError> {
        let invalid = |reason: String| TransportError::InvalidRunFile {
            path: path.to_path_buf(),
            reason,
        };
        let io_err = |source| TransportError::RunFile {
            path: path.to_path_buf(),
            source,
        };
        let (file, file_len) = SharedMap::open_file(path).map_err(io_err)?;
        if file_len < LINE as u64 {
            return Err(invalid(format!(
                "{file_len} bytes is too short for a header"
            )));
        }
        let map = SharedMap::map(&file, file_len as usize).map_err(io_err)?;
        // SAFETY: the mapping is at least one line long; every header field is an atomic.
        let header = unsafe { &*map.base().cast::<Header>() };
        if header.magic.load(Ordering::Acquire) != MAGIC {
            return Err(invalid("not a swarm command slots file (bad magic)".into()));
        }
        let version = (
            header.version.load(Ordering::Relaxed),
            header.message_version.load(Ordering::Relaxed),
        );
        if version != (LAYOUT_VERSION, MESSAGE_VERSION) {
            return Err(invalid(format!(
                "layout version {}, message version {}; this build speaks {LAYOUT_VERSION} and \
                 {MESSAGE_VERSION}",
                version.0, version.1
            )));
        }
        let capacity = header.capacity.load(Ordering::Relaxed);
        let mail = header.mail.load(Ordering::Relaxed) != 0;
        let len = Self::size_for(capacity, mail);
        if map.len() < len {
            return Err(invalid(format!(
                "{file_len} bytes cannot hold {capacity} robots' slots ({len} bytes)"
            )));
        }
        Ok(CommandSlots {
            map,
            capacity,
            mail,
        })
    }

    fn header(&self) -> &Header {
        // SAFETY: the mapping starts with the header; every field is an atomic.
        unsafe { &*self.map.base().cast::<Header>() }
    }

    /// The start of `robot`'s command slot: its [`SlotHead`], then its command.
    fn slot(&self, robot: u32) -> *mut u8 {
        assert!(robot < self.capacity, "robot {robot} has no command slot");
        // SAFETY: robot < capacity, and the mapping holds `capacity` slots after the header line.
        unsafe { self.map.base().add(LINE + robot as usize * COMMAND_STRIDE) }
    }

    fn head(&self, robot: u32) -> &SlotHead {
        // SAFETY: a slot starts with its head, a line-aligned atomic.
        unsafe { &*self.slot(robot).cast::<SlotHead>() }
    }

    /// Where `robot`'s command lies; read and written only under its slot's state word.
    fn command(&self, robot: u32) -> *mut ActuatorCommand {
        // SAFETY: the command follows the head within the slot.
        unsafe {
            self.slot(robot)
                .add(size_of::<SlotHead>())
                .cast::<ActuatorCommand>()
        }
    }

    /// Where `robot`'s outbox lies in a run with mail; read and written only under its command slot's state word.
    fn outbox(&self, robot: u32) -> Option<*mut Mailbox> {
        if !self.mail || robot >= self.capacity {
            return None;
        }
        let offset =
            LINE + self.capacity as usize * COMMAND_STRIDE + robot as usize * OUTBOX_STRIDE;
        // SAFETY: robot < capacity, and a file with mail holds `capacity` outboxes after the command slots.
        Some(unsafe { self.map.base().add(offset).cast::<Mailbox>() })
    }

    /// Number of robots the file has slots for.
    pub(crate) fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Agent side, once as it joins: makes `robot`'s slot `writer`'s (its pid) and puts an idle command in it, so
    /// nothing a predecessor wrote is read as its answer. A predecessor that died in the middle of a write left
    /// the slot taken, and the slot is taken back; one that is alive and stopped in the middle of a write is
    /// waited for until `deadline`.
    pub(crate) fn take_over(
        &self,
        robot: u32,
        writer: u32,
        deadline: Instant,
    ) -> Result<(), TransportError> {
        let head = self.head(robot);
        loop {
            let state = head.state.load(Ordering::Acquire);
            let held_by = holder(state);
            if held_by == 0 || held_by == writer || !process_exists(held_by) {
                let free = state & u64::from(u32::MAX);
                if head
                    .state
                    .compare_exchange(
                        state,
                        taken(free, writer),
                        Ordering::Acquire,
                        Ordering::Relaxed,
                    )
                    .is_ok()
                {
                    self.fill(robot, free, &ActuatorCommand::idle(robot, 0), None);
                    return Ok(());
                }
                continue;
            }
            if Instant::now() >= deadline {
                return Err(TransportError::CommandSlotHeld {
                    robot,
                    pid: held_by,
                });
            }
            std::thread::sleep(HOLDER_POLL);
        }
    }

    /// Agent side, every tick: writes `command`, and `outbox` if the run has mail, into `robot`'s slot as
    /// `writer`, provided `owns()` still says `writer` is the robot's agent once the slot is taken. Returns
    /// whether it wrote; it does not when the robot has another agent, or when a predecessor is stopped in the
    /// middle of a write ([`CommandSlots::take_over`] waited for it, so only a predecessor continued since can).
    #[unsafe(link_section = "swarm_hot")]
    pub(crate) fn write(
        &self,
        robot: u32,
        writer: u32,
        owns: impl FnOnce() -> bool,
        command: &ActuatorCommand,
        outbox: Option<&Mailbox>,
    ) -> bool {
        let head = self.head(robot);
        let state = head.state.load(Ordering::Relaxed);
        if holder(state) != 0
            || head
                .state
                .compare_exchange(
                    state,
                    taken(state, writer),
                    Ordering::Acquire,
                    Ordering::Relaxed,
                )
                .is_err()
        {
            return false;
        }
        if !owns() {
            head.state.store(state, Ordering::Release);
            return false;
        }
        self.fill(robot, state, command, outbox);
        true
    }

    /// With `robot`'s slot taken by the caller from the free state `free`: copies `command`, and `outbox` if the
    /// run has mail, in and frees the slot with the count advanced.
    #[unsafe(link_section = "swarm_hot")]
    fn fill(&self, robot: u32, free: u64, command: &ActuatorCommand, outbox: Option<&Mailbox>) {
        // A reader that sees any byte written below sees the slot taken when it loads the state again.
        fence(Ordering::Release);
        if let (Some(outbox), Some(slot)) = (outbox, self.outbox(robot)) {
            // SAFETY: the slot is taken by the caller; source and destination are distinct memory.
            unsafe { std::ptr::copy_nonoverlapping(outbox, slot, 1) };
        }
        // SAFETY: as above.
        unsafe { std::ptr::copy_nonoverlapping(command, self.command(robot), 1) };
        self.head(robot)
            .state
            .store(written(free), Ordering::Release);
    }

    /// World side: `robot`'s last command and the state word it was read under (for
    /// [`CommandSlots::read_outbox`]); `None` while a writer has the slot.
    pub(crate) fn read(&self, robot: u32) -> Option<(ActuatorCommand, u64)> {
        let head = self.head(robot);
        let before = head.state.load(Ordering::Acquire);
        if holder(before) != 0 {
            return None;
        }
        Some((
            self.copy_unchanged(robot, self.command(robot), before)?,
            before,
        ))
    }

    /// World side: `robot`'s outbox as written with the command [`CommandSlots::read`] returned with `state`;
    /// `None` without mail, or when the agent has written its slot since.
    pub(crate) fn read_outbox(&self, robot: u32, state: u64) -> Option<Mailbox> {
        let slot = self.outbox(robot)?;
        if self.head(robot).state.load(Ordering::Acquire) != state {
            return None;
        }
        self.copy_unchanged(robot, slot, state)
    }

    /// Copies the value at `from`, part of `robot`'s slot, whose state word the caller has just loaded (with
    /// acquire ordering) as the free state `state`; `None` if the word has changed by the end of the copy, i.e. a
    /// writer may have touched the value meanwhile.
    fn copy_unchanged<T>(&self, robot: u32, from: *const T, state: u64) -> Option<T> {
        let mut copy = MaybeUninit::<T>::uninit();
        // SAFETY: `from` points at a value of the slot; a copy torn by a concurrent writer is detected below and
        // dropped before it is used.
        unsafe { std::ptr::copy_nonoverlapping(from, copy.as_mut_ptr(), 1) };
        fence(Ordering::Acquire);
        // SAFETY: the state word did not change during the copy, so it is one whole value a writer stored.
        (self.head(robot).state.load(Ordering::Relaxed) == state)
            .then(|| unsafe { copy.assume_init() })
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;
    use std::time::{Duration, Instant};

    use super::CommandSlots;
    use crate::mail::Mailbox;
    use crate::messages::ActuatorCommand;

    /// Command slots in shared memory whose file is removed when the test ends, passed or not.
    struct TestSlots {
        slots: CommandSlots,
        path: PathBuf,
    }

    impl TestSlots {
        fn new(name: &str, robots: u32, mail: bool) -> TestSlots {
            let path = PathBuf::from(format!(
                "/dev/shm/swarm-test-{}-slots-{name}",
                std::process::id()
            ));
            let slots = CommandSlots::create(&path, robots, mail).expect("create the slots");
            TestSlots { slots, path }
        }
    }

    impl Drop for TestSlots {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.path);
        }
    }

    fn command(robot: u32, tick: u64) -> ActuatorCommand {
        let mut command = ActuatorCommand::idle(robot, tick);
        command.wheels = [tick as f32, -(tick as f32)];
        command
    }

    #[test]
    fn an_agent_reads_what_another_mapping_wrote_and_only_its_own_robot_changes() {
        let test = TestSlots::new("roundtrip", 3, true);
        let agent = CommandSlots::open(&test.path).expect("open the slots");
        assert_eq!(agent.capacity(), 3);
        let mut outbox = Mailbox::empty(1);
        outbox.tick = 7;
        assert!(agent.write(1, 42, || true, &command(1, 7), Some(&outbox)));
        let (read, state) = test.slots.read(1).expect("a whole command");
        assert_eq!(read, command(1, 7));
        assert_eq!(test.slots.read_outbox(1, state), Some(outbox));
        assert_eq!(
            test.slots.read(0).map(|(c, _)| c),
            Some(ActuatorCommand::idle(0, 0))
        );
        assert_eq!(
            test.slots.read(2).map(|(c, _)| c),
            Some(ActuatorCommand::idle(2, 0))
        );
        // A later write makes the earlier state's outbox unreadable.
        assert!(agent.write(1, 42, || true, &command(1, 8), None));
        assert_eq!(test.slots.read_outbox(1, state), None);
    }

    #[test]
    fn a_writer_that_no_longer_owns_its_robot_writes_nothing() {
        let test = TestSlots::new("owner", 1, false);
        assert!(test.slots.write(0, 42, || true, &command(0, 3), None));
        assert!(!test.slots.write(0, 42, || false, &command(0, 4), None));
        assert_eq!(test.slots.read(0).map(|(c, _)| c), Some(command(0, 3)));
        // The refused write left the slot free for the owner.
        assert!(test.slots.write(0, 43, || true, &command(0, 4), None));
        assert_eq!(test.slots.read(0).map(|(c, _)| c), Some(command(0, 4)));
    }

    #[test]
    fn a_slot_left_taken_by_a_dead_writer_is_taken_over_and_one_held_by_a_live_one_is_not() {
        let test = TestSlots::new("takeover", 1, false);
        let slots = &test.slots;
        assert!(slots.write(0, 42, || true, &command(0, 5), None));
        // A writer that died in the middle of a write (a pid no process has) left the slot taken.
        let head = &slots.head(0).state;
        let dead = u32::MAX - 1;
        head.store(
            super::taken(head.load(std::sync::atomic::Ordering::Relaxed), dead),
            std::sync::atomic::Ordering::Release,
        );
        assert_eq!(slots.read(0), None, "a taken slot has no whole command");
        assert!(!slots.write(0, 43, || true, &command(0, 6), None));
        slots
            .take_over(0, 43, Instant::now())
            .expect("a dead writer's slot is taken over");
        assert_eq!(
            slots.read(0).map(|(c, _)| c),
            Some(ActuatorCommand::idle(0, 0))
        );
        assert!(slots.write(0, 43, || true, &command(0, 6), None));
        // A live process in the middle of a write (this one, as another writer) is waited for.
        let state = head.load(std::sync::atomic::Ordering::Relaxed);
        head.store(
            super::taken(state, std::process::id()),
            std::sync::atomic::Ordering::Release,
        );
        let error = slots
            .take_over(0, 44, Instant::now() + Duration::from_millis(30))
            .expect_err("a live writer keeps its slot");
        assert!(
            error.to_string().contains(&std::process::id().to_string()),
            "{error}"
        );
    }

    #[test]
    fn a_file_too_short_for_its_robots_is_refused() {
        let test = TestSlots::new("short", 4, true);
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(&test.path)
            .expect("open the file");
        file.set_len(super::LINE as u64 + super::COMMAND_STRIDE as u64)
            .expect("truncate");
        let error = CommandSlots::open(&test.path).err().expect("refused");
        assert!(
            error.to_string().contains("cannot hold 4 robots"),
            "{error}"
        );
    }

    #[test]
    fn a_file_of_another_layout_is_refused_with_its_path() {
        let test = TestSlots::new("layout", 1, false);
        let header = test.slots.header();
        header
            .version
            .store(99, std::sync::atomic::Ordering::Release);
        let error = CommandSlots::open(&test.path).err().expect("refused");
        let message = error.to_string();
        assert!(message.contains("layout version 99"), "{message}");
        assert!(
            message.contains(&test.path.display().to_string()),
            "{message}"
        );
    }
}
