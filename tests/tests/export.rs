//! `swarm export`: a recorded run's files as Parquet and back, through the command a user types.

use swarm_system_tests::{run_to_completion, swarm};

#[test]
fn a_run_exported_to_parquet_and_back_gives_the_worlds_csv_byte_for_byte() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion(
        "configs/messages/coordinator.argos",
        run.path(),
        &["--ticks", "60"],
    );
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    let dir = run.path().display().to_string();
    let tables = ["trajectory", "events", "messages"];
    let recorded: Vec<Vec<u8>> = tables
        .iter()
        .map(|t| std::fs::read(run.path().join(format!("{t}.csv"))).expect("a record file"))
        .collect();

    let to_parquet = swarm(&["export", &dir, "--format", "parquet"]);
    assert!(
        to_parquet.output.status.success(),
        "{}",
        to_parquet.stderr()
    );
    for table in tables {
        assert!(
            to_parquet
                .stdout()
                .contains(&format!("{table}.csv -> {table}.parquet")),
            "{}",
            to_parquet.stdout()
        );
        let header =
            std::fs::read(run.path().join(format!("{table}.parquet"))).expect("a Parquet file");
        assert_eq!(&header[..4], b"PAR1");
        std::fs::remove_file(run.path().join(format!("{table}.csv"))).expect("CSV removed");
    }

    let to_csv = swarm(&["export", &dir, "--format", "csv"]);
    assert!(to_csv.output.status.success(), "{}", to_csv.stderr());
    for (table, original) in tables.iter().zip(&recorded) {
        let again = std::fs::read(run.path().join(format!("{table}.csv"))).expect("CSV again");
        assert!(
            again == *original,
            "{table}.csv differs after the round trip"
        );
    }

    // A cut Parquet file is refused with its name, and nothing is half written.
    let trajectory = run.path().join("trajectory.parquet");
    let bytes = std::fs::read(&trajectory).expect("Parquet");
    std::fs::write(&trajectory, &bytes[..bytes.len() / 2]).expect("cut");
    std::fs::remove_file(run.path().join("trajectory.csv")).expect("CSV removed");
    let refused = swarm(&["export", &dir, "--format", "csv"]);
    assert_eq!(refused.output.status.code(), Some(1));
    assert!(
        refused.stderr().contains("trajectory.parquet"),
        "{}",
        refused.stderr()
    );
    assert!(!run.path().join("trajectory.csv").exists());
    let leftovers: Vec<_> = std::fs::read_dir(run.path())
        .expect("the run folder")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn a_run_drawn_as_an_animated_gif() {
    let run = tempfile::tempdir().expect("temp dir");
    let outcome = run_to_completion(
        "configs/foraging/quick.argos",
        run.path(),
        &["--ticks", "40"],
    );
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    let gif = run.path().join("run.gif");
    let (dir, path) = (run.path().display().to_string(), gif.display().to_string());
    let drawn = swarm(&[
        "view",
        &dir,
        "--gif",
        &path,
        "--gif-frames",
        "20",
        "--gif-width",
        "200",
    ]);
    assert!(drawn.output.status.success(), "{}", drawn.stderr());
    assert!(
        drawn.stdout().contains("20 frames, 200 x 200"),
        "{}",
        drawn.stdout()
    );
    assert_eq!(&std::fs::read(&gif).expect("the GIF")[..6], b"GIF89a");

    std::fs::remove_file(run.path().join("scene.json")).expect("scene removed");
    let refused = swarm(&["view", &dir, "--gif", &path]);
    assert_eq!(refused.output.status.code(), Some(1));
    assert!(
        refused.stderr().contains("scene.json is missing"),
        "{}",
        refused.stderr()
    );
}
