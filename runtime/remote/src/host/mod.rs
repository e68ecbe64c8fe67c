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
//!
//! This module takes the world's messages and answers them; `share.rs` is a share's local run and its ticks.

mod share;

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::Duration;

use zenoh::Session;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::query::{Query, Queryable};

use super::auth::{Seal, answer_channel};
use super::codec::{self, WireError};
use super::host_to_world::{AssignmentReply, OrderReply};
use super::session::{ZenohOptions, zenoh_error};
use super::world_to_host::{Assignment, Order, parse_kill};
use super::{RemoteError, keys};
use swarm_contract::process::binaries::Binaries;

use share::Share;

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
