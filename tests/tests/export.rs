//! The records a run leaves (Parquet by default, CSV with `--records csv`) and `swarm export` between the two,
//! through the commands a user types.

use swarm_system_tests::{run_to_completion, swarm};

#[test]
fn a_run_leaves_parquet_records_that_export_gives_back_as_the_worlds_csv_byte_for_byte() {
    let (parquet_run, csv_run) = (
        tempfile::tempdir().expect("temp dir"),
        tempfile::tempdir().expect("temp dir"),
    );
    let common = ["--ticks", "60", "--seed", "5"];
    for (run, extra) in [
        (&parquet_run, &[][..]),
        (&csv_run, &["--records", "csv"][..]),
    ] {
        let args: Vec<&str> = common.iter().chain(extra).copied().collect();
        let outcome = run_to_completion("configs/messages/coordinator.argos", run.path(), &args);
        assert!(outcome.output.status.success(), "{}", outcome.stderr());
    }
    let tables = ["trajectory", "events", "messages"];
    let read = |run: &tempfile::TempDir, name: String| {
        std::fs::read(run.path().join(&name)).unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    for table in tables {
        // The default leaves Parquet files only; `--records csv` leaves the world's CSV files only.
        assert_eq!(
            &read(&parquet_run, format!("{table}.parquet"))[..4],
            b"PAR1"
        );
        assert!(!parquet_run.path().join(format!("{table}.csv")).exists());
        assert!(!csv_run.path().join(format!("{table}.parquet")).exists());
    }
    let recorded: Vec<Vec<u8>> = tables
        .iter()
        .map(|t| read(&csv_run, format!("{t}.csv")))
        .collect();

    let dir = parquet_run.path().display().to_string();
    let to_csv = swarm(&["export", &dir, "--format", "csv"]);
    assert!(to_csv.output.status.success(), "{}", to_csv.stderr());
    for (table, original) in tables.iter().zip(&recorded) {
        assert!(
            to_csv
                .stdout()
                .contains(&format!("{table}.parquet -> {table}.csv")),
            "{}",
            to_csv.stdout()
        );
        assert!(
            read(&parquet_run, format!("{table}.csv")) == *original,
            "{table}.csv of the Parquet run differs from the CSV run's"
        );
    }

    let csv_dir = csv_run.path().display().to_string();
    let to_parquet = swarm(&["export", &csv_dir, "--format", "parquet"]);
    assert!(
        to_parquet.output.status.success(),
        "{}",
        to_parquet.stderr()
    );
    for table in tables {
        let name = format!("{table}.parquet");
        assert!(
            read(&csv_run, name.clone()) == read(&parquet_run, name.clone()),
            "{name} exported from the CSV run differs from the one the run left"
        );
    }

    let run = parquet_run;
    for table in tables {
        std::fs::remove_file(run.path().join(format!("{table}.csv"))).expect("CSV removed");
    }
    // A cut Parquet file is refused with its name, and nothing is half written.
    let trajectory = run.path().join("trajectory.parquet");
    let bytes = std::fs::read(&trajectory).expect("Parquet");
    std::fs::write(&trajectory, &bytes[..bytes.len() / 2]).expect("cut");
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
