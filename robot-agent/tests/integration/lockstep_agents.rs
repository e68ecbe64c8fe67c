//! Real robot-agent processes in a lockstep run over the runtime's iceoryx2 transport, driven by an in-test world.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use swarm_contract::messages::SensorFrame;
use swarm_contract::transport::{LinkConfig, RunSpec, WorldLink};

const AGENT: &str = env!("CARGO_BIN_EXE_robot-agent");
/// Generous: agents of a loaded machine may take seconds to start.
const JOIN_TIMEOUT: Duration = Duration::from_secs(120);

/// Owns the run's agent processes and shared-memory files; cleans both up even when the test fails.
struct Run {
    spec: RunSpec,
    children: Vec<Child>,
}

impl Run {
    fn spawn(&mut self, robot: u32, controller: &[&str]) {
        let child = Command::new(AGENT)
            .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
            .env("RUST_LOG", "warn")
            .args([
                "--run",
                self.spec.name(),
                "--robot",
                &robot.to_string(),
                "--seed",
                "124",
                "--iox-root",
            ])
            .arg(self.spec.root_dir())
            .args(controller)
            .stdin(Stdio::null())
            .spawn()
            .unwrap();
        self.children.push(child);
    }
}

impl Drop for Run {
    fn drop(&mut self) {
        for child in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = self.spec.cleanup();
    }
}

/// Robot 0 sees an obstacle on its right (sensor 7), robot 1 on its left (sensor 0).
fn sense(_tick: u64, first: usize, frames: &mut [SensorFrame]) {
    for (robot, frame) in (first..).zip(frames.iter_mut()) {
        match robot {
            0 => frame.proximity[7] = 0.8,
            _ => frame.proximity[0] = 0.5,
        }
    }
}

#[test]
fn native_and_supervised_agents_answer_every_tick_and_exit_when_the_run_ends() {
    let mut run = Run {
        spec: RunSpec::unique(),
        children: Vec::new(),
    };
    let mut world = WorldLink::create(&run.spec, LinkConfig::new(2)).unwrap();
    run.spawn(0, &["--element", "epuck_obstacleavoidance_controller"]);
    run.spawn(
        1,
        &[
            "--config",
            "configs/obstacle_avoidance/thesis_example.argos",
            "--controller",
            "fdc",
        ],
    );
    world.wait_for_agents(JOIN_TIMEOUT).unwrap();
    for tick in 1..=10 {
        let outcome = world.tick_with(sense).unwrap();
        assert_eq!(outcome.answered, 2, "tick {tick}: {outcome:?}");
        let native = world.command(0).unwrap();
        assert_eq!(
            (native.tick, native.wheels),
            (tick, [0.0, 12.8]),
            "native turns left, away from sensor 7"
        );
        assert_eq!(native.events_len, 0);
        let supervised = world.command(1).unwrap();
        assert_eq!(supervised.tick, tick);
        assert_eq!(
            supervised.wheels,
            [12.8, 0.0],
            "supervised turns right, away from sensor 0"
        );
        assert_eq!(supervised.events_len, 2, "saw-obs and turn-inv-obs");
        assert_eq!(supervised.supervisors.count, 2);
    }
    drop(world);
    for child in &mut run.children {
        assert!(child.wait().unwrap().success());
    }
    run.children.clear();
    run.spec.cleanup().unwrap();
    assert_eq!(run.spec.leftovers(), Vec::<std::path::PathBuf>::new());
}
