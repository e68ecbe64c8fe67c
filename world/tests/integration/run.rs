//! Whole runs: determinism of the trajectory, the recorder's files and the obstacle-avoidance metrics.

use crate::common::config::thesis_example;
use crate::common::{builder, drive, wall, wheels};
use swarm_contract::config::{Element, LoopFunctions};
use swarm_world::devices::Devices;
use swarm_world::geometry::Vec2;
use swarm_world::in_process::avoid_obstacles;
use swarm_world::loop_functions::LoopFunctionsParams;
use swarm_world::loop_functions::obstacle_avoidance::ObstacleAvoidance;
use swarm_world::recorder::Records;
use swarm_world::{Recorder, World};

/// Runs the thesis example, with proximity noise 0.02 and wheel noise 0.05 so that every random stream is used,
/// for `ticks` with the obstacle-avoidance rule and returns the trajectory file's bytes.
fn recorded_run(seed: u64, ticks: u64, dir: &std::path::Path) -> Vec<u8> {
    let mut exp = thesis_example();
    exp.controllers[0].sensors[0].noise_level = 0.02;
    exp.controllers[0].actuators[0].noise_std_dev = 0.05;
    let mut world = World::new(&exp, seed).expect("builds");
    let mut recorder = Recorder::create(dir, &world, &[], Records::Csv).expect("recorder");
    recorder.record(&mut world).expect("record");
    for _ in 0..ticks {
        world.run_in_process(1, avoid_obstacles);
        recorder.record(&mut world).expect("record");
    }
    recorder.sync().expect("written");
    std::fs::read(dir.join("trajectory.csv")).expect("trajectory written")
}

#[test]
fn same_config_and_seed_give_bit_identical_trajectories_and_another_seed_does_not() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = recorded_run(124, 200, &dir.path().join("a"));
    let b = recorded_run(124, 200, &dir.path().join("b"));
    let c = recorded_run(125, 200, &dir.path().join("c"));
    assert_eq!(a.len(), b.len());
    assert!(a == b, "same seed, same bytes");
    assert!(a != c, "another seed, another run");
    let text = String::from_utf8(a).expect("utf-8");
    assert_eq!(
        text.lines().next(),
        Some("tick,robot,robot_id,x,y,heading,led_r,led_g,led_b,alive")
    );
    assert_eq!(
        text.lines().count(),
        1 + 40 * 201,
        "a header and 40 rows for ticks 0..=200"
    );
    assert!(
        text.lines()
            .nth(1)
            .is_some_and(|l| l.starts_with("0,0,fb0,"))
    );
}

#[test]
fn recorder_writes_summary_metrics_and_png_snapshots_of_the_start_and_the_final_state() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut exp = thesis_example();
    exp.loop_functions = Some(LoopFunctions {
        label: "obstacle_avoidance_loop_functions".into(),
        library: String::new(),
        params: Element::default(),
        location: crate::common::config::at(20),
    });
    let mut world = World::new(&exp, 7).expect("builds");
    let mut recorder = Recorder::create(dir.path(), &world, &[0], Records::Csv).expect("recorder");
    recorder.record(&mut world).expect("record");
    for _ in 0..20 {
        world.run_in_process(1, avoid_obstacles);
        recorder.record(&mut world).expect("record");
    }
    let summary = recorder
        .finish(&world, serde_json::json!({ "seed": 7 }))
        .expect("summary");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(summary).expect("read")).expect("json");
    assert_eq!(json["ticks"], 20);
    assert_eq!(json["seed"], 7);
    assert!(
        json["metrics"]["forward_fraction"]
            .as_f64()
            .is_some_and(|f| (0.0..=1.0).contains(&f))
    );
    for tick in ["000000", "000020"] {
        let png = std::fs::read(dir.path().join(format!("snapshot_{tick}.png")))
            .expect("snapshot written");
        assert_eq!(&png[1..4], b"PNG");
    }
}

#[test]
fn a_finished_recorder_completes_the_parquet_tables_and_an_unfinished_one_leaves_none() {
    let exp = thesis_example();
    for finished in [true, false] {
        let dir = tempfile::tempdir().expect("tempdir");
        let mut world = World::new(&exp, 3).expect("builds");
        let mut recorder =
            Recorder::create(dir.path(), &world, &[], Records::Parquet).expect("recorder");
        recorder.record(&mut world).expect("record");
        for _ in 0..30 {
            world.run_in_process(1, avoid_obstacles);
            recorder.record(&mut world).expect("record");
        }
        if finished {
            recorder
                .finish(&world, serde_json::json!({}))
                .expect("summary");
        } else {
            // A tick loop that returned early: its rows reach the CSV file, its Parquet file is not completed.
            drop(recorder);
        }
        let parquet = dir.path().join("trajectory.parquet");
        let csv = std::fs::read_to_string(dir.path().join("trajectory.csv")).expect("CSV");
        assert_eq!(csv.lines().count(), 1 + 40 * 31);
        if !finished {
            let names: Vec<String> = std::fs::read_dir(dir.path())
                .expect("listed")
                .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .filter(|name| name.contains("parquet"))
                .collect();
            assert_eq!(
                names,
                Vec::<String>::new(),
                "no Parquet file, not even a temporary one"
            );
            continue;
        }
        let table = swarm_records::ParquetTable::open(swarm_records::Table::Trajectory, &parquet)
            .expect("a complete Parquet trajectory");
        assert_eq!(table.ticks(0), Some((0, 30)));
        assert_eq!(table.rows(0), 40 * 31);
        assert!(
            swarm_records::ParquetTable::open(
                swarm_records::Table::Events,
                &dir.path().join("events.parquet")
            )
            .is_ok()
        );
    }
}

#[test]
fn obstacle_avoidance_metrics_count_collisions_per_robot_minute_and_forward_ticks() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::PROXIMITY_ONLY);
    wall(&mut b, Vec2::new(0.3, 0.0), Vec2::new(0.1, 1.0));
    b.loop_functions(ObstacleAvoidance::factory(&LoopFunctionsParams::default()).expect("factory"));
    let mut world = b.build();
    // 1200 ticks at 20 ticks/s are one robot-minute, all of it commanded straight ahead into the wall.
    drive(&mut world, 1200, wheels(12.8, 12.8));
    let m = world.metrics();
    assert_eq!(m["collisions"], 1);
    assert_eq!(m["collisions_per_robot_minute"], 1.0);
    assert_eq!(m["forward_fraction"], 1.0);
}

#[test]
fn experiment_length_finishes_the_run_after_its_ticks() {
    let mut exp = thesis_example();
    exp.framework.length_seconds = 0.5;
    let mut world = World::new(&exp, 1).expect("builds");
    assert_eq!(world.max_ticks(), Some(10), "0.5 s at 20 ticks/s");
    world.run_in_process(9, avoid_obstacles);
    assert!(!world.is_finished());
    world.run_in_process(1, avoid_obstacles);
    assert!(world.is_finished());
}
