//! The path-planning task end to end with real processes (docs/planning.md): one agent running the supervisor
//! of `configs/planning/models` with the GSA or Theta* planner as its `plan` action and a range finder that finds
//! the cylinders its map leaves out; the world's loop functions send the goal, the known map and the box, read
//! the robot's planner reports and judge the trip against the reference optimum.

use std::path::Path;

use swarm_system_tests::{
    assert_same_records, edited_config, run_summary, run_to_completion, run_twice, swarm,
    workspace_file,
};

const HIDDEN: &str = "configs/planning/hidden.argos";
const ROBOT_RADIUS: f64 = 0.105;

fn metrics(out: &Path) -> serde_json::Value {
    run_summary(out)["metrics"].clone()
}

/// Every cylinder of the configuration at `path`: id, centre and radius.
fn cylinders(path: &str) -> Vec<(String, f64, f64, f64)> {
    let text = std::fs::read_to_string(path).expect("the configuration");
    let attribute = |line: &str, name: &str| -> String {
        let from = line.find(&format!("{name}=\"")).expect(name) + name.len() + 2;
        line[from..].split('"').next().expect("a value").to_owned()
    };
    text.lines()
        .filter(|l| l.trim_start().starts_with("<cylinder"))
        .map(|l| {
            let position = attribute(l, "position");
            let xy: Vec<f64> = position
                .split(',')
                .map(|v| v.parse().expect("a number"))
                .collect();
            let radius = attribute(l, "radius").parse().expect("a radius");
            (attribute(l, "id"), xy[0], xy[1], radius)
        })
        .collect()
}

/// The closest the robot's centre came to each cylinder's edge, by id.
fn closest_approach(out: &Path, config: &str) -> Vec<(String, f64)> {
    let trajectory = swarm_system_tests::run_text(out, "trajectory.csv");
    let poses: Vec<(f64, f64)> = trajectory
        .lines()
        .skip(1)
        .map(|line| line.split(',').collect::<Vec<_>>())
        .map(|f| (f[3].parse().expect("x"), f[4].parse().expect("y")))
        .collect();
    cylinders(config)
        .into_iter()
        .map(|(id, x, y, r)| {
            let closest = poses
                .iter()
                .map(|(px, py)| (px - x).hypot(py - y) - r)
                .fold(f64::INFINITY, f64::min);
            (id, closest)
        })
        .collect()
}

/// Eight cylinders of radius 0.3 m whose centres lie 0.55 m round `(x, y)`: they overlap, walling the point off.
fn ring_round(x: f64, y: f64) -> String {
    (0..8)
        .map(|k| {
            let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
            format!(
                "    <cylinder id=\"w{k}\" radius=\"0.3\" height=\"0.5\" movable=\"false\"><body position=\"{},{},0\" \
                 orientation=\"0,0,0\" /></cylinder>\n",
                x + 0.55 * a.cos(),
                y + 0.55 * a.sin()
            )
        })
        .collect()
}

#[test]
fn a_gsa_robot_finds_the_hidden_cylinders_replans_and_arrives_the_same_way_for_a_seed() {
    let runs = run_twice(HIDDEN, &[]);
    let out = runs[0].path();
    let m = metrics(out);
    assert_eq!(m["tasks_completed"], 1, "{m}");
    assert_eq!(m["failures"], 0, "{m}");
    assert!(m["replans"].as_u64().expect("replans") >= 1, "{m}");
    assert!(
        m["plans"].as_u64().expect("plans") > m["replans"].as_u64().expect("replans"),
        "{m}"
    );
    let ratio = m["mean_path_ratio"].as_f64().expect("a path ratio");
    assert!(ratio >= 0.99, "shorter than the optimum: {m}");
    // The body never touched a cylinder, hidden or known.
    for (id, closest) in closest_approach(out, &workspace_file(HIDDEN).display().to_string()) {
        assert!(
            closest > ROBOT_RADIUS - 0.005,
            "{id}: the centre came within {closest} m of its edge"
        );
    }
    let events = swarm_system_tests::run_text(out, "events.csv");
    assert!(events.lines().any(|l| l.ends_with(",path_blocked")));
    // The robot's reports reach the world, recorded as letters to it.
    let messages = swarm_system_tests::run_text(out, "messages.csv");
    assert!(
        messages
            .lines()
            .any(|l| l.contains(",0,world,one,") && l.ends_with(",delivered,")),
        "no report"
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
fn with_every_cylinder_on_its_map_a_theta_star_robot_never_replans_and_drives_the_optimum() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = edited_config(dir.path(), HIDDEN, |text| {
        text.replace(" hidden=\"h*\"", "")
            .replace("planner=\"gsa\"", "planner=\"theta_star\"")
    });
    let out = dir.path().join("run");
    run_to_completion(&config, &out, &[]);
    let m = metrics(&out);
    assert_eq!(m["tasks_completed"], 1, "{m}");
    // Nothing is found that the map does not explain, so the first plan is the only one.
    assert_eq!(m["replans"], 0, "{m}");
    assert_eq!(m["plans"], 1, "{m}");
    let ratio = m["mean_path_ratio"].as_f64().expect("a path ratio");
    assert!((0.98..1.03).contains(&ratio), "{m}");
}

#[test]
fn bad_planning_settings_are_refused_with_their_place() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (from, to, expected) in [
        (
            "hidden=\"h*\"",
            "hidden=\"x*\"",
            "`hidden` names `x*`, which matches no cylinder of the arena",
        ),
        (
            "planner=\"gsa\"",
            "planner=\"rrt\"",
            "parameter `planner` = \"rrt\"",
        ),
        (
            "planner=\"gsa\"",
            "planner=\"gsa\" agents=\"x\"",
            "parameter `agents` = \"x\"",
        ),
        (
            "goals=\"9,9\"",
            "goals=\"5.5,5.5\"",
            "is inside obstacle `h1`",
        ),
        (
            "goals=\"9,9\"",
            "goals=\"8.5,8.5\"",
            "the goal (8.5, 8.5) of robot `robot` cannot be reached from its start (1, 1): obstacles wall it off",
        ),
    ] {
        let config = edited_config(dir.path(), HIDDEN, |text| {
            text.replace(from, to)
                .replace("  </arena>", &format!("{}  </arena>", ring_round(8.5, 8.5)))
        });
        let run = dir.path().join("run").display().to_string();
        let outcome = swarm(&["run", &config, "--out", &run, "--overwrite"]);
        assert!(!outcome.output.status.success(), "{to} was accepted");
        let stderr = outcome.stderr();
        assert!(
            stderr.contains(&format!("{config}:")),
            "{to}: no location in\n{stderr}"
        );
        assert!(
            stderr.contains(expected),
            "{to}: no `{expected}` in\n{stderr}"
        );
    }
}
