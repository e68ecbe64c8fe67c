//! A hostile client over real zenoh against a live run on two real `swarm host` daemons (loopback).
//!
//! A stranger without a key must not even get a session. An insider who holds one host's key (a compromised
//! machine of the swarm) tries what an attacker would: garbage and forged assignments, fault orders and kill
//! messages for the other host, frames from the far future and replayed, replies on the other host's key, and a
//! subscriber on every run key that never reads. The run must go on untouched: no host lost, no robot dead, every
//! forged message refused and counted, and the world keeps ticking while the subscriber stalls.

use std::path::Path;
use std::sync::Arc;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use swarm_remote::auth::{HostKey, Seal};
use swarm_remote::codec::{self, Header, Kind};
use swarm_remote::host_to_world::{Reply, without_outboxes};
use swarm_remote::keys;
use swarm_remote::world_to_host::{Order, OrderAction, kill_payload, without_inboxes};
use swarm_system_tests::{
    HostDaemon, TestKeys, follow_lines, free_port, remove_run_leftovers, spawn_swarm, swarm_ctl,
};
use zenoh::{Session, Wait};

const EXPERIMENT: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";
/// Bound for daemons, the run and each attack to show their effect (process start-up under a loaded machine).
const EVENT_TIMEOUT: Duration = Duration::from_secs(120);
/// Ticks the world must run while the stalled subscriber is connected: far more frames than the socket buffers
/// between the world and the subscriber hold.
const TICKS_WHILE_STALLED: u64 = 5_000;

/// A zenoh client session to `endpoint`, presenting `credentials` if given; an error when refused.
fn open(endpoint: &str, credentials: Option<(&str, &str)>) -> zenoh::Result<Session> {
    let mut config = zenoh::Config::default();
    let set = |config: &mut zenoh::Config, key: &str, value: String| {
        config.insert_json5(key, &value).expect("a zenoh setting");
    };
    set(&mut config, "mode", r#""client""#.into());
    set(&mut config, "scouting/multicast/enabled", "false".into());
    set(
        &mut config,
        "connect/endpoints",
        format!(r#"["{endpoint}"]"#),
    );
    set(&mut config, "connect/exit_on_failure", "true".into());
    set(&mut config, "connect/timeout_ms", "5000".into());
    if let Some((user, password)) = credentials {
        set(
            &mut config,
            "transport/auth/usrpwd/user",
            format!("{user:?}"),
        );
        set(
            &mut config,
            "transport/auth/usrpwd/password",
            format!("{password:?}"),
        );
    }
    zenoh::open(config).wait()
}

/// Sends a query and waits until it ends (answered or not).
fn query(session: &Session, key: &str, payload: Vec<u8>) {
    let replies = session
        .get(key)
        .payload(payload)
        .timeout(Duration::from_secs(10))
        .wait()
        .expect("a query");
    while replies.recv().is_ok() {}
}

/// The run id in the world's liveliness token (`swarm/runs/<run>/world`).
fn run_id(session: &Session) -> u64 {
    let replies = session
        .liveliness()
        .get("swarm/runs/*/world")
        .timeout(Duration::from_secs(10))
        .wait()
        .expect("a liveliness query");
    let reply = replies.recv().expect("the world's token");
    let sample = reply.result().expect("a token");
    let key = sample.key_expr().as_str();
    let hex = key
        .strip_prefix("swarm/runs/")
        .and_then(|rest| rest.strip_suffix("/world"))
        .expect("a run token");
    u64::from_str_radix(hex, 16).expect("a hex run id")
}

/// The last tick a live run reported, from `swarm ctl list`.
fn current_tick(out: &Path) -> u64 {
    swarm_ctl(out, &["list"])
        .lines()
        .find_map(|line| line.strip_prefix("tick "))
        .and_then(|tick| tick.trim().parse().ok())
        .expect("`swarm ctl list` names the tick")
}

#[test]
fn strangers_cannot_join_and_an_insider_cannot_command_another_host_or_stall_the_world() {
    let keys = TestKeys::new();
    let endpoint = format!("tcp/127.0.0.1:{}", free_port("127.0.0.1"));
    let mut alpha = HostDaemon::start("alpha", &endpoint, None, &keys);
    let mut beta = HostDaemon::start("beta", &endpoint, None, &keys);
    let out = tempfile::tempdir().expect("a temporary directory");
    let out_dir = out.path().display().to_string();
    let keys_dir = keys.dir().display().to_string();
    let mut run = spawn_swarm(&[
        "run",
        EXPERIMENT,
        "--robots",
        "4",
        "--ticks",
        "0",
        "--no-progress",
        "--out",
        &out_dir,
        "--hosts",
        "alpha,beta",
        "--listen",
        &endpoint,
        "--keys",
        &keys_dir,
    ]);
    let launcher = run.id();
    let run_log = follow_lines(run.stderr.take());
    let mut run_seen: Vec<String> = Vec::new();
    for daemon in [&mut alpha, &mut beta] {
        assert!(
            daemon.wait_for("first tick of the share", EVENT_TIMEOUT),
            "host {} never ticked:\n{}",
            daemon.name,
            daemon.log()
        );
    }

    // Strangers: no credentials, or a host's name with a made-up password.
    assert!(
        open(&endpoint, None).is_err(),
        "a client without a key got a session"
    );
    assert!(
        open(&endpoint, Some(("beta", "0123456789abcdef"))).is_err(),
        "a client with a made-up password got a session"
    );

    // The insider: admitted with alpha's key, attacking beta (robots 2 and 3).
    let alpha_key = Arc::new(HostKey::read(&keys.key("alpha")).expect("alpha's key"));
    let insider = open(&endpoint, Some(("alpha", alpha_key.admission_password())))
        .expect("a holder of alpha's key is admitted");
    let seal = Seal::Key(alpha_key);
    let run_id = run_id(&insider);
    let sealed = |channel: &str, mut bytes: Vec<u8>| {
        seal.seal(channel, &mut bytes);
        bytes
    };

    let assign = keys::assign("beta");
    query(&insider, &assign, vec![0xA5; 16]);
    query(&insider, &assign, sealed(&assign, vec![0xA5; 16]));
    let kill_order = Order {
        run: run_id,
        epoch: 1,
        number: u64::MAX,
        robot: 2,
        action: OrderAction::Kill,
    };
    let order = codec::encode_message(&kill_order).expect("encodes");
    let orders = keys::orders("beta");
    query(&insider, &orders, order.clone());
    query(&insider, &orders, sealed(&orders, order));
    let kill = keys::kill("beta");
    for payload in [
        kill_payload(run_id, 1),
        sealed(&kill, kill_payload(run_id, 1)),
    ] {
        insider.put(&kill, payload).wait().expect("a put");
    }

    // Frames: one captured from the world and replayed, and one from the far future tagged with alpha's key.
    let frames_key = keys::frames(run_id, "beta");
    let captured = insider
        .declare_subscriber(&frames_key)
        .wait()
        .expect("a subscriber");
    let genuine = captured
        .recv_timeout(EVENT_TIMEOUT)
        .expect("the subscriber works")
        .expect("a frames message of the world")
        .payload()
        .to_bytes()
        .into_owned();
    drop(captured);
    insider.put(&frames_key, genuine).wait().expect("a put");
    let mut future = Vec::new();
    codec::encode_batch(
        &mut future,
        &Header::new(Kind::Frames, run_id, 1, 1, u64::MAX - 1),
        &[2, 3],
        without_inboxes(&[
            swarm_contract::messages::SensorFrame::empty(2),
            swarm_contract::messages::SensorFrame::empty(3),
        ]),
    )
    .expect("encodes");
    insider
        .put(&frames_key, sealed(&frames_key, future))
        .wait()
        .expect("a put");

    // Replies on beta's key, commanding beta's robots, tagged with alpha's key.
    let replies_key = keys::replies(run_id, "beta");
    let tick = current_tick(out.path());
    let mut forged = Vec::new();
    for ahead in 0..50 {
        let command = |robot| {
            let mut command = swarm_contract::messages::ActuatorCommand::idle(robot, tick + ahead);
            command.wheels = [9.0, 9.0];
            Reply::Answered(command)
        };
        codec::encode_batch(
            &mut forged,
            &Header::new(Kind::Replies, run_id, 1, 1, tick + ahead),
            &[2, 3],
            without_outboxes(&[command(2), command(3)]),
        )
        .expect("encodes");
        insider
            .put(&replies_key, sealed(&replies_key, forged.clone()))
            .wait()
            .expect("a put");
    }

    for needle in [
        "ignoring an assignment",
        "ignoring an order",
        "ignoring a kill message",
    ] {
        assert!(
            beta.wait_for(needle, EVENT_TIMEOUT),
            "beta did not refuse a forged message ({needle}):\n{}",
            beta.log()
        );
    }

    // A subscriber on every key of the run that never reads: the world must not wait for it.
    let (release, stalled) = mpsc::channel::<()>();
    let stalled = std::sync::Mutex::new(stalled);
    let _stall = insider
        .declare_subscriber("swarm/runs/**")
        .callback(move |_| {
            let _ = stalled.lock().map(|r| r.recv());
        })
        .wait()
        .expect("a subscriber");
    let from = current_tick(out.path());
    let deadline = Instant::now() + EVENT_TIMEOUT;
    while current_tick(out.path()) < from + TICKS_WHILE_STALLED {
        assert!(
            Instant::now() < deadline,
            "the world stopped ticking while a subscriber stalled (at tick {}, from {from})",
            current_tick(out.path())
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    drop(release);

    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(launcher as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .expect("SIGINT to the launcher");
    let status = run.wait().expect("the launcher ends");
    run_seen.extend(run_log.try_iter());
    assert_eq!(
        status.code(),
        Some(130),
        "the interrupted run:\n{}",
        run_seen.join("\n")
    );
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.path().join("summary.json")).expect("summary.json"),
    )
    .expect("JSON");
    for host in summary["hosts"]["hosts"].as_array().expect("hosts") {
        assert_eq!(
            host["lost_at_ticks"],
            serde_json::json!([]),
            "a host was lost: {summary:#}"
        );
    }
    assert!(
        summary["hosts"]["unauthenticated_payloads"].as_u64() >= Some(1),
        "the forged replies were not counted: {summary:#}"
    );
    assert_eq!(
        (&summary["deaths"], &summary["alive_final"]),
        (&serde_json::json!([]), &serde_json::json!(4)),
        "a robot died: {summary:#}"
    );
    assert!(
        beta.wait_for("share ended", EVENT_TIMEOUT) && !beta.log().contains("killed by"),
        "beta's share did not end cleanly or was killed:\n{}",
        beta.log()
    );
    let ended = beta
        .log()
        .lines()
        .find(|line| line.contains("share ended"))
        .map(str::to_owned)
        .unwrap_or_default();
    assert!(
        ended.contains("unauthenticated=") && !ended.contains("unauthenticated=0"),
        "beta did not count the forged frames: {ended}"
    );
    let _ = insider.close().wait();
    assert!(
        alpha.stop() && beta.stop(),
        "the hosts did not stop cleanly"
    );
    remove_run_leftovers(&format!("sw{launcher:x}-"));
}
