//! `swarm run` across hosts: real `swarm host` daemons, each in its own Linux network namespace joined by a veth pair
//! (root and iproute2 needed; otherwise the tests say so loudly and run the hosts on loopback), each with its own
//! iceoryx2 prefix and root, speaking zenoh with the world.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::Duration;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use swarm_system_tests::{
    HostDaemon, Netns, TestKeys, arrivals_by, assert_clean, bin_dir, follow_lines, free_port,
    shm_leftovers, swarm, swarm_ctl, wait_for_line, workspace_root,
};

const OBSTACLE_AVOIDANCE: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";
/// Robots of the fault tests' runs.
const RUN_ROBOTS: usize = 6;
/// The restart policy of the host fault tests whose lost robots come back with their host.
const RESTART_ON_FAILURE: [&str; 2] = ["--fault", "restart policy=on-failure backoff=0"];
/// Generous bound for events that take milliseconds to seconds (process start-up under a loaded machine).
const EVENT_TIMEOUT: Duration = Duration::from_secs(120);

/// Where the hosts of a test run: network namespaces when possible, else loopback (said loudly).
struct Hosts {
    daemons: Vec<HostDaemon>,
    namespaces: Vec<Netns>,
    listen: Vec<String>,
    keys: TestKeys,
}

impl Hosts {
    fn start(names: &[&str]) -> Hosts {
        let keys = TestKeys::new();
        let namespaces: Result<Vec<Netns>, String> =
            names.iter().map(|_| Netns::create()).collect();
        match namespaces {
            Ok(namespaces) => {
                let mut listen = Vec::new();
                let mut daemons = Vec::new();
                for (name, ns) in names.iter().zip(&namespaces) {
                    let endpoint = format!("tcp/{}:{}", ns.outer_ip, free_port(&ns.outer_ip));
                    daemons.push(HostDaemon::start(name, &endpoint, Some(&ns.name), &keys));
                    listen.push(endpoint);
                }
                Hosts {
                    daemons,
                    namespaces,
                    listen,
                    keys,
                }
            }
            Err(reason) => {
                eprintln!(
                    "\n*** SKIPPED network namespaces ({reason}): the hosts run on loopback instead ***\n"
                );
                let endpoint = format!("tcp/127.0.0.1:{}", free_port("127.0.0.1"));
                Hosts {
                    daemons: names
                        .iter()
                        .map(|name| HostDaemon::start(name, &endpoint, None, &keys))
                        .collect(),
                    namespaces: Vec::new(),
                    listen: vec![endpoint],
                    keys,
                }
            }
        }
    }

    /// `--hosts a,b --listen ...` for `swarm run`.
    fn run_args(&self) -> Vec<String> {
        let names: Vec<&str> = self.daemons.iter().map(|d| d.name.as_str()).collect();
        let mut args = vec!["--hosts".to_owned(), names.join(",")];
        for endpoint in &self.listen {
            args.extend(["--listen".to_owned(), endpoint.clone()]);
        }
        args.extend(self.keys.run_args());
        args
    }

    /// Restarts daemon `i` under the same name (in its namespace, if any).
    fn restart(&mut self, i: usize) {
        let name = self.daemons[i].name.clone();
        let endpoint = self.listen[i.min(self.listen.len() - 1)].clone();
        let ns = self.namespaces.get(i).map(|n| n.name.clone());
        self.daemons[i] = HostDaemon::start(&name, &endpoint, ns.as_deref(), &self.keys);
    }

    /// Stops every daemon gracefully and checks it left no process and no shared memory.
    fn stop_and_check_clean(mut self) {
        for daemon in &mut self.daemons {
            let pid = daemon.pid();
            assert!(
                daemon.stop(),
                "host {} did not stop cleanly:\n{}",
                daemon.name,
                daemon.log()
            );
            assert_eq!(
                shm_leftovers(&format!("sw{pid:x}-")),
                Vec::<std::path::PathBuf>::new(),
                "host {}'s shared memory outlived it",
                daemon.name
            );
        }
    }
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn read(out: &Path, name: &str) -> Vec<u8> {
    swarm_system_tests::run_file(out, name)
}

/// A tick deadline far above any tick of these runs on a loaded machine: a run is a pure function of (config,
/// seed, schedule) only while no command misses its tick's deadline, and the suite's other tests share the CPUs.
const COMPARED_TICK_DEADLINE_MS: &str = "10000";

/// Runs `config` with the arguments `common` once on this machine and once on two hosts, both to success, with no
/// command missing its tick and the second with nothing left behind; returns both run folders (single host first)
/// and the hosts, still running.
fn run_single_and_on_two_hosts(
    config: &str,
    common: &[&str],
) -> (tempfile::TempDir, tempfile::TempDir, Hosts) {
    let common: Vec<&str> = ["--tick-deadline-ms", COMPARED_TICK_DEADLINE_MS]
        .into_iter()
        .chain(common.iter().copied())
        .collect();
    let single = tempfile::tempdir().expect("a temporary directory");
    let out = single.path().display().to_string();
    let mut args = vec!["run", config, "--out", &out, "--no-progress"];
    args.extend(&common);
    let outcome = swarm(&args);
    assert!(
        outcome.output.status.success(),
        "single-host run failed:\n{}",
        outcome.stderr()
    );

    let mut hosts = Hosts::start(&["alpha", "beta"]);
    let multi = tempfile::tempdir().expect("a temporary directory");
    let out = multi.path().display().to_string();
    let host_args = hosts.run_args();
    let mut args = vec!["run", config, "--out", &out, "--no-progress"];
    args.extend(&common);
    args.extend(host_args.iter().map(String::as_str));
    let outcome = swarm(&args);
    assert!(
        outcome.output.status.success(),
        "two-host run failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
    for daemon in &mut hosts.daemons {
        assert!(
            daemon.wait_for("the world ended the run", EVENT_TIMEOUT)
                && daemon.wait_for("share ended", EVENT_TIMEOUT),
            "host {} kept its share after the run ended:\n{}",
            daemon.name,
            daemon.log()
        );
    }
    for run in [&single, &multi] {
        assert_eq!(
            summary(run.path())["commands_missing"],
            0,
            "a command missed its tick in {}: the runs cannot be compared",
            run.path().display()
        );
    }
    (single, multi, hosts)
}

/// Runs the obstacle-avoidance experiment (10 robots, 150 ticks, seed 11, plus `extra` arguments) once on this
/// machine and once on two hosts; checks the hosts shared the robots and the records are the same byte for byte.
/// Returns both summaries (single host first) and the hosts, still running.
fn single_and_two_hosts(extra: &[&str]) -> (serde_json::Value, serde_json::Value, Hosts) {
    let mut common = vec!["--robots", "10", "--ticks", "150", "--seed", "11"];
    common.extend(extra);
    let (single, multi, hosts) = run_single_and_on_two_hosts(OBSTACLE_AVOIDANCE, &common);
    let multi_summary = summary(multi.path());
    assert_eq!(multi_summary["ticks"], 150);
    let shares = multi_summary["hosts"]["hosts"]
        .as_array()
        .expect("hosts in the summary");
    let sizes: Vec<usize> = shares
        .iter()
        .map(|h| h["robots"].as_array().map_or(0, Vec::len))
        .collect();
    assert_eq!(sizes, [5, 5], "10 robots shared equally by two hosts");
    assert_eq!(
        multi_summary["processes"]["agents"]
            .as_array()
            .map(Vec::len),
        Some(0),
        "the launcher started no local agent"
    );
    assert!(
        read(single.path(), "trajectory.csv") == read(multi.path(), "trajectory.csv"),
        "trajectory.csv of the two-host run differs from the single-host run with the same seed"
    );
    assert!(
        read(single.path(), "events.csv") == read(multi.path(), "events.csv"),
        "events.csv of the two-host run differs from the single-host run with the same seed"
    );
    (summary(single.path()), multi_summary, hosts)
}

#[test]
fn messages_between_robots_on_two_hosts_have_the_fates_they_have_on_one() {
    let (single, multi, hosts) =
        run_single_and_on_two_hosts("configs/messages/talk.argos", &["--ticks", "40"]);
    for file in ["messages.csv", "trajectory.csv"] {
        assert!(
            read(single.path(), file) == read(multi.path(), file),
            "{file} of the two-host run differs from the single-host run with the same seed"
        );
    }
    let messages = String::from_utf8(read(multi.path(), "messages.csv")).expect("UTF-8");
    for outcome in [",delivered,", ",lost", ",out_of_range", ",forged_sender"] {
        assert!(messages.contains(outcome), "no `{outcome}` in:\n{messages}");
    }
    hosts.stop_and_check_clean();
}

#[test]
fn a_coordinator_on_a_host_is_killed_restarted_and_answers_as_on_one_host() {
    let (single, multi, hosts) =
        run_single_and_on_two_hosts("configs/messages/coordinator.argos", &[]);
    for file in ["messages.csv", "events.csv", "trajectory.csv"] {
        assert!(
            read(single.path(), file) == read(multi.path(), file),
            "{file} of the two-host run differs from the single-host run with the same seed"
        );
    }
    let placed: Vec<u64> = summary(multi.path())["hosts"]["hosts"]
        .as_array()
        .expect("hosts in the summary")
        .iter()
        .flat_map(|h| h["robots"].as_array().cloned().unwrap_or_default())
        .filter_map(|r| r.as_u64())
        .collect();
    assert!(
        placed.contains(&4),
        "the coordinator runs on a host: {placed:?}"
    );
    let events = String::from_utf8(read(multi.path(), "events.csv")).expect("UTF-8");
    assert!(events.contains("20,4,central,fault:kill"), "{events}");
    assert!(events.contains("22,4,central,fault:up"), "{events}");
    hosts.stop_and_check_clean();
}

#[test]
fn scheduled_joins_on_two_hosts_give_the_single_host_records() {
    let (single, multi, hosts) =
        run_single_and_on_two_hosts("configs/joins/late_arrivals.argos", &[]);
    for file in ["events.csv", "trajectory.csv"] {
        assert!(
            read(single.path(), file) == read(multi.path(), file),
            "{file} of the two-host run differs from the single-host run with the same seed"
        );
    }
    let events = String::from_utf8(read(multi.path(), "events.csv")).expect("UTF-8");
    assert!(events.contains("30,4,late,join"), "{events}");
    assert_eq!(
        summary(single.path())["arrivals"],
        summary(multi.path())["arrivals"]
    );
    hosts.stop_and_check_clean();
}

#[test]
fn swarm_ctl_spawns_and_removes_robots_on_hosts() {
    let hosts = Hosts::start(&["alpha", "beta"]);
    let out = tempfile::tempdir().expect("a temporary directory");
    let mut run = BackgroundRun::start_config(
        "configs/joins/late_arrivals.argos",
        out.path(),
        &hosts,
        &["--ticks", "0", "--real-time"],
    );
    run.wait_for("first tick completed");
    let joined = swarm_ctl(out.path(), &["spawn", "9"]);
    let joined_at: u64 = joined
        .trim_end()
        .strip_prefix("robot 9 joins at tick ")
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{joined}"));
    // The spare takes part: its agent on a host answers tick after tick (a robot that did not answer would be down
    // from the next tick). The trajectory is written tick by tick.
    let alive_since_join = || {
        let text = std::fs::read_to_string(out.path().join("trajectory.csv")).unwrap_or_default();
        let whole = text.rfind('\n').map_or("", |end| &text[..end]);
        whole
            .lines()
            .filter(|l| l.split(',').nth(1) == Some("9"))
            .filter(|l| l.split(',').next().and_then(|t| t.parse::<u64>().ok()) >= Some(joined_at))
            .map(|l| l.ends_with(",1"))
            .collect::<Vec<bool>>()
    };
    let deadline = std::time::Instant::now() + EVENT_TIMEOUT;
    while alive_since_join().len() < 5 {
        assert!(
            std::time::Instant::now() < deadline,
            "the run stopped recording"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(
        alive_since_join().iter().all(|&alive| alive),
        "{:?}",
        alive_since_join()
    );
    let left = swarm_ctl(out.path(), &["remove", "1"]);
    assert!(left.starts_with("robot 1 left at tick "), "{left}");
    run.interrupt();
    let summary = summary(out.path());
    let by_ctl = arrivals_by(&summary, "ctl");
    assert_eq!(by_ctl, [("join".to_owned(), 9), ("leave".to_owned(), 1)]);
    let events = String::from_utf8(read(out.path(), "events.csv")).expect("UTF-8");
    assert!(
        events.contains(",9,spare0,join\n") && events.contains(",1,ep1,leave\n"),
        "{events}"
    );
    hosts.stop_and_check_clean();
}

#[test]
fn two_hosts_reproduce_the_single_host_trajectory_and_events() {
    let (_, _, hosts) = single_and_two_hosts(&[]);
    for (daemon, robot) in hosts.daemons.iter().zip([0, 5]) {
        let log = daemon.agent_log(robot);
        assert!(
            log.contains("supervisors/fdc.ptsct"),
            "an agent on host {} loads the run's compiled supervisors, not the models:\n{log}",
            daemon.name
        );
    }
    hosts.stop_and_check_clean();
}

/// The robot faults of a run on hosts, as `(what, robot, scheduled tick, restarted, rejoin tick)`.
fn fault_log(summary: &serde_json::Value) -> Vec<(String, u64, u64, bool, Option<u64>)> {
    summary["faults"]
        .as_array()
        .expect("faults are listed")
        .iter()
        .filter(|f| f["robot"].is_u64() && f["scheduled_tick"].is_u64())
        .map(|f| {
            (
                f["what"].as_str().unwrap_or_default().to_owned(),
                f["robot"].as_u64().unwrap_or_default(),
                f["scheduled_tick"].as_u64().unwrap_or_default(),
                f["restarted"] == true,
                f["rejoin_tick"].as_u64(),
            )
        })
        .collect()
}

/// A fault schedule with restarts on hosts: the hosts kill, freeze and thaw their agents and start replacements
/// that resume from the world's record, between the same ticks as a single-host run does, so the records are the
/// same byte for byte; the fault logs agree too.
#[test]
fn a_fault_schedule_with_restarts_on_hosts_reproduces_the_single_host_run() {
    let (single, multi, hosts) = single_and_two_hosts(&[
        "--fault",
        "restart policy=on-failure robots=1,2,7 backoff=0.25",
        "--fault",
        "kill robots=1 tick=0",
        "--fault",
        "kill robots=2,7 tick=30",
        "--fault",
        "freeze robots=4 tick=40",
        "--fault",
        "thaw robots=4 tick=70",
        "--fault",
        "kill robots=9 tick=90",
    ]);
    let log = fault_log(&multi);
    assert_eq!(log, fault_log(&single), "{multi}");
    let restarted_kill = |robot: u64| {
        log.iter()
            .find(|(what, r, tick, ..)| what == "kill" && *r == robot && *tick == 30)
            .map(|(.., restarted, rejoin)| (*restarted, *rejoin))
    };
    // backoff 0.25 s at 20 ticks/s: the replacements take part from tick 35.
    assert_eq!(restarted_kill(2), Some((true, Some(35))), "{log:?}");
    assert_eq!(restarted_kill(7), Some((true, Some(35))), "{log:?}");
    assert!(
        log.iter()
            .any(|(what, r, tick, restarted, _)| what == "kill"
                && *r == 9
                && *tick == 90
                && !restarted),
        "robot 9 has no restart rule: {log:?}"
    );
    assert_eq!(multi["alive_final"], 9, "only robot 9 stays dead");
    for robot in [2u64, 7] {
        let host = hosts
            .daemons
            .iter()
            .find(|d| d.agent_log(robot).contains("resumed supervisors"))
            .unwrap_or_else(|| panic!("no host's agent of robot {robot} resumed"));
        let agent_log = host.agent_log(robot);
        assert!(
            agent_log.contains("resumed supervisors at tick 35 from the snapshot of tick 29"),
            "robot {robot}'s replacement on host {}:\n{agent_log}",
            host.name
        );
    }
    hosts.stop_and_check_clean();
}

/// A `swarm run` in the background whose log lines the test follows.
struct BackgroundRun {
    child: Child,
    lines: Receiver<String>,
    seen: Vec<String>,
}

impl BackgroundRun {
    /// `swarm run` of the fault tests' experiment on `hosts`, with `extra` arguments.
    fn start(out: &Path, hosts: &Hosts, extra: &[&str]) -> BackgroundRun {
        let robots = RUN_ROBOTS.to_string();
        let mut args = vec!["--robots", &robots, "--ticks", "0", "--seed", "3"];
        args.extend(extra);
        BackgroundRun::start_config(OBSTACLE_AVOIDANCE, out, hosts, &args)
    }

    /// `swarm run config` on `hosts`, with `extra` arguments.
    fn start_config(config: &str, out: &Path, hosts: &Hosts, extra: &[&str]) -> BackgroundRun {
        let dir = bin_dir();
        let mut child = Command::new(dir.join("swarm"))
            .args(["run", config])
            .args(["--tick-deadline-ms", "200", "--no-progress", "--out"])
            .arg(out)
            .args(hosts.run_args())
            .args(extra)
            .env("SWARM_BIN_DIR", dir)
            .env("RUST_LOG", "info,zenoh=warn")
            .current_dir(workspace_root())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("swarm starts");
        let lines = follow_lines(child.stderr.take());
        BackgroundRun {
            child,
            lines,
            seen: Vec::new(),
        }
    }

    fn wait_for(&mut self, needle: &str) {
        assert!(
            wait_for_line(&self.lines, &mut self.seen, needle, EVENT_TIMEOUT),
            "the run never logged {needle:?}:\n{}",
            self.seen.join("\n")
        );
    }

    /// Interrupts the run (it finishes its tick and flushes) and checks it ended as an interrupted run (130).
    fn interrupt(mut self) {
        kill(Pid::from_raw(self.child.id() as i32), Signal::SIGINT)
            .expect("interrupt the launcher");
        let status = self.child.wait().expect("the launcher exits");
        while let Ok(line) = self.lines.recv_timeout(Duration::from_secs(5)) {
            self.seen.push(line);
        }
        assert_eq!(
            status.code(),
            Some(130),
            "the run did not end as interrupted:\n{}",
            self.seen.join("\n")
        );
    }
}

impl Drop for BackgroundRun {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The alive flags of robot `robot` (of `robots`) in tick order, from trajectory.csv (one row per robot per tick,
/// in robot order).
fn alive_over_time(out: &Path, robot: usize, robots: usize) -> Vec<(u64, bool)> {
    let text = String::from_utf8(read(out, "trajectory.csv")).expect("UTF-8");
    text.lines()
        .skip(1)
        .skip(robot)
        .step_by(robots)
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            let tick = fields[0].parse().expect("a tick");
            (tick, fields.last() == Some(&"1"))
        })
        .collect()
}

/// Checks the summary recorded one loss and one return of host 1 and that its first robot died and came back at
/// those ticks while host 0's robots lived throughout. The world applies a decision between ticks, so the record
/// shows a robot alive before the loss tick, dead from the tick after it, and alive from the tick after its host's
/// first answer. The
/// robot's fresh agent on the rejoined host must have resumed its supervisors at a world tick after the loss, from
/// the world's last record before it.
fn assert_lost_and_rejoined(out: &Path, rejoined: &HostDaemon) {
    let summary = summary(out);
    let host = &summary["hosts"]["hosts"][1];
    let lost: Vec<u64> = serde_json::from_value(host["lost_at_ticks"].clone()).expect("lost ticks");
    let back: Vec<u64> =
        serde_json::from_value(host["rejoined_at_ticks"].clone()).expect("rejoin ticks");
    assert_eq!(lost.len(), 1, "one loss recorded: {summary}");
    assert_eq!(back.len(), 1, "one return recorded: {summary}");
    assert!(
        lost[0] < back[0],
        "lost at {} before back at {}",
        lost[0],
        back[0]
    );
    let robot = host["robots"][0].as_u64().expect("a robot id") as usize;
    assert_resumed_after(&rejoined.agent_log(robot as u64), lost[0]);
    for (tick, alive) in alive_over_time(out, robot, RUN_ROBOTS) {
        // The loss is noticed when the link's lease runs out, at any moment of a tick: the tick in which the world
        // notices it may record the robots either way (their replies are already missing), every other tick not.
        if tick == lost[0] {
            continue;
        }
        let expected = tick < lost[0] || tick > back[0];
        assert_eq!(
            alive, expected,
            "robot {robot} alive at tick {tick} (lost {}, back {})",
            lost[0], back[0]
        );
    }
    let other = summary["hosts"]["hosts"][0]["robots"][0]
        .as_u64()
        .expect("a robot id") as usize;
    assert!(
        alive_over_time(out, other, RUN_ROBOTS)
            .iter()
            .all(|(_, alive)| *alive),
        "host 0's robots lived throughout"
    );
}

/// Checks an agent's log says it resumed its supervisors at a tick after `lost`, from a snapshot recorded before.
fn assert_resumed_after(log: &str, lost: u64) {
    let line = log
        .lines()
        .find(|l| l.contains("resumed supervisors at tick "))
        .unwrap_or_else(|| panic!("the rejoined robot's agent did not resume:\n{log}"));
    let number_after = |marker: &str| -> Option<u64> {
        let rest = &line[line.find(marker)? + marker.len()..];
        rest.split(|c: char| !c.is_ascii_digit())
            .next()?
            .parse()
            .ok()
    };
    let at = number_after("resumed supervisors at tick ").expect("a tick");
    assert!(
        at > lost,
        "resumed at tick {at}, not after the loss at {lost}: {line}"
    );
    if let Some(recorded) = number_after("from the snapshot of tick ") {
        assert!(
            (1..lost).contains(&recorded),
            "resumed from tick {recorded}, not a record before the loss at {lost}: {line}"
        );
    } else {
        assert!(line.contains("its initial states"), "{line}");
    }
}

/// Checks the summary recorded one loss and one return of host 1, and that its first robot, whose restart policy
/// does not restart it, stayed dead from the tick after the loss although its host came back.
fn assert_lost_for_good(out: &Path) {
    let summary = summary(out);
    let host = &summary["hosts"]["hosts"][1];
    let lost: Vec<u64> = serde_json::from_value(host["lost_at_ticks"].clone()).expect("lost ticks");
    let back: Vec<u64> =
        serde_json::from_value(host["rejoined_at_ticks"].clone()).expect("rejoin ticks");
    assert_eq!((lost.len(), back.len()), (1, 1), "{summary}");
    let robot = host["robots"][0].as_u64().expect("a robot id") as usize;
    let timeline = alive_over_time(out, robot, RUN_ROBOTS);
    assert!(timeline.last().is_some_and(|(tick, _)| *tick > back[0]));
    // As in `assert_lost_and_rejoined`, the tick in which the loss is noticed may record the robot either way.
    for (tick, alive) in timeline.into_iter().filter(|(tick, _)| *tick != lost[0]) {
        assert_eq!(
            alive,
            tick < lost[0],
            "robot {robot} alive at tick {tick} (lost {}, host back {})",
            lost[0],
            back[0]
        );
    }
}

/// A run on hosts `names` (whose robots the launcher restarts on failure if `restart`); host 1 goes with
/// `take_down` (given the hosts and the run directory) once it ticks, is restarted after the world noticed the
/// loss, and rejoins; the records say whether its robots came back.
fn lose_and_restart_host(names: &[&str], restart: bool, take_down: impl FnOnce(&mut Hosts, &Path)) {
    let mut hosts = Hosts::start(names);
    let out = tempfile::tempdir().expect("a temporary directory");
    let policy: &[&str] = if restart { &RESTART_ON_FAILURE } else { &[] };
    let mut run = BackgroundRun::start(out.path(), &hosts, policy);
    assert!(
        hosts.daemons[1].wait_for("first tick of the share", EVENT_TIMEOUT),
        "host {} never ticked:\n{}",
        names[1],
        hosts.daemons[1].log()
    );
    take_down(&mut hosts, out.path());
    run.wait_for("host lost");
    hosts.restart(1);
    run.wait_for("host rejoined");
    assert!(
        hosts.daemons[1].wait_for("first tick of the share", EVENT_TIMEOUT),
        "the restarted host never ticked:\n{}",
        hosts.daemons[1].log()
    );
    let (needle, what) = if restart {
        ("the share's robots take part", "took part again")
    } else {
        ("carrying out a fault order", "were killed again")
    };
    assert!(
        hosts.daemons[1].wait_for(needle, EVENT_TIMEOUT),
        "the rejoined host's robots never {what}:\n{}",
        hosts.daemons[1].log()
    );
    run.interrupt();
    if restart {
        assert_lost_and_rejoined(out.path(), &hosts.daemons[1]);
    } else {
        assert_lost_for_good(out.path());
    }
    hosts.stop_and_check_clean();
}

#[test]
fn a_killed_host_is_lost_its_robots_die_and_a_restarted_one_rejoins() {
    lose_and_restart_host(&["gamma", "delta"], true, |hosts, _| {
        hosts.daemons[1].kill()
    });
}

/// Without a restart policy the lost robots stay dead, as killed local agents do.
#[test]
fn a_host_killed_with_swarm_ctl_dies_is_lost_and_its_robots_stay_dead_without_a_restart_policy() {
    lose_and_restart_host(&["eta", "theta"], false, |hosts, out| {
        assert_eq!(
            swarm_ctl(out, &["kill-host", "theta"]),
            "host theta killed\n"
        );
        assert!(
            hosts.daemons[1].wait_for("killed by `swarm ctl kill-host`", EVENT_TIMEOUT),
            "the host did not die:\n{}",
            hosts.daemons[1].log()
        );
    });
}

#[test]
fn a_partitioned_host_is_lost_after_the_lease_and_rejoins_when_its_link_returns() {
    let mut hosts = Hosts::start(&["epsilon", "zeta"]);
    if hosts.namespaces.is_empty() {
        eprintln!(
            "\n*** SKIPPED partition test: it needs network namespaces to cut a host's link ***\n"
        );
        return;
    }
    let out = tempfile::tempdir().expect("a temporary directory");
    let mut run = BackgroundRun::start(out.path(), &hosts, &RESTART_ON_FAILURE);
    assert!(
        hosts.daemons[1].wait_for("first tick of the share", EVENT_TIMEOUT),
        "host zeta never ticked:\n{}",
        hosts.daemons[1].log()
    );
    hosts.namespaces[1].set_link(false).expect("cut the link");
    run.wait_for("host lost");
    hosts.namespaces[1]
        .set_link(true)
        .expect("restore the link");
    run.wait_for("host rejoined");
    assert!(
        hosts.daemons[1].wait_for("first tick of the share", EVENT_TIMEOUT),
        "the host never ticked after its link returned:\n{}",
        hosts.daemons[1].log()
    );
    assert!(
        hosts.daemons[1].wait_for("the share's robots take part", EVENT_TIMEOUT),
        "the rejoined host's robots never took part again:\n{}",
        hosts.daemons[1].log()
    );
    run.interrupt();
    assert_lost_and_rejoined(out.path(), &hosts.daemons[1]);
    hosts.stop_and_check_clean();
}

/// The process id of host `daemon`'s agent for robot `robot` (one of its child processes).
fn agent_pid(daemon: &HostDaemon, robot: u64) -> Option<i32> {
    let children = std::fs::read_to_string(format!(
        "/proc/{pid}/task/{pid}/children",
        pid = daemon.pid()
    ))
    .ok()?;
    let wanted = ["--robot".to_owned(), robot.to_string()];
    children
        .split_whitespace()
        .filter_map(|pid| pid.parse::<i32>().ok())
        .find(|pid| {
            let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
            let args: Vec<String> = cmdline
                .split(|&b| b == 0)
                .map(|a| String::from_utf8_lossy(a).into_owned())
                .collect();
            args.windows(2).any(|pair| pair == wanted)
        })
}

/// An agent that dies on a host outside any schedule is reported by its host, and its restart policy has the
/// host start a replacement that resumes and takes part again, as a local agent would.
#[test]
fn an_agent_killed_on_a_host_is_restarted_there_by_its_policy() {
    let mut hosts = Hosts::start(&["alpha", "beta"]);
    let out = tempfile::tempdir().expect("a temporary directory");
    let mut run = BackgroundRun::start(
        out.path(),
        &hosts,
        &["--fault", "restart policy=on-failure backoff=0.05"],
    );
    assert!(
        hosts.daemons[1].wait_for("the share's robots take part", EVENT_TIMEOUT),
        "host beta never ticked:\n{}",
        hosts.daemons[1].log()
    );
    let robot = (0..RUN_ROBOTS as u64)
        .find(|&r| !hosts.daemons[1].agent_log(r).is_empty())
        .expect("beta runs a robot");
    let pid = agent_pid(&hosts.daemons[1], robot).expect("beta's agent process of the robot");
    kill(Pid::from_raw(pid), Signal::SIGKILL).expect("kill the agent");
    run.wait_for(&format!("robot {robot} takes part again from tick"));
    let replacement = agent_pid(&hosts.daemons[1], robot).expect("a replacement agent on beta");
    assert_ne!(replacement, pid, "a new process");
    run.interrupt();

    let summary = summary(out.path());
    let faults = summary["faults"].as_array().expect("faults are listed");
    let restarted = faults
        .iter()
        .find(|f| f["what"] == "exit" && f["robot"] == robot)
        .unwrap_or_else(|| panic!("the death is logged: {summary}"))
        .clone();
    // The robot is out from the first tick the world noticed: the exit, or a tick before it when the killed
    // agent missed that tick's deadline before its host reaped it.
    let down = faults
        .iter()
        .filter(|f| f["robot"] == robot)
        .filter_map(|f| f["detection_tick"].as_u64())
        .min()
        .expect("detected");
    let back = restarted["rejoin_tick"].as_u64().expect("rejoined");
    assert!(restarted["restarted"] == true && down < back, "{restarted}");
    assert_resumed_after(&hosts.daemons[1].agent_log(robot), down - 1);
    for (tick, alive) in alive_over_time(out.path(), robot as usize, RUN_ROBOTS) {
        assert_eq!(
            alive,
            tick < down || tick >= back,
            "robot {robot} alive at tick {tick} (down {down}, back {back})"
        );
    }
    hosts.stop_and_check_clean();
}

/// A `ZENOH_RUNTIME` zenoh cannot parse (zenoh itself would panic on it) is an error that names it, and nothing
/// starts.
#[test]
fn a_malformed_zenoh_runtime_layout_is_an_error_not_a_panic() {
    let output = Command::new(bin_dir().join("swarm"))
        .args(["host", "--connect", "tcp/127.0.0.1:1", "--insecure"])
        .env("ZENOH_RUNTIME", "(app: (worker_threads: many))")
        .output()
        .expect("swarm starts");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("ZENOH_RUNTIME=(app: (worker_threads: many))")
            && stderr.contains("not a zenoh runtime layout"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}
