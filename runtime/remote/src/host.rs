//! `swarm host`: the daemon that runs one machine's share of multi-host runs.
//!
//! It announces itself with a liveliness token, waits for an [`Assignment`] on its queryable, and runs the share as
//! a local lockstep run: its own iceoryx2 prefix and root, one `robot-agent` process per robot (told its run-wide
//! id for its random stream and profile, and its local slot in this host's transport). Per tick it takes the
//! newest frames message of its share, runs one local tick with those frames, and publishes its robots' replies.
//! An agent that dies is reported `Dead` from then on (the same semantics as a single-host run). Between ticks the
//! world may send fault orders for the share's agents ([`Order`]): kill, freeze, thaw, stop or start waiting for
//! one, or replace one with an agent that resumes from the world's record. When the world's
//! liveliness token goes (the run ended or the world died) or a new assignment arrives (the host rejoined), the
//! share is stopped: agents are told to end, then killed, and every shared-memory file is removed.
//!
//! It must never answer for a robot of another host (its replies carry exactly its share) and never let a stale
//! or malformed message reach its agents (dropped and counted).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use zenoh::Session;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::query::{Query, Queryable};
use zenoh::sample::SampleKind;

use super::codec::{self, Header, Kind};
use super::host_to_world::{AssignmentReply, OrderReply, Reply};
use super::session::{ZenohOptions, zenoh_error};
use super::world_to_host::{Assignment, Order, OrderAction};
use super::{RemoteError, keys};
use swarm_contract::messages::{SensorFrame, SupervisorSnapshot};
use swarm_contract::process::binaries::Binaries;
use swarm_contract::process::children::{self, Children};
use swarm_contract::protocol::launcher_to_agent::{AgentArgs, RunArgs, start_agent};
use swarm_contract::protocol::resume::{ResumeError, ResumePoint};
use swarm_contract::run_dir;
use swarm_contract::transport::{CommandStatus, LinkConfig, RunSpec, WorldLink, priority};

/// How often the daemon looks at its agents when no message arrives.
const IDLE_PERIOD: Duration = Duration::from_millis(50);
/// Lines of an agent's log quoted when it fails to start.
const LOG_LINES_QUOTED: usize = 8;
/// How often a replacement agent's join is looked at.
const REPLACEMENT_POLL: Duration = Duration::from_millis(5);

/// What `swarm host` was asked to do.
#[derive(Debug, Clone)]
pub struct HostOptions {
    /// Host name (its liveliness token and keys).
    pub name: String,
    /// The world's zenoh endpoint, e.g. `tcp/10.0.0.1:7447`.
    pub connect: String,
    /// Most robots this host accepts in one run.
    pub capacity: u32,
    /// Session settings.
    pub zenoh: ZenohOptions,
    /// Largest payload accepted.
    pub max_payload: usize,
    /// Folder for the agents' logs (`robot-<id>.log`).
    pub logs: PathBuf,
}

/// What reaches the daemon's loop from zenoh's callbacks.
enum Event {
    /// A new share.
    Assign(Query),
    /// A fault order for one of the share's agents.
    Order(Query),
    /// A frames message of run `run`.
    Frames { run: u64, bytes: Vec<u8> },
    /// The world of run `run` is gone.
    WorldGone { run: u64 },
    /// The world of run `run` told the host to die.
    Kill { run: u64 },
}

/// Counters of dropped messages, logged when a share ends.
#[derive(Debug, Default, Clone, Copy)]
struct Dropped {
    stale: u64,
    malformed: u64,
}

/// Runs the daemon until `stop` is set.
pub fn serve(options: &HostOptions, stop: &AtomicBool) -> Result<(), RemoteError> {
    swarm_contract::config::hosts::check_host_name(&options.name)?;
    let binaries = Binaries::locate()?;
    std::fs::create_dir_all(&options.logs).map_err(|source| RemoteError::Io {
        what: format!("creating {}", options.logs.display()),
        source,
    })?;
    tracing::info!(
        host = options.name,
        endpoint = options.connect,
        "connecting"
    );
    let Some(session) = connect(options, stop)? else {
        return Ok(());
    };
    let (sender, events) = mpsc::channel();
    let assign_sender = sender.clone();
    let _queryable: Queryable<()> = session
        .declare_queryable(keys::assign(&options.name))
        .callback(move |query| {
            let _ = assign_sender.send(Event::Assign(query));
        })
        .wait()
        .map_err(zenoh_error("declaring the assignment queryable"))?;
    let order_sender = sender.clone();
    let _orders: Queryable<()> = session
        .declare_queryable(keys::orders(&options.name))
        .callback(move |query| {
            let _ = order_sender.send(Event::Order(query));
        })
        .wait()
        .map_err(zenoh_error("declaring the orders queryable"))?;
    let kill_sender = sender.clone();
    let _kill: Subscriber<()> = session
        .declare_subscriber(keys::kill(&options.name))
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes();
            match <[u8; 8]>::try_from(bytes.as_ref()) {
                Ok(run) => {
                    let _ = kill_sender.send(Event::Kill {
                        run: u64::from_le_bytes(run),
                    });
                }
                Err(_) => tracing::warn!(len = bytes.len(), "ignoring a malformed kill message"),
            }
        })
        .wait()
        .map_err(zenoh_error("subscribing to kill requests"))?;
    let _token: LivelinessToken = session
        .liveliness()
        .declare_token(keys::host_token(&options.name))
        .wait()
        .map_err(zenoh_error("declaring the host's liveliness token"))?;
    tracing::info!(
        host = options.name,
        capacity = options.capacity,
        "ready for runs"
    );

    let mut share: Option<Share> = None;
    while !stop.load(Ordering::Relaxed) {
        let event = match events.recv_timeout(IDLE_PERIOD) {
            Ok(event) => Some(event),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        match event {
            Some(Event::Assign(query)) => {
                // A new assignment replaces the current share (the host rejoined after a loss).
                drop(share.take());
                share = accept(&session, options, &binaries, &query, &sender);
            }
            Some(Event::Order(query)) => answer_order(&query, share.as_mut(), options.max_payload),
            Some(Event::Frames { run, bytes }) => {
                if let Some(current) = share.as_mut().filter(|s| s.assignment.run == run) {
                    let newest = newest_frames(&events, &sender, run, bytes, &mut current.dropped);
                    if let Err(e) = current.tick(&newest, options.max_payload) {
                        tracing::error!(run = format!("{run:016x}"), "ending the share: {e}");
                        share = None;
                    }
                }
            }
            Some(Event::WorldGone { run })
                if share.as_ref().is_some_and(|s| s.assignment.run == run) =>
            {
                tracing::info!(run = format!("{run:016x}"), "the world ended the run");
                share = None;
            }
            Some(Event::Kill { run })
                if share.as_ref().is_some_and(|s| s.assignment.run == run) =>
            {
                // As if the machine died: the share ends and the daemon exits without a goodbye.
                tracing::error!(
                    run = format!("{run:016x}"),
                    "killed by `swarm ctl kill-host`"
                );
                drop(share);
                return Err(RemoteError::Killed { run });
            }
            Some(Event::WorldGone { .. } | Event::Kill { .. }) | None => {}
        }
        if let Some(current) = share.as_mut() {
            current.reap();
        }
    }
    drop(share);
    session
        .close()
        .wait()
        .map_err(zenoh_error("closing the session"))
}

/// Opens the host's session; zenoh's client mode blocks until the world's endpoint answers, so it runs on a thread
/// while this one watches `stop`. `None` when stopped first.
fn connect(options: &HostOptions, stop: &AtomicBool) -> Result<Option<Session>, RemoteError> {
    let (sender, opened) = mpsc::channel();
    let zenoh = options.zenoh.clone();
    let endpoint = options.connect.clone();
    std::thread::spawn(move || {
        let _ = sender.send(zenoh.open_host(&endpoint));
    });
    loop {
        match opened.recv_timeout(IDLE_PERIOD) {
            Ok(session) => return session.map(Some),
            Err(RecvTimeoutError::Timeout) if stop.load(Ordering::Relaxed) => return Ok(None),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                return Err(RemoteError::Zenoh {
                    action: format!("connecting to {}", options.connect),
                    detail: "the connecting thread ended without a session".into(),
                });
            }
        }
    }
}

/// Takes every frames message already queued: the newest of `run` wins, older ones count as stale; other events
/// are put back in order.
fn newest_frames(
    events: &Receiver<Event>,
    sender: &Sender<Event>,
    run: u64,
    first: Vec<u8>,
    dropped: &mut Dropped,
) -> Vec<u8> {
    let mut newest = first;
    let mut others = Vec::new();
    while let Ok(event) = events.try_recv() {
        match event {
            Event::Frames { run: r, bytes } if r == run => {
                dropped.stale += 1;
                newest = bytes;
            }
            other => others.push(other),
        }
    }
    for other in others {
        let _ = sender.send(other);
    }
    newest
}

/// Answers an assignment query: starts the share, or refuses with the reason.
fn accept(
    session: &Session,
    options: &HostOptions,
    binaries: &Binaries,
    query: &Query,
    sender: &Sender<Event>,
) -> Option<Share> {
    let assignment = match query.payload() {
        Some(payload) => {
            codec::decode_message::<Assignment>(&payload.to_bytes(), options.max_payload)
        }
        None => Err(codec::WireError::Malformed(
            "an assignment without payload".into(),
        )),
    };
    let (reply, share) = match assignment {
        Err(e) => {
            tracing::warn!("ignoring a malformed assignment: {e}");
            (
                AssignmentReply::Refused {
                    epoch: 0,
                    reason: format!("malformed assignment: {e}"),
                },
                None,
            )
        }
        Ok(assignment) => {
            let epoch = assignment.epoch;
            match Share::start(session, options, binaries, assignment, sender) {
                Ok(share) => (AssignmentReply::Ready { epoch }, Some(share)),
                Err(e) => {
                    tracing::error!("refusing the share: {e}");
                    (
                        AssignmentReply::Refused {
                            epoch,
                            reason: e.to_string(),
                        },
                        None,
                    )
                }
            }
        }
    };
    match codec::encode_message(&reply) {
        Ok(bytes) => {
            if let Err(e) = query.reply(query.key_expr().clone(), bytes).wait() {
                tracing::warn!("answering the assignment: {e}");
            }
        }
        Err(e) => tracing::warn!("encoding the assignment reply: {e}"),
    }
    share
}

/// Answers a fault order: carried out by the current share if the order is for it, refused otherwise.
fn answer_order(query: &Query, share: Option<&mut Share>, max_payload: usize) {
    let order = match query.payload() {
        Some(payload) => codec::decode_message::<Order>(&payload.to_bytes(), max_payload),
        None => Err(codec::WireError::Malformed(
            "an order without payload".into(),
        )),
    };
    let reply = match (order, share) {
        (Err(e), _) => {
            tracing::warn!("refusing a malformed order: {e}");
            OrderReply::Failed {
                reason: format!("malformed order: {e}"),
            }
        }
        (Ok(order), Some(share))
            if order.run == share.assignment.run && order.epoch == share.assignment.epoch =>
        {
            match share.carry_out(order.robot, order.action) {
                Ok(()) => OrderReply::Done,
                Err(reason) => {
                    tracing::warn!(robot = order.robot, "order not carried out: {reason}");
                    OrderReply::Failed { reason }
                }
            }
        }
        (Ok(order), _) => OrderReply::Failed {
            reason: format!(
                "no share of run {:016x} epoch {} on this host",
                order.run, order.epoch
            ),
        },
    };
    match codec::encode_message(&reply) {
        Ok(bytes) => {
            if let Err(e) = query.reply(query.key_expr().clone(), bytes).wait() {
                tracing::warn!("answering an order: {e}");
            }
        }
        Err(e) => tracing::warn!("encoding an order's answer: {e}"),
    }
}

/// One run's share on this host.
struct Share {
    assignment: Assignment,
    robots: Vec<u32>,
    spec: RunSpec,
    link: Option<WorldLink>,
    /// Agent processes by slot; `None` once one ended (killed, exited, or a replacement that never joined): the
    /// robot is reported `Dead` then.
    children: Children,
    /// The robot-agent program and the folder of the agents' logs, for replacements.
    agent: PathBuf,
    logs: PathBuf,
    frames: Vec<SensorFrame>,
    replies: Vec<Reply>,
    buf: Vec<u8>,
    last_tick: u64,
    /// Whether a tick ran in which the share's live robots all answered (a rejoined share's robots are dead for
    /// the world at first).
    took_part: bool,
    dropped: Dropped,
    publisher: Publisher<'static>,
    _frames: Subscriber<()>,
    _world: Subscriber<()>,
}

impl Share {
    /// Creates the local run, starts one agent per robot and waits until all joined.
    fn start(
        session: &Session,
        options: &HostOptions,
        binaries: &Binaries,
        assignment: Assignment,
        sender: &Sender<Event>,
    ) -> Result<Share, RemoteError> {
        let count = assignment.robots.len() as u32;
        swarm_contract::process::open_files::ensure(count).map_err(|e| RemoteError::Refused {
            host: options.name.clone(),
            reason: e.to_string(),
        })?;
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
        link_config.realtime = priority::tick_at_realtime(assignment.realtime_priority);
        let link = WorldLink::create(&spec, link_config)?;
        let publisher = session
            .declare_publisher(keys::replies(run, &options.name))
            .congestion_control(CongestionControl::Block)
            .express(true)
            .wait()
            .map_err(zenoh_error("declaring the replies publisher"))?;
        let frames_sender = sender.clone();
        let frames = session
            .declare_subscriber(keys::frames(run, &options.name))
            .callback(move |sample| {
                let bytes = sample.payload().to_bytes().into_owned();
                let _ = frames_sender.send(Event::Frames { run, bytes });
            })
            .wait()
            .map_err(zenoh_error("subscribing to the frames"))?;
        let world_sender = sender.clone();
        let world = session
            .liveliness()
            .declare_subscriber(keys::world_token(run))
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
            frames: vec![SensorFrame::empty(0); count as usize],
            replies: vec![Reply::Missing; count as usize],
            buf: Vec::new(),
            last_tick: 0,
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
    ) -> Result<std::process::Child, RemoteError> {
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
        let log_path = log_file(&self.logs, *robot);
        let log = std::fs::File::create(&log_path).map_err(|source| RemoteError::Io {
            what: format!("creating {}", log_path.display()),
            source,
        })?;
        start_agent(&self.agent, &args, log).map_err(|source| RemoteError::Io {
            what: format!("starting {}", self.agent.display()),
            source,
        })
    }

    /// Carries out a fault order for robot `robot` of the share; the reason when it cannot be.
    fn carry_out(&mut self, robot: u32, action: OrderAction) -> Result<(), String> {
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
                children::signal(agent, nix::sys::signal::Signal::SIGSTOP);
                link.mark_dead(slot_id).map_err(|e| e.to_string())
            }
            OrderAction::Thaw => {
                let agent = agent.ok_or_else(|| format!("robot {robot}'s agent is gone"))?;
                children::signal(agent, nix::sys::signal::Signal::SIGCONT);
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
            // Serves the replacement's request for a fresh command board while waiting.
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
        let log = run_dir::tail(&log_file(&self.logs, robot), LOG_LINES_QUOTED);
        Some(format!("robot {robot} failed to start ({status}):\n{log}"))
    }

    /// Whether this tick had live robots and every one of them answered (so each has stepped its controller).
    fn live_robots_answered(&self) -> bool {
        let mut live = self
            .frames
            .iter()
            .zip(&self.replies)
            .filter(|(frame, _)| frame.alive != 0)
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
    fn reap(&mut self) -> Vec<(u32, std::process::ExitStatus)> {
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
    fn tick(&mut self, bytes: &[u8], max_payload: usize) -> Result<(), RemoteError> {
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
        if header.epoch != self.assignment.epoch
            || header.host != self.assignment.host
            || header.tick <= self.last_tick
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
        let frames = &self.frames;
        link.start_at(header.tick);
        link.tick_with(|_, first, local| {
            local.copy_from_slice(&frames[first..first + local.len()]);
        })?;
        for (slot, reply) in self.replies.iter_mut().enumerate() {
            // `Dead` means the process ended: an agent the world froze or stopped waiting for is `Missing`.
            *reply = match (link.statuses()[slot], link.command(slot as u32)) {
                (CommandStatus::Answered, Some(command)) => {
                    let mut command = *command;
                    command.robot = self.robots[slot];
                    command.tick = header.tick;
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
        codec::encode_batch(&mut self.buf, &out, &self.robots, &self.replies)?;
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

fn log_file(logs: &Path, robot: u32) -> PathBuf {
    logs.join(format!("robot-{robot}.log"))
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
