//! Exploration with task allocation end to end with real processes (docs/exploration.md): one agent per robot
//! running the supervisor of `configs/exploration/models` with Multi-SRT and TangentBug as its actions, the
//! coordinator (central memory and FGA) in its own process, the world's loop functions revealing tasks and
//! judging their execution.

use std::path::Path;

use swarm_system_tests::{
    assert_refused, assert_same_records, edited_config, run_summary, run_to_completion, run_twice,
    with_faults,
};

const SMALL: &str = "configs/exploration/small.argos";
/// The coordinator's participant index in `small.argos` (after its three robots).
const COORDINATOR: u32 = 3;

fn metrics(out: &Path) -> serde_json::Value {
    run_summary(out)["metrics"].clone()
}

/// The rows of `exploration.csv` with `event`, as their fields.
fn task_rows(out: &Path, event: &str) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(out.join("exploration.csv")).expect("exploration.csv");
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_owned).collect::<Vec<_>>())
        .filter(|f| f[1] == event)
        .collect()
}

fn tick(row: &[String]) -> u64 {
    row[0].parse().expect("a tick")
}

/// `(tick, robot)` of every `event` in `events.csv`.
fn events(out: &Path, event: &str) -> Vec<(u64, u32)> {
    let text = swarm_system_tests::run_text(out, "events.csv");
    text.lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[3] == event)
        .map(|f| (f[0].parse().expect("tick"), f[1].parse().expect("robot")))
        .collect()
}

#[test]
fn a_small_problem_is_explored_and_every_task_done_the_same_way_for_a_seed() {
    let runs = run_twice(SMALL, &[]);
    let out = runs[0].path();
    let m = metrics(out);
    assert_eq!(m["tasks"], 3, "{m}");
    assert_eq!(m["tasks_completed"], 3, "{m}");
    assert_eq!(m["upper_bound"], 130.0, "{m}");
    assert!(m["utility"].as_f64().expect("utility") > 0.0, "{m}");
    assert!(m["allocations"].as_u64().expect("allocations") >= 1, "{m}");
    // Every task was found by a robot before it was started, and started before it was complete.
    for task in ["0", "1", "2"] {
        let at = |event: &str| {
            task_rows(out, event)
                .iter()
                .find(|r| r[2] == task)
                .map(|r| tick(r))
                .unwrap_or_else(|| panic!("task {task} has no `{event}` row"))
        };
        assert!(at("discovered") < at("started") && at("started") < at("completed"));
    }
    // The type-2 task (1) is done by the type-2 robot or by both type-1 robots.
    let team = &task_rows(out, "completed")
        .into_iter()
        .find(|r| r[2] == "1")
        .expect("task 1 completed")[3];
    assert!(team == "2" || team == "0 1" || team == "1 0", "team {team}");
    assert_same_records(
        out,
        runs[1].path(),
        &[
            "trajectory.csv",
            "events.csv",
            "messages.csv",
            "exploration.csv",
        ],
    );
}

#[test]
fn a_robot_killed_on_its_way_loses_its_task_to_the_survivors_the_same_way_every_time() {
    let dir = tempfile::tempdir().expect("tempdir");
    let baseline = dir.path().join("baseline");
    run_to_completion(SMALL, &baseline, &[]);
    // The first robot to take up a task; the run is a function of the seed, so it does so again below.
    let (taken, robot) = events(&baseline, "take_task")[0];
    let kill = taken + 10;
    let faults = format!("<kill robots=\"{robot}\" tick=\"{kill}\" />");
    let config = with_faults(dir.path(), SMALL, &faults);
    let out = dir.path().join("killed");
    run_to_completion(&config, &out, &[]);
    // The same seed and fault schedule give the same run.
    let again = dir.path().join("again");
    run_to_completion(&config, &again, &[]);
    assert_same_records(
        &out,
        &again,
        &[
            "trajectory.csv",
            "events.csv",
            "messages.csv",
            "exploration.csv",
        ],
    );
    assert_eq!(events(&out, "take_task")[0], (taken, robot));
    assert!(
        !events(&out, "at_task")
            .iter()
            .any(|&(t, r)| r == robot && t < kill),
        "robot {robot} was already at its task when it was killed"
    );
    let m = metrics(&out);
    assert_eq!(m["tasks_completed"], 3, "{m}");
    for row in task_rows(&out, "completed") {
        assert!(
            !row[3].split(' ').any(|r| r == robot.to_string()),
            "the dead robot {robot} is in the team of {row:?}"
        );
    }
}

#[test]
fn a_killed_coordinator_is_restarted_and_loses_no_task_the_robots_found() {
    let dir = tempfile::tempdir().expect("tempdir");
    let baseline = dir.path().join("baseline");
    run_to_completion(SMALL, &baseline, &[]);
    // The world tells the robot of its find after tick d; the robot reports it in tick d + 1; a coordinator
    // killed before tick d + 2 never reads the report. Only a recall after its restart can bring the task back.
    let discovered = tick(&task_rows(&baseline, "discovered")[0]);
    let kill = discovered + 2;
    let faults = format!("<kill robots=\"{COORDINATOR}\" tick=\"{kill}\" />");
    let config = with_faults(dir.path(), SMALL, &faults);
    let out = dir.path().join("killed");
    run_to_completion(&config, &out, &[]);
    let m = metrics(&out);
    assert_eq!(m["tasks_completed"], 3, "{m}");
    assert_eq!(tick(&task_rows(&out, "discovered")[0]), discovered);
    let messages = swarm_system_tests::run_text(&out, "messages.csv");
    let down = format!(",{COORDINATOR},one,");
    assert!(
        messages
            .lines()
            .any(|l| l.contains(&down) && l.ends_with("recipient_down")),
        "nothing reached the coordinator while it was down"
    );
    // The restarted coordinator recalls (a broadcast after the kill) and the robots answer.
    assert!(
        messages.lines().any(|l| {
            let f: Vec<&str> = l.split(',').collect();
            f[1] == COORDINATOR.to_string()
                && f[3] == "all"
                && f[0].parse::<u64>().is_ok_and(|t| t > kill)
        }),
        "no broadcast from the restarted coordinator"
    );
    // The first task found is done although no robot but its finder had sensed it when the coordinator died.
    let first = &task_rows(&out, "discovered")[0][2];
    assert!(
        task_rows(&out, "completed").iter().any(|r| &r[2] == first),
        "task {first} was lost"
    );
}

#[test]
fn impossible_problems_are_refused_with_the_place_in_the_configuration() {
    let dir = tempfile::tempdir().expect("tempdir");
    let one_scout = |text: String| {
        text.lines()
            .filter(|l| !l.contains("id=\"scout2\"") && !l.contains("id=\"hauler1\""))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let no_robots = |text: String| {
        text.lines()
            .filter(|l| !l.contains("<disc-robot"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    type Edit = Box<dyn Fn(String) -> String>;
    let cases: [(Edit, &str, &str); 3] = [
        (
            Box::new(one_scout),
            "loop_functions",
            "task 1 at (4.8, 4.8) is of type 2, which no team of this swarm can do",
        ),
        (
            Box::new(|text: String| text.replace("4.6,1.3,1,30,300", "3.6,3.4,1,30,300")),
            "loop_functions",
            "`o1`",
        ),
        (Box::new(no_robots), "arena", "the arena has no robot"),
    ];
    for (edit, element, expected) in cases {
        let config = edited_config(dir.path(), SMALL, edit);
        assert_refused(dir.path(), &config, element, expected);
    }
}
