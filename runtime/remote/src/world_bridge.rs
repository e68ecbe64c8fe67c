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

use super::auth::{HostKeys, Seal, answer_channel};
use super::codec::{self, Header, Kind};
use super::host_to_world::{AssignmentReply, OrderReply, Reply, ReplyEntry};
use super::session::{ZenohOptions, zenoh_error};
use super::world_to_host::{Assignment, Order, OrderAction, kill_payload};
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
                let keys = match self.options.keys {
                    HostKeys::On(_) => {
                        "; each needs its key from this machine (`swarm host-key <name>` says where it is): a host \
                         with another key or none is never admitted"
                    }
                    HostKeys::Off => " --insecure",
                };
                return Err(RemoteError::HostsMissing(format!(
                    "hosts not ready within {timeout:?}: {} (start them with `swarm host --connect {} --name \
                     <name>`{keys})",
                    missing.join(", "),
                    self.options
                        .listen
                        .first()
                        .map_or("<endpoint>", String::as_str)
                )));
            }
            match self
                .incoming
                .recv_timeout((deadline - now).min(RETRY_PERIOD))
            {
                Ok(event) => self.handle(event, true)?,
                Err(RecvTimeoutError::Timeout) => self.retry_assignments()?,
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        Ok(())
    }

    /// Sends their share again to hosts that are up but whose last assignment went unanswered.
    fn retry_assignments(&mut self) -> Result<(), RemoteError> {
        for index in 0..self.hosts.len() {
            if self.hosts[index].up && self.hosts[index].state == State::Absent {
                self.assign(index)?;
            }
        }
        Ok(())
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
            agent_exit_grace_ms: self.options.agent_exit_grace.as_millis() as u64,
            pin_agents: self.options.pin_agents,
            realtime_priority: self.options.realtime_priority,
            mail: self.options.mail,
            compiled_supervisors: self.options.compiled_supervisors.clone(),
            limits: self.options.limits.clone(),
            resume: if host.epoch > 1 {
                host.share
                    .robots
                    .iter()
                    .map(|&r| {
                        let last = &self.commands[r as usize];
                        (last.tick, last.supervisors)
                    })
                    .collect()
            } else {
                Vec::new()
            },
        };
        let key = keys::assign(&host.share.name);
        let mut payload = codec::encode_versioned(&assignment)?;
        host.seal.seal(&key, &mut payload);
        tracing::info!(
            host = host.share.name,
            epoch = host.epoch,
            robots = host.share.robots.len(),
            "assigning"
        );
        let ended = Incoming::AssignEnded(index, host.epoch);
        let seal = host.seal.clone();
        self.query(
            key,
            payload,
            seal,
            self.options.join_timeout + Duration::from_secs(5),
            move |answer| Incoming::Assigned(index, answer),
            ended,
        )
        .map_err(zenoh_error("sending a host its share"))
    }

    /// Sends a query whose answer arrives as the event `answered` makes of it, followed by `ended` when the
    /// query is finished (answered or not). An answer not tagged for this request with `seal` counts as
    /// unauthenticated and is dropped.
    fn query(
        &self,
        key: String,
        payload: Vec<u8>,
        seal: Seal,
        timeout: Duration,
        answered: impl Fn(Result<Vec<u8>, String>) -> Incoming + Send + Sync + 'static,
        ended: Incoming,
    ) -> Result<(), zenoh::Error> {
        let sender = self.sender.clone();
        let ended = QueryEnded {
            sender: self.sender.clone(),
            ended: Some(ended),
        };
        let channel = answer_channel(&key, &payload);
        let unauthenticated = Arc::clone(&self.unauthenticated);
        self.session
            .get(key)
            .payload(payload)
            .timeout(timeout)
            // A host that stopped reading must not block the world: an unsent query goes unanswered.
            .congestion_control(CongestionControl::Drop)
            .callback(move |reply| {
                let _ = &ended;
                let answer = match reply.result() {
                    Ok(sample) => match seal.open(&channel, &sample.payload().to_bytes()) {
                        Ok(payload) => Ok(payload.to_vec()),
                        Err(e) => {
                            unauthenticated.fetch_add(1, Ordering::Relaxed);
                            tracing::debug!("dropping an answer: {e}");
                            return;
                        }
                    },
                    Err(e) => Err(String::from_utf8_lossy(&e.payload().to_bytes()).into_owned()),
                };
                let _ = sender.send(answered(answer));
            })
            .wait()
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
                for &robot in &host.share.robots {
                    self.present[robot as usize] = true;
                    self.held[robot as usize] = false;
                }
                host.returning = !before_run;
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
            // Epoch 0: the host could not read the assignment, so it cannot read this one either.
            Ok(AssignmentReply::Refused { epoch, reason }) if epoch == host.epoch || epoch == 0 => {
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

    /// Sends `robot`'s host a fault order and waits for the answer (a replacement agent's join included), while
    /// following the hosts' news: `Ok(true)` when carried out, `Ok(false)` when the host is not live, is lost
    /// meanwhile, does not answer in time or cannot carry it out (logged). Never waits past the host's loss.
    pub fn order(&mut self, robot: u32, action: OrderAction) -> Result<bool, RemoteError> {
        let Some(&index) = self.owner.get(robot as usize) else {
            return Ok(false);
        };
        if self.hosts[index].state != State::Live {
            return Ok(false);
        }
        let name = self.hosts[index].share.name.clone();
        let epoch = self.hosts[index].epoch;
        let timeout = match action {
            OrderAction::Respawn { .. } => self.options.join_timeout + Duration::from_secs(5),
            _ => self.options.tick_deadline.max(Duration::from_secs(5)),
        };
        self.orders_sent += 1;
        let number = self.orders_sent;
        let order = Order {
            run: self.run,
            epoch,
            number,
            robot,
            action: action.clone(),
        };
        let key = keys::orders(&name);
        let mut payload = codec::encode_message(&order)?;
        let seal = self.hosts[index].seal.clone();
        seal.seal(&key, &mut payload);
        self.answer = None;
        self.query(
            key,
            payload,
            seal,
            timeout,
            move |answer| Incoming::Ordered(number, answer),
            Incoming::OrderEnded(number),
        )
        .map_err(zenoh_error("sending a host a fault order"))?;
        let deadline = Instant::now() + timeout;
        while self.answer.is_none() {
            let now = Instant::now();
            if now >= deadline
                || self.hosts[index].state != State::Live
                || epoch != self.hosts[index].epoch
            {
                break;
            }
            match self.incoming.recv_timeout(deadline - now) {
                Ok(event) => self.handle(event, false)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        let outcome = match self.answer.take() {
            None => Err("the host was lost or did not answer in time".to_owned()),
            Some(answer) => answer
                .and_then(|bytes| {
                    codec::decode_message::<OrderReply>(&bytes, self.options.max_payload).map_err(
                        |e| {
                            self.dropped.rejected += 1;
                            e.to_string()
                        },
                    )
                })
                .and_then(|reply| match reply {
                    OrderReply::Done => Ok(()),
                    OrderReply::Failed { reason } => Err(reason),
                }),
        };
        if let Err(reason) = outcome {
            tracing::warn!(
                host = name,
                robot,
                order = action.name(),
                "fault order not carried out: {reason}"
            );
            return Ok(false);
        }
        let r = robot as usize;
        match action {
            OrderAction::Kill => (self.present[r], self.held[r]) = (false, true),
            OrderAction::Freeze | OrderAction::Skip => self.held[r] = true,
            OrderAction::Thaw | OrderAction::Revive => self.held[r] = false,
            OrderAction::Respawn { .. } => (self.present[r], self.held[r]) = (true, false),
        }
        Ok(true)
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
mod tests {
    //! The world's side against fake hosts: real zenoh sessions on loopback, hosts played by the test.

    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    use super::*;
    use crate::auth::HostKey;
    use crate::host_to_world::without_outboxes;
    use crate::world_to_host::FrameEntry;

    fn shares(robots: &[&[u32]]) -> Vec<HostShare> {
        robots
            .iter()
            .enumerate()
            .map(|(i, robots)| HostShare {
                name: format!("h{i}"),
                robots: robots.to_vec(),
            })
            .collect()
    }

    #[test]
    fn hosts_are_sensed_one_by_one_only_when_their_ranges_cover_the_robots() {
        assert!(shares_cover_in_ranges(&shares(&[&[0, 1], &[2, 3, 4]]), 5));
        assert!(shares_cover_in_ranges(&shares(&[&[3, 4], &[0, 1, 2]]), 5));
        assert!(
            !shares_cover_in_ranges(&shares(&[&[0, 2], &[1, 3]]), 4),
            "not ranges"
        );
        assert!(
            !shares_cover_in_ranges(&shares(&[&[0, 1], &[3]]), 4),
            "robot 2 on no host"
        );
        assert!(
            !shares_cover_in_ranges(&shares(&[&[0, 1], &[1, 2]]), 3),
            "robot 1 twice"
        );
        assert!(
            !shares_cover_in_ranges(&shares(&[&[0, 1, 2]]), 2),
            "robot 2 is not in the run"
        );
    }

    /// How a fake host answers frames.
    #[derive(Clone, Copy)]
    enum Behaviour {
        /// Answers for its own robots.
        Honest,
        /// Claims another host's robot in its batch.
        Impostor(u32),
        /// Sends bytes that are not a batch.
        Garbage,
        /// Answers honestly, and also sends replies on another host's key for that host's robot, tagged with its
        /// own key (one host speaking for another).
        Forger { victim: &'static str, robot: u32 },
        /// Built from another source: refuses every assignment as unreadable (epoch 0).
        OtherBuild,
    }

    /// The test's key of host `name` (made of its name, so every test agrees).
    fn key_of(name: &str) -> Arc<HostKey> {
        let mut secret = [0u8; crate::auth::KEY_LEN];
        for (byte, b) in secret.iter_mut().zip(name.bytes().cycle()) {
            *byte = b;
        }
        Arc::new(HostKey::from_secret(&secret))
    }

    /// A host played by the test: answers its assignment, then every frames message, until dropped.
    struct FakeHost {
        session: Option<Session>,
        stop: Arc<AtomicBool>,
        threads: Vec<std::thread::JoinHandle<()>>,
    }

    impl FakeHost {
        fn start(endpoint: &str, name: &str, behaviour: Behaviour) -> FakeHost {
            let session = ZenohOptions::default()
                .open_host(endpoint)
                .expect("the fake host connects");
            let stop = Arc::new(AtomicBool::new(false));
            let seal = Seal::Key(key_of(name));
            let queryable = session
                .declare_queryable(keys::assign(name))
                .wait()
                .expect("queryable");
            let (share_tx, share_rx) = mpsc::channel();
            let flag = Arc::clone(&stop);
            let declaring = session.clone();
            let token_key = keys::host_token(name);
            let name = name.to_owned();
            let assign_seal = seal.clone();
            let assign = std::thread::spawn(move || {
                while !flag.load(Ordering::Relaxed) {
                    let Ok(Some(query)) = queryable.recv_timeout(Duration::from_millis(20)) else {
                        continue;
                    };
                    let bytes = query
                        .payload()
                        .map(|p| p.to_bytes().into_owned())
                        .unwrap_or_default();
                    let payload = assign_seal
                        .open(&keys::assign(&name), &bytes)
                        .expect("the world's key");
                    let reply = |answer: &AssignmentReply| {
                        let mut reply = codec::encode_message(answer).expect("encodes");
                        assign_seal.seal(
                            &answer_channel(query.key_expr().as_str(), &bytes),
                            &mut reply,
                        );
                        query
                            .reply(query.key_expr().clone(), reply)
                            .wait()
                            .expect("reply");
                    };
                    if let Behaviour::OtherBuild = behaviour {
                        reply(&AssignmentReply::Refused {
                            epoch: 0,
                            reason: "wire version 1, this build speaks version 2".into(),
                        });
                        continue;
                    }
                    let assignment: Assignment =
                        codec::decode_versioned(payload, codec::DEFAULT_MAX_PAYLOAD)
                            .expect("an assignment");
                    // Like a real host: ready to receive frames before saying so.
                    let frames = declaring
                        .declare_subscriber(keys::frames(assignment.run, &name))
                        .wait()
                        .expect("subscriber");
                    let publisher = declaring
                        .declare_publisher(keys::replies(assignment.run, &name))
                        .wait()
                        .expect("publisher");
                    let forged = match behaviour {
                        Behaviour::Forger { victim, .. } => Some(
                            declaring
                                .declare_publisher(keys::replies(assignment.run, victim))
                                .wait()
                                .expect("publisher"),
                        ),
                        _ => None,
                    };
                    let robots: Vec<u32> = assignment.robots.iter().map(|(r, _)| *r).collect();
                    let _ = share_tx.send((robots, frames, publisher, forged));
                    reply(&AssignmentReply::Ready {
                        epoch: assignment.epoch,
                    });
                }
            });
            let token = session
                .liveliness()
                .declare_token(token_key)
                .wait()
                .expect("token");
            let flag = Arc::clone(&stop);
            let answer = std::thread::spawn(move || {
                let _token = token;
                // The world assigns the share once it sees the token, i.e. once the test waits for the hosts.
                let Ok((robots, frames, publisher, forged)) = share_rx.recv() else {
                    return;
                };
                let mut out = vec![FrameEntry::empty(0); robots.len()];
                let mut buf = Vec::new();
                while !flag.load(Ordering::Relaxed) {
                    let Ok(Some(sample)) = frames.recv_timeout(Duration::from_millis(20)) else {
                        continue;
                    };
                    let bytes = sample.payload().to_bytes();
                    let frames_key = sample.key_expr().as_str();
                    let bytes = seal.open(frames_key, &bytes).expect("the world's key");
                    let header =
                        codec::decode_batch(bytes, Kind::Frames, &robots, &mut out, 1 << 20)
                            .expect("frames decode");
                    let reply_header = Header::new(
                        Kind::Replies,
                        header.run,
                        header.host,
                        header.epoch,
                        header.tick,
                    );
                    let mut claimed = robots.clone();
                    if let Behaviour::Impostor(other) = behaviour {
                        claimed[0] = other;
                    }
                    let replies: Vec<Reply> = claimed
                        .iter()
                        .map(|&r| {
                            let mut command = ActuatorCommand::idle(r, header.tick);
                            command.wheels = [1.0, 2.0];
                            Reply::Answered(command)
                        })
                        .collect();
                    codec::encode_batch(
                        &mut buf,
                        &reply_header,
                        &claimed,
                        without_outboxes(&replies),
                    )
                    .expect("encodes");
                    if let Behaviour::Garbage = behaviour {
                        buf = b"not a batch".to_vec();
                    }
                    seal.seal(publisher.key_expr().as_str(), &mut buf);
                    publisher.put(buf.clone()).wait().expect("put");
                    if let (Behaviour::Forger { robot, .. }, Some(forged)) = (behaviour, &forged) {
                        let mut command = ActuatorCommand::idle(robot, header.tick);
                        command.wheels = [9.0, 9.0];
                        let header = Header::new(Kind::Replies, header.run, 0, 1, header.tick);
                        codec::encode_batch(
                            &mut buf,
                            &header,
                            &[robot],
                            without_outboxes(&[Reply::Answered(command)]),
                        )
                        .expect("encodes");
                        seal.seal(forged.key_expr().as_str(), &mut buf);
                        forged.put(buf.clone()).wait().expect("put");
                    }
                }
            });
            FakeHost {
                session: Some(session),
                stop,
                threads: vec![assign, answer],
            }
        }
    }

    impl Drop for FakeHost {
        fn drop(&mut self) {
            self.stop.store(true, Ordering::Relaxed);
            for thread in self.threads.drain(..) {
                let _ = thread.join();
            }
            if let Some(session) = self.session.take() {
                let _ = session.close().wait();
            }
        }
    }

    fn world(endpoint: &str, shares: &[(&str, &[u32])]) -> RemoteHosts {
        let robots: u32 = shares.iter().map(|(_, r)| r.len() as u32).sum();
        let options = RemoteOptions {
            listen: vec![endpoint.to_owned()],
            zenoh: ZenohOptions::default(),
            hosts: shares
                .iter()
                .map(|(name, robots)| HostShare {
                    name: (*name).to_owned(),
                    robots: robots.to_vec(),
                })
                .collect(),
            controllers: vec!["c".into(); robots as usize],
            config: PathBuf::from("/experiment.argos"),
            seed: 1,
            robots_override: None,
            tick_deadline: Duration::from_millis(300),
            join_timeout: Duration::from_secs(30),
            agent_exit_grace: Duration::from_secs(5),
            pin_agents: true,
            realtime_priority: false,
            mail: false,
            max_payload: codec::DEFAULT_MAX_PAYLOAD,
            compiled_supervisors: Vec::new(),
            limits: Vec::new(),
            keys: HostKeys::On(
                shares
                    .iter()
                    .map(|(name, _)| ((*name).to_owned(), key_of(name)))
                    .collect(),
            ),
        };
        RemoteHosts::start(options, robots, 0x5eed).expect("the world listens")
    }

    fn endpoint() -> String {
        let port = std::net::TcpListener::bind(("127.0.0.1", 0))
            .and_then(|l| l.local_addr())
            .map(|a| a.port())
            .expect("a free port");
        format!("tcp/127.0.0.1:{port}")
    }

    #[test]
    fn a_host_that_cannot_read_its_assignment_fails_the_run_before_it_starts() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("old", &[0, 1])]);
        let _old = FakeHost::start(&endpoint, "old", Behaviour::OtherBuild);
        let joined = world.wait_for_hosts(Duration::from_secs(30));
        assert!(
            matches!(&joined, Err(RemoteError::Refused { host, reason })
                if host == "old" && reason.contains("wire version")),
            "{joined:?}"
        );
    }

    #[test]
    fn replies_naming_another_hosts_robot_are_rejected_whole() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("honest", &[0, 1]), ("impostor", &[2])]);
        let _honest = FakeHost::start(&endpoint, "honest", Behaviour::Honest);
        let _impostor = FakeHost::start(&endpoint, "impostor", Behaviour::Impostor(0));
        world
            .wait_for_hosts(Duration::from_secs(30))
            .expect("both hosts join");
        let outcome = world.tick_with(|_, _, _| {}).expect("a tick");
        assert_eq!((outcome.answered, outcome.missing, outcome.dead), (2, 1, 0));
        assert_eq!(world.command(0).map(|c| c.wheels), Some([1.0, 2.0]));
        assert_eq!(
            world.command(2),
            None,
            "the impostor's batch must not command robot 2"
        );
        assert!(world.dropped().rejected >= 1);
    }

    #[test]
    fn replies_tagged_with_another_hosts_key_are_never_taken() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("victim", &[0]), ("forger", &[1])]);
        let _victim = FakeHost::start(&endpoint, "victim", Behaviour::Honest);
        let _forger = FakeHost::start(
            &endpoint,
            "forger",
            Behaviour::Forger {
                victim: "victim",
                robot: 0,
            },
        );
        world
            .wait_for_hosts(Duration::from_secs(30))
            .expect("both hosts join");
        for _ in 0..20 {
            world.tick_with(|_, _, _| {}).expect("a tick");
            assert_ne!(
                world.command(0).map(|c| c.wheels),
                Some([9.0, 9.0]),
                "the forger commanded the victim's robot"
            );
        }
        assert!(
            world.dropped().unauthenticated >= 1,
            "{:?}",
            world.dropped()
        );
    }

    #[test]
    fn an_order_nobody_carries_out_is_reported_and_changes_nothing() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("quiet", &[0, 1])]);
        // The fake host answers frames but has no orders queryable.
        let _quiet = FakeHost::start(&endpoint, "quiet", Behaviour::Honest);
        world
            .wait_for_hosts(Duration::from_secs(30))
            .expect("the host joins");
        world.tick_with(|_, _, _| {}).expect("a tick");
        assert_eq!(world.order(1, OrderAction::Kill).ok(), Some(false));
        assert!(
            world.agent_present(1),
            "a kill not carried out keeps the agent"
        );
        assert_eq!(
            world.order(7, OrderAction::Kill).ok(),
            Some(false),
            "a robot of no host"
        );
        let outcome = world.tick_with(|_, _, _| {}).expect("the next tick");
        assert_eq!(outcome.answered, 2, "ticks go on as before");
    }

    #[test]
    fn a_malformed_batch_is_dropped_and_counted_and_the_tick_goes_on() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("garbled", &[0])]);
        let _host = FakeHost::start(&endpoint, "garbled", Behaviour::Garbage);
        world
            .wait_for_hosts(Duration::from_secs(30))
            .expect("the host joins");
        for tick in 1..=2 {
            let outcome = world.tick_with(|_, _, _| {}).expect("a tick");
            assert_eq!((outcome.tick, outcome.missing), (tick, 1));
        }
        assert!(world.dropped().rejected >= 2, "{:?}", world.dropped());
    }

    #[test]
    fn a_host_whose_session_ends_is_lost_and_its_robots_die_at_a_recorded_tick() {
        let endpoint = endpoint();
        let mut world = world(&endpoint, &[("stays", &[0]), ("goes", &[1, 2])]);
        let _stays = FakeHost::start(&endpoint, "stays", Behaviour::Honest);
        let goes = FakeHost::start(&endpoint, "goes", Behaviour::Honest);
        world
            .wait_for_hosts(Duration::from_secs(30))
            .expect("both hosts join");
        let first = world.tick_with(|_, _, _| {}).expect("a tick");
        assert_eq!(first.answered, 3);
        drop(goes);
        // The loss is decided within a tick or two (the session's end is seen in milliseconds); no tick blocks.
        let mut lost_at = None;
        for _ in 0..50 {
            let outcome = world.tick_with(|_, _, _| {}).expect("a tick");
            if outcome.dead == 2 {
                lost_at = Some(outcome.tick);
                break;
            }
        }
        let lost_at = lost_at.expect("the host was declared lost");
        let news: Vec<RobotNews> = world.take_news().collect();
        assert_eq!(news, [RobotNews::HostLost(1), RobotNews::HostLost(2)]);
        assert!(!world.agent_present(1) && world.agent_present(0));
        let events: Vec<HostEvent> = world
            .host_events()
            .find(|(share, _)| share.name == "goes")
            .map(|(_, events)| events.to_vec())
            .expect("the host is listed");
        assert_eq!(events, [HostEvent::Lost { tick: lost_at }]);
        assert_eq!(world.statuses()[0], CommandStatus::Answered);
    }
}
