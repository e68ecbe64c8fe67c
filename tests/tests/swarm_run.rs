//! `swarm run` end to end: a real world process, one real agent process per robot, real iceoryx2 shared memory
//! and real files. Every test also checks that its run left no process and no shared-memory file behind.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use swarm_system_tests::{
    SwarmOutcome, assert_clean, bin_dir, iceoryx_root_leftovers, process_leftovers,
    run_to_completion, shm_leftovers, swarm, wait_gone, workspace_file, workspace_root,
};

const OBSTACLE_AVOIDANCE: &str = "configs/obstacle_avoidance/obstacle_avoidance.argos";

fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary directory")
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

fn run_ok(config: &str, out: &Path, extra: &[&str]) -> SwarmOutcome {
    run_to_completion(config, out, extra)
}

#[test]
fn forty_robot_run_completes_with_one_process_per_robot() {
    let out = temp_dir();
    let outcome = run_ok(
        OBSTACLE_AVOIDANCE,
        out.path(),
        &["--ticks", "40", "--limit", "fault_apply_timeout_ms=12345"],
    );
    let summary = summary(out.path());
    assert_eq!(summary["robots"], 40);
    assert_eq!(summary["ticks"], 40);
    assert_eq!(
        summary["limits"]["fault_apply_timeout_ms"], 12345,
        "the run records the limits it used, with the command line's"
    );
    assert_eq!(summary["limits"]["tick_deadline_ms"], 500);
    let agent_log =
        std::fs::read_to_string(out.path().join("logs/robot-0.log")).expect("the agent's log");
    assert!(
        agent_log.contains("robot runs") && !agent_log.contains('\u{1b}'),
        "a log file carries no colour codes:\n{agent_log}"
    );
    assert!(
        !outcome.stderr().contains('\u{1b}'),
        "nor does standard error off a terminal"
    );
    let agents: Vec<u64> = summary["processes"]["agents"]
        .as_array()
        .expect("agent pids are listed")
        .iter()
        .filter_map(serde_json::Value::as_u64)
        .collect();
    let world = summary["processes"]["world"]
        .as_u64()
        .expect("the world pid is listed");
    let mut distinct = agents.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(
        distinct.len(),
        40,
        "every robot had its own process: {agents:?}"
    );
    assert!(
        !agents.contains(&world),
        "no robot ran inside the world process"
    );
    assert!(
        !agents.contains(&u64::from(outcome.pid)),
        "no robot ran inside the launcher"
    );
    for cpu in ["cpu_agents_us_per_robot_step", "cpu_world_us_per_tick"] {
        let used = summary[cpu].as_f64().unwrap_or(0.0);
        assert!(used > 0.0, "{cpu} is measured: {}", summary[cpu]);
    }
    let trajectory = swarm_system_tests::run_text(out.path(), "trajectory.csv");
    assert_eq!(
        trajectory.lines().count(),
        1 + 41 * 40,
        "a header, then 40 robots at ticks 0..=40"
    );
    let events = swarm_system_tests::run_text(out.path(), "events.csv");
    assert!(events.lines().skip(1).all(|l| l.split(',').count() == 4));
    assert!(
        events.contains(",Go\n") && events.contains(",saw-obs\n"),
        "events are recorded by name"
    );
    let compiled = out.path().join("supervisors").join("fdc.ptsct");
    assert!(compiled.is_file(), "the launcher compiles the models once");
    let logs = std::fs::read_dir(out.path().join("logs")).expect("agent logs");
    let agent_logs = logs
        .flatten()
        .filter(|log| log.file_name().to_string_lossy().starts_with("robot-"));
    for log in agent_logs {
        let text = std::fs::read_to_string(log.path()).expect("agent log");
        assert!(
            text.contains("fdc.ptsct"),
            "{} loaded the run's compiled supervisors",
            log.path().display()
        );
    }
}

#[test]
fn same_seed_gives_identical_trajectory_and_events() {
    let records = |seed: &str| {
        let out = temp_dir();
        run_ok(
            OBSTACLE_AVOIDANCE,
            out.path(),
            &["--ticks", "60", "--seed", seed],
        );
        let read = |name: &str| swarm_system_tests::run_file(out.path(), name);
        let summary: serde_json::Value =
            serde_json::from_slice(&read("summary.json")).expect("summary.json is JSON");
        assert_eq!(
            summary["commands_missing"], 0,
            "every command arrived by its deadline, so the run is a function of its seed"
        );
        (read("trajectory.csv"), read("events.csv"))
    };
    let first = records("7");
    let second = records("7");
    assert!(
        first.0 == second.0,
        "trajectory.csv differs between two runs with seed 7"
    );
    assert!(
        first.1 == second.1,
        "events.csv differs between two runs with seed 7"
    );
    let other = records("8");
    assert!(
        first.0 != other.0,
        "seed 8 should place and drive the robots differently"
    );
}

#[test]
fn the_run_folders_configuration_reruns_the_same_run_from_elsewhere() {
    let first = temp_dir();
    run_ok(
        OBSTACLE_AVOIDANCE,
        first.path(),
        &[
            "--robots",
            "6",
            "--ticks",
            "45",
            "--seed",
            "5",
            "--fault",
            "kill robots=1 tick=10",
            "--limit",
            "tick_deadline_ms=400",
        ],
    );
    // A copy in a folder of its own: relative paths in it would no longer resolve.
    let elsewhere = temp_dir();
    let copy = elsewhere.path().join("config.argos");
    std::fs::copy(first.path().join("config.argos"), &copy).expect("copy the configuration");
    let second = temp_dir();
    run_ok(&copy.display().to_string(), second.path(), &[]);
    for name in ["trajectory.csv", "events.csv"] {
        let read = |dir: &Path| swarm_system_tests::run_file(dir, name);
        assert!(
            read(first.path()) == read(second.path()),
            "{name} of the rerun differs from the run"
        );
    }
    let (original, rerun) = (summary(first.path()), summary(second.path()));
    for field in ["ticks", "robots", "seed", "deaths", "limits"] {
        assert_eq!(original[field], rerun[field], "summary field {field}");
    }
    assert_eq!(original["ticks"], 45);
    assert_eq!(original["robots"], 6);
}

#[test]
fn a_run_stops_cleanly_at_its_disk_budget_with_its_records_complete() {
    let out = temp_dir();
    let out_arg = out.path().display().to_string();
    // No length: only the budget ends the run.
    let outcome = swarm(&[
        "run",
        OBSTACLE_AVOIDANCE,
        "--ticks",
        "0",
        "--no-progress",
        "--out",
        &out_arg,
        "--limit",
        "records_max_mb=1",
    ]);
    assert_clean(&outcome);
    let stderr = outcome.stderr();
    assert!(!outcome.output.status.success(), "{stderr}");
    assert!(
        stderr.contains("stopped after") && stderr.contains("records_max_mb"),
        "{stderr}"
    );
    let summary = summary(out.path());
    assert!(summary["stopped_early"].is_string(), "{summary:#}");
    let ticks = summary["ticks"].as_u64().expect("ticks");
    assert!(ticks > 0, "{summary:#}");
    let trajectory = swarm_system_tests::run_text(out.path(), "trajectory.csv");
    assert!(trajectory.ends_with('\n'), "a torn last line");
    let last_tick: u64 = trajectory
        .lines()
        .last()
        .and_then(|line| line.split(',').next())
        .and_then(|tick| tick.parse().ok())
        .expect("a last row");
    assert_eq!(
        last_tick, ticks,
        "the last recorded tick is the last tick run"
    );

    let full = temp_dir();
    let full_arg = full.path().display().to_string();
    let outcome = swarm(&[
        "run",
        OBSTACLE_AVOIDANCE,
        "--no-progress",
        "--out",
        &full_arg,
        "--limit",
        "disk_reserve_mb=1000000000000",
    ]);
    assert_clean(&outcome);
    let stderr = outcome.stderr();
    assert!(!outcome.output.status.success(), "{stderr}");
    assert!(
        stderr.contains("not starting the run") && stderr.contains("disk_reserve_mb"),
        "{stderr}"
    );
}

#[test]
fn thesis_and_argos_example_configurations_run_unchanged() {
    for config in [
        "configs/obstacle_avoidance/thesis_example.argos",
        "configs/argos_examples/epuck_obstacleavoidance.argos",
    ] {
        let out = temp_dir();
        run_ok(config, out.path(), &["--ticks", "10"]);
        let summary = summary(out.path());
        assert_eq!(summary["ticks"], 10, "{config}");
        assert!(summary["robots"].as_u64().unwrap_or(0) > 0, "{config}");
    }
}

/// A copy of the main experiment with other controller params; supervisor paths in `params` are absolute.
fn experiment_with_params(dir: &Path, params: &str) -> String {
    let text =
        std::fs::read_to_string(workspace_file(OBSTACLE_AVOIDANCE)).expect("the main experiment");
    let original =
        r#"<params profile="obstacle_avoidance" supervisors="models/ptsct" velocity="12.8" />"#;
    assert!(
        text.contains(original),
        "the main experiment's params changed; update this test"
    );
    let path = dir.join("experiment.argos");
    std::fs::write(&path, text.replace(original, params)).expect("write the experiment");
    path.display().to_string()
}

fn assert_fails_before_first_tick(config: &str, out: &Path, expected: &[&str]) {
    let out_arg = out.display().to_string();
    let outcome = swarm(&[
        "run",
        config,
        "--out",
        &out_arg,
        "--no-progress",
        "--ticks",
        "5",
    ]);
    assert!(!outcome.output.status.success(), "the run should fail");
    let stderr = outcome.stderr();
    for needle in expected {
        assert!(
            stderr.contains(needle),
            "stderr should mention {needle:?}:\n{stderr}"
        );
    }
    assert_eq!(
        stderr.matches(expected[0]).count(),
        1,
        "the error is said once:\n{stderr}"
    );
    for records in ["trajectory.csv", "trajectory.parquet"] {
        assert!(!out.join(records).exists(), "no tick may run");
    }
    assert_clean(&outcome);
}

#[test]
fn agent_with_unbound_events_fails_before_the_first_tick() {
    let dir = temp_dir();
    let sct_models = workspace_file("configs/obstacle_avoidance/models/sct");
    let config = experiment_with_params(
        dir.path(),
        &format!(
            r#"<params profile="obstacle_avoidance" supervisors="{}" />"#,
            sct_models.display()
        ),
    );
    assert_fails_before_first_tick(
        &config,
        &dir.path().join("out"),
        &["robot 0 (fb0) failed to start", "timer_1"],
    );
}

#[test]
fn agent_with_a_corrupt_supervisor_file_fails_before_the_first_tick() {
    let dir = temp_dir();
    let corrupt = dir.path().join("corrupt.ptsct");
    std::fs::write(&corrupt, b"PTSC\x00\x01 this is not a supervisor set").expect("write the file");
    let config = experiment_with_params(
        dir.path(),
        &format!(
            r#"<params profile="obstacle_avoidance" supervisors="{}" />"#,
            corrupt.display()
        ),
    );
    assert_fails_before_first_tick(
        &config,
        &dir.path().join("out"),
        &["failed to start", "corrupt.ptsct"],
    );
}

#[test]
fn invalid_configuration_is_reported_with_its_location() {
    let dir = temp_dir();
    let text =
        std::fs::read_to_string(workspace_file(OBSTACLE_AVOIDANCE)).expect("the main experiment");
    let path = dir.path().join("typo.argos");
    std::fs::write(&path, text.replace("<epuck_proximity ", "<epuck_prox "))
        .expect("write the experiment");
    let config = path.display().to_string();
    let expected = format!("{config}:18:9: unknown sensor 'epuck_prox'");
    assert_fails_before_first_tick(
        &config,
        &dir.path().join("out"),
        &[&expected, "epuck_proximity"],
    );
}

/// The thesis example (no length) started as a user would, its log read until its first tick.
struct LiveRun {
    child: std::process::Child,
    pid: u32,
    stderr: BufReader<std::process::ChildStderr>,
    /// The launcher's log up to the first tick.
    seen: String,
}

impl LiveRun {
    fn start(out: &Path) -> LiveRun {
        let dir = bin_dir();
        let mut child = Command::new(dir.join("swarm"))
            .args([
                "run",
                "configs/obstacle_avoidance/thesis_example.argos",
                "--no-progress",
                "--out",
            ])
            .arg(out)
            .env("SWARM_BIN_DIR", dir)
            .env("RUST_LOG", "info")
            .current_dir(workspace_root())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("swarm starts");
        let pid = child.id();
        let mut stderr = BufReader::new(child.stderr.take().expect("stderr is piped"));
        let mut seen = String::new();
        let mut line = String::new();
        while stderr
            .read_line(&mut line)
            .expect("read the launcher's log")
            > 0
        {
            seen.push_str(&line);
            if line.contains("first tick completed") {
                break;
            }
            line.clear();
        }
        LiveRun {
            child,
            pid,
            stderr,
            seen,
        }
    }
}

#[test]
fn interrupt_stops_the_run_cleanly_with_every_record_flushed() {
    let out = temp_dir();
    let LiveRun {
        mut child,
        pid,
        mut stderr,
        seen,
    } = LiveRun::start(out.path());
    let prefix = format!("sw{pid:x}-");
    assert!(
        seen.contains("first tick completed"),
        "the run never ticked:\n{seen}"
    );
    assert!(
        seen.contains("it runs until Ctrl-C"),
        "a run without a length says so at its start:\n{seen}"
    );
    kill(Pid::from_raw(pid as i32), Signal::SIGINT).expect("interrupt the launcher");
    let mut rest = String::new();
    while stderr.read_line(&mut rest).unwrap_or(0) > 0 {}
    let status = child.wait().expect("the launcher exits");
    assert_eq!(
        status.code(),
        Some(130),
        "an interrupted run ends cleanly with the exit status of an interrupted program:\n{seen}{rest}"
    );
    let summary = summary(out.path());
    assert_eq!(summary["interrupted"], true);
    let ticks = summary["ticks"].as_u64().expect("ticks are counted");
    assert!(ticks >= 1);
    let trajectory = swarm_system_tests::run_text(out.path(), "trajectory.csv");
    let last_tick: u64 = trajectory
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|t| t.parse().ok())
        .expect("the last row starts with its tick");
    assert_eq!(
        last_tick, ticks,
        "every completed tick is in the trajectory, and nothing more"
    );
    assert_eq!(
        trajectory.lines().count() as u64,
        1 + (ticks + 1) * 40,
        "no partial tick"
    );
    assert_eq!(process_leftovers(&prefix), Vec::<u32>::new());
    assert!(shm_leftovers(&prefix).is_empty());
}

/// A second run into a used `--out` is refused and loses nothing; `--overwrite` empties the folder first. The
/// summary says what ran, by which program, when and from which configuration.
#[test]
fn a_used_run_folder_is_refused_unless_overwritten_and_the_summary_says_what_ran() {
    let out = temp_dir();
    let out_arg = out.path().display().to_string();
    run_ok(OBSTACLE_AVOIDANCE, out.path(), &["--ticks", "5"]);
    let first = summary(out.path());
    assert_eq!(first["version"], env!("CARGO_PKG_VERSION"));
    assert!(first["git_commit"].is_string() || first["git_commit"].is_null());
    assert!(
        first["started_at"]
            .as_str()
            .is_some_and(|t| t.ends_with('Z')),
        "{}",
        first["started_at"]
    );
    assert_eq!(
        first["config"],
        workspace_file(OBSTACLE_AVOIDANCE).display().to_string()
    );
    let command_line: Vec<&str> = first["command_line"]
        .as_array()
        .expect("the command line is recorded")
        .iter()
        .filter_map(serde_json::Value::as_str)
        .collect();
    assert_eq!(command_line[1..3], ["run", OBSTACLE_AVOIDANCE]);

    let refused = swarm(&[
        "run",
        OBSTACLE_AVOIDANCE,
        "--out",
        &out_arg,
        "--ticks",
        "7",
        "--no-progress",
    ]);
    assert!(!refused.output.status.success());
    assert!(
        refused.stderr().contains("pass --overwrite"),
        "{}",
        refused.stderr()
    );
    assert_eq!(summary(out.path()), first, "the refused run lost nothing");

    run_ok(
        OBSTACLE_AVOIDANCE,
        out.path(),
        &["--ticks", "7", "--overwrite"],
    );
    assert_eq!(summary(out.path())["ticks"], 7);
}

/// `--ticks` replaces the experiment's length both ways: longer than `length` as well as shorter.
#[test]
fn ticks_make_a_run_longer_than_the_experiments_length() {
    let out = temp_dir();
    // density_N10.argos: length 60 s at 20 ticks/s, 1,200 ticks.
    run_ok(
        "configs/obstacle_avoidance/density_N10.argos",
        out.path(),
        &["--ticks", "1210"],
    );
    assert_eq!(summary(out.path())["ticks"], 1210);
}

#[test]
fn a_run_without_records_leaves_its_summary_and_snapshots_only() {
    let out = temp_dir();
    run_ok(
        OBSTACLE_AVOIDANCE,
        out.path(),
        &["--ticks", "40", "--records", "off"],
    );
    let summary = summary(out.path());
    assert_eq!(summary["ticks"], 40);
    assert!(summary["metrics"].is_object(), "{summary}");
    let mut names: Vec<String> = std::fs::read_dir(out.path())
        .expect("the run folder")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|name| !name.starts_with('.'))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "config.argos",
            "event_tables.json",
            "logs",
            "scene.json",
            "snapshot_000000.png",
            "snapshot_000040.png",
            "summary.json",
            "supervisors"
        ]
    );
}

/// A launcher killed with SIGKILL takes its world and its agents with it, and the next run removes the shared
/// memory it could not remove itself.
#[test]
fn nothing_of_a_run_survives_its_killed_launcher() {
    /// Removes what the killed run left even if an assertion below fails.
    struct RemoveDeadRuns;
    impl Drop for RemoveDeadRuns {
        fn drop(&mut self) {
            swarm_contract::transport::RunSpec::remove_dead_runs();
        }
    }
    let _cleanup = RemoveDeadRuns;
    let out = temp_dir();
    // The log pipe stays open until the end: a launcher must not be disturbed by a closed standard error.
    let LiveRun {
        mut child,
        pid,
        stderr: _stderr,
        seen,
    } = LiveRun::start(out.path());
    let prefix = format!("sw{pid:x}-");
    let survivors = process_leftovers(&prefix);
    assert!(
        survivors.len() > 1,
        "the world and the agents run: {survivors:?}\n{seen}"
    );
    kill(Pid::from_raw(pid as i32), Signal::SIGKILL).expect("kill the launcher");
    child.wait().expect("the launcher is reaped");
    for process in survivors {
        assert!(
            wait_gone(process, std::time::Duration::from_secs(30)),
            "process {process} of the run outlived its launcher"
        );
    }
    let next = temp_dir();
    run_ok(OBSTACLE_AVOIDANCE, next.path(), &["--ticks", "1"]);
    assert!(
        shm_leftovers(&prefix).is_empty() && iceoryx_root_leftovers(&prefix).is_empty(),
        "the next run removed the killed run's shared memory: {:?} {:?}",
        shm_leftovers(&prefix),
        iceoryx_root_leftovers(&prefix)
    );
}

/// A misspelt controller parameter is not silently ignored: the run names it, where it is, and the likely meant
/// one.
#[test]
fn a_misspelt_controller_parameter_is_warned_with_a_suggestion() {
    let dir = temp_dir();
    let text =
        std::fs::read_to_string(workspace_file(OBSTACLE_AVOIDANCE)).expect("the main experiment");
    assert!(
        text.contains("<params "),
        "the experiment has controller parameters"
    );
    // The models by absolute path, so the copy runs from the temporary folder.
    let models = workspace_file("configs/obstacle_avoidance/models/ptsct");
    let text = text
        .replacen("<params ", "<params velocty=\"5\" ", 1)
        .replace(
            "supervisors=\"models/ptsct\"",
            &format!("supervisors=\"{}\"", models.display()),
        );
    let path = dir.path().join("misspelt_params.argos");
    std::fs::write(&path, text).expect("write the experiment");
    let outcome = run_ok(
        &path.display().to_string(),
        &dir.path().join("out"),
        &["--ticks", "1"],
    );
    let stderr = outcome.stderr();
    assert!(
        stderr.contains("parameter 'velocty' is not used by this controller and is ignored (did you mean 'velocity'?)")
            && stderr.contains("misspelt_params.argos:"),
        "{stderr}"
    );
}

/// No process of a run holds descriptors per robot (the command slots are one file; iceoryx2's per-robot files are
/// the agents' own): 1,000 robots run under a limit of 64 open files per process, far below the usual 1,024.
#[test]
fn a_thousand_robots_run_within_64_open_files_per_process() {
    use std::os::unix::process::CommandExt;
    let out = temp_dir();
    let dir = bin_dir();
    let mut command = Command::new(dir.join("swarm"));
    command
        .args([
            "run",
            "configs/obstacle_avoidance/density_N1000.argos",
            "--ticks",
            "2",
            "--no-progress",
            "--out",
        ])
        .arg(out.path())
        .env("SWARM_BIN_DIR", dir)
        .current_dir(workspace_root());
    // SAFETY: between fork and exec the closure only makes the async-signal-safe setrlimit call.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 64,
                rlim_max: 64,
            };
            if libc::setrlimit(libc::RLIMIT_NOFILE, &limit) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let output = command.output().expect("swarm runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let summary = summary(out.path());
    assert_eq!(summary["robots"], 1000, "{summary}");
    assert_eq!(summary["commands_missing"], 0, "{summary}");
}

/// Off a terminal the progress bar cannot be drawn: the run logs plain progress lines instead, at a low rate.
#[test]
fn a_run_off_a_terminal_logs_its_progress_as_lines() {
    let out = temp_dir();
    let out_arg = out.path().display().to_string();
    let outcome = swarm(&["run", OBSTACLE_AVOIDANCE, "--out", &out_arg, "--ticks", "5"]);
    assert!(outcome.output.status.success(), "{}", outcome.stderr());
    assert!(
        outcome
            .stderr()
            .contains("tick 1/5 (20%), 40/40 robots alive"),
        "{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
}
