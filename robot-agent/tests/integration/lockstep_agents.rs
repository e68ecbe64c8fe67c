//! Real robot-agent processes in a lockstep run over the runtime's iceoryx2 transport, driven by an in-test world.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use swarm_contract::messages::SensorFrame;
use swarm_contract::process::children::AgentProcess;
use swarm_contract::protocol::launcher_to_agent::ZygoteReply;
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

/// Starts `robot-agent zygote` for robots 0..3 of the thesis example (cut to 3 robots), logging into `logs`.
fn start_zygote(spec: &RunSpec, logs: &Path) -> Child {
    Command::new(AGENT)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .env("RUST_LOG", "info")
        .args(["zygote", "--run", spec.name(), "--iox-root"])
        .arg(spec.root_dir())
        .args(["--seed", "124", "--robots", "3", "--logs"])
        .arg(logs)
        .args([
            "--config",
            "configs/obstacle_avoidance/thesis_example.argos",
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

#[test]
fn zygote_agents_are_the_callers_children_and_join_only_when_let_in() {
    let logs = tempfile::tempdir().unwrap();
    let run = Run {
        spec: RunSpec::unique(),
        children: Vec::new(),
    };
    let mut zygote = start_zygote(&run.spec, logs.path());
    let mut gate = zygote.stdin.take().unwrap();
    gate.write_all(b"0 0\n1 1\n2 2\n\n").unwrap();
    let replies: Vec<ZygoteReply> = BufReader::new(zygote.stdout.take().unwrap())
        .lines()
        .map(|line| line.unwrap().parse().unwrap())
        .collect();
    assert!(zygote.wait().unwrap().success());
    let mut agents = Agents(Vec::new());
    for (robot, reply) in (0..).zip(&replies) {
        let ZygoteReply::Started { robot: r, pid } = reply else {
            panic!("robot {robot} was not started: {reply}");
        };
        assert_eq!(*r, robot);
        // Forked with CLONE_PARENT: this process, not the zygote, is their parent and reaps them.
        agents.0.push(AgentProcess::adopt(*pid).unwrap());
    }
    assert_eq!(agents.0.len(), 3);
    // The run's shared memory is created only now, as the world of a launcher does while the agents wait.
    let mut world = WorldLink::create(&run.spec, LinkConfig::new(3)).unwrap();
    for agent in &agents.0 {
        assert_eq!(
            agent.try_wait().unwrap(),
            None,
            "an agent ended before it was let in"
        );
    }
    drop(gate);
    world.wait_for_agents(JOIN_TIMEOUT).unwrap();
    for tick in 1..=5 {
        let outcome = world.tick_with(sense).unwrap();
        assert_eq!(outcome.answered, 3, "tick {tick}: {outcome:?}");
    }
    drop(world);
    for agent in agents.0.drain(..) {
        assert!(agent.wait().unwrap().success());
    }
    for robot in 0..3 {
        let log = std::fs::read_to_string(logs.path().join(format!("robot-{robot}.log"))).unwrap();
        assert!(
            log.contains("joined the run"),
            "robot {robot}'s log:\n{log}"
        );
        assert!(
            log.contains("the world ended the run"),
            "robot {robot}'s log:\n{log}"
        );
    }
    run.spec.cleanup().unwrap();
    assert_eq!(run.spec.leftovers(), Vec::<std::path::PathBuf>::new());
}

#[test]
fn a_zygote_refuses_a_malformed_order_before_forking_anything() {
    let logs = tempfile::tempdir().unwrap();
    let spec = RunSpec::unique();
    let mut zygote = start_zygote(&spec, logs.path());
    zygote
        .stdin
        .take()
        .unwrap()
        .write_all(b"0 0\nthree\n\n")
        .unwrap();
    let output = zygote.wait_with_output().unwrap();
    assert!(!output.status.success());
    assert!(output.stdout.is_empty(), "{:?}", output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("standard input, line 2: `three` is not `<robot> <slot>`"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(logs.path()).unwrap().count(), 0);
}

/// Agents forked by a zygote; killed and reaped if a test fails before it reaps them itself.
struct Agents(Vec<AgentProcess>);

impl Drop for Agents {
    fn drop(&mut self) {
        for agent in &self.0 {
            agent.signal(nix::sys::signal::Signal::SIGKILL);
            let _ = agent.wait();
        }
    }
}
