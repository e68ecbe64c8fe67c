//! An agent's side of the lockstep: join a run for one robot, sleep on its chain's wake word until the chain
//! starts an open tick (waking the rest of the chain if it is the first to run), load the robot's own frame
//! from the frame board, and answer by writing its robot's command slot.
//!
//! It must never answer for another robot (it writes its robot's command slot only, and only while the robot is
//! its own) and never answer a tick the world has not opened yet, nor the same tick twice.
//!
//! Every function an agent runs once per tick (here, in the sync block and futex modules, in the player and in
//! `robot-agent`'s tick loop) is placed in the link section `swarm_hot`. With a thousand agent processes on two
//! cores, each agent starts its tick with an empty TLB: the code it runs, scattered over the binary, cost one
//! page walk per page; gathered in one section it spans a few adjacent pages (docs/transport.md, "Agent code
//! locality"). The section is an ordinary executable one that the linker places after `.text`.

use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::reader::{EntryHandle, Reader, ReaderCreateError};
use iceoryx2::prelude::{ZeroCopySend, ipc};

use super::TransportError;
use super::command_slots::CommandSlots;
use super::run::RunSpec;
use super::services::{self, Board};
use super::sync_block::{JoinClaim, SyncBlock};
use super::world_watch::WorldEndNotice;
use super::{placement, priority};
use crate::mail::Mailbox;
use crate::messages::{ActuatorCommand, SensorFrame};

/// Default number of polls of the chain's wake word before an agent sleeps on it (see [`AgentLink::set_spin`]).
pub const DEFAULT_AGENT_SPIN: u32 = 0;

/// A tick the world opened for this agent's robot: the robot's frame, answered at most once with
/// [`Tick::answer`]. Dropping it leaves the tick unanswered (an agent that leaves the run, or a frozen one).
pub struct Tick<'link> {
    link: &'link mut AgentLink,
}

impl Tick<'_> {
    /// The robot's frame.
    pub fn frame(&self) -> &SensorFrame {
        &self.link.frame
    }

    /// The tick's number.
    pub fn number(&self) -> u64 {
        self.link.frame.tick
    }

    /// The robot's frame, the messages delivered to it this tick and an empty outbox for what it sends in its
    /// answer. In a run without mail the inbox is always empty and the outbox refuses every message
    /// ([`SendError::NoMedium`](crate::mail::SendError)); neither is touched per tick, so a robot that does not
    /// talk pays nothing for them. The inbox is loaded from the inbox board only when the frame says messages
    /// wait.
    #[unsafe(link_section = "swarm_hot")]
    pub fn parts(&mut self) -> (&SensorFrame, &Mailbox, &mut Mailbox) {
        let link = &mut *self.link;
        let mail = &mut *link.mail;
        if !link.has_mail {
            // Not even a look at the mailboxes: they are on a page of their own.
            return (&link.frame, &mail.inbox, &mut mail.outbox);
        }
        if let Some(ports) = &mail.ports {
            let tick = link.frame.tick;
            mail.inbox.clear();
            if link.frame.inbox_len > 0 {
                let posted = *ports.inbox.get();
                if posted.tick == tick {
                    mail.inbox = posted;
                }
            }
            mail.outbox.clear();
        }
        (&link.frame, &mail.inbox, &mut mail.outbox)
    }

    /// Sends `command` as the robot's answer to this tick, with its `tick` and `robot` fields set here, and the
    /// messages of its outbox ([`Tick::parts`]; the world decides their fate and delivers them in the next tick);
    /// counts the robot as answered (the last answer of the tick wakes the world).
    #[unsafe(link_section = "swarm_hot")]
    pub fn answer(self, command: &mut ActuatorCommand) {
        command.outbox_len = 0;
        let link = self.link;
        let (robot, writer, tick) = (link.robot, link.pid, link.frame.tick);
        let mut posted = None;
        if link.has_mail {
            let outbox = &link.mail.outbox;
            if !outbox.is_empty() {
                let mut mailbox = *outbox;
                mailbox.tick = tick;
                mailbox.owner = robot;
                command.outbox_len = outbox.messages().len() as u8;
                posted = Some(mailbox);
            }
        }
        command.tick = tick;
        command.robot = robot;
        let sync = &link.sync;
        // An agent whose robot another agent has claimed since (it was frozen, then replaced) is not counted.
        let owns = || sync.claimer(robot) == writer;
        if link
            .slots
            .write(robot, writer, owns, command, posted.as_ref())
        {
            sync.claim(robot, tick);
        }
    }
}

/// The iceoryx2 side of an agent: its node and its robot's entry of the frame board. The entry handle keeps its
/// port and service alive; the other fields are only held, in drop order.
struct Ports {
    frame_entry: EntryHandle<ipc::Service, u32, SensorFrame>,
    _frame_reader: Reader<ipc::Service, u32>,
    _frame_board: Board,
    _node: Node<ipc::Service>,
}

/// An agent's mailboxes, on the heap so that the per-tick path (the agent's stack and its link) stays as small as
/// it was without them: with `ports` (runs with mail), the inbox and outbox of the current tick; without, an empty
/// inbox and a closed outbox that nothing reads.
struct Mail {
    inbox: Mailbox,
    outbox: Mailbox,
    ports: Option<MailPorts>,
}

/// An agent's inbox port (runs with mail only; its outbox is in its command slot). Fields drop in declaration
/// order.
struct MailPorts {
    inbox: EntryHandle<ipc::Service, u32, Mailbox>,
    _inbox_reader: Reader<ipc::Service, u32>,
    _inbox_board: Board,
}

/// A board with one entry per robot, the agent's reader of it and its robot's entry (the caller keeps them so that the
/// entry drops first and the board last).
type OwnEntry<T> = (
    Board,
    Reader<ipc::Service, u32>,
    EntryHandle<ipc::Service, u32, T>,
);

/// A robot's iceoryx2 node in a run, made before the agent joins (see [`AgentLink::join_on`]). A node needs only the
/// run's iceoryx2 root, not the world's services, so an agent started before the world is ready makes it while it
/// waits instead of after (docs/transport.md, "Starting the agents").
pub struct AgentNode {
    robot: u32,
    node: Node<ipc::Service>,
}

impl AgentNode {
    /// Creates the node of robot `robot`'s agent in `run`.
    pub fn create(run: &RunSpec, robot: u32) -> Result<AgentNode, TransportError> {
        let node = services::node(run, &format!("robot-{robot}"))?;
        Ok(AgentNode { robot, node })
    }
}

/// Who ends an agent whose world process ends without stopping the run (killed, or crashed).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorldEnd {
    /// The agent itself: a thread of the agent watches the world process and wakes the agent, whose wait then
    /// fails with [`TransportError::WorldGone`]. For agents started by hand or by a host.
    Watched,
    /// The agent's parent: `swarm run`'s launcher kills every agent when its world dies, and the kernel kills the
    /// agents of a launcher that dies (`PR_SET_PDEATHSIG`). The agent then starts no thread of its own (creating
    /// and ending it cost about 60 us per agent) and sleeps without a timer.
    ByParent,
}

/// An agent's end of a run's local transport, for one robot.
pub struct AgentLink {
    robot: u32,
    /// This process's id: it writes the robot's command slot as that.
    pid: u32,
    spin: u32,
    /// The last tick handed out by [`AgentLink::next_tick`] (0: none yet).
    last_tick: u64,
    /// The robot's frame of the last tick loaded; [`Tick::frame`] lends it out.
    frame: SensorFrame,
    /// Whether the run has mail: read on every tick instead of `mail`, which is on a page of its own.
    has_mail: bool,
    /// The robot's mailboxes (see [`Mail`]); their ports drop before the node in `ports`.
    mail: Box<Mail>,
    ports: Ports,
    slots: CommandSlots,
    sync: Arc<SyncBlock>,
    /// Notices the end of the world process, so that waits need no timeout where it can.
    world_end: WorldEndNotice,
}

impl AgentLink {
    /// Joins robot `robot` of `run` with the default wait for a predecessor
    /// ([`Limits::agent_board_wait_ms`](crate::limits::Limits)); see [`AgentLink::join_waiting`].
    pub fn join(run: &RunSpec, robot: u32) -> Result<AgentLink, TransportError> {
        AgentLink::join_waiting(
            run,
            robot,
            crate::limits::Limits::default().agent_board_wait(),
        )
    }

    /// Joins `run` as the agent of `robot`, waiting up to `board_wait` for a dead predecessor's death notice.
    /// Fails with a message naming the limit when the run has no place for it, or when another live agent
    /// already runs this robot.
    pub fn join_waiting(
        run: &RunSpec,
        robot: u32,
        board_wait: Duration,
    ) -> Result<AgentLink, TransportError> {
        AgentLink::join_with(run, robot, None, board_wait, WorldEnd::Watched)
    }

    /// Joins `run` as the agent of `node`'s robot on that node, as [`AgentLink::join_waiting`] does on a node of
    /// its own; `world_end` says who ends the agent if the world process ends without stopping the run.
    pub fn join_on(
        run: &RunSpec,
        node: AgentNode,
        board_wait: Duration,
        world_end: WorldEnd,
    ) -> Result<AgentLink, TransportError> {
        AgentLink::join_with(run, node.robot, Some(node.node), board_wait, world_end)
    }

    fn join_with(
        run: &RunSpec,
        robot: u32,
        node: Option<Node<ipc::Service>>,
        board_wait: Duration,
        world_end: WorldEnd,
    ) -> Result<AgentLink, TransportError> {
        let sync = Arc::new(SyncBlock::open(&run.sync_block_path())?);
        let capacity = sync.capacity();
        if robot >= capacity {
            return Err(TransportError::RobotOutOfRange { robot, capacity });
        }
        if let JoinClaim::Taken = sync.claim_robot(robot, Instant::now() + board_wait) {
            return Err(TransportError::RobotTaken { robot });
        }
        let pid = std::process::id();
        match Self::connect(run, robot, node, &sync, pid, board_wait) {
            Ok((ports, slots, mail_ports)) => {
                let has_mail = mail_ports.is_some();
                let mail = Box::new(Mail {
                    inbox: Mailbox::empty(robot),
                    outbox: match mail_ports {
                        Some(_) => Mailbox::empty(robot),
                        None => Mailbox::closed(robot),
                    },
                    ports: mail_ports,
                });
                let placement = sync.placement();
                if placement.pin_chains {
                    match placement::pin_to_chain_cpu(robot, sync.chain_len()) {
                        Ok(cpu) => tracing::debug!(robot, cpu, "pinned to the CPU of its chain"),
                        Err(e) => tracing::warn!(robot, "running unpinned: {e}"),
                    }
                }
                // A replacement agent must not answer a tick its predecessor already answered.
                let last_tick = sync.tick();
                let world_end = match world_end {
                    WorldEnd::ByParent => WorldEndNotice::Parent,
                    WorldEnd::Watched => {
                        let watched = Arc::clone(&sync);
                        WorldEndNotice::watch(sync.world_pid(), move || watched.nudge(robot))
                    }
                };
                if placement.realtime
                    && let Err(e) = priority::enter_realtime(priority::AGENT_PRIORITY)
                {
                    tracing::warn!(robot, "running at normal priority: {e}");
                }
                sync.announce_ready(robot);
                Ok(AgentLink {
                    robot,
                    pid,
                    spin: DEFAULT_AGENT_SPIN,
                    last_tick,
                    frame: SensorFrame::empty(robot),
                    ports,
                    slots,
                    sync,
                    world_end,
                    has_mail,
                    mail,
                })
            }
            Err(e) => {
                sync.release_claim(robot);
                Err(e)
            }
        }
    }

    fn connect(
        run: &RunSpec,
        robot: u32,
        node: Option<Node<ipc::Service>>,
        sync: &SyncBlock,
        pid: u32,
        board_wait: Duration,
    ) -> Result<(Ports, CommandSlots, Option<MailPorts>), TransportError> {
        let slots = CommandSlots::open(&run.command_slots_path())?;
        if slots.capacity() != sync.capacity() {
            return Err(TransportError::InvalidRunFile {
                path: run.command_slots_path(),
                reason: format!(
                    "slots for {} robots in a run of {}",
                    slots.capacity(),
                    sync.capacity()
                ),
            });
        }
        slots.take_over(robot, pid, Instant::now() + board_wait)?;
        let node = match node {
            Some(node) => node,
            None => AgentNode::create(run, robot)?.node,
        };
        let (frame_board, frame_reader, frame_entry) = Self::read_own_entry::<SensorFrame>(
            &node,
            &services::frame_service_name(),
            robot,
            sync.capacity(),
        )?;
        let mail = if sync.placement().mail {
            Some(Self::connect_inbox(&node, robot, sync.capacity())?)
        } else {
            None
        };
        let ports = Ports {
            frame_entry,
            _frame_reader: frame_reader,
            _frame_board: frame_board,
            _node: node,
        };
        Ok((ports, slots, mail))
    }

    fn connect_inbox(
        node: &Node<ipc::Service>,
        robot: u32,
        capacity: u32,
    ) -> Result<MailPorts, TransportError> {
        let (board, reader, inbox) = Self::read_own_entry::<Mailbox>(
            node,
            &services::inbox_service_name(),
            robot,
            capacity,
        )?;
        Ok(MailPorts {
            inbox,
            _inbox_reader: reader,
            _inbox_board: board,
        })
    }

    /// Opens the board `name` that has one entry per robot (of `capacity`) and this robot's entry in it.
    fn read_own_entry<T: Copy + ZeroCopySend>(
        node: &Node<ipc::Service>,
        name: &str,
        robot: u32,
        capacity: u32,
    ) -> Result<OwnEntry<T>, TransportError> {
        let board = services::open_per_robot_board(node, name, robot, capacity)?;
        let reader = board.reader_builder().create().map_err(|e| match e {
            ReaderCreateError::ExceedsMaxSupportedReaders => TransportError::ServiceFull {
                robot,
                service: name.to_owned(),
                limit: capacity as usize + services::SPARE_AGENT_PLACES,
                what: "readers",
            },
            other => TransportError::iceoryx(format!("reading {name}"), other),
        })?;
        let entry = reader
            .entry::<T>(&robot)
            .map_err(|e| TransportError::iceoryx(format!("robot {robot}'s entry of {name}"), e))?;
        Ok((board, reader, entry))
    }

    /// Sends this robot's messages as participant `id` (default: the robot it joined as). A host's agent joins
    /// its local run as a slot and sends as its run-wide index.
    pub fn set_sender(&mut self, id: u32) {
        self.mail.outbox.owner = id;
    }

    /// The robot this agent runs.
    pub fn robot(&self) -> u32 {
        self.robot
    }

    /// How many times the agent polls its chain's wake word before it sleeps on it (default 0: the lockstep benchmark
    /// on 2 cores is fastest without agent polling). Polling only pays when every agent has a core to itself.
    pub fn set_spin(&mut self, polls: u32) {
        self.spin = polls;
    }

    /// Waits for the next tick the world opens and hands it out with this robot's frame; `None` when the world
    /// ended the run, [`TransportError::WorldGone`] when the world process died without ending it. An agent that
    /// fell behind skips straight to the newest tick.
    #[unsafe(link_section = "swarm_hot")]
    pub fn next_tick(&mut self) -> Result<Option<Tick<'_>>, TransportError> {
        loop {
            let seen = self.sync.chain_word(self.robot);
            if self.sync.stopped() {
                return Ok(None);
            }
            let open = self.sync.tick();
            if open > self.last_tick {
                // The world opens the tick before it writes the frames: until this robot's chain starts, the
                // frame is still the last tick's, and the chain's start changes its wake word.
                self.frame = *self.ports.frame_entry.get();
                if self.frame.tick == open {
                    self.last_tick = open;
                    self.sync.spread(self.robot, open);
                    return Ok(Some(Tick { link: self }));
                }
            }
            self.sync
                .wait_chain(self.robot, seen, self.spin, &self.world_end)
                .map_err(|pid| TransportError::WorldGone { pid })?;
        }
    }
}

impl AgentLink {
    /// Lets go of a run the world has ended without taking down this agent's iceoryx2 node one file at a time:
    /// the process is about to exit, and whoever created the run removes its shared memory as a whole. A robot
    /// that leaves a run still going drops its link instead, so a later agent can have its place.
    pub fn release_ended_run(self) {
        self.sync.leave(self.robot);
        std::mem::forget(self);
    }
}

impl Drop for AgentLink {
    fn drop(&mut self) {
        self.sync.leave(self.robot);
    }
}
