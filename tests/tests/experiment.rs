//! `swarm experiment` end to end: a tiny grid of real runs (world process, one agent process per robot), a batch
//! killed with SIGKILL right after its first finished run, and a rerun that completes the batch without
//! recomputing any run that had finished and without counting the one the kill cut short.

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use swarm_system_tests::{assert_clean, bin_dir, swarm, wipe_runs, workspace_file};

/// Two configurations (sensor noise 0 and 0.05) x two seeds, four robots, 20 ticks.
fn write_grid(dir: &Path) -> PathBuf {
    let base = workspace_file("configs/obstacle_avoidance/density_N10.argos");
    let grid = dir.join("tiny.toml");
    let text = format!(
        r#"base = "{}"
out = "{}"
repetitions = 2
ticks = 20
median_metric = "collisions_per_robot_minute"

[[factor]]
name = "Nr"
set = ["robots"]
values = [4]

[[factor]]
name = "E"
set = ["noise"]
values = [0, 0.05]
"#,
        base.display(),
        dir.join("batch").display()
    );
    std::fs::write(&grid, text).expect("grid file written");
    grid
}

/// Kills the batch (if still running) and wipes what its runs left, whatever the test's outcome.
struct KilledBatch {
    child: Child,
}

impl KilledBatch {
    fn run_prefix(&self) -> String {
        format!("sw{:x}-", self.child.id())
    }
}

impl Drop for KilledBatch {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        wipe_runs(&self.run_prefix());
    }
}

/// Finished run directories (`runs/<configuration>/seed-<s>`) with their `summary.json` text.
fn finished_runs(batch: &Path) -> BTreeMap<String, String> {
    let mut runs = BTreeMap::new();
    for configuration in std::fs::read_dir(batch.join("runs"))
        .expect("runs folder")
        .flatten()
    {
        for run in std::fs::read_dir(configuration.path())
            .expect("configuration folder")
            .flatten()
        {
            let name = run.file_name().to_string_lossy().into_owned();
            if name.ends_with(".partial") {
                continue;
            }
            let summary = std::fs::read_to_string(run.path().join("summary.json"))
                .expect("a finished run has a summary");
            runs.insert(
                format!("{}/{name}", configuration.file_name().to_string_lossy()),
                summary,
            );
        }
    }
    runs
}

fn partial_runs(batch: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(batch.join("runs"))
        .expect("runs folder")
        .flatten()
        .flat_map(|c| {
            std::fs::read_dir(c.path())
                .expect("configuration folder")
                .flatten()
        })
        .map(|r| r.path())
        .filter(|p| p.to_string_lossy().ends_with(".partial"))
        .collect()
}

#[test]
fn killed_batch_resumes_without_recomputing_finished_runs() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let grid = write_grid(dir.path());
    let batch_dir = dir.path().join("batch");
    let grid_arg = grid.display().to_string();

    // One run at a time, so that the kill lands while the second run is under way.
    let mut batch = KilledBatch {
        child: Command::new(bin_dir().join("swarm"))
            .args(["experiment", &grid_arg, "--jobs", "1", "--no-progress"])
            .env("SWARM_BIN_DIR", bin_dir())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("swarm experiment starts"),
    };
    let stdout = batch.child.stdout.take().expect("piped stdout");
    let first = BufReader::new(stdout)
        .lines()
        .map_while(Result::ok)
        .find_map(|line| line.strip_prefix("finished ").map(str::to_owned))
        .expect("the batch reports its first finished run");
    let pid = i32::try_from(batch.child.id()).expect("pid fits");
    kill(Pid::from_raw(pid), Signal::SIGKILL).expect("the batch can be killed");
    let status = batch.child.wait().expect("the killed batch is reaped");
    assert!(!status.success(), "the batch was killed before it finished");
    drop(batch);

    let before = finished_runs(&batch_dir);
    assert!(
        before.contains_key(&first),
        "{first} is finished: {before:?}"
    );
    assert!(
        before.len() < 4,
        "the kill came before the batch ended: {before:?}"
    );

    let outcome = swarm(&["experiment", &grid_arg, "--no-progress"]);
    assert!(
        outcome.output.status.success(),
        "the rerun completes the batch:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
    let rerun: Vec<String> = outcome
        .stdout()
        .lines()
        .filter_map(|l| l.strip_prefix("finished ").map(str::to_owned))
        .collect();
    assert_eq!(
        rerun.len(),
        4 - before.len(),
        "only the missing runs ran: {rerun:?}"
    );
    for name in &rerun {
        assert!(
            !before.contains_key(name),
            "{name} was finished and ran again"
        );
    }

    let after = finished_runs(&batch_dir);
    assert_eq!(after.len(), 4, "every run of the grid is finished");
    for (name, summary) in &before {
        assert_eq!(
            &after[name], summary,
            "{name} was not recomputed (same summary, same process ids)"
        );
    }
    assert!(
        partial_runs(&batch_dir).is_empty(),
        "no partial run is left or counted"
    );

    let csv = std::fs::read_to_string(batch_dir.join("results.csv")).expect("results.csv");
    let kinds: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap_or(""))
        .collect();
    assert_eq!(kinds.iter().filter(|k| **k == "run").count(), 4, "{csv}");
    assert_eq!(
        kinds.iter().filter(|k| **k == "configuration").count(),
        2,
        "{csv}"
    );
    let header: Vec<&str> = csv.lines().next().unwrap_or("").split(',').collect();
    for column in [
        "kind",
        "configuration",
        "Nr",
        "E",
        "robots",
        "seed",
        "collisions_per_robot_minute",
    ] {
        assert!(
            header.contains(&column),
            "results.csv has a '{column}' column: {header:?}"
        );
    }
    let report = std::fs::read_to_string(batch_dir.join("report.md")).expect("report.md");
    assert!(report.contains("runs finished: 4 of 4"), "{report}");
}

#[test]
fn grid_with_an_address_matching_nothing_fails_before_any_run() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let grid = write_grid(dir.path());
    let text = std::fs::read_to_string(&grid).expect("grid");
    std::fs::write(
        &grid,
        text.replace(
            r#"set = ["noise"]"#,
            r#"set = ["arena/distribute[entity/foot-bot]/entity@quantity"]"#,
        ),
    )
    .expect("grid rewritten");
    let outcome = swarm(&["experiment", &grid.display().to_string(), "--no-progress"]);
    assert!(!outcome.output.status.success());
    let stderr = outcome.stderr();
    assert!(
        stderr.contains(&format!("{}:14:7: factor 'E'", grid.display())),
        "the error names the grid file, line and column: {stderr}"
    );
    assert!(
        stderr.contains("the elements under 'arena' are: box, distribute"),
        "{stderr}"
    );
    assert!(
        !dir.path().join("batch").join("runs").exists(),
        "no run started"
    );
}

#[test]
fn shards_share_the_grid_once_and_merge_into_one_table() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let grid = write_grid(dir.path());
    let grid_arg = grid.display().to_string();
    let batch_dir = dir.path().join("batch");
    for shard in ["1/2", "2/2"] {
        let outcome = swarm(&["experiment", &grid_arg, "--shard", shard, "--no-progress"]);
        assert_clean(&outcome);
        assert!(
            outcome.output.status.success(),
            "shard {shard} failed:\n{}",
            outcome.stderr()
        );
    }
    let first = finished_runs(&batch_dir.join("shard-1-of-2"));
    let second = finished_runs(&batch_dir.join("shard-2-of-2"));
    assert_eq!((first.len(), second.len()), (2, 2), "{first:?} {second:?}");
    assert!(
        first.keys().all(|run| !second.contains_key(run)),
        "a run belongs to both shards: {first:?} {second:?}"
    );

    let merged = dir.path().join("merged");
    let merged_arg = merged.display().to_string();
    let shard_args: Vec<String> = ["shard-1-of-2", "shard-2-of-2"]
        .iter()
        .flat_map(|s| {
            [
                "--merge".to_owned(),
                batch_dir.join(s).display().to_string(),
            ]
        })
        .collect();
    let mut args = vec![
        "experiment",
        grid_arg.as_str(),
        "--out",
        merged_arg.as_str(),
    ];
    args.extend(shard_args.iter().map(String::as_str));
    let outcome = swarm(&args);
    assert!(
        outcome.output.status.success(),
        "merge failed:\n{}",
        outcome.stderr()
    );
    let table = std::fs::read_to_string(merged.join("results.csv")).expect("results.csv");
    let runs = table.lines().filter(|l| l.starts_with("run,")).count();
    assert_eq!(runs, 4, "every run of the grid in one table:\n{table}");
    assert!(merged.join("report.md").is_file());
    assert!(!merged.join("runs").exists(), "a merge runs nothing");
}

#[test]
fn a_batch_folder_has_one_writer() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let grid = write_grid(dir.path());
    let batch_dir = dir.path().join("batch");
    let _held = swarm_contract::run_dir::lock_folder(&batch_dir).expect("the folder locks");
    let outcome = swarm(&["experiment", &grid.display().to_string(), "--no-progress"]);
    assert!(!outcome.output.status.success());
    assert!(
        outcome
            .stderr()
            .contains("another swarm run or experiment is writing into it"),
        "{}",
        outcome.stderr()
    );
    assert!(
        !batch_dir.join("runs").exists(),
        "the refused batch touched the folder"
    );
}

#[test]
fn a_grid_runs_from_its_own_folder() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    for name in ["phototaxis.argos", "grid.toml"] {
        std::fs::copy(
            workspace_file(&format!("configs/phototaxis/{name}")),
            dir.path().join(name),
        )
        .expect("a copy");
    }
    let models = dir.path().join("models");
    std::fs::create_dir(&models).expect("a models folder");
    for model in std::fs::read_dir(workspace_file("configs/phototaxis/models")).expect("models") {
        let model = model.expect("a model").path();
        std::fs::copy(&model, models.join(model.file_name().expect("a name"))).expect("a copy");
    }
    let output = Command::new(bin_dir().join("swarm"))
        .args(["experiment", "grid.toml", "--no-progress", "--out", "batch"])
        .current_dir(dir.path())
        .env("SWARM_BIN_DIR", bin_dir())
        .output()
        .expect("swarm experiment starts");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(dir.path().join("batch/results.csv").is_file());
}
