//! The agent binary checks its controller before the first tick and exits non-zero with the reason.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn agent(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robot-agent"))
        .current_dir(repo())
        .env("RUST_LOG", "off")
        .args(["--run", "startup-test", "--robot", "7", "--check"])
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn thesis_example_config_passes_the_startup_check() {
    let o = agent(&[
        "--config",
        "configs/obstacle_avoidance/thesis_example.argos",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn plain_sct_models_bind_to_the_sct_profile() {
    let o = agent(&[
        "--profile",
        "obstacle_avoidance_sct",
        "--supervisors",
        "configs/obstacle_avoidance/models/sct",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn unbound_supervisor_events_fail_startup_with_one_message() {
    let o = agent(&[
        "--profile",
        "obstacle_avoidance",
        "--supervisors",
        "configs/obstacle_avoidance/models/sct",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains(
            "error: robot 7: cannot start its controller: profile `obstacle_avoidance` does not fit the supervisors\n  \
             supervisor events without a callback: `start_timer_1` (controllable), `end_timer_1` (controllable), \
             `timer_1_lw_5` (uncontrollable), `inc_timer_1` (controllable), `timer_1_eq_5` (uncontrollable)\n"
        ),
        "{}",
        stderr(&o)
    );
}

#[test]
fn unknown_profile_fails_startup() {
    let o = agent(&[
        "--profile",
        "flocking",
        "--supervisors",
        "configs/obstacle_avoidance/models/ptsct",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("unknown profile `flocking`"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bad_supervisor_file_fails_startup_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.sup");
    std::fs::write(&bad, b"not a supervisor set").unwrap();
    let o = agent(&[
        "--profile",
        "obstacle_avoidance",
        "--supervisors",
        bad.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(bad.to_str().unwrap()), "{}", stderr(&o));
}

#[test]
fn native_controller_passes_the_startup_check() {
    let o = agent(&[
        "--element",
        "epuck_obstacleavoidance_controller",
        "--param",
        "velocity=6.4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}
