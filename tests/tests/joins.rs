//! Robots that join a running swarm and leave it, end to end with real processes (docs/joins.md): by the
//! configuration's schedule (`configs/joins/late_arrivals.argos`) and by `swarm ctl spawn` and `swarm ctl remove`.
//! Across hosts: `hosts::scheduled_joins_on_two_hosts_give_the_single_host_records`.

use std::path::Path;

use swarm_system_tests::{
    LiveSwarm, arrivals_by, assert_same_records, run_to_completion, swarm, swarm_ctl,
};

const LATE_ARRIVALS: &str = "configs/joins/late_arrivals.argos";

fn text(out: &Path, file: &str) -> String {
    swarm_system_tests::run_text(out, file)
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&text(out, "summary.json")).expect("summary.json is JSON")
}

/// `(tick, alive, has a pose)` of `robot` in every row of `trajectory.csv`.
fn presence(out: &Path, robot: u32) -> Vec<(u64, bool, bool)> {
    let trajectory = text(out, "trajectory.csv");
    trajectory
        .lines()
        .skip(1)
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            (f[1].parse::<u32>().ok()? == robot).then(|| {
                (
                    f[0].parse().expect("tick"),
                    f[9] == "1",
                    f[3].parse::<f64>().is_ok_and(f64::is_finite),
                )
            })
        })
        .collect()
}

#[test]
fn scheduled_joins_take_part_from_their_tick_and_a_blocked_one_is_refused_where_it_is_declared() {
    let runs: Vec<tempfile::TempDir> = (0..2)
        .map(|_| tempfile::tempdir().expect("a temporary directory"))
        .collect();
    for out in &runs {
        run_to_completion(LATE_ARRIVALS, out.path(), &[]);
    }
    let out = runs[0].path();
    let events = text(out, "events.csv");
    for row in [
        "30,4,late,join",
        "40,8,walled,join:refused",
        "50,5,wave0,join",
        "50,6,wave1,join",
        "50,7,wave2,join",
    ] {
        assert!(events.contains(row), "no `{row}` in:\n{events}");
    }
    // `late` has no pose and is not alive before tick 30, and takes part from tick 30 on.
    for (tick, alive, placed) in presence(out, 4) {
        assert_eq!((alive, placed), (tick >= 30, tick >= 30), "tick {tick}");
    }
    // Spares never join without `swarm ctl spawn`; the refused robot never does.
    for robot in [8, 9, 10] {
        assert!(
            presence(out, robot)
                .iter()
                .all(|&(_, alive, placed)| !alive && !placed)
        );
    }
    let summary = summary(out);
    let arrivals = summary["arrivals"].as_array().expect("arrivals");
    assert_eq!(arrivals.len(), 5, "{arrivals:?}");
    let refused = arrivals
        .iter()
        .find(|a| a["what"] == "join-refused")
        .expect("a refusal");
    let reason = refused["reason"].as_str().expect("a reason");
    assert!(
        reason.contains("late_arrivals.argos:68:5") && reason.contains("'block'"),
        "{reason}"
    );
    assert_eq!(summary["alive_final"], 8);
    // Each joined robot's agent was started when it joined: it has a log, the refused one has none.
    assert!(out.join("logs/robot-4.log").is_file());
    assert!(!out.join("logs/robot-8.log").exists());
    assert_same_records(
        runs[0].path(),
        runs[1].path(),
        &["trajectory.csv", "events.csv"],
    );
}

#[test]
fn swarm_ctl_spawns_spares_removes_robots_and_refuses_what_cannot_be() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let out_arg = out.path().display().to_string();
    let run = LiveSwarm::run(LATE_ARRIVALS, out.path(), &[]);
    let ctl = |request: &[&str]| swarm_ctl(out.path(), request);
    let joined = ctl(&["spawn", "9"]);
    assert!(joined.starts_with("robot 9 joins at tick "), "{joined}");
    let placed = ctl(&["spawn", "10", "-0.2", "0.9", "45"]);
    assert!(placed.starts_with("robot 10 joins at tick "), "{placed}");
    let left = ctl(&["remove", "0"]);
    let left_at: u64 = left
        .trim_end()
        .strip_prefix("robot 0 left at tick ")
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{left}"));
    let list = ctl(&["list"]);
    for (robot, state) in [
        (0, "absent"),
        (9, "running"),
        (10, "running"),
        (8, "absent"),
    ] {
        assert!(
            list.lines()
                .any(|l| l.starts_with(&format!("robot {robot} ")) && l.contains(state)),
            "robot {robot} {state}:\n{list}"
        );
    }
    // Requests that cannot be carried out are refused with the reason; the run goes on.
    let refused = swarm(&["ctl", &out_arg, "spawn", "10"]);
    assert!(
        refused.stderr().contains("robot 10 is in the run already"),
        "{}",
        refused.stderr()
    );
    let refused = swarm(&["ctl", &out_arg, "remove", "0"]);
    assert!(refused.stderr().contains("robot 0 is not in the run"));
    let blocked = swarm(&["ctl", &out_arg, "spawn", "8"]);
    assert!(blocked.stderr().contains("'block'"), "{}", blocked.stderr());
    run.interrupt();

    let summary = summary(out.path());
    let by_ctl = arrivals_by(&summary, "ctl");
    for expected in [("join", 9), ("join", 10), ("leave", 0), ("join-refused", 8)] {
        assert!(
            by_ctl.contains(&(expected.0.to_owned(), expected.1)),
            "{expected:?} in {by_ctl:?}"
        );
    }
    let spawned = summary["arrivals"]
        .as_array()
        .expect("arrivals")
        .iter()
        .find(|a| a["robot"] == 10)
        .expect("robot 10 joined");
    assert!((spawned["x"].as_f64().expect("x") + 0.2).abs() < 1e-6);
    assert!((spawned["heading"].as_f64().expect("heading") - 45f64.to_radians()).abs() < 1e-6);
    // Robot 0 has no pose from the tick it left.
    for (tick, alive, placed) in presence(out.path(), 0) {
        assert_eq!(
            (alive, placed),
            (tick < left_at, tick < left_at),
            "tick {tick}"
        );
    }
}
