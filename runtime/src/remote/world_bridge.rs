//! The world's side across hosts: [`RemoteHosts`] runs the lockstep with host daemons over zenoh.
//!
//! Per tick it fills every robot's frame, publishes one frames message per live host, and waits until every live
//! host answered this tick or the tick deadline passed. Replies are stored by run-wide robot id, so the world's
//! view never depends on arrival order, and a host's batch must name exactly the robots it owns. Host liveness is
//! a zenoh liveliness token: a host whose token goes (killed: milliseconds; frozen or cut off: after the lease) is
//! *lost* at the tick the world processes that news, and its robots are dead from that tick on; the tick is
//! recorded. A lost host whose token comes back gets its share again (a new epoch, so its old messages are
//! stale) and its robots come back to life at the tick it answers the assignment, with freshly started agents.
//!
//! It must never stall: every wait is bounded by the tick deadline, and a malformed, oversized or stale payload is
//! dropped and counted.

use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

use super::assignment::{Assignment, AssignmentReply};
use super::codec::{self, Header, Kind, Reply};
use super::session::{ZenohOptions, zenoh_error};
use super::{RemoteError, keys};
use crate::messages::{ActuatorCommand, SensorFrame};
use crate::transport::{CommandStatus, TickOutcome};

/// One host of the placement: its name and the run-wide ids of its robots.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostShare {
    /// Host name (as given to `swarm host --name`).
    pub name: String,
    /// Run-wide robot ids, in batch order.
    pub robots: Vec<u32>,
}

/// Everything the world needs to run robots on hosts.
#[derive(Debug, Clone)]
pub struct RemoteOptions {
    /// Endpoints the world listens on (hosts connect to one of them).
    pub listen: Vec<String>,
    /// Session settings.
    pub zenoh: ZenohOptions,
    /// The placement.
    pub hosts: Vec<HostShare>,
    /// Controller id of every robot, by run-wide id.
    pub controllers: Vec<String>,
    /// The experiment (absolute path; hosts must see it at the same path).
    pub config: PathBuf,
    /// Run seed.
    pub seed: u64,
    /// Robot count override of the run, if any.
    pub robots_override: Option<u32>,
    /// How long a tick waits for a host's replies.
    pub tick_deadline: Duration,
    /// How long a host may take to start its agents.
    pub join_timeout: Duration,
    /// Largest payload accepted.
    pub max_payload: usize,
}

/// What happened to a host during the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HostEvent {
    /// The host was lost; its robots are dead from this tick on.
    Lost {
        /// The tick at which the world decided.
        tick: u64,
    },
    /// The host rejoined; its robots live again from this tick on.
    Rejoined {
        /// The first tick with the host back.
        tick: u64,
    },
}

/// Counters of rejected payloads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Messages of an earlier tick, epoch or run.
    pub stale: u64,
    /// Messages that did not decode, were oversized, or named robots their host does not own.
    pub rejected: u64,
}

/// What reaches the world from zenoh's callbacks.
enum Incoming {
    HostUp(String),
    HostDown(String),
    Replies(String, Vec<u8>),
    Assigned(usize, Result<Vec<u8>, String>),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Not announced yet (before the first tick), or lost and not back.
    Absent,
    /// Its share was sent; waiting for its answer.
    Assigning,
    /// Running its share.
    Live,
}

struct Host {
    share: HostShare,
    state: State,
    /// Whether its liveliness token is present.
    up: bool,
    epoch: u32,
    /// The last tick it answered.
    answered: u64,
    /// The first tick it runs (after joining or rejoining).
    live_from: u64,
    replies: Vec<Reply>,
    publisher: Publisher<'static>,
    events: Vec<HostEvent>,
}

/// The world's end of a multi-host run.
pub struct RemoteHosts {
    options: RemoteOptions,
    session: Session,
    run: u64,
    /// The current (or last) tick.
    tick: u64,
    /// Whether the current tick's frames are sent.
    sent: bool,
    hosts: Vec<Host>,
    incoming: Receiver<Incoming>,
    sender: Sender<Incoming>,
    frames: Vec<SensorFrame>,
    commands: Vec<ActuatorCommand>,
    status: Vec<CommandStatus>,
    alive: Vec<bool>,
    changes: Vec<(u32, bool)>,
    buf: Vec<u8>,
    dropped: Dropped,
    _token: LivelinessToken,
    _replies: Subscriber<()>,
    _hosts: Subscriber<()>,
}

impl RemoteHosts {
    /// Opens the world's session (listening on `options.listen`) for a run of `robots` robots and starts watching
    /// for the hosts of the placement. `run` identifies the run in every message.
    pub fn start(
        options: RemoteOptions,
        robots: u32,
        run: u64,
    ) -> Result<RemoteHosts, RemoteError> {
        for host in &options.hosts {
            keys::check_host_name(&host.name)?;
        }
        let session = options.zenoh.open_world(&options.listen)?;
        let (sender, incoming) = mpsc::channel();
        let replies_sender = sender.clone();
        let replies = session
            .declare_subscriber(keys::all_replies(run))
            .callback(move |sample| {
                if let Some(host) = keys::host_of_replies(sample.key_expr().as_str()) {
                    let bytes = sample.payload().to_bytes().into_owned();
                    let _ = replies_sender.send(Incoming::Replies(host.to_owned(), bytes));
                }
            })
            .wait()
            .map_err(zenoh_error("subscribing to the hosts' replies"))?;
        let hosts_sender = sender.clone();
        let hosts_watch = session
            .liveliness()
            .declare_subscriber(keys::HOSTS_WILDCARD)
            .history(true)
            .callback(move |sample| {
                if let Some(host) = keys::host_of_token(sample.key_expr().as_str()) {
                    let event = match sample.kind() {
                        SampleKind::Put => Incoming::HostUp(host.to_owned()),
                        SampleKind::Delete => Incoming::HostDown(host.to_owned()),
                    };
                    let _ = hosts_sender.send(event);
                }
            })
            .wait()
            .map_err(zenoh_error("watching the hosts' liveliness"))?;
        let token = session
            .liveliness()
            .declare_token(keys::world_token(run))
            .wait()
            .map_err(zenoh_error("declaring the world's liveliness token"))?;
        let mut hosts = Vec::with_capacity(options.hosts.len());
        for share in &options.hosts {
            let publisher = session
                .declare_publisher(keys::frames(run, &share.name))
                .congestion_control(CongestionControl::Block)
                .express(true)
                .wait()
                .map_err(zenoh_error("declaring a frames publisher"))?;
            hosts.push(Host {
                replies: vec![Reply::Missing; share.robots.len()],
                share: share.clone(),
                state: State::Absent,
                up: false,
                epoch: 0,
                answered: 0,
                live_from: 1,
                publisher,
                events: Vec::new(),
            });
        }
        let n = robots as usize;
        Ok(RemoteHosts {
            options,
            session,
            run,
            tick: 0,
            sent: false,
            hosts,
            incoming,
            sender,
            frames: (0..robots).map(SensorFrame::empty).collect(),
            commands: (0..robots).map(|r| ActuatorCommand::idle(r, 0)).collect(),
            status: vec![CommandStatus::Missing; n],
            alive: vec![true; n],
            changes: Vec::new(),
            buf: Vec::new(),
            dropped: Dropped::default(),
            _token: token,
            _replies: replies,
            _hosts: hosts_watch,
        })
    }

    /// Waits until every host of the placement announced itself and started its share (its agents joined).
    pub fn wait_for_hosts(&mut self, timeout: Duration) -> Result<(), RemoteError> {
        let deadline = Instant::now() + timeout;
        while self.hosts.iter().any(|h| h.state != State::Live) {
            let now = Instant::now();
            if now >= deadline {
                let missing: Vec<String> = self
                    .hosts
                    .iter()
                    .filter(|h| h.state != State::Live)
                    .map(|h| {
                        let what = if h.up {
                            "did not start its robots"
                        } else {
                            "did not announce itself"
                        };
                        format!("'{}' {what}", h.share.name)
                    })
                    .collect();
                return Err(RemoteError::HostsMissing(format!(
                    "hosts not ready within {timeout:?}: {} (start them with `swarm host --connect {} --name <name>`)",
                    missing.join(", "),
                    self.options
                        .listen
                        .first()
                        .map_or("<endpoint>", String::as_str)
                )));
            }
            match self.incoming.recv_timeout(deadline - now) {
                Ok(event) => self.handle(event, true)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(())
    }

    /// The last tick run (0 before the first).
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Runs one tick: `sense` fills every robot's frame, one message per live host goes out, and the call returns
    /// when every live host answered or the deadline passed. Read the commands with [`RemoteHosts::command`].
    pub fn tick_with(
        &mut self,
        sense: impl FnOnce(u64, &mut [SensorFrame]),
    ) -> Result<TickOutcome, RemoteError> {
        let tick = self.tick + 1;
        self.tick = tick;
        self.sent = false;
        while let Ok(event) = self.incoming.try_recv() {
            self.handle(event, false)?;
        }
        for (i, frame) in self.frames.iter_mut().enumerate() {
            *frame = SensorFrame::empty(i as u32);
            frame.tick = tick;
        }
        sense(tick, &mut self.frames);
        for (i, frame) in self.frames.iter_mut().enumerate() {
            frame.tick = tick;
            frame.robot = i as u32;
        }
        for status in &mut self.status {
            *status = CommandStatus::Missing;
        }
        for (index, host) in self.hosts.iter_mut().enumerate() {
            if host.state != State::Live || host.live_from > tick {
                continue;
            }
            let header = Header::new(Kind::Frames, self.run, index as u16, host.epoch, tick);
            let frames = host.share.robots.iter().map(|&r| &self.frames[r as usize]);
            codec::encode_batch(&mut self.buf, &header, &host.share.robots, frames)?;
            host.publisher
                .put(self.buf.clone())
                .wait()
                .map_err(zenoh_error("publishing frames"))?;
        }
        self.sent = true;
        let deadline = Instant::now() + self.options.tick_deadline;
        while self
            .hosts
            .iter()
            .any(|h| h.state == State::Live && h.live_from <= tick && h.answered < tick)
        {
            let now = Instant::now();
            if now >= deadline {
                tracing::debug!(tick, "tick deadline passed with hosts missing");
                break;
            }
            match self.incoming.recv_timeout(deadline - now) {
                Ok(event) => self.handle(event, false)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(self.outcome(tick))
    }

    /// Statuses of this tick and the robots whose life changed.
    fn outcome(&mut self, tick: u64) -> TickOutcome {
        let mut outcome = TickOutcome {
            tick,
            answered: 0,
            missing: 0,
            dead: 0,
        };
        for host in &self.hosts {
            let live = host.state == State::Live && host.live_from <= tick;
            for (slot, &robot) in host.share.robots.iter().enumerate() {
                let r = robot as usize;
                let status = match (live, host.answered == tick, host.replies[slot]) {
                    (true, true, Reply::Answered(command)) => {
                        self.commands[r] = command;
                        CommandStatus::Answered
                    }
                    (true, true, Reply::Missing) | (true, false, _) => CommandStatus::Missing,
                    (true, true, Reply::Dead) | (false, _, _) => CommandStatus::Dead,
                };
                self.status[r] = status;
                let alive = status != CommandStatus::Dead;
                if self.alive[r] != alive {
                    self.alive[r] = alive;
                    self.changes.push((robot, alive));
                }
                match status {
                    CommandStatus::Answered => outcome.answered += 1,
                    CommandStatus::Missing => outcome.missing += 1,
                    CommandStatus::Dead => outcome.dead += 1,
                }
            }
        }
        outcome
    }

    fn handle(&mut self, event: Incoming, before_run: bool) -> Result<(), RemoteError> {
        match event {
            Incoming::HostUp(name) => {
                let Some(index) = self.host_named(&name) else {
                    return Ok(());
                };
                self.hosts[index].up = true;
                if self.hosts[index].state == State::Absent {
                    self.assign(index)?;
                }
            }
            Incoming::HostDown(name) => {
                let Some(index) = self.host_named(&name) else {
                    return Ok(());
                };
                let tick = self.tick;
                let host = &mut self.hosts[index];
                host.up = false;
                if before_run || host.state == State::Assigning {
                    host.state = State::Absent;
                } else if host.state == State::Live {
                    host.state = State::Absent;
                    host.events.push(HostEvent::Lost { tick });
                    tracing::warn!(host = name, tick, "host lost: its robots are dead");
                }
            }
            Incoming::Assigned(index, answer) => self.assigned(index, answer, before_run)?,
            Incoming::Replies(name, bytes) => self.replies(&name, &bytes),
        }
        Ok(())
    }

    fn host_named(&self, name: &str) -> Option<usize> {
        self.hosts.iter().position(|h| h.share.name == name)
    }

    /// Sends host `index` its share with a new epoch; the answer arrives as an event.
    fn assign(&mut self, index: usize) -> Result<(), RemoteError> {
        let host = &mut self.hosts[index];
        host.epoch += 1;
        host.state = State::Assigning;
        let assignment = Assignment {
            run: self.run,
            host: index as u16,
            name: host.share.name.clone(),
            epoch: host.epoch,
            config: self.options.config.clone(),
            seed: self.options.seed,
            robots_override: self.options.robots_override,
            robots: host
                .share
                .robots
                .iter()
                .map(|&r| {
                    let controller = self
                        .options
                        .controllers
                        .get(r as usize)
                        .cloned()
                        .unwrap_or_default();
                    (r, controller)
                })
                .collect(),
            tick_deadline_ms: (self.options.tick_deadline / 2).as_millis() as u64,
            join_timeout_ms: self.options.join_timeout.as_millis() as u64,
        };
        let payload = codec::encode_message(&assignment)?;
        let sender = self.sender.clone();
        tracing::info!(
            host = host.share.name,
            epoch = host.epoch,
            robots = host.share.robots.len(),
            "assigning"
        );
        self.session
            .get(keys::assign(&host.share.name))
            .payload(payload)
            .timeout(self.options.join_timeout + Duration::from_secs(5))
            .callback(move |reply| {
                let answer = match reply.result() {
                    Ok(sample) => Ok(sample.payload().to_bytes().into_owned()),
                    Err(e) => Err(String::from_utf8_lossy(&e.payload().to_bytes()).into_owned()),
                };
                let _ = sender.send(Incoming::Assigned(index, answer));
            })
            .wait()
            .map_err(zenoh_error("sending a host its share"))
    }

    fn assigned(
        &mut self,
        index: usize,
        answer: Result<Vec<u8>, String>,
        before_run: bool,
    ) -> Result<(), RemoteError> {
        let Some(host) = self.hosts.get_mut(index) else {
            return Ok(());
        };
        let reply = answer
            .map_err(|e| format!("zenoh error: {e}"))
            .and_then(|bytes| {
                codec::decode_message::<AssignmentReply>(&bytes, self.options.max_payload)
                    .map_err(|e| e.to_string())
            });
        match reply {
            Ok(AssignmentReply::Ready { epoch })
                if epoch == host.epoch && host.state == State::Assigning =>
            {
                host.state = State::Live;
                host.answered = 0;
                // The host gets frames from the first tick whose frames are not sent yet.
                host.live_from = if self.sent {
                    self.tick + 1
                } else {
                    self.tick.max(1)
                };
                if !before_run {
                    host.events.push(HostEvent::Rejoined {
                        tick: host.live_from,
                    });
                    tracing::info!(
                        host = host.share.name,
                        tick = host.live_from,
                        "host rejoined"
                    );
                }
                Ok(())
            }
            Ok(AssignmentReply::Ready { .. }) => {
                self.dropped.stale += 1;
                Ok(())
            }
            Ok(AssignmentReply::Refused { epoch, reason }) if epoch == host.epoch => {
                host.state = State::Absent;
                if before_run {
                    Err(RemoteError::Refused {
                        host: host.share.name.clone(),
                        reason,
                    })
                } else {
                    tracing::error!(host = host.share.name, "host refused to rejoin: {reason}");
                    Ok(())
                }
            }
            Ok(AssignmentReply::Refused { .. }) => Ok(()),
            Err(reason) => {
                self.dropped.rejected += 1;
                tracing::warn!(
                    host = host.share.name,
                    "bad answer to an assignment: {reason}"
                );
                Ok(())
            }
        }
    }

    /// Decodes a host's replies into its slots if they answer the current tick of its current epoch.
    fn replies(&mut self, name: &str, bytes: &[u8]) {
        let Some(index) = self.host_named(name) else {
            self.dropped.rejected += 1;
            return;
        };
        let max = self.options.max_payload;
        let host = &mut self.hosts[index];
        let header = match codec::decode_header(bytes, max) {
            Ok((header, _)) => header,
            Err(e) => {
                self.dropped.rejected += 1;
                tracing::debug!(host = name, "rejecting replies: {e}");
                return;
            }
        };
        if header.run != self.run
            || header.host as usize != index
            || header.epoch != host.epoch
            || header.tick != self.tick
            || host.state != State::Live
        {
            self.dropped.stale += 1;
            return;
        }
        match codec::decode_batch(
            bytes,
            Kind::Replies,
            &host.share.robots,
            &mut host.replies,
            max,
        ) {
            Ok(_) => {
                let owned = host.replies.iter().zip(&host.share.robots).all(
                    |(reply, &robot)| !matches!(reply, Reply::Answered(c) if c.robot != robot),
                );
                if owned {
                    host.answered = self.tick;
                } else {
                    self.dropped.rejected += 1;
                    tracing::warn!(
                        host = name,
                        "rejecting replies with a command for a robot the host does not own"
                    );
                }
            }
            Err(e) => {
                self.dropped.rejected += 1;
                tracing::debug!(host = name, "rejecting replies: {e}");
            }
        }
    }

    /// The command `robot` sent in the last tick; `None` if it did not answer.
    pub fn command(&self, robot: u32) -> Option<&ActuatorCommand> {
        let r = robot as usize;
        match self.status.get(r) {
            Some(CommandStatus::Answered) => self.commands.get(r),
            _ => None,
        }
    }

    /// What the world got from each robot in the last tick, indexed by robot.
    pub fn statuses(&self) -> &[CommandStatus] {
        &self.status
    }

    /// Robots whose life changed in the last ticks (`false`: dead, `true`: back), oldest first; drains the list.
    pub fn take_changes(&mut self) -> std::vec::Drain<'_, (u32, bool)> {
        self.changes.drain(..)
    }

    /// Each host with what happened to it.
    pub fn host_events(&self) -> impl Iterator<Item = (&HostShare, &[HostEvent])> {
        self.hosts.iter().map(|h| (&h.share, h.events.as_slice()))
    }

    /// Payloads dropped so far.
    pub fn dropped(&self) -> Dropped {
        self.dropped
    }
}
