//! The runtime's ptSCT player driving the obstacle-avoidance profiles over hand-made frames, in process.

use std::path::Path;

use robot_agent::params::Params;
use robot_agent::profiles::{BoxedCallbacks, bind_profile};
use robot_agent::supervisors::{self, OBSTACLE_AVOIDANCE_PTSCT};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::Player;
use swarm_contract::supervisor_gen::compiled::SupervisorSet;

struct Robot {
    names: Vec<String>,
    player: Player,
    callbacks: BoxedCallbacks,
    command: ActuatorCommand,
}

impl Robot {
    fn new(set: SupervisorSet, profile: &str, seed: u64) -> Robot {
        let names = set.events.iter().map(|e| e.name.clone()).collect();
        let callbacks = bind_profile(profile, &Params::default(), &set.events).unwrap();
        Robot {
            names,
            player: Player::new(set, seed, 0).unwrap(),
            callbacks,
            command: ActuatorCommand::idle(0, 0),
        }
    }

    fn ptsct(seed: u64) -> Robot {
        Robot::new(
            supervisors::synthesise(OBSTACLE_AVOIDANCE_PTSCT).unwrap(),
            "obstacle_avoidance",
            seed,
        )
    }

    fn sct(seed: u64) -> Robot {
        let dir =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/obstacle_avoidance/models/sct");
        Robot::new(
            supervisors::load(&[dir]).unwrap(),
            "obstacle_avoidance_sct",
            seed,
        )
    }

    /// One tick; returns the names of the events fired.
    fn step(&mut self, frame: &SensorFrame) -> Vec<String> {
        self.player
            .step(frame, &mut self.callbacks, &mut self.command);
        self.command
            .fired_events()
            .iter()
            .map(|&e| self.names[usize::from(e)].clone())
            .collect()
    }
}

fn clear() -> SensorFrame {
    SensorFrame::empty(0)
}

fn obstacle(sensor: usize, reading: f32) -> SensorFrame {
    let mut f = SensorFrame::empty(0);
    f.proximity[sensor] = reading;
    f
}

#[test]
fn obstacle_ahead_fires_saw_obs_then_turn_inv_obs_in_the_same_tick() {
    let mut robot = Robot::ptsct(1);
    assert_eq!(robot.step(&obstacle(0, 0.5)), ["saw-obs", "turn-inv-obs"]);
    assert_eq!(
        robot.command.wheels,
        [12.8, 0.0],
        "obstacle on the left: turn right"
    );
    assert_eq!(robot.step(&obstacle(7, 0.5)), ["saw-obs", "turn-inv-obs"]);
    assert_eq!(
        robot.command.wheels,
        [0.0, 12.8],
        "obstacle on the right: turn left"
    );
}

#[test]
fn reading_of_exactly_0_1_does_not_count_as_an_obstacle() {
    let mut robot = Robot::ptsct(1);
    for _ in 0..20 {
        let fired = robot.step(&obstacle(0, 0.1));
        assert!(
            !fired.iter().any(|e| e == "saw-obs" || e == "turn-inv-obs"),
            "{fired:?}"
        );
    }
}

#[test]
fn go_follows_a_turn_exactly_5_ticks_later_and_wheels_persist_meanwhile() {
    let mut robot = Robot::ptsct(7);
    let mut turns = 0;
    let mut tick = 0;
    while turns < 5 {
        tick += 1;
        assert!(tick < 10_000, "no turns seen");
        let fired = robot.step(&clear());
        if fired.iter().any(|e| e.starts_with("turn-")) {
            turns += 1;
            let wheels = robot.command.wheels;
            for _ in 1..5 {
                assert!(
                    robot.step(&clear()).is_empty(),
                    "nothing is enabled before the 5-tick bound"
                );
                assert_eq!(robot.command.wheels, wheels);
            }
            assert_eq!(robot.step(&clear()), ["Go"]);
            assert_eq!(robot.command.wheels, [12.8, 12.8]);
        }
    }
}

#[test]
fn walk_goes_about_9_times_as_often_as_it_turns() {
    let mut robot = Robot::ptsct(3);
    let (mut go_in_fwd, mut turns) = (0u32, 0u32);
    let mut after_turn = false;
    for _ in 0..20_000 {
        let fired = robot.step(&clear());
        match fired.first().map(String::as_str) {
            Some("Go") if after_turn => after_turn = false,
            Some("Go") => go_in_fwd += 1,
            Some("turn-left" | "turn-right") => {
                turns += 1;
                after_turn = true;
            }
            _ => {}
        }
    }
    // Weights 9 : 1 : 1 in `fwd`: Go per turn is 4.5 in expectation.
    let ratio = f64::from(go_in_fwd) / f64::from(turns);
    assert!((4.0..5.0).contains(&ratio), "Go per turn = {ratio}");
}

#[test]
fn same_seed_gives_the_same_walk() {
    let (mut a, mut b) = (Robot::ptsct(11), Robot::ptsct(11));
    for _ in 0..500 {
        assert_eq!(a.step(&clear()), b.step(&clear()));
    }
}

#[test]
fn plain_sct_go_follows_a_turn_through_the_timer_generator() {
    let mut robot = Robot::sct(5);
    let mut tick = 0;
    loop {
        tick += 1;
        assert!(tick < 1_000, "no turn seen");
        if robot.step(&clear()).iter().any(|e| e.starts_with("turn-")) {
            break;
        }
    }
    assert_eq!(robot.step(&clear()), ["start_timer_1"]);
    for _ in 0..5 {
        assert_eq!(robot.step(&clear()), ["timer_1_lw_5", "inc_timer_1"]);
    }
    assert_eq!(robot.step(&clear()), ["timer_1_eq_5", "end_timer_1"]);
    assert_eq!(robot.step(&clear()), ["Go"]);
}

#[test]
fn plain_sct_avoids_obstacles_like_ptsct() {
    let mut robot = Robot::sct(5);
    assert_eq!(robot.step(&obstacle(0, 0.9)), ["saw-obs", "turn-inv-obs"]);
    assert_eq!(robot.command.wheels, [12.8, 0.0]);
}
