//! One share of a run on this host: its local run, its agents, and the lockstep of its robots with the world.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::Sender;
use std::time::{Duration, Instant};

use zenoh::Session;
use zenoh::Wait;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;

use crate::auth::Seal;
use crate::codec::{self, Header, Kind};
use crate::host_to_world::Reply;
use crate::session::zenoh_error;
use crate::world_to_host::{Assignment, FrameEntry, OrderAction};
use crate::{RemoteError, keys};
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::SupervisorSnapshot;
use swarm_contract::process::binaries::Binaries;
use swarm_contract::process::children::{AgentProcess, Children};
use swarm_contract::protocol::launcher_to_agent::{AgentArgs, RunArgs, start_agent};
use swarm_contract::protocol::resume::{ResumeError, ResumePoint};
use swarm_contract::run_dir;
use swarm_contract::transport::{CommandStatus, LinkConfig, RunSpec, WorldLink, priority};

use super::{
    Dropped, Event, HostOptions, IDLE_PERIOD, LOG_LINES_QUOTED, MAX_TICK_GAP, REPLACEMENT_POLL,
};

/// One run's share on this host.
pub(super) struct Share {
    pub(super) assignment: Assignment,
    robots: Vec<u32>,
    spec: RunSpec,
    link: Option<WorldLink>,
    /// Agent processes by slot; `None` once one ended (killed, exited, or a replacement that never joined): the
    /// robot is reported `Dead` then.
    children: Children,
    /// The robot-agent program and the folder of the agents' logs, for replacements.
    agent: PathBuf,
    logs: PathBuf,
    frames: Vec<FrameEntry>,
    replies: Vec<Reply>,
    /// Per slot: the messages its robot sent in the last tick, if any.
    outboxes: Vec<Option<Box<Mailbox>>>,
    buf: Vec<u8>,
    last_tick: u64,
    /// Number of the last fault order carried out (orders are numbered by the world, growing).
    pub(super) last_order: u64,
    /// How the share's messages are authenticated, and the channel its replies are tagged for.
    seal: Seal,
    replies_key: String,
    /// Frames messages dropped because they were not from the world (counted by zenoh's callback).
    unauthenticated: Arc<AtomicU64>,
    /// Whether a tick ran in which the share's live robots all answered (a rejoined share's robots are dead for
    /// the world at first).
    took_part: bool,
    pub(super) dropped: Dropped,
    publisher: Publisher<'static>,
    _frames: Subscriber<()>,
    _world: Subscriber<()>,
}

impl Share {
    /// Creates the local run, starts one agent per robot and waits until all joined.
    pub(super) fn start(
        session: &Session,
        options: &HostOptions,
        binaries: &Binaries,
        assignment: Assignment,
        sender: &Sender<Event>,
    ) -> Result<Share, RemoteError> {
        let count = assignment.robots.len() as u32;
        if count > options.capacity {
            return Err(RemoteError::Refused {
                host: options.name.clone(),
                reason: format!(
                    "{count} robots exceed the host's capacity of {} (swarm host --capacity)",
                    options.capacity
                ),
            });
        }
        if !assignment.config.is_file() {
            return Err(RemoteError::Refused {
                host: options.name.clone(),
                reason: format!(
                    "the configuration {} does not exist on this host (every host needs the experiment's files \
                     at the same path)",
                    assignment.config.display()
                ),
            });
        }
        let run = assignment.run;
        RunSpec::remove_dead_runs();
        let spec = RunSpec::unique();
        let mut link_config = LinkConfig::new(count.max(1));
        link_config.tick_deadline = Duration::from_millis(assignment.tick_deadline_ms);
        link_config.pin_chains = assignment.pin_agents;
        // A spin saves a wake-up of a few microseconds when the agents answer fast, next to a round trip to the
        // world of some 100 us per tick, and burns a CPU that another host on the same machine could use.
        link_config.spin = Duration::ZERO;
        link_config.realtime = priority::tick_at_realtime(assignment.realtime_priority);
        link_config.mail = assignment.mail;
        let link = WorldLink::create(&spec, link_config)?;
        let replies_key = keys::replies(run, &options.name);
        let publisher = session
            .declare_publisher(replies_key.clone())
            // The world never waits on a stalled link: a dropped batch is a missed tick.
            .congestion_control(CongestionControl::Drop)
            .express(true)
            .wait()
            .map_err(zenoh_error("declaring the replies publisher"))?;
        let frames_sender = sender.clone();
        let frames_key = keys::frames(run, &options.name);
        let frames_seal = options.seal.clone();
        let unauthenticated = Arc::new(AtomicU64::new(0));
        let frames_rejected = Arc::clone(&unauthenticated);
        let frames = session
            .declare_subscriber(frames_key.clone())
            .callback(move |sample| {
                // Checked here, so a message not from the world never reaches the daemon's queue.
                let bytes = sample.payload().to_bytes();
                match frames_seal.open(&frames_key, &bytes) {
                    Ok(payload) => {
                        let bytes = payload.to_vec();
                        let _ = frames_sender.send(Event::Frames { run, bytes });
                    }
                    Err(e) => {
                        frames_rejected.fetch_add(1, Ordering::Relaxed);
                        tracing::debug!("dropping a frames message: {e}");
                    }
                }
            })
            .wait()
            .map_err(zenoh_error("subscribing to the frames"))?;
        let world_sender = sender.clone();
        let world = session
            .liveliness()
            .declare_subscriber(keys::world_token(run))
            // With history the subscriber learns of the world's token, so zenoh also tells it when the token goes.
            .history(true)
            .callback(move |sample| {
                if sample.kind() == SampleKind::Delete {
                    let _ = world_sender.send(Event::WorldGone { run });
                }
            })
            .wait()
            .map_err(zenoh_error("watching the world"))?;
        write_compiled_supervisors(&options.logs, &assignment.compiled_supervisors)?;
        let robots: Vec<u32> = assignment.robots.iter().map(|(id, _)| *id).collect();
        let mut share = Share {
            robots,
            frames: vec![FrameEntry::empty(0); count as usize],
            replies: vec![Reply::Missing; count as usize],
            outboxes: vec![None; count as usize],
            buf: Vec::new(),
            last_tick: 0,
            last_order: 0,
            seal: options.seal.clone(),
            replies_key,
            unauthenticated,
            took_part: false,
            dropped: Dropped::default(),
            spec,
            link: Some(link),
            children: Children::default(),
            agent: binaries.agent.clone(),
            logs: options.logs.clone(),
            publisher,
            _frames: frames,
            _world: world,
            assignment,
        };
        share.spawn_agents()?;
        share.wait_joined(Duration::from_millis(share.assignment.join_timeout_ms))?;
        tracing::info!(
            run = format!("{run:016x}"),
            epoch = share.assignment.epoch,
            robots = count,
            "share started"
        );
        Ok(share)
    }

    /// Starts one agent per robot of the share (resuming from the world's record when the host rejoins).
    fn spawn_agents(&mut self) -> Result<(), RemoteError> {
        let resume = self.write_resume_points()?;
        for slot in 0..self.robots.len() {
            let child = self.spawn_agent(slot, resume.get(slot).cloned())?;
            self.children.agents.push(Some(child));
        }
        Ok(())
    }

    /// Starts the agent of `slot`, resuming from the point in `resume` if given.
    fn spawn_agent(
        &self,
        slot: usize,
        resume: Option<PathBuf>,
    ) -> Result<AgentProcess, RemoteError> {
        let (robot, controller) = &self.assignment.robots[slot];
        let run = RunArgs {
            run: self.spec.name().to_owned(),
            iox_root: self.spec.root_dir().to_path_buf(),
        };
        let mut args = AgentArgs::launched(
            &run,
            *robot,
            &self.assignment.config,
            controller,
            self.assignment.seed,
        );
        args.slot = Some(slot as u32);
        args.compiled_supervisors = self
            .assignment
            .compiled_supervisors
            .iter()
            .any(|(id, _)| id == controller)
            .then(|| run_dir::compiled_supervisors(&self.logs, controller).ok())
            .flatten();
        args.robots = self.assignment.robots_override;
        args.limits = self.assignment.limits.clone();
        args.resume = resume;
        let log_path = run_dir::agent_log_in(&self.logs, *robot);
        let log = std::fs::File::create(&log_path).map_err(|source| RemoteError::Io {
            what: format!("creating {}", log_path.display()),
            source,
        })?;
        start_agent(&self.agent, &args, log)
            .map(AgentProcess::from)
            .map_err(|source| RemoteError::Io {
                what: format!("starting {}", self.agent.display()),
                source,
            })
    }

    /// Carries out a fault order for robot `robot` of the share; the reason when it cannot be.
    pub(super) fn carry_out(&mut self, robot: u32, action: OrderAction) -> Result<(), String> {
        let slot = self
            .robots
            .iter()
            .position(|&r| r == robot)
            .ok_or_else(|| format!("robot {robot} is not in this host's share"))?;
        tracing::info!(robot, order = action.name(), "carrying out a fault order");
        let slot_id = slot as u32;
        let link = self.link.as_ref().ok_or("the share is ending")?;
        let agent = self.children.agents.get(slot).and_then(Option::as_ref);
        match action {
            OrderAction::Kill => {
                self.children.kill_agent(slot_id);
                link.mark_dead(slot_id).map_err(|e| e.to_string())
            }
            OrderAction::Freeze => {
                let agent = agent.ok_or_else(|| format!("robot {robot} has no running agent"))?;
                agent.signal(nix::sys::signal::Signal::SIGSTOP);
                link.mark_dead(slot_id).map_err(|e| e.to_string())
            }
            OrderAction::Thaw => {
                let agent = agent.ok_or_else(|| format!("robot {robot}'s agent is gone"))?;
                agent.signal(nix::sys::signal::Signal::SIGCONT);
                revive(link, slot_id, robot)
            }
            OrderAction::Skip => link.mark_dead(slot_id).map_err(|e| e.to_string()),
            OrderAction::Revive => revive(link, slot_id, robot),
            OrderAction::Respawn { tick, snapshot } => self.replace(slot, tick, *snapshot),
        }
    }

    /// Replaces the agent of `slot` with one that resumes from `snapshot` (of tick `tick`); returns once it joined.
    fn replace(
        &mut self,
        slot: usize,
        tick: u64,
        snapshot: SupervisorSnapshot,
    ) -> Result<(), String> {
        let robot = self.robots[slot];
        self.children.kill_agent(slot as u32);
        let link = self.link.as_ref().ok_or("the share is ending")?;
        link.mark_dead(slot as u32).map_err(|e| e.to_string())?;
        let point = self
            .write_resume_point(robot, tick, snapshot)
            .map_err(|e| e.to_string())?;
        let child = self
            .spawn_agent(slot, Some(point))
            .map_err(|e| e.to_string())?;
        tracing::info!(robot, pid = child.id(), "replacing the robot's agent");
        self.children.agents[slot] = Some(child);
        let deadline = Instant::now() + Duration::from_millis(self.assignment.join_timeout_ms);
        loop {
            let Some(link) = self.link.as_mut() else {
                return Err("the share is ending".into());
            };
            // Has the dead predecessor's iceoryx2 resources removed while waiting.
            let _ = link.wait_for_agents(REPLACEMENT_POLL);
            if link.agent_present(slot as u32) {
                return Ok(());
            }
            if let Some(failure) = self.failed_start(|s| s == slot) {
                return Err(failure);
            }
            if Instant::now() >= deadline {
                // A replacement that never joined is no agent of the slot: the robot stays `Dead`.
                self.children.kill_agent(slot as u32);
                return Err(format!(
                    "robot {robot}'s replacement agent did not join within {} ms",
                    self.assignment.join_timeout_ms
                ));
            }
        }
    }

    /// If one of `slots`' agents exited (others that exited are reaped as deaths): which robot, how, and the end
    /// of its log.
    fn failed_start(&mut self, slots: impl Fn(usize) -> bool) -> Option<String> {
        let (slot, status) = self
            .reap()
            .into_iter()
            .find(|(slot, _)| slots(*slot as usize))?;
        let robot = self.robots.get(slot as usize).copied().unwrap_or(slot);
        let log = run_dir::tail(&run_dir::agent_log_in(&self.logs, robot), LOG_LINES_QUOTED);
        Some(format!("robot {robot} failed to start ({status}):\n{log}"))
    }

    /// Whether this tick had live robots and every one of them answered (so each has stepped its controller).
    fn live_robots_answered(&self) -> bool {
        let mut live = self
            .frames
            .iter()
            .zip(&self.replies)
            .filter(|(entry, _)| entry.frame.alive != 0)
            .peekable();
        live.peek().is_some() && live.all(|(_, reply)| matches!(reply, Reply::Answered(_)))
    }

    /// Writes a rejoining share's resume points and returns them in slot order; none on a first assignment.
    fn write_resume_points(&self) -> Result<Vec<PathBuf>, RemoteError> {
        let robots = self.assignment.robots.iter().map(|(id, _)| *id);
        robots
            .zip(&self.assignment.resume)
            .map(|(robot, &(tick, snapshot))| Ok(self.write_resume_point(robot, tick, snapshot)?))
            .collect()
    }

    /// Writes robot `robot`'s resume point (`<logs>/resume/robot-<id>.json`, as in a run directory).
    fn write_resume_point(
        &self,
        robot: u32,
        tick: u64,
        snapshot: SupervisorSnapshot,
    ) -> Result<PathBuf, ResumeError> {
        ResumePoint {
            robot,
            tick,
            snapshot,
        }
        .write(&self.logs)
    }

    /// Waits for every agent to join; an agent that exits first fails the share with the end of its log.
    fn wait_joined(&mut self, timeout: Duration) -> Result<(), RemoteError> {
        let deadline = Instant::now() + timeout;
        loop {
            let Some(link) = &mut self.link else {
                return Ok(());
            };
            match link.wait_for_agents(IDLE_PERIOD) {
                Ok(()) => return Ok(()),
                Err(e) if Instant::now() >= deadline => return Err(e.into()),
                Err(_) => {}
            }
            if let Some(reason) = self.failed_start(|_| true) {
                return Err(RemoteError::Refused {
                    host: self.assignment.name.clone(),
                    reason,
                });
            }
        }
    }

    /// Reports agents that exited to the local transport, so their robots are `Dead` from now on; returns them.
    pub(super) fn reap(&mut self) -> Vec<(u32, std::process::ExitStatus)> {
        let exits = self.children.reap_agents();
        for &(slot, status) in &exits {
            let robot = self.robots.get(slot as usize).copied().unwrap_or(slot);
            tracing::warn!(robot, %status, "robot agent died");
            if let Some(link) = &self.link
                && let Err(e) = link.mark_dead(slot)
            {
                tracing::warn!(robot, "reporting the death: {e}");
            }
        }
        exits
    }

    /// Runs one local tick with a frames message and publishes the replies.
    pub(super) fn tick(&mut self, bytes: &[u8], max_payload: usize) -> Result<(), RemoteError> {
        let header = match codec::decode_batch(
            bytes,
            Kind::Frames,
            &self.robots,
            &mut self.frames,
            max_payload,
        ) {
            Ok(header) => header,
            Err(e) => {
                self.dropped.malformed += 1;
                tracing::debug!("dropping a frames message: {e}");
                return Ok(());
            }
        };
        if header.run != self.assignment.run
            || header.epoch != self.assignment.epoch
            || header.host != self.assignment.host
            || header.tick <= self.last_tick
            || (self.last_tick > 0 && header.tick - self.last_tick > MAX_TICK_GAP)
        {
            self.dropped.stale += 1;
            tracing::trace!(tick = header.tick, "dropping a stale frames message");
            return Ok(());
        }
        self.reap();
        let agents = &self.children.agents;
        let Some(link) = self.link.as_mut() else {
            return Ok(());
        };
        link.start_at(header.tick);
        for (slot, entry) in (0..).zip(self.frames.iter_mut()) {
            if let Some(inbox) = entry.inbox.as_deref_mut() {
                link.post(slot, inbox);
            }
        }
        let frames = &self.frames;
        link.tick_with(|_, first, local| {
            for (frame, entry) in local.iter_mut().zip(&frames[first..]) {
                *frame = entry.frame;
            }
        })?;
        for (slot, (reply, outbox)) in self.replies.iter_mut().zip(&mut self.outboxes).enumerate() {
            *outbox = None;
            // `Dead` means the process ended: an agent the world froze or stopped waiting for is `Missing`.
            *reply = match (link.statuses()[slot], link.command(slot as u32)) {
                (CommandStatus::Answered, Some(command)) => {
                    let mut command = *command;
                    command.robot = self.robots[slot];
                    command.tick = header.tick;
                    *outbox = link.outbox(slot as u32).map(Box::new);
                    Reply::Answered(command)
                }
                _ if agents[slot].is_none() => Reply::Dead,
                _ => Reply::Missing,
            };
        }
        if self.last_tick == 0 {
            tracing::info!(tick = header.tick, "first tick of the share");
        }
        if !self.took_part && self.live_robots_answered() {
            self.took_part = true;
            tracing::info!(tick = header.tick, "the share's robots take part");
        }
        self.last_tick = header.tick;
        let out = Header::new(
            Kind::Replies,
            self.assignment.run,
            self.assignment.host,
            self.assignment.epoch,
            header.tick,
        );
        let entries = self
            .replies
            .iter()
            .zip(&self.outboxes)
            .map(|(reply, outbox)| (reply, outbox.as_deref()));
        codec::encode_batch(&mut self.buf, &out, &self.robots, entries)?;
        self.seal.seal(&self.replies_key, &mut self.buf);
        self.publisher
            .put(self.buf.clone())
            .wait()
            .map_err(zenoh_error("publishing the replies"))
    }
}

impl Drop for Share {
    fn drop(&mut self) {
        // Ending the local run tells the agents to exit; stragglers are killed after a grace period.
        self.link = None;
        self.children.end_agents(
            Duration::from_millis(self.assignment.agent_exit_grace_ms),
            IDLE_PERIOD,
        );
        if let Err(e) = self.spec.cleanup() {
            tracing::warn!("removing the share's shared memory: {e}");
        }
        tracing::info!(
            run = format!("{:016x}", self.assignment.run),
            last_tick = self.last_tick,
            stale = self.dropped.stale,
            malformed = self.dropped.malformed,
            unauthenticated = self.unauthenticated.load(Ordering::Relaxed),
            "share ended"
        );
    }
}

/// Ticks wait for the agent of `slot` (robot `robot`) again; fails when its agent is no longer connected.
fn revive(link: &WorldLink, slot: u32, robot: u32) -> Result<(), String> {
    if link.revive(slot) {
        Ok(())
    } else {
        Err(format!("robot {robot}'s agent is no longer connected"))
    }
}

/// Writes the run's compiled supervisor sets where this host's agents load them (`<logs>/supervisors/`, as in a
/// run directory).
fn write_compiled_supervisors(logs: &Path, sets: &[(String, Vec<u8>)]) -> Result<(), RemoteError> {
    for (controller, bytes) in sets {
        let written = run_dir::compiled_supervisors(logs, controller).and_then(|path| {
            std::fs::create_dir_all(logs.join(run_dir::COMPILED_SUPERVISORS_DIR))?;
            run_dir::write_atomically(&path, bytes)
        });
        written.map_err(|source| RemoteError::Io {
            what: format!("writing the compiled supervisor set of controller {controller:?}"),
            source,
        })?;
    }
    Ok(())
}
