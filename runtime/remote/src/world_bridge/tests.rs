//! The world's side against fake hosts: real zenoh sessions on loopback, hosts played by the test.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::*;
use crate::auth::{HostKey, answer_channel};
use crate::host_to_world::{AssignmentReply, without_outboxes};
use crate::world_to_host::{Assignment, FrameEntry, OrderAction};

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
                let header = codec::decode_batch(bytes, Kind::Frames, &robots, &mut out, 1 << 20)
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
