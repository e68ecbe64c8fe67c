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
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use zenoh::Session;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::query::{Query, Queryable};
use zenoh::sample::SampleKind;

use super::auth::{Seal, answer_channel};
use super::codec::{self, Header, Kind, WireError};
use super::host_to_world::{AssignmentReply, OrderReply, Reply};
use super::session::{ZenohOptions, zenoh_error};
use super::world_to_host::{Assignment, FrameEntry, Order, OrderAction, parse_kill};
use super::{RemoteError, keys};
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::SupervisorSnapshot;
use swarm_contract::process::binaries::Binaries;
use swarm_contract::process::children::{AgentProcess, Children};
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
/// Largest step between the ticks of two frames messages a share accepts: the world's ticks only grow, by one
/// unless frames were lost on the way.
const MAX_TICK_GAP: u64 = 1 << 20;
/// How many (run, epoch) pairs the daemon remembers to refuse a replayed assignment.
const SERVED_REMEMBERED: usize = 64;
/// How long the daemon looks for the world's liveliness token before it takes a share.
const WORLD_CHECK_TIMEOUT: Duration = Duration::from_secs(5);

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
    /// How this host's messages are authenticated (its key, see [`crate::auth`]).
    pub seal: Seal,
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
    /// The world of run `run` told the host's share of epoch `epoch` to die.
    Kill { run: u64, epoch: u32 },
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
    let kill_seal = options.seal.clone();
    let kill_key = keys::kill(&options.name);
    let _kill: Subscriber<()> = session
        .declare_subscriber(kill_key.clone())
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes();
            match kill_seal.open(&kill_key, &bytes).map(parse_kill) {
                Ok(Some((run, epoch))) => {
                    let _ = kill_sender.send(Event::Kill { run, epoch });
                }
                Ok(None) => tracing::warn!(len = bytes.len(), "ignoring a malformed kill message"),
                Err(e) => tracing::warn!("ignoring a kill message: {e}"),
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
    let mut served: Vec<(u64, u32)> = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        let event = match events.recv_timeout(IDLE_PERIOD) {
            Ok(event) => Some(event),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        match event {
            Some(Event::Assign(query)) => {
                match authentic_assignment(&session, options, &query, &served) {
                    Ok(assignment) => {
                        // A new assignment replaces the current share (the host rejoined after a loss).
                        drop(share.take());
                        remember(&mut served, &assignment);
                        share = accept(&session, options, &binaries, &query, assignment, &sender);
                    }
                    Err(Refusal::Silent(reason)) => {
                        tracing::warn!("ignoring an assignment: {reason}");
                    }
                    Err(Refusal::Answered(reason)) => {
                        tracing::warn!("refusing an assignment: {reason}");
                        let refused = AssignmentReply::Refused { epoch: 0, reason };
                        answer(&query, &options.seal, &refused, "the assignment");
                    }
                }
            }
            Some(Event::Order(query)) => answer_order(&query, share.as_mut(), options),
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
            Some(Event::Kill { run, epoch })
                if share
                    .as_ref()
                    .is_some_and(|s| s.assignment.run == run && s.assignment.epoch == epoch) =>
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

/// Why an assignment is not taken: `Silent` when it may not be from the world (no answer, so a stranger learns
/// nothing), `Answered` when the world sent it but it cannot be run.
enum Refusal {
    Silent(String),
    Answered(String),
}

/// The assignment a query carries, if it is authentic (tagged with this host's key on its queryable), decodes,
/// and is fresh: neither a (run, epoch) this daemon served already nor a run whose world is gone (a replay).
fn authentic_assignment(
    session: &Session,
    options: &HostOptions,
    query: &Query,
    served: &[(u64, u32)],
) -> Result<Assignment, Refusal> {
    let bytes = request_bytes(query);
    let payload = options
        .seal
        .open(&keys::assign(&options.name), &bytes)
        .map_err(|e| Refusal::Silent(e.to_string()))?;
    let assignment = codec::decode_versioned::<Assignment>(payload, options.max_payload).map_err(
        |e| match e {
            WireError::Version { .. } => Refusal::Answered(format!(
                "{e}: build the world's machine and the hosts from the same source"
            )),
            e => Refusal::Answered(format!("malformed assignment: {e}")),
        },
    )?;
    if assignment.name != options.name {
        return Err(Refusal::Answered(format!(
            "the assignment is for host '{}', this is '{}'",
            assignment.name, options.name
        )));
    }
    if served
        .iter()
        .any(|&(run, epoch)| run == assignment.run && epoch >= assignment.epoch)
    {
        return Err(Refusal::Silent(format!(
            "run {:016x} epoch {} was served already (a replayed assignment)",
            assignment.run, assignment.epoch
        )));
    }
    let world_up = session
        .liveliness()
        .get(keys::world_token(assignment.run))
        .timeout(WORLD_CHECK_TIMEOUT)
        .wait()
        .map_err(|e| Refusal::Silent(format!("looking for the run's world: {e}")))?
        .recv()
        .is_ok_and(|reply| reply.result().is_ok());
    if !world_up {
        return Err(Refusal::Silent(format!(
            "the world of run {:016x} is not up (a replayed assignment?)",
            assignment.run
        )));
    }
    Ok(assignment)
}

/// The bytes a query carries (none: empty, which no check accepts).
fn request_bytes(query: &Query) -> Vec<u8> {
    query
        .payload()
        .map(|p| p.to_bytes().into_owned())
        .unwrap_or_default()
}

/// Remembers a served (run, epoch), forgetting the oldest beyond [`SERVED_REMEMBERED`].
fn remember(served: &mut Vec<(u64, u32)>, assignment: &Assignment) {
    if served.len() >= SERVED_REMEMBERED {
        served.remove(0);
    }
    served.push((assignment.run, assignment.epoch));
}

/// Answers `query` with `message`, tagged for the request it answers.
fn answer<T: bincode::Encode>(query: &Query, seal: &Seal, message: &T, what: &str) {
    let request = request_bytes(query);
    let channel = answer_channel(query.key_expr().as_str(), &request);
    match codec::encode_message(message) {
        Ok(mut bytes) => {
            seal.seal(&channel, &mut bytes);
            if let Err(e) = query.reply(query.key_expr().clone(), bytes).wait() {
                tracing::warn!("answering {what}: {e}");
            }
        }
        Err(e) => tracing::warn!("encoding the answer to {what}: {e}"),
    }
}

/// Starts the share of an authentic assignment and answers the query: ready, or refused with the reason.
fn accept(
    session: &Session,
    options: &HostOptions,
    binaries: &Binaries,
    query: &Query,
    assignment: Assignment,
    sender: &Sender<Event>,
) -> Option<Share> {
    let epoch = assignment.epoch;
    let (reply, share) = match Share::start(session, options, binaries, assignment, sender) {
        Ok(share) => (AssignmentReply::Ready { epoch }, Some(share)),
        Err(e) => {
            tracing::error!("refusing the share: {e}");
            let reason = e.to_string();
            (AssignmentReply::Refused { epoch, reason }, None)
        }
    };
    answer(query, &options.seal, &reply, "the assignment");
    share
}

/// Answers a fault order: carried out by the current share if the order is authentic, for it, and newer than
/// every order it carried out (a replayed order is refused); refused otherwise.
fn answer_order(query: &Query, share: Option<&mut Share>, options: &HostOptions) {
    let bytes = request_bytes(query);
    let order = match options.seal.open(&keys::orders(&options.name), &bytes) {
        Ok(payload) => codec::decode_message::<Order>(payload, options.max_payload),
        Err(e) => {
            tracing::warn!("ignoring an order: {e}");
            return;
        }
    };
    let reply = match (order, share) {
        (Err(e), _) => {
            tracing::warn!("refusing a malformed order: {e}");
            OrderReply::Failed {
                reason: format!("malformed order: {e}"),
            }
        }
        (Ok(order), Some(share))
            if order.run == share.assignment.run
                && order.epoch == share.assignment.epoch
                && order.number > share.last_order =>
        {
            share.last_order = order.number;
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
                "no share of run {:016x} epoch {} on this host, or order {} is not newer than the last one",
                order.run, order.epoch, order.number
            ),
        },
    };
    answer(query, &options.seal, &reply, "an order");
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
    frames: Vec<FrameEntry>,
    replies: Vec<Reply>,
    /// Per slot: the messages its robot sent in the last tick, if any.
    outboxes: Vec<Option<Box<Mailbox>>>,
    buf: Vec<u8>,
    last_tick: u64,
    /// Number of the last fault order carried out (orders are numbered by the world, growing).
    last_order: u64,
    /// How the share's messages are authenticated, and the channel its replies are tagged for.
    seal: Seal,
    replies_key: String,
    /// Frames messages dropped because they were not from the world (counted by zenoh's callback).
    unauthenticated: Arc<AtomicU64>,
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
