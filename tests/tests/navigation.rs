//! The navigation task end to end with real processes (docs/navigation.md): one agent per robot running the
//! supervisor of `configs/navigation/models` with the AMR-APF planner as its `drive` action, the coordinator
//! in its own process, the world's loop functions as task server and judge.

use std::path::Path;

use swarm_system_tests::{
    assert_refused, assert_same_records, edited_config, run_summary, run_to_completion, run_twice,
    swarm, with_faults,
};

const CASE1: &str = "configs/navigation/case1.argos";

/// `(x, y)` of every robot in `tick`'s rows of `trajectory.csv`.
fn poses(out: &Path, tick: u64) -> Vec<(f64, f64)> {
    let trajectory = swarm_system_tests::run_text(out, "trajectory.csv");
    trajectory
        .lines()
        .skip(1)
        .map(|line| line.split(',').collect::<Vec<_>>())
        .filter(|f| f[0].parse::<u64>().ok() == Some(tick))
        .map(|f| (f[3].parse().expect("x"), f[4].parse().expect("y")))
        .collect()
}

#[test]
fn eight_robots_cross_the_obstacle_rows_and_every_one_arrives_the_same_way_for_a_seed() {
    let runs = run_twice(CASE1, &[]);
    let out = runs[0].path();
    let metrics = &run_summary(out)["metrics"];
    assert_eq!(metrics["robots"], 8, "{metrics}");
    assert_eq!(metrics["failures"], 0, "{metrics}");
    assert_eq!(metrics["tasks_completed"], 8, "{metrics}");
    let makespan = metrics["makespan_s"].as_f64().expect("a makespan");
    // The straight line is 9 m at 0.22 m/s: no robot can be faster than 41 s, and the run ended well within
    // the cap because everyone arrived.
    assert!((40.9..500.0).contains(&makespan), "{metrics}");
    let arrivals = std::fs::read_to_string(out.join("navigation.csv")).expect("navigation.csv");
    assert_eq!(arrivals.lines().count(), 9, "{arrivals}");
    // Goals reached and messages go through the world: the task server's letters are recorded.
    let messages = swarm_system_tests::run_text(out, "messages.csv");
    assert!(
        messages.lines().any(|l| l.starts_with("1,world,0,one,")),
        "{}",
        &messages[..500]
    );
    assert_same_records(
        out,
        runs[1].path(),
        &[
            "trajectory.csv",
            "events.csv",
            "messages.csv",
            "navigation.csv",
        ],
    );
}

#[test]
fn without_the_coordinator_robots_hold_still_and_they_finish_once_it_is_back() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = with_faults(
        dir.path(),
        CASE1,
        "<kill robots=\"8\" tick=\"200\" /><restart policy=\"on-failure\" robots=\"8\" backoff=\"2\" />",
    );
    let out = dir.path().join("run");
    run_to_completion(&config, &out, &[]);
    let metrics = &run_summary(&out)["metrics"];
    assert_eq!(metrics["failures"], 0, "{metrics}");
    // Ten ticks without a snapshot and every robot halts; nothing moves until the coordinator is back.
    let (still_from, still_to) = (215, 235);
    let (a, b) = (poses(&out, still_from), poses(&out, still_to));
    assert_eq!(a.len(), 8);
    for (p, q) in a.iter().zip(&b) {
        assert!(
            (p.0 - q.0).abs() < 1e-3 && (p.1 - q.1).abs() < 1e-3,
            "{p:?} -> {q:?}"
        );
    }
    let events = swarm_system_tests::run_text(&out, "events.csv");
    assert!(
        events.lines().any(|l| l.ends_with(",coordinator_lost")),
        "no robot lost its coordinator"
    );
    assert!(
        events
            .lines()
            .any(|l| l.starts_with("2") && l.ends_with(",coordinator_back"))
    );
}

#[test]
fn robots_joining_a_lifelong_run_get_goals_and_everyone_gets_new_ones_on_arrival() {
    let out = tempfile::tempdir().expect("tempdir");
    run_to_completion(
        "configs/navigation/lifelong.argos",
        out.path(),
        &["--ticks", "900"],
    );
    let metrics = &run_summary(out.path())["metrics"];
    let completed = metrics["tasks_completed"].as_u64().expect("a count");
    assert!(completed > 8, "{metrics}");
    let arrivals =
        std::fs::read_to_string(out.path().join("navigation.csv")).expect("navigation.csv");
    let rows: Vec<Vec<&str>> = arrivals
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // The robots joining at 20 s (tick 400) reach goals, and only after they joined.
    let late: Vec<&Vec<&str>> = rows.iter().filter(|r| r[1] == "6" || r[1] == "7").collect();
    assert!(!late.is_empty(), "{arrivals}");
    assert!(
        late.iter()
            .all(|r| r[0].parse::<u64>().expect("tick") > 400)
    );
    // Somebody reached a second goal: a new goal follows every arrival.
    assert!(rows.iter().any(|r| r[2] == "2"), "{arrivals}");
}

#[test]
fn impossible_tasks_are_refused_with_the_place_in_the_configuration() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (edit, expected) in [
        (
            "radius=\"0.05\"",
            "<navigation>: the start positions of robots `tb0` and `tb1` overlap",
        ),
        (
            "radius=\"4.5\" goals=\"2.1,2.2; 1,1; 1,2; 1,3; 1,4; 1,5; 1,6; 1,7\"",
            "the goal (2.1, 2.2) of robot `tb0` is inside obstacle `o11`",
        ),
        (
            "radius=\"4.5\" goals=\"20,1; 1,1; 1,2; 1,3; 1,4; 1,5; 1,6; 1,7\"",
            "the goal (20, 1) of robot `tb0` is unreachable",
        ),
        (
            "radius=\"4.5\" goals=\"1,1; 1,2\"",
            "`goals` lists 2 points for 8 robots",
        ),
    ] {
        let config = edited_config(dir.path(), CASE1, |text| {
            text.replace("radius=\"4.5\"", edit)
        });
        assert_refused(dir.path(), &config, "loop_functions", expected);
    }
    let config = edited_config(dir.path(), CASE1, |text| {
        text.replace("layout=\"circle\"", "layout=\"spiral\"")
    });
    let run = dir.path().join("run").display().to_string();
    let outcome = swarm(&["run", &config, "--out", &run, "--overwrite"]);
    assert!(
        outcome
            .stderr()
            .contains("<navigation layout=\"spiral\">: must be one of circle, random, as_placed")
    );
}
