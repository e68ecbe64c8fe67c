//! System tests of the lockstep transport with real agent processes and real iceoryx2 shared memory.

use std::process::{Child, Command, Stdio};
use std::time::Duration;

use swarm_contract::messages::ActuatorCommand;
use swarm_contract::transport::{
    AgentLink, AgentNode, CommandStatus, LinkConfig, RunSpec, TransportError, WorldEnd, WorldLink,
    priority,
};

const AGENT: &str = env!("CARGO_BIN_EXE_swarm-lockstep-agent");
/// Generous: agents of a loaded CI machine may take seconds to start.
const JOIN_TIMEOUT: Duration = Duration::from_secs(60);

/// Owns a run's agent processes and files: kills the children and removes every file even when a test fails.
struct Run {
    spec: RunSpec,
    children: Vec<Child>,
}

impl Run {
    fn new() -> Run {
        Run {
            spec: RunSpec::unique(),
            children: Vec::new(),
        }
    }

    fn spawn(&mut self, robot: u32, extra: &[&str]) {
        let child = Command::new(AGENT)
            .arg("--run")
            .arg(self.spec.name())
            .arg("--root")
            .arg(self.spec.root_dir())
            .arg("--robot")
            .arg(robot.to_string())
            .args(extra)
            .stdin(Stdio::null())
            .spawn()
            .expect("spawn the lockstep agent");
        self.children.push(child);
    }

    /// Sends `signal` to the `index`-th agent started.
    fn signal(&self, index: usize, signal: libc::c_int) {
        let pid = libc::pid_t::try_from(self.children[index].id()).expect("a pid");
        // SAFETY: kill(2) with a valid signal on our own child.
        assert_eq!(unsafe { libc::kill(pid, signal) }, 0);
    }

    fn kill_all(&mut self) {
        for child in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
        self.children.clear();
    }
}

impl Drop for Run {
    fn drop(&mut self) {
        self.kill_all();
        let _ = self.spec.cleanup();
    }
}

/// The world writes a per-robot, per-tick marker into each frame; the agent echoes it as its wheel speeds.
fn sense(tick: u64, first: usize, frames: &mut [swarm_contract::messages::SensorFrame]) {
    for (robot, frame) in (first..).zip(frames.iter_mut()) {
        frame.position = [robot as f32 * 10.0 + 1.0, tick as f32];
    }
}

fn expect_echo(world: &WorldLink, robot: u32, tick: u64) {
    let command = world
        .command(robot)
        .unwrap_or_else(|| panic!("robot {robot} has no command in tick {tick}"));
    assert_eq!(command.robot, robot);
    assert_eq!(command.tick, tick);
    assert_eq!(command.wheels, [robot as f32 * 10.0 + 1.0, tick as f32]);
}

fn config(robots: u32, deadline_ms: u64) -> LinkConfig {
    let mut config = LinkConfig::new(robots);
    config.tick_deadline = Duration::from_millis(deadline_ms);
    config
}

#[test]
fn every_agent_receives_its_own_frame_and_answers_into_its_own_slot() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(8, 10_000)).expect("create world");
    for robot in 0..8 {
        run.spawn(robot, &[]);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    for tick in 1..=30 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!(outcome.tick, tick);
        assert_eq!(outcome.answered, 8, "tick {tick}: {outcome:?}");
        for robot in 0..8 {
            expect_echo(&world, robot, tick);
        }
    }
}

#[test]
fn agents_whose_nodes_were_made_before_the_world_existed_join_on_them() {
    let run = Run::new();
    // As the zygote's agents do: nodes made before the world has created anything of the run.
    let nodes: Vec<AgentNode> = (0..2)
        .map(|robot| AgentNode::create(&run.spec, robot).expect("a node before the world"))
        .collect();
    let mut world = WorldLink::create(&run.spec, config(2, 10_000)).expect("create world");
    let agents: Vec<_> = nodes
        .into_iter()
        .zip(0..)
        .map(|(node, robot)| {
            let spec = run.spec.clone();
            std::thread::spawn(move || {
                let mut link = AgentLink::join_on(&spec, node, JOIN_TIMEOUT, WorldEnd::ByParent)
                    .expect("joins on its node");
                let tick = link.next_tick().expect("a tick").expect("the run goes on");
                let mut command = ActuatorCommand::idle(robot, tick.number());
                command.wheels = tick.frame().position;
                tick.answer(&mut command);
                let next = link.next_tick().expect("the end of the run");
                assert!(next.is_none(), "the world ended the run after one tick");
                link.release_ended_run();
            })
        })
        .collect();
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    let outcome = world.tick_with(sense).expect("tick");
    assert_eq!(outcome.answered, 2, "{outcome:?}");
    for robot in 0..2 {
        expect_echo(&world, robot, 1);
    }
    drop(world);
    for agent in agents {
        agent.join().expect("the agent's thread");
    }
}

#[test]
fn killed_agent_does_not_block_the_tick_and_is_reported_missing_then_dead() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(4, 300)).expect("create world");
    for robot in 0..4 {
        let extra: &[&str] = if robot == 2 { &["--die-at", "3"] } else { &[] };
        run.spawn(robot, extra);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    for _ in 1..=2 {
        assert_eq!(world.tick_with(sense).expect("tick").answered, 4);
    }
    // Tick 3: robot 2 aborts on reading its frame; the deadline ends the tick.
    let outcome = world.tick_with(sense).expect("tick 3");
    assert_eq!((outcome.answered, outcome.missing, outcome.dead), (3, 1, 0));
    assert_eq!(world.statuses()[2], CommandStatus::Missing);
    assert!(world.command(2).is_none());
    for robot in [0, 1, 3] {
        expect_echo(&world, robot, 3);
    }
    // The launcher's death notice: later ticks no longer wait for robot 2.
    world.mark_dead(2).expect("death notice");
    for tick in 4..=6 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!((outcome.answered, outcome.missing, outcome.dead), (3, 0, 1));
        assert_eq!(world.statuses()[2], CommandStatus::Dead);
        for robot in [0, 1, 3] {
            expect_echo(&world, robot, tick);
        }
    }
}

#[test]
fn death_notice_from_another_thread_releases_the_waiting_tick() {
    let mut run = Run::new();
    // A deadline far beyond the test's patience: only the death notice can end tick 2.
    let mut world = WorldLink::create(&run.spec, config(2, 600_000)).expect("create world");
    run.spawn(0, &[]);
    run.spawn(1, &["--freeze-at", "2"]);
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick 1").answered, 2);
    let notices = world.death_notices();
    let (started_tx, started_rx) = std::sync::mpsc::channel();
    let launcher = std::thread::spawn(move || {
        // Wait until the world is inside tick 2, then report robot 1 dead as a launcher would.
        started_rx.recv().expect("tick 2 started");
        notices.mark_dead(1).expect("death notice");
    });
    let outcome = world
        .tick_with(|tick, first, frames| {
            sense(tick, first, frames);
            // Once: the launcher thread ends after the first notice (the world senses each chain apart).
            if first == 0 {
                started_tx.send(()).expect("notify");
            }
        })
        .expect("tick 2");
    launcher.join().expect("launcher thread");
    assert_eq!((outcome.answered, outcome.dead), (1, 1));
    expect_echo(&world, 0, 2);
}

#[test]
fn frozen_agent_misses_the_deadline_while_the_others_keep_ticking() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(3, 200)).expect("create world");
    run.spawn(0, &[]);
    run.spawn(1, &["--freeze-at", "2"]);
    run.spawn(2, &[]);
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick 1").answered, 3);
    for tick in 2..=4 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!((outcome.answered, outcome.missing), (2, 1));
        assert_eq!(world.statuses()[1], CommandStatus::Missing);
        expect_echo(&world, 0, tick);
        expect_echo(&world, 2, tick);
    }
}

/// A world of 8 robots woken in two chains of four (0-1-2-3 and 4-5-6-7) whose agent for `frozen` stops
/// answering from tick 2, after a tick 1 that every agent answered.
fn two_chains_of_four_after_tick_1(run: &mut Run, deadline_ms: u64, frozen: u32) -> WorldLink {
    let mut link_config = config(8, deadline_ms);
    link_config.chains = 2;
    let mut world = WorldLink::create(&run.spec, link_config).expect("create world");
    for robot in 0..8 {
        let extra: &[&str] = if robot == frozen {
            &["--freeze-at", "2"]
        } else {
            &[]
        };
        run.spawn(robot, extra);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick 1").answered, 8);
    world
}

#[test]
fn an_agent_that_stops_answering_holds_up_no_other_robot_of_its_chain() {
    let mut run = Run::new();
    // Robot 1 stops answering; robots 2 and 3 of its chain answer long before the deadline.
    let mut world = two_chains_of_four_after_tick_1(&mut run, 5_000, 1);
    for tick in 2..=4 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!((outcome.answered, outcome.missing), (7, 1), "tick {tick}");
        assert_eq!(world.statuses()[1], CommandStatus::Missing);
        for robot in [0, 2, 3, 4, 5, 6, 7] {
            expect_echo(&world, robot, tick);
        }
    }
    // Once the robot is reported dead, ticks no longer wait for it.
    world.mark_dead(1).expect("death notice");
    let outcome = world.tick_with(sense).expect("tick 5");
    assert_eq!((outcome.answered, outcome.dead), (7, 1));
}

#[test]
fn a_stopped_agent_holds_up_no_other_robot_of_its_chain() {
    let mut run = Run::new();
    // Two chains of two; robot 0's process is stopped (SIGSTOP, as `swarm ctl freeze` does). The stop signal
    // takes it out of its chain's wait, so the world's one wake-up of chain 0 reaches robot 1's agent, which
    // answers long before the deadline.
    let mut link_config = config(4, 20_000);
    link_config.chains = 2;
    let mut world = agents_after_one_tick(&mut run, link_config);
    run.signal(0, libc::SIGSTOP);
    // As the fault driver does for a frozen robot: ticks stop waiting for it.
    world.mark_dead(0).expect("death notice");
    for tick in 2..=6 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!((outcome.answered, outcome.dead), (3, 1), "tick {tick}");
        for robot in 1..4 {
            expect_echo(&world, robot, tick);
        }
    }
    run.signal(0, libc::SIGCONT);
}

#[test]
fn death_notice_for_a_chain_not_yet_started_wakes_nobody_before_their_frames_are_in_place() {
    let mut run = Run::new();
    // Robot 5's agent stops answering at tick 2 and its death notice arrives while the world is still sensing
    // chain 0: chain 1 must step over robot 5 when it starts, and robots 6 and 7 answer with their own frames.
    // (The sync block's unit test checks that the notice wakes nobody in chain 1 early, which this race seldom
    // shows.)
    let mut world = two_chains_of_four_after_tick_1(&mut run, 20_000, 5);
    let notices = world.death_notices();
    let outcome = world
        .tick_with(|tick, first, frames| {
            if first == 0 {
                notices.mark_dead(5).expect("death notice");
            }
            sense(tick, first, frames);
        })
        .expect("tick 2");
    assert_eq!((outcome.answered, outcome.missing, outcome.dead), (7, 0, 1));
    for robot in [0, 1, 2, 3, 4, 6, 7] {
        expect_echo(&world, robot, 2);
    }
}

#[test]
fn robot_beyond_the_run_cannot_join_and_the_error_names_the_limit() {
    let run = Run::new();
    let _world = WorldLink::create(&run.spec, config(4, 100)).expect("create world");
    let error = AgentLink::join(&run.spec, 4)
        .err()
        .expect("robot 4 must be rejected");
    assert!(matches!(
        error,
        TransportError::RobotOutOfRange {
            robot: 4,
            capacity: 4
        }
    ));
    assert_eq!(
        error.to_string(),
        "robot 4 cannot join: the service was created for 4 robots (0..4)"
    );
}

#[test]
fn second_agent_for_the_same_robot_is_rejected() {
    let run = Run::new();
    let _world = WorldLink::create(&run.spec, config(2, 100)).expect("create world");
    let _first = AgentLink::join(&run.spec, 1).expect("first agent joins");
    let error = AgentLink::join(&run.spec, 1)
        .err()
        .expect("second agent must be rejected");
    assert!(matches!(error, TransportError::RobotTaken { robot: 1 }));
}

#[test]
fn cleanup_after_sigkill_of_every_process_leaves_nothing_in_dev_shm() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(3, 10_000)).expect("create world");
    for robot in 0..3 {
        run.spawn(robot, &[]);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick").answered, 3);
    // Everyone dies without running a destructor: agents by SIGKILL, the world by forgetting its link.
    run.kill_all();
    std::mem::forget(world);
    assert!(
        !run.spec.leftovers().is_empty(),
        "a live run must have files to clean up"
    );
    run.spec.cleanup().expect("cleanup");
    assert_eq!(run.spec.leftovers(), Vec::<std::path::PathBuf>::new());
}

#[test]
fn replacement_agent_joins_after_a_death_notice_and_answers_again() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(3, 300)).expect("create world");
    for robot in 0..3 {
        let extra: &[&str] = if robot == 1 { &["--die-at", "2"] } else { &[] };
        run.spawn(robot, extra);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick 1").answered, 3);
    assert_eq!(world.tick_with(sense).expect("tick 2").missing, 1);
    world.mark_dead(1).expect("death notice");
    // This tick does not wait for robot 1 and removes the dead agent's iceoryx2 node.
    assert_eq!(world.tick_with(sense).expect("tick 3").dead, 1);
    run.spawn(1, &[]);
    world
        .wait_for_agents(JOIN_TIMEOUT)
        .expect("replacement joins");
    let outcome = world.tick_with(sense).expect("tick 4");
    assert_eq!(outcome.answered, 3, "{outcome:?}");
    expect_echo(&world, 1, 4);
}

#[test]
fn an_agent_continued_after_its_robot_was_replaced_is_not_counted() {
    let mut run = Run::new();
    let mut world = agents_after_one_tick(&mut run, config(2, 300));
    // Robot 1's agent is stopped and reported, as the fault driver does for a frozen robot.
    run.signal(1, libc::SIGSTOP);
    world.mark_dead(1).expect("death notice");
    assert_eq!(world.tick_with(sense).expect("tick 2").dead, 1);
    // A replacement that joins and never answers: any answer for robot 1 now comes from the stopped agent.
    run.spawn(1, &["--freeze-at", "0"]);
    world
        .wait_for_agents(JOIN_TIMEOUT)
        .expect("replacement joins");
    run.signal(1, libc::SIGCONT);
    for tick in 3..=6 {
        let outcome = world.tick_with(sense).expect("tick");
        assert_eq!(
            (outcome.answered, outcome.missing),
            (1, 1),
            "tick {tick}: {outcome:?}"
        );
        expect_echo(&world, 0, tick);
    }
}

#[test]
fn a_death_notice_read_after_the_replacement_joined_leaves_the_robot_to_it() {
    let mut run = Run::new();
    let mut world = WorldLink::create(&run.spec, config(2, 300)).expect("create world");
    world.start_without_agents();
    // Robot 1's first agent (never started here) is killed at start-up; its replacement joins before the world
    // reads the launcher's death notice.
    for robot in 0..2 {
        run.spawn(robot, &[]);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    let notices = world.death_notices();
    let replacement = run.children[1].id();
    let took = notices
        .mark_agent_dead(1, replacement + 1)
        .expect("robot 1 is in the run");
    assert!(!took, "a notice for another agent took effect");
    assert!(world.agent_present(1), "the late notice took the robot");
    let outcome = world.tick_with(sense).expect("tick 1");
    assert_eq!(outcome.answered, 2, "{outcome:?}");
    // A notice for the agent that owns the robot takes effect.
    assert!(
        notices
            .mark_agent_dead(1, replacement)
            .expect("robot 1 is in the run")
    );
    assert!(!world.agent_present(1));
}

/// Names the run a [`world_process_for_the_world_death_test`] process is the world of.
const WORLD_RUN_ENV: &str = "SWARM_TEST_WORLD_RUN";
/// The iceoryx2 root directory of that run.
const WORLD_ROOT_ENV: &str = "SWARM_TEST_WORLD_ROOT";

/// Not a test of its own: when [`an_agent_exits_on_its_own_when_the_world_process_dies`] starts this test binary
/// again with [`WORLD_RUN_ENV`] set, this is its world process (one robot, one tick, then it waits to be killed).
/// Run any other way, it returns at once.
#[test]
fn world_process_for_the_world_death_test() {
    let (Ok(name), Ok(root)) = (std::env::var(WORLD_RUN_ENV), std::env::var(WORLD_ROOT_ENV)) else {
        return;
    };
    let spec = RunSpec::new(&name, root).expect("run spec");
    let mut world = WorldLink::create(&spec, config(1, 10_000)).expect("create world");
    println!("world ready");
    world
        .wait_for_agents(JOIN_TIMEOUT)
        .expect("the agent joins");
    assert_eq!(world.tick_with(sense).expect("tick").answered, 1);
    println!("world ticked");
    loop {
        std::thread::park();
    }
}

#[test]
fn an_agent_exits_on_its_own_when_the_world_process_dies() {
    use std::io::{BufRead, BufReader, Read};

    let mut run = Run::new();
    let world = Command::new(std::env::current_exe().expect("the test binary"))
        .args([
            "--exact",
            "world_process_for_the_world_death_test",
            "--nocapture",
        ])
        .env(WORLD_RUN_ENV, run.spec.name())
        .env(WORLD_ROOT_ENV, run.spec.root_dir())
        .stdout(Stdio::piped())
        .stdin(Stdio::null())
        .spawn()
        .expect("start the world process");
    run.children.push(world);
    let mut world_says = BufReader::new(run.children[0].stdout.take().expect("piped")).lines();
    let mut wait_for = |line: &str| {
        world_says
            .by_ref()
            .map(|l| l.expect("the world's output"))
            .find(|l| l == line)
            .unwrap_or_else(|| panic!("the world process ended before saying '{line}'"));
    };
    wait_for("world ready");
    let agent = Command::new(AGENT)
        .arg("--run")
        .arg(run.spec.name())
        .arg("--root")
        .arg(run.spec.root_dir())
        .args(["--robot", "0"])
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn the lockstep agent");
    run.children.push(agent);
    wait_for("world ticked");

    run.children[0].kill().expect("SIGKILL the world");
    let _ = run.children[0].wait();
    // Only a guard against a hang: the agent is expected to exit by itself long before. It cannot hit another
    // process: the agent's pid stays taken until the wait below has reaped it, and that ends the guard.
    let (exited, guard_ends) = std::sync::mpsc::channel::<()>();
    let agent_pid = run.children[1].id().to_string();
    let guard = std::thread::spawn(move || {
        if guard_ends.recv_timeout(Duration::from_secs(60)).is_err() {
            let _ = Command::new("kill").args(["-KILL", &agent_pid]).status();
        }
    });
    let status = run.children[1].wait().expect("wait for the agent");
    let _ = exited.send(());
    let _ = guard.join();
    let mut stderr = String::new();
    run.children[1]
        .stderr
        .take()
        .expect("piped")
        .read_to_string(&mut stderr)
        .expect("the agent's error output");
    assert_eq!(
        status.code(),
        Some(1),
        "the agent ends with an error of its own, not a signal: {status:?} {stderr}"
    );
    assert!(
        stderr.contains("is gone without ending the run"),
        "the agent says why: {stderr}"
    );
}

/// The CPUs `pid`'s main thread may run on (`Cpus_allowed_list` of `/proc/<pid>/status`, ranges expanded).
fn allowed_cpus(pid: u32) -> Vec<usize> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("read the status");
    let list = status
        .lines()
        .find_map(|line| line.strip_prefix("Cpus_allowed_list:"))
        .expect("the status lists the allowed CPUs")
        .trim();
    list.split(',')
        .flat_map(|range| {
            let (first, last) = range.split_once('-').unwrap_or((range, range));
            let parse = |cpu: &str| cpu.parse::<usize>().expect("a CPU number");
            parse(first)..=parse(last)
        })
        .collect()
}

/// Starts a world with `link_config` and one agent per robot, and runs the first tick: by then every agent has
/// joined and settled where and how it runs.
fn agents_after_one_tick(run: &mut Run, link_config: LinkConfig) -> WorldLink {
    let robots = link_config.robots;
    let mut world = WorldLink::create(&run.spec, link_config).expect("create world");
    for robot in 0..robots {
        run.spawn(robot, &[]);
    }
    world.wait_for_agents(JOIN_TIMEOUT).expect("agents join");
    assert_eq!(world.tick_with(sense).expect("tick 1").answered, robots);
    world
}

/// The CPUs of 8 agents in two chains of four, after they joined a world that does or does not pin them.
fn agent_cpus_in_two_chains(pin_chains: bool) -> Vec<Vec<usize>> {
    let mut run = Run::new();
    let mut link_config = config(8, 10_000);
    link_config.chains = 2;
    link_config.pin_chains = pin_chains;
    let _world = agents_after_one_tick(&mut run, link_config);
    run.children
        .iter()
        .map(|child| allowed_cpus(child.id()))
        .collect()
}

#[test]
fn each_chain_runs_on_one_cpu_and_the_chains_take_the_cpus_in_turn() {
    let allowed = allowed_cpus(std::process::id());
    let cpus = agent_cpus_in_two_chains(true);
    for (robot, cpus) in cpus.iter().enumerate() {
        let chain = robot / 4;
        assert_eq!(
            cpus,
            &vec![allowed[chain % allowed.len()]],
            "robot {robot} of chain {chain}"
        );
    }
}

#[test]
fn agents_of_a_world_that_does_not_pin_keep_every_cpu() {
    let allowed = allowed_cpus(std::process::id());
    for (robot, cpus) in agent_cpus_in_two_chains(false).iter().enumerate() {
        assert_eq!(cpus, &allowed, "robot {robot}");
    }
}

/// The scheduling policy and real-time priority of `pid`'s main thread (fields 41 and 40 of its stat line).
fn scheduling(pid: u32) -> (i32, i32) {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).expect("read the stat line");
    // Fields after the command name, which is in parentheses and may contain spaces.
    let fields: Vec<&str> = stat[stat.rfind(')').expect("a command name") + 2..]
        .split(' ')
        .collect();
    let field = |n: usize| fields[n - 3].parse::<i32>().expect("a number");
    (field(41), field(40))
}

#[test]
fn agents_of_a_realtime_world_run_round_robin_when_the_system_allows_it() {
    let allowed = std::thread::spawn(|| priority::enter_realtime(priority::AGENT_PRIORITY).is_ok())
        .join()
        .expect("the probe thread ends");
    let mut run = Run::new();
    let mut link_config = config(4, 10_000);
    link_config.realtime = true;
    let _world = agents_after_one_tick(&mut run, link_config);
    let expected = if allowed {
        (libc::SCHED_RR, priority::AGENT_PRIORITY)
    } else {
        (libc::SCHED_OTHER, 0)
    };
    for (robot, child) in run.children.iter().enumerate() {
        assert_eq!(scheduling(child.id()), expected, "robot {robot}");
    }
}
