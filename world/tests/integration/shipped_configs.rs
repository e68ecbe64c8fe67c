//! The shipped `.argos` files, parsed by the runtime's parser, build into worlds as the tasks describe them.

use std::path::PathBuf;

use swarm_contract::config::Experiment;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_world::World;
use swarm_world::entities::TargetState;
use swarm_world::in_process::avoid_obstacles;

fn load(relative: &str) -> Experiment {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative);
    match Experiment::load(&path) {
        Ok((exp, _warnings)) => exp,
        Err(e) => panic!("{relative} does not load: {e}"),
    }
}

#[test]
fn thesis_example_file_builds_with_robots_in_the_shared_canonical_order() {
    let exp = load("configs/obstacle_avoidance/thesis_example.argos");
    let world = World::new(&exp, 124).expect("builds");
    assert_eq!(world.robot_count(), 40);
    assert_eq!(
        world.arena.obstacles.len(),
        24,
        "4 walls, 10 boxes, 10 cylinders"
    );
    let canonical: Vec<String> = exp.arena.robots().into_iter().map(|r| r.id).collect();
    let ours: Vec<String> = world.arena.robots.iter().map(|r| r.name.clone()).collect();
    assert_eq!(ours, canonical);
    assert_eq!(world.arena.ticks_per_second, 20);
}

#[test]
fn density_file_with_1000_robots_builds() {
    let exp = load("configs/obstacle_avoidance/density_N1000.argos");
    let world = World::new(&exp, 1).expect("builds");
    assert_eq!(world.robot_count(), 1000);
    assert_eq!(world.arena.obstacles.len(), 4 + 200);
}

#[test]
fn foraging_file_starts_robots_on_the_black_home_strip_with_the_lights_in_view() {
    let exp = load("configs/foraging/foraging.argos");
    let mut world = World::new(&exp, 1).expect("builds with the foraging loop functions");
    assert_eq!(world.robot_count(), 40);
    assert_eq!(world.arena.targets.len(), 40);
    assert!(
        world
            .arena
            .targets
            .iter()
            .all(|t| t.state == TargetState::InArena && t.placed.position.y >= -1.9)
    );
    assert_eq!(world.arena.lights.len(), 4);
    assert_eq!(world.arena.obstacles.len(), 4 + 10);
    assert_eq!(world.max_ticks(), Some(144_000));
    let mut frames: Vec<SensorFrame> = (0..40).map(SensorFrame::empty).collect();
    world.sense(&mut frames);
    for f in &frames {
        assert!(
            f.ground_readings().iter().all(|&g| g <= 0.02),
            "home is black, noise E = 0.02: {:?}",
            f.ground
        );
        assert!(
            f.light_readings().iter().any(|&l| l > 0.0),
            "every robot in home senses a home light"
        );
    }
}

#[test]
fn sensing_in_parts_in_any_order_gives_the_frames_of_sensing_all_at_once() {
    for config in [
        "configs/foraging/foraging.argos",
        "configs/pheromone_foraging/pheromone_foraging.argos",
    ] {
        let exp = load(config);
        let mut whole = World::new(&exp, 7).expect("builds");
        let mut parts = World::new(&exp, 7).expect("builds");
        let n = whole.robot_count();
        let mut expected: Vec<SensorFrame> = (0..n as u32).map(SensorFrame::empty).collect();
        let mut frames = expected.clone();
        let mut commands: Vec<ActuatorCommand> =
            (0..n as u32).map(|r| ActuatorCommand::idle(r, 0)).collect();
        let has = vec![true; n];
        for tick in 0..40 {
            whole.sense(&mut expected);
            let starts: Vec<usize> = (0..n).step_by(7).collect();
            for &first in starts.iter().rev() {
                let end = (first + 7).min(n);
                parts.sense_robots(first, &mut frames[first..end]);
            }
            assert_eq!(frames, expected, "{config}, tick {tick}");
            for (f, c) in expected.iter().zip(commands.iter_mut()) {
                avoid_obstacles(f, c);
            }
            whole.act_and_step(&commands, &has);
            parts.act_and_step(&commands, &has);
        }
    }
}
