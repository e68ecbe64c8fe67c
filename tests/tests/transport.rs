//! Cooperative transport end to end with real processes (docs/cooperative_transport.md): one agent per foot-bot
//! running the supervisor of `configs/transport/models`, the team's protocol in real messages between them, the
//! world's loop functions telling the robots where the box is, planning its path on request and judging the
//! delivery.

use std::path::Path;

use swarm_system_tests::{
    assert_refused, assert_same_records, edited_config, run_summary, run_to_completion, run_twice,
    with_faults,
};

const TWO: &str = "configs/transport/sample2.argos";
const THREE: &str = "configs/transport/sample3.argos";
const OBSTACLES: &str = "configs/transport/sample4.argos";

/// The tick of the first `event` row of `transport.csv`.
fn first(out: &Path, event: &str) -> u64 {
    let text = std::fs::read_to_string(out.join("transport.csv")).expect("transport.csv");
    text.lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|f| f[1] == event)
        .unwrap_or_else(|| panic!("no `{event}` row in\n{text}"))[0]
        .parse()
        .expect("a tick")
}

fn assert_delivered(out: &Path) {
    let m = &run_summary(out)["metrics"];
    assert_eq!(m["outcome"], "delivered", "{m}");
    assert_eq!(m["success"], true, "{m}");
    assert!(
        m["position_error_m"].as_f64().expect("an error") <= 0.02,
        "{m}"
    );
    assert!(
        m["angle_error_deg"].as_f64().expect("an error") <= 3.0,
        "{m}"
    );
}

#[test]
fn two_robots_carry_the_box_to_its_goal_pose_the_same_way_for_a_seed() {
    let runs = run_twice(TWO, &[]);
    let out = runs[0].path();
    assert_delivered(out);
    // The box was lifted before it moved and lowered at the end.
    assert!(first(out, "lifted") < first(out, "lowered"));
    let events = swarm_system_tests::run_text(out, "events.csv");
    assert!(events.contains("gripper:lifted") && events.contains(",take"));
    assert_same_records(
        out,
        runs[1].path(),
        &[
            "trajectory.csv",
            "events.csv",
            "messages.csv",
            "transport.csv",
        ],
    );
}

#[test]
fn a_carrier_killed_mid_carry_makes_its_teammate_put_the_box_down_and_the_run_end() {
    let dir = tempfile::tempdir().expect("tempdir");
    let baseline = dir.path().join("baseline");
    run_to_completion(TWO, &baseline, &[]);
    let kill = first(&baseline, "lifted") + 200;
    let config = with_faults(
        dir.path(),
        TWO,
        &format!("<kill robots=\"1\" tick=\"{kill}\" />"),
    );
    let out = dir.path().join("killed");
    run_to_completion(&config, &out, &[]);
    let s = run_summary(&out);
    let m = &s["metrics"];
    assert_eq!(m["outcome"], "dropped", "{m}");
    assert_eq!(m["success"], false, "{m}");
    // The run ended on the outcome, long before its 900 s.
    assert!(s["ticks"].as_u64().expect("ticks") < 9000, "{s}");
    assert!(first(&out, "lowered") >= kill);
}

#[test]
fn three_carriers_lose_one_and_the_two_left_deliver_the_box_even_without_their_coordinator() {
    let dir = tempfile::tempdir().expect("tempdir");
    let baseline = dir.path().join("baseline");
    run_to_completion(THREE, &baseline, &[]);
    assert_delivered(&baseline);
    let kill = first(&baseline, "lifted") + 200;
    // Robot 2, a member; robot 0, the coordinator (the smallest index), whose place robot 1 takes.
    for robot in [2, 0] {
        let config = with_faults(
            dir.path(),
            THREE,
            &format!("<kill robots=\"{robot}\" tick=\"{kill}\" />"),
        );
        let out = dir.path().join(format!("killed-{robot}"));
        run_to_completion(&config, &out, &[]);
        assert_delivered(&out);
        let lowered = first(&out, "lowered");
        assert!(
            lowered > kill + 150,
            "the box went down at {lowered}, right after the kill"
        );
    }
}

#[test]
fn a_post_nobody_planned_for_is_passed_by_moving_the_whole_formation_aside() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("deviated");
    run_to_completion("configs/transport/unseen.argos", &out, &[]);
    assert_delivered(&out);
    let m = &run_summary(&out)["metrics"];
    // A local path (no plan asked for), and the box went round: longer than the straight 2.6 m.
    assert_eq!(m["plans"], 0, "{m}");
    assert!(m["object_path_m"].as_f64().expect("a length") > 2.61, "{m}");
    // Without the field's push the box runs into the post and the team never finishes the path.
    let config = edited_config(dir.path(), "configs/transport/unseen.argos", |text| {
        text.replace(
            "profile=\"transport\"",
            "profile=\"transport\" alpha=\"0\" beta=\"0\"",
        )
    });
    let out = dir.path().join("straight");
    run_to_completion(&config, &out, &[]);
    assert_eq!(run_summary(&out)["metrics"]["success"], false);
}

#[test]
fn lost_messages_are_sent_again_and_the_box_still_arrives() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = edited_config(dir.path(), TWO, |text| {
        text.replace(
            "<messages id=\"net\" />",
            "<messages id=\"net\" loss=\"0.3\" />",
        )
    });
    let out = dir.path().join("lossy");
    run_to_completion(&config, &out, &[]);
    assert_delivered(&out);
    let messages = swarm_system_tests::run_text(&out, "messages.csv");
    assert!(
        messages.lines().any(|l| l.ends_with(",lost")),
        "no message was lost"
    );
}

#[test]
fn impossible_transports_are_refused_with_the_place_in_the_configuration() {
    let dir = tempfile::tempdir().expect("tempdir");
    type Edit = Box<dyn Fn(String) -> String>;
    let cases: [(Edit, &str); 3] = [
        (
            Box::new(|text: String| text.replace("goal=\"5,2,90\"", "goal=\"4,5,90\"")),
            "`o2`",
        ),
        (
            // A wall of cylinders across the whole square: no way round for the formation.
            Box::new(|text: String| {
                let wall: String = (0..11)
                    .map(|i| {
                        format!(
                            "<cylinder id=\"w{i}\" radius=\"0.4\" height=\"0.5\" movable=\"false\">\
                             <body position=\"{},3.5,0\" orientation=\"0,0,0\" /></cylinder>\n",
                            i
                        )
                    })
                    .collect();
                text.replace("    <box id=\"box\"", &format!("{wall}    <box id=\"box\""))
            }),
            "unreachable",
        ),
        (
            Box::new(|text: String| text.replace("lift_by=\"2\"", "lift_by=\"3\"")),
            "lift",
        ),
    ];
    for (edit, expected) in cases {
        let config = edited_config(dir.path(), OBSTACLES, edit);
        assert_refused(dir.path(), &config, "loop_functions", expected);
    }
}
