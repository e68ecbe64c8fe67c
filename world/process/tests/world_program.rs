//! The `swarm-world` program started by hand with the command line the launcher gives it
//! ([`WorldArgs`](swarm_contract::protocol::launcher_to_world::WorldArgs)).

use std::path::Path;
use std::process::Command;

use swarm_contract::protocol::launcher_to_agent::RunArgs;
use swarm_contract::protocol::launcher_to_world::WorldArgs;

const WORLD: &str = env!("CARGO_BIN_EXE_swarm-world");

fn world_args(dir: &Path, config: &Path) -> WorldArgs {
    WorldArgs {
        run: RunArgs {
            run: format!("world-program-test-{}", std::process::id()),
            iox_root: dir.join("iox2"),
        },
        config: config.to_path_buf(),
        seed: 1,
        ticks: 10,
        robots: None,
        out: dir.join("run"),
        limits: vec!["join_timeout_ms=1000".into()],
        real_time: false,
        faults: Vec::new(),
        records: Default::default(),
    }
}

#[test]
fn a_misspelt_sensor_stops_the_world_with_the_file_line_and_a_suggestion() {
    let dir = tempfile::tempdir().expect("temp dir");
    let config = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../runtime/contract/tests/fixtures/bad/unknown_sensor.argos");
    let output = Command::new(WORLD)
        .args(world_args(dir.path(), &config).to_args())
        .output()
        .expect("the world program starts");
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("unknown_sensor.argos:12:") && stderr.contains("epuck_proximity"),
        "{stderr}"
    );
    assert!(
        output.stdout.is_empty(),
        "no report line before the configuration is valid"
    );
    assert!(
        !dir.path().join("iox2").exists(),
        "no shared memory for a run that never starts"
    );
}
