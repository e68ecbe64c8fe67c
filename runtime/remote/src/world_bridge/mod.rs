//! The world's side across hosts: [`RemoteHosts`] runs the lockstep with host daemons over zenoh.
//!
//! Per tick it fills every robot's frame, publishes one frames message per live host, and waits until every live
//! host answered this tick or the tick deadline passed. Replies are stored by run-wide robot id, so the world's
//! view never depends on arrival order, and a host's batch must name exactly the robots it owns. Host liveness is
//! a zenoh liveliness token: a host whose token goes (killed: milliseconds; frozen or cut off: after the lease) is
//! *lost* at the tick the world processes that news, and its robots are dead from that tick on; the tick is
//! recorded. A lost host whose token comes back gets its share again (a new epoch, so its old messages are
//! stale) and its robots come back to life at the tick it answers the assignment, with freshly started agents.
//! Between ticks the world's fault driver sends hosts fault orders ([`RemoteHosts::order`]) and learns of agents
//! that died on a host and of hosts lost and back ([`RemoteHosts::take_news`]).
//!
//! It must never stall: every wait is bounded by the tick deadline, and a malformed, oversized or stale payload is
//! dropped and counted.
//!
//! Admitting hosts (assignments, their answers, retries) is in `admission.rs`, fault orders in `orders.rs`.

mod admission;
mod orders;

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

use super::auth::{HostKeys, Seal};
use super::codec::{self, Header, Kind};
use super::host_to_world::{Reply, ReplyEntry};
use super::session::{ZenohOptions, zenoh_error};
use super::world_to_host::kill_payload;
use super::{RemoteError, keys};
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::transport::{CommandStatus, TickOutcome};

/// Before the first tick, how often unanswered assignments are sent again.
const RETRY_PERIOD: Duration = Duration::from_millis(100);

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
    /// How long a host's agents get to exit by themselves when its share ends.
    pub agent_exit_grace: Duration,
    /// Whether the hosts' agents pin themselves to CPUs by chain.
    pub pin_agents: bool,
    /// Whether the hosts tick and run their agents at real-time priority if they can.
    pub realtime_priority: bool,
    /// Whether the run has a messages medium (the hosts' local runs then carry inboxes and outboxes).
    pub mail: bool,
    /// Largest payload accepted.
    pub max_payload: usize,
    /// The run's compiled supervisor sets by controller id, handed to every host with its share.
    pub compiled_supervisors: Vec<(String, Vec<u8>)>,
    /// The run's `--limit` overrides, handed to every host for its agents.
    pub limits: Vec<String>,
    /// The hosts' keys: every message to and from a host is authenticated with its key ([`crate::auth`]).
    pub keys: HostKeys,
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

/// What the fault driver learns of the robots on hosts, besides their replies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RobotNews {
    /// The robot's agent process ended on its host (not by an order).
    Died(u32),
    /// The robot's host was lost.
    HostLost(u32),
    /// The robot's host rejoined and started a fresh agent for it.
    HostBack(u32),
}

/// Counters of rejected payloads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Messages of an earlier tick, epoch or run.
    pub stale: u64,
    /// Messages that did not decode, were oversized, or named robots their host does not own.
    pub rejected: u64,
    /// Messages whose tag did not match their host's key (not from that host).
    pub unauthenticated: u64,
}

/// What reaches the world from zenoh's callbacks.
enum Incoming {
    HostUp(String),
    HostDown(String),
    Replies(String, Vec<u8>),
    Assigned(usize, Result<Vec<u8>, String>),
    /// The assignment query of (host, epoch) finished (after its answer, if any).
    AssignEnded(usize, u32),
    /// The answer to order number `n`.
    Ordered(u64, Result<Vec<u8>, String>),
    /// Order number `n` finished (after its answer, if any).
    OrderEnded(u64),
}

/// Says when a query is finished (after its answer, if any): zenoh drops the reply callback, and this with it.
struct QueryEnded {
    sender: Sender<Incoming>,
    ended: Option<Incoming>,
}

impl Drop for QueryEnded {
    fn drop(&mut self) {
        if let Some(ended) = self.ended.take() {
            let _ = self.sender.send(ended);
        }
    }
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
    /// It rejoined and its robots' return is still to be told (at the end of tick `live_from`).
    returning: bool,
    replies: Vec<ReplyEntry>,
    publisher: Publisher<'static>,
    /// How the host's messages are authenticated, and the channel its frames are tagged for.
    seal: Seal,
    frames_key: String,
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
    /// Per robot: the messages it receives in the next tick ([`RemoteHosts::post`]); empty until the first post.
    inboxes: Vec<Mailbox>,
    /// Per robot: whether `inboxes` holds messages for the next tick.
    posted: Vec<bool>,
    /// Per robot: the messages it sent in the last tick.
    outboxes: Vec<Option<Box<Mailbox>>>,
    status: Vec<CommandStatus>,
    /// Index in `hosts` of each robot's host.
    owner: Vec<usize>,
    /// Whether every host's robots are one range of ids and the ranges cover all robots (as the launcher's
    /// placement makes them): then each host's frames are sensed and sent before the next host's are sensed.
    sensed_by_host: bool,
    /// Per robot: its host runs an agent for it, as far as the world knows.
    present: Vec<bool>,
    /// Per robot: an order made its host stop waiting for it (killed, frozen, missed a deadline).
    held: Vec<bool>,
    news: Vec<RobotNews>,
    /// Orders sent so far; the answers of the one waited for are in `answer`.
    orders_sent: u64,
    answer: Option<Result<Vec<u8>, String>>,
    buf: Vec<u8>,
    dropped: Dropped,
    /// Messages dropped in zenoh's callbacks because their tag did not match (they never reach `incoming`).
    unauthenticated: Arc<AtomicU64>,
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
        let mut host_seals = Vec::with_capacity(options.hosts.len());
        for host in &options.hosts {
            swarm_contract::config::hosts::check_host_name(&host.name)?;
            let seal = options
                .keys
                .seal(&host.name)
                .ok_or_else(|| RemoteError::NoKey(host.name.clone()))?;
            host_seals.push(seal);
        }
        let seals: HashMap<String, (String, Seal)> = options
            .hosts
            .iter()
            .zip(&host_seals)
            .map(|(host, seal)| {
                (
                    keys::replies(run, &host.name),
                    (host.name.clone(), seal.clone()),
                )
            })
            .collect();
        let session = options.zenoh.open_world(&options.listen)?;
        let (sender, incoming) = mpsc::channel();
        let replies_sender = sender.clone();
        let unauthenticated = Arc::new(AtomicU64::new(0));
        let replies_rejected = Arc::clone(&unauthenticated);
        let replies = session
            .declare_subscriber(keys::all_replies(run))
            .callback(move |sample| {
                // Checked here, so a batch its host did not send never reaches the world's queue.
                let key = sample.key_expr().as_str();
                let Some((host, seal)) = seals.get(key) else {
                    replies_rejected.fetch_add(1, Ordering::Relaxed);
                    return;
                };
                match seal.open(key, &sample.payload().to_bytes()) {
                    Ok(payload) => {
                        let bytes = payload.to_vec();
                        let _ = replies_sender.send(Incoming::Replies(host.clone(), bytes));
                    }
                    Err(e) => {
                        replies_rejected.fetch_add(1, Ordering::Relaxed);
                        tracing::debug!(host, "dropping replies: {e}");
                    }
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
        for (share, seal) in options.hosts.iter().zip(host_seals) {
            let frames_key = keys::frames(run, &share.name);
            let publisher = session
                .declare_publisher(frames_key.clone())
                // A stalled link must never block the world: a dropped batch is a missed tick for that host.
                .congestion_control(CongestionControl::Drop)
                .express(true)
                .wait()
                .map_err(zenoh_error("declaring a frames publisher"))?;
            hosts.push(Host {
                replies: vec![ReplyEntry::MISSING; share.robots.len()],
                share: share.clone(),
                state: State::Absent,
                up: false,
                epoch: 0,
                answered: 0,
                live_from: 1,
                returning: false,
                publisher,
                seal,
                frames_key,
                events: Vec::new(),
            });
        }
        let n = robots as usize;
        let mut owner = vec![0; n];
        for (index, share) in options.hosts.iter().enumerate() {
            for &robot in &share.robots {
                if let Some(slot) = owner.get_mut(robot as usize) {
                    *slot = index;
                }
            }
        }
        let sensed_by_host = shares_cover_in_ranges(&options.hosts, robots);
        Ok(RemoteHosts {
            sensed_by_host,
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
            inboxes: Vec::new(),
            posted: vec![false; n],
            outboxes: vec![None; n],
            status: vec![CommandStatus::Missing; n],
            owner,
            present: vec![true; n],
            held: vec![false; n],
            news: Vec::new(),
            orders_sent: 0,
            answer: None,
            buf: Vec::new(),
            dropped: Dropped::default(),
            unauthenticated,
            _token: token,
            _replies: replies,
            _hosts: hosts_watch,
        })
    }

    /// Tells host `index` of the placement to die (`swarm ctl kill-host`); its loss is then noticed like any
    /// other, through its liveliness token.
    pub fn kill_host(&self, index: usize) -> Result<(), RemoteError> {
        let Some(host) = self.hosts.get(index) else {
            return Ok(());
        };
        tracing::warn!(host = host.share.name, "killing the host as asked");
        let key = keys::kill(&host.share.name);
        let mut payload = kill_payload(self.run, host.epoch);
        host.seal.seal(&key, &mut payload);
        self.session
            .put(key, payload)
            .wait()
            .map_err(zenoh_error("telling a host to die"))
    }

    /// The last tick run (0 before the first).
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Runs one tick: `sense(tick, first, frames)` fills the frames of robots `first..` (the arguments of
    /// `WorldLink::tick_with`), one host's robots at a time when the placement gives each host a range of ids
    /// (else all robots at once), and each live host's message goes out as soon as its frames are sensed; the
    /// call returns when every live host answered or the deadline passed. Read the commands with
    /// [`RemoteHosts::command`].
    pub fn tick_with(
        &mut self,
        mut sense: impl FnMut(u64, usize, &mut [SensorFrame]),
    ) -> Result<TickOutcome, RemoteError> {
        let tick = self.tick + 1;
        self.tick = tick;
        self.sent = false;
        while let Ok(event) = self.incoming.try_recv() {
            self.handle(event, false)?;
        }
        self.retry_assignments()?;
        if !self.sensed_by_host {
            SensorFrame::sense_into(tick, 0, &mut self.frames, &mut sense);
        }
        for status in &mut self.status {
            *status = CommandStatus::Missing;
        }
        for (index, host) in self.hosts.iter_mut().enumerate() {
            if self.sensed_by_host
                && let Some(&first) = host.share.robots.first()
            {
                // The host's agents start while the world senses the next host's robots.
                let range = first as usize..first as usize + host.share.robots.len();
                SensorFrame::sense_into(tick, range.start, &mut self.frames[range], &mut sense);
            }
            if host.state != State::Live || host.live_from > tick {
                continue;
            }
            let header = Header::new(Kind::Frames, self.run, index as u16, host.epoch, tick);
            let (inboxes, posted) = (&self.inboxes, &self.posted);
            let frames = host.share.robots.iter().map(|&r| {
                let r = r as usize;
                let inbox = posted[r].then(|| &inboxes[r]);
                (&self.frames[r], inbox)
            });
            codec::encode_batch(&mut self.buf, &header, &host.share.robots, frames)?;
            host.seal.seal(&host.frames_key, &mut self.buf);
            host.publisher
                .put(self.buf.clone())
                .wait()
                .map_err(zenoh_error("publishing frames"))?;
        }
        self.sent = true;
        self.posted.fill(false);
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
        for host in &mut self.hosts {
            let live = host.state == State::Live && host.live_from <= tick;
            if live && host.returning {
                // Its robots take part from the next tick, as after any return the world learns of in a tick.
                host.returning = false;
                self.news
                    .extend(host.share.robots.iter().map(|&r| RobotNews::HostBack(r)));
            }
            for (slot, &robot) in host.share.robots.iter().enumerate() {
                let r = robot as usize;
                let entry = &mut host.replies[slot];
                self.outboxes[r] = None;
                let status = match (live, host.answered == tick, entry.reply) {
                    (true, true, Reply::Answered(command)) => {
                        self.commands[r] = command;
                        self.outboxes[r] = entry.outbox.take();
                        CommandStatus::Answered
                    }
                    (true, true, Reply::Dead) => {
                        if std::mem::replace(&mut self.present[r], false) {
                            self.news.push(RobotNews::Died(robot));
                        }
                        CommandStatus::Dead
                    }
                    (true, _, _) if self.held[r] => CommandStatus::Dead,
                    (true, true, Reply::Missing) | (true, false, _) => CommandStatus::Missing,
                    (false, _, _) => CommandStatus::Dead,
                };
                self.status[r] = status;
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
                    host.returning = false;
                    host.events.push(HostEvent::Lost { tick });
                    tracing::warn!(host = name, tick, "host lost: its robots are dead");
                    for &robot in &host.share.robots {
                        self.present[robot as usize] = false;
                        self.held[robot as usize] = false;
                        self.news.push(RobotNews::HostLost(robot));
                    }
                }
            }
            Incoming::Assigned(index, answer) => self.assigned(index, answer, before_run)?,
            Incoming::AssignEnded(index, epoch) => {
                // No answer (e.g. the host's queryable was not known yet after a reconnection): try again later.
                if let Some(host) = self.hosts.get_mut(index)
                    && host.epoch == epoch
                    && host.state == State::Assigning
                {
                    tracing::debug!(host = host.share.name, epoch, "assignment unanswered");
                    host.state = State::Absent;
                }
            }
            Incoming::Replies(name, bytes) => self.replies(&name, &bytes),
            Incoming::Ordered(order, answer) if order == self.orders_sent => {
                self.answer = Some(answer);
            }
            Incoming::OrderEnded(order) if order == self.orders_sent && self.answer.is_none() => {
                self.answer = Some(Err("no answer".into()));
            }
            Incoming::Ordered(..) | Incoming::OrderEnded(_) => {}
        }
        Ok(())
    }

    fn host_named(&self, name: &str) -> Option<usize> {
        self.hosts.iter().position(|h| h.share.name == name)
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
                    |(entry, &robot)| !matches!(entry.reply, Reply::Answered(c) if c.robot != robot),
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

    /// Puts `inbox` into `robot`'s inbox for the next tick (sent with its frame); see `WorldLink::post`.
    pub fn post(&mut self, robot: u32, inbox: &mut Mailbox) {
        let r = robot as usize;
        if r >= self.posted.len() {
            return;
        }
        if self.inboxes.is_empty() {
            self.inboxes = (0..self.posted.len() as u32).map(Mailbox::empty).collect();
        }
        inbox.tick = self.tick + 1;
        inbox.owner = robot;
        self.inboxes[r] = *inbox;
        self.posted[r] = true;
    }

    /// The messages `robot` sent in the last tick; `None` when it did not answer or sent nothing. The sender is
    /// the robot whose entry carried them, whatever the host put in the outbox.
    pub fn outbox(&self, robot: u32) -> Option<Mailbox> {
        self.command(robot)?;
        let mut outbox = **self.outboxes.get(robot as usize)?.as_ref()?;
        outbox.owner = robot;
        Some(outbox)
    }

    /// What the world got from each robot in the last tick, indexed by robot.
    pub fn statuses(&self) -> &[CommandStatus] {
        &self.status
    }

    /// What happened to robots' agents and hosts since the last call, oldest first; drains the list.
    pub fn take_news(&mut self) -> std::vec::Drain<'_, RobotNews> {
        self.news.drain(..)
    }

    /// Whether `robot`'s host runs an agent for it, as far as the world knows, and has run a tick with it (a
    /// rejoined host's robots are present from the end of its first tick back).
    pub fn agent_present(&self, robot: u32) -> bool {
        let r = robot as usize;
        self.owner.get(r).is_some_and(|&index| {
            let host = &self.hosts[index];
            self.present[r] && host.state == State::Live && host.live_from <= self.tick
        })
    }

    /// Each host with what happened to it.
    pub fn host_events(&self) -> impl Iterator<Item = (&HostShare, &[HostEvent])> {
        self.hosts.iter().map(|h| (&h.share, h.events.as_slice()))
    }

    /// Payloads dropped so far.
    pub fn dropped(&self) -> Dropped {
        Dropped {
            unauthenticated: self.unauthenticated.load(Ordering::Relaxed),
            ..self.dropped
        }
    }
}

/// Whether the robots of `hosts` are, host by host, consecutive ids whose ranges together are exactly `0..robots`.
fn shares_cover_in_ranges(hosts: &[HostShare], robots: u32) -> bool {
    let mut covered = vec![false; robots as usize];
    for share in hosts {
        let first = share.robots.first().copied().unwrap_or(0);
        for (offset, &robot) in (0..).zip(&share.robots) {
            match covered.get_mut(robot as usize) {
                Some(seen) if !*seen && robot == first + offset => *seen = true,
                _ => return false,
            }
        }
    }
    covered.into_iter().all(|seen| seen)
}

#[cfg(test)]
mod tests;
