//! Fault injection and process supervision end to end: 40 real robot-agent processes (obstacle avoidance), a real
//! world process, real signals. Every test asserts on the records (`trajectory.csv`, `events.csv`,
//! `summary.json`, agent logs), never on timing, and checks that nothing of its run is left behind.

use std::path::Path;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use swarm_system_tests::{LiveSwarm, SwarmOutcome, assert_nothing_left, swarm, swarm_ctl};

const OBSTACLE_AVOIDANCE: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";
const ROBOTS: usize = 40;

fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary directory")
}

/// Runs the 40-robot experiment for `ticks` ticks with `faults` (each a `--fault`) and checks it left nothing.
fn run_with_faults(out: &Path, ticks: u64, seed: u64, faults: &[&str]) -> SwarmOutcome {
    let out_arg = out.display().to_string();
    let ticks = ticks.to_string();
    let seed = seed.to_string();
    let mut args = vec![
        "run",
        OBSTACLE_AVOIDANCE,
        "--out",
        out_arg.as_str(),
        "--no-progress",
        "--ticks",
        ticks.as_str(),
        "--seed",
        seed.as_str(),
        // Scheduled faults never wait for a deadline; a generous one keeps a loaded machine from adding
        // unscheduled deadline misses to the records.
        "--tick-deadline-ms",
        "10000",
    ];
    for fault in faults {
        args.extend(["--fault", fault]);
    }
    let outcome = swarm(&args);
    assert_nothing_left(outcome.pid);
    outcome
}

fn run_ok(out: &Path, ticks: u64, faults: &[&str]) -> serde_json::Value {
    let outcome = run_with_faults(out, ticks, 124, faults);
    assert!(
        outcome.output.status.success(),
        "swarm run failed:\n{}",
        outcome.stderr()
    );
    summary(out)
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// `trajectory.csv` as (tick, robot index, alive, led sum) rows; robots are in index order within a tick.
fn trajectory(out: &Path) -> Vec<(u64, usize, bool, u32)> {
    let text = swarm_system_tests::run_text(out, "trajectory.csv");
    text.lines()
        .skip(1)
        .enumerate()
        .map(|(i, line)| {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), 10, "a complete row: {line}");
            let led: u32 = fields[6..9]
                .iter()
                .map(|v| v.parse::<u32>().expect("LED"))
                .sum();
            let robot: usize = fields[1].parse().expect("robot index");
            assert_eq!(robot, i % ROBOTS, "robots in index order within a tick");
            (
                fields[0].parse().expect("tick"),
                robot,
                fields[9] == "1",
                led,
            )
        })
        .collect()
}

/// `events.csv` as (tick, robot index, event) rows.
fn events(out: &Path) -> Vec<(u64, usize, String)> {
    let text = swarm_system_tests::run_text(out, "events.csv");
    text.lines()
        .skip(1)
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            (
                fields[0].parse().expect("tick"),
                fields[1].parse().expect("robot"),
                fields[3].to_owned(),
            )
        })
        .collect()
}

fn faults(summary: &serde_json::Value) -> Vec<serde_json::Value> {
    summary["faults"]
        .as_array()
        .expect("faults are listed")
        .clone()
}

fn killed_robots(summary: &serde_json::Value) -> Vec<u64> {
    let mut robots: Vec<u64> = faults(summary)
        .iter()
        .filter(|f| f["what"] == "kill")
        .map(|f| f["robot"].as_u64().expect("a robot"))
        .collect();
    robots.sort_unstable();
    robots
}

#[test]
fn a_killed_robot_stays_as_an_inert_body_and_the_run_completes() {
    let out = temp_dir();
    let summary = run_ok(out.path(), 80, &["kill robots=5 tick=30"]);
    assert_eq!(summary["ticks"], 80);
    assert_eq!(summary["alive_final"], 39);
    let fault = &faults(&summary)[0];
    assert_eq!(fault["what"], "kill");
    assert_eq!(fault["robot"], 5);
    assert_eq!(fault["scheduled_tick"], 30);
    assert_eq!(fault["detection_tick"], 30);
    assert_eq!(fault["restarted"], false);

    let rows = trajectory(out.path());
    assert_eq!(
        rows.len(),
        81 * ROBOTS,
        "every tick recorded for every robot"
    );
    for &(tick, robot, alive, led) in rows.iter().filter(|r| r.1 == 5) {
        assert_eq!(alive, tick < 30, "robot {robot} alive at tick {tick}");
        if tick >= 30 {
            assert_eq!(led, 0, "a dead robot's LEDs are off");
        }
    }
    assert!(
        rows.iter().filter(|r| r.1 != 5).all(|r| r.2),
        "the other robots live on"
    );
    let events = events(out.path());
    assert!(events.contains(&(30, 5, "fault:kill".to_owned())));
    assert!(
        events
            .iter()
            .all(|e| e.1 != 5 || e.0 < 30 || e.2.starts_with("fault:")),
        "a dead robot fires no event"
    );
}

#[test]
fn killing_ten_percent_of_forty_kills_four_robots() {
    let out = temp_dir();
    let summary = run_ok(out.path(), 60, &["kill fraction=0.1 tick=20"]);
    let killed = killed_robots(&summary);
    assert_eq!(killed.len(), 4, "{killed:?}");
    assert_eq!(summary["alive_final"], 36);
    let rows = trajectory(out.path());
    let dead_at_end = rows
        .iter()
        .filter(|r| r.0 == 60 && !r.2)
        .map(|r| r.1 as u64)
        .collect::<Vec<_>>();
    assert_eq!(dead_at_end, killed);
}

#[test]
fn killing_half_the_swarm_leaves_the_other_half_running_every_tick() {
    let out = temp_dir();
    let summary = run_ok(out.path(), 60, &["kill fraction=0.5 time=1.0"]);
    assert_eq!(killed_robots(&summary).len(), 20);
    assert_eq!(summary["alive_final"], 20);
    assert_eq!(summary["ticks"], 60, "no tick was lost to the deaths");
    let events = events(out.path());
    let late_movers: std::collections::BTreeSet<usize> = events
        .iter()
        .filter(|e| e.0 > 20 && !e.2.starts_with("fault:"))
        .map(|e| e.1)
        .collect();
    assert!(
        late_movers
            .iter()
            .all(|r| !killed_robots(&summary).contains(&(*r as u64))),
        "only survivors fire events after the kill"
    );
}

#[test]
fn a_robot_killed_during_start_up_never_takes_part() {
    let out = temp_dir();
    let summary = run_ok(out.path(), 40, &["kill robots=7 tick=0"]);
    assert_eq!(summary["alive_final"], 39);
    assert_eq!(faults(&summary)[0]["detection_tick"], 0);
    let rows = trajectory(out.path());
    assert!(
        rows.iter().filter(|r| r.1 == 7 && r.0 >= 1).all(|r| !r.2),
        "robot 7 is dead from the first tick"
    );
    let events = events(out.path());
    let of_seven: Vec<&(u64, usize, String)> = events.iter().filter(|e| e.1 == 7).collect();
    assert_eq!(of_seven, vec![&(0, 7, "fault:kill".to_owned())]);
}

#[test]
fn on_failure_restarts_the_same_robot_up_to_max_restarts() {
    let out = temp_dir();
    let summary = run_ok(
        out.path(),
        120,
        &[
            "restart robots=5 policy=on-failure max_restarts=2 backoff=0.1",
            "kill robots=5 tick=20",
            "kill robots=5 tick=50",
            "kill robots=5 tick=80",
        ],
    );
    let kills: Vec<serde_json::Value> = faults(&summary)
        .into_iter()
        .filter(|f| f["what"] == "kill")
        .collect();
    let restarted: Vec<bool> = kills.iter().map(|f| f["restarted"] == true).collect();
    assert_eq!(restarted, vec![true, true, false], "{kills:?}");
    // backoff 0.1 s = 2 ticks at 20 ticks/s, doubling with the second restart in the window.
    assert_eq!(kills[0]["rejoin_tick"], 22);
    assert_eq!(kills[1]["rejoin_tick"], 54);
    assert_eq!(summary["alive_final"], 39);
    let events = events(out.path());
    assert!(events.contains(&(22, 5, "fault:up".to_owned())));
    assert!(events.contains(&(54, 5, "fault:up".to_owned())));
    assert!(
        events
            .iter()
            .any(|e| e.1 == 5 && (23..50).contains(&e.0) && !e.2.starts_with("fault:")),
        "the restarted robot fires events again"
    );
    let rows = trajectory(out.path());
    for &(tick, _, alive, _) in rows.iter().filter(|r| r.1 == 5) {
        let expected = !((20..22).contains(&tick) || (50..54).contains(&tick) || tick >= 80);
        assert_eq!(alive, expected, "robot 5 at tick {tick}");
    }
}

#[test]
fn a_restarted_agent_resumes_the_recorded_supervisor_state() {
    let out = temp_dir();
    let summary = run_ok(
        out.path(),
        80,
        &[
            "restart robots=3 policy=on-failure backoff=0.1",
            "kill robots=3 tick=40",
        ],
    );
    assert_eq!(faults(&summary)[0]["rejoin_tick"], 42);
    let point: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.path().join("resume/robot-3.json")).expect("resume point"),
    )
    .expect("JSON");
    assert_eq!(point["tick"], 39, "the last command the world recorded");
    let states: Vec<u64> = point["states"]
        .as_array()
        .expect("states")
        .iter()
        .map(|s| s.as_u64().expect("a state"))
        .collect();
    let log = std::fs::read_to_string(out.path().join("logs/robot-3.log")).expect("agent log");
    let resumed = log
        .lines()
        .find(|l| l.contains("resumed supervisors at tick 42 from the snapshot of tick 39"))
        .unwrap_or_else(|| panic!("the replacement reports its resume:\n{log}"));
    let shown = format!("states {states:?}");
    assert!(
        resumed.contains(&shown),
        "the replacement runs the recorded states {shown}: {resumed}"
    );
}

#[test]
fn a_frozen_robot_holds_still_and_takes_part_again_after_its_thaw() {
    let out = temp_dir();
    let summary = run_ok(
        out.path(),
        100,
        &["freeze robots=2 tick=20", "thaw robots=2 tick=60"],
    );
    assert_eq!(summary["ticks"], 100);
    assert_eq!(summary["alive_final"], 40);
    let whats: Vec<String> = faults(&summary)
        .iter()
        .map(|f| f["what"].as_str().unwrap_or_default().to_owned())
        .collect();
    assert_eq!(whats, vec!["freeze", "thaw"]);
    let rows = trajectory(out.path());
    for &(tick, _, alive, _) in rows.iter().filter(|r| r.1 == 2) {
        assert_eq!(alive, !(20..60).contains(&tick), "robot 2 at tick {tick}");
    }
    let events = events(out.path());
    assert!(
        !events
            .iter()
            .any(|e| e.1 == 2 && (20..60).contains(&e.0) && !e.2.starts_with("fault:")),
        "a frozen robot fires nothing"
    );
    assert!(
        events
            .iter()
            .any(|e| e.1 == 2 && e.0 >= 60 && !e.2.starts_with("fault:")),
        "the thawed robot acts again"
    );
}

#[test]
fn killing_the_world_stops_every_agent_and_keeps_the_record_readable() {
    let out = temp_dir();
    let outcome = run_with_faults(out.path(), 200, 124, &["kill_world tick=50"]);
    assert!(
        !outcome.output.status.success(),
        "a run whose world died fails"
    );
    let stderr = outcome.stderr();
    assert!(
        stderr.contains("the world process ended")
            && stderr.contains("killed by the fault schedule"),
        "the reason is given:\n{stderr}"
    );
    let rows = trajectory(out.path());
    assert_eq!(rows.len(), 50 * ROBOTS, "ticks 0..=49, complete");
    assert_eq!(rows.last().map(|r| r.0), Some(49));
    // The records were cut back to whole ticks, then left as Parquet like any run's.
    for table in ["trajectory", "events"] {
        assert!(out.path().join(format!("{table}.parquet")).exists());
        assert!(!out.path().join(format!("{table}.csv")).exists());
    }
    let summary = summary(out.path());
    assert_eq!(faults(&summary)[0]["what"], "kill-world");
    assert!(
        summary["world_died"]
            .as_str()
            .is_some_and(|s| s.contains("before tick 50"))
    );
}

#[test]
fn same_seed_and_fault_schedule_give_identical_records() {
    let schedule = [
        "restart robots=3 policy=on-failure backoff=0.2",
        "kill fraction=0.1 tick=10",
        "kill robots=3 tick=25",
        "freeze robots=6 tick=15",
        "thaw robots=6 tick=35",
        "chaos every=1 count=1 stop=3",
    ];
    let records = || {
        let out = temp_dir();
        run_ok(out.path(), 80, &schedule);
        let read = |name: &str| swarm_system_tests::run_file(out.path(), name);
        (read("trajectory.csv"), read("events.csv"))
    };
    let first = records();
    let second = records();
    assert!(
        first.0 == second.0,
        "trajectory.csv differs between the two runs"
    );
    assert!(
        first.1 == second.1,
        "events.csv differs between the two runs"
    );
}

/// A `swarm run` of the 40-robot experiment that goes on until it is interrupted, followed from its first tick.
/// Dropping it unfinished (a failed assertion) kills the launcher, whose children die with it, and removes the
/// run's shared memory.
struct LiveRun {
    live: LiveSwarm,
    out: tempfile::TempDir,
}

impl LiveRun {
    /// Starts the run for at most `ticks` ticks with `extra` arguments and returns once its first tick has
    /// completed.
    fn start(ticks: u64, extra: &[&str]) -> LiveRun {
        let out = temp_dir();
        let out_arg = out.path().display().to_string();
        let ticks = ticks.to_string();
        let mut args = vec![
            "run",
            OBSTACLE_AVOIDANCE,
            "--no-progress",
            "--ticks",
            ticks.as_str(),
            "--tick-deadline-ms",
            "100",
            "--out",
            out_arg.as_str(),
        ];
        args.extend(extra);
        LiveRun {
            live: LiveSwarm::start(&args),
            out,
        }
    }

    /// Runs `swarm ctl <out> <request>` and returns its standard output.
    fn ctl(&self, request: &[&str]) -> String {
        swarm_ctl(self.out.path(), request)
    }

    /// The line of `swarm ctl list` about `robot`.
    fn robot_line(&self, robot: u32) -> String {
        let prefix = format!("robot {robot} ");
        self.ctl(&["list"])
            .lines()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_default()
            .to_owned()
    }

    /// The launcher's next log line.
    fn next_log_line(&mut self) -> String {
        self.live.next_line()
    }

    /// Interrupts the run, checks it ended cleanly and left nothing, and returns its summary.
    fn stop(self) -> serde_json::Value {
        self.live.interrupt();
        assert!(
            !self.out.path().join("control.sock").exists(),
            "the control socket is removed"
        );
        summary(self.out.path())
    }
}

fn fault_whats(summary: &serde_json::Value) -> Vec<String> {
    faults(summary)
        .iter()
        .map(|f| f["what"].as_str().unwrap_or_default().to_owned())
        .collect()
}

#[test]
fn swarm_ctl_lists_freezes_thaws_and_kills_robots_of_a_live_run() {
    let run = LiveRun::start(1_000_000, &[]);
    let list = run.ctl(&["list"]);
    assert_eq!(
        list.lines()
            .filter(|l| l.ends_with("running restarts 0"))
            .count(),
        ROBOTS,
        "{list}"
    );
    assert_eq!(run.ctl(&["freeze", "4"]), "robot 4 frozen\n");
    assert!(
        run.robot_line(4).starts_with("robot 4 fb"),
        "robots are listed by id"
    );
    assert!(run.robot_line(4).contains(" frozen "));
    assert_eq!(run.ctl(&["thaw", "4"]), "robot 4 thawed\n");
    assert_eq!(run.ctl(&["kill", "6"]), "robot 6 killed\n");
    let whats = fault_whats(&run.stop());
    assert!(whats.contains(&"ctl-freeze".to_owned()), "{whats:?}");
    assert!(whats.contains(&"ctl-thaw".to_owned()), "{whats:?}");
    assert!(whats.contains(&"ctl-kill".to_owned()), "{whats:?}");
}

/// The process id `swarm ctl list` shows for `robot`.
fn agent_pid(run: &LiveRun, robot: u32) -> i32 {
    let line = run.robot_line(robot);
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words
        .iter()
        .position(|w| *w == "pid")
        .expect("a pid column");
    words[at + 1].parse().expect("a process id")
}

#[test]
fn an_agent_asked_to_stop_leaves_cleanly_and_only_always_restarts_it() {
    // A bounded run: should the expected log lines never come, the launcher ends and the test fails.
    let mut run = LiveRun::start(
        20_000,
        &[
            "--fault",
            "restart robots=3 policy=always backoff=0",
            "--fault",
            "restart robots=5 policy=on-failure backoff=0",
        ],
    );
    for robot in [3, 5] {
        kill(Pid::from_raw(agent_pid(&run, robot)), Signal::SIGTERM).expect("SIGTERM the agent");
    }
    // Either order: the two agents leave at the same tick.
    let (mut back, mut out) = (false, false);
    while !(back && out) {
        let line = run.next_log_line();
        back |= line.contains("robot 3 takes part again");
        out |= line.contains("robot 5 stays out of the run");
    }
    assert!(run.robot_line(3).ends_with("running restarts 1"));
    assert!(run.robot_line(5).contains(" dead "));
    let summary = run.stop();
    let exits: Vec<serde_json::Value> = faults(&summary)
        .into_iter()
        .filter(|f| f["what"] == "exit")
        .collect();
    let exit_of = |robot: u64| {
        exits
            .iter()
            .find(|f| f["robot"] == robot)
            .unwrap_or_else(|| panic!("robot {robot}'s exit is logged: {exits:?}"))
    };
    for robot in [3, 5] {
        assert_eq!(exit_of(robot)["status"], "exit status: 0", "a clean exit");
    }
    assert_eq!(
        exit_of(3)["restarted"],
        true,
        "always restarts a clean exit"
    );
    assert_eq!(exit_of(5)["restarted"], false, "on-failure does not");
}
