//! The configurable disc robot: (v, w) commands within its limits, wheel limits, and the range-finder ring
//! against analytic geometry; a `<disc-robot>` from a configuration file.

use crate::common::{TPS, builder, drive, frames, wall, wheels};
use swarm_contract::bodies::{BodyModel, DISC};
use swarm_contract::config::Experiment;
use swarm_contract::messages::ActuatorCommand;
use swarm_world::World;
use swarm_world::devices::{Devices, RangeFinderOptions};
use swarm_world::geometry::{Placed, Shape, Vec2};
use swarm_world::physics::Motion;

fn ranging(rays: u8, range: f32) -> Devices {
    Devices {
        range_finder: Some(RangeFinderOptions {
            rays,
            range,
            noise_std_dev: 0.0,
        }),
        ..Devices::PROXIMITY_ONLY
    }
}

fn twist(v: f32, w: f32) -> ActuatorCommand {
    let mut c = ActuatorCommand::idle(0, 0);
    c.set_twist(v, w);
    c
}

fn one_disc(body: BodyModel) -> World {
    let mut b = builder();
    b.robot_with_body(body, "d", "c", Vec2::ZERO, 0.0, ranging(20, 1.0));
    b.build()
}

#[test]
fn a_twist_within_the_limits_drives_the_arc_it_names() {
    let mut world = one_disc(DISC);
    drive(&mut world, u64::from(TPS), twist(0.1, 0.5));
    let r = &world.arena.robots[0];
    // One second on a circle of radius v / w = 0.2 m: heading 0.5 rad, at 0.2 (sin 0.5, 1 - cos 0.5).
    let want = Vec2::new(0.2 * 0.5f32.sin(), 0.2 * (1.0 - 0.5f32.cos()));
    assert!((r.heading - 0.5).abs() < 5e-3, "heading {}", r.heading);
    assert!(
        (r.position - want).length() < 2e-3,
        "{:?} vs {want:?}",
        r.position
    );
}

#[test]
fn a_twist_beyond_the_limits_is_clamped_to_0_22_m_per_s_and_2_84_rad_per_s() {
    let mut world = one_disc(DISC);
    drive(&mut world, 1, twist(5.0, 0.0));
    let moved = world.arena.robots[0].position.length();
    assert!((moved - 0.22 / TPS as f32).abs() < 1e-4, "{moved}");
    let mut world = one_disc(DISC);
    drive(&mut world, 1, twist(0.0, -40.0));
    let turned = world.arena.robots[0].heading;
    assert!((turned + 2.84 / TPS as f32).abs() < 1e-4, "{turned}");
}

#[test]
fn wheel_commands_are_clamped_to_the_configured_top_speed() {
    let slow = BodyModel {
        max_wheel_speed_cm_s: 10.0,
        ..DISC
    };
    let mut world = one_disc(slow);
    drive(&mut world, u64::from(TPS), wheels(50.0, 50.0));
    assert!((world.arena.robots[0].position.x - 0.1).abs() < 1e-3);
}

#[test]
fn range_finder_rays_measure_centre_to_surface_distances() {
    let mut b = builder();
    b.robot_with_body(DISC, "d", "c", Vec2::ZERO, 0.0, ranging(20, 1.0));
    // A wall whose face is 0.5 m ahead, and a pillar of radius 0.1 m 0.8 m to the left.
    wall(&mut b, Vec2::new(0.55, 0.0), Vec2::new(0.1, 0.6));
    b.obstacle(
        "pillar",
        Placed::new(Shape::Disc { radius: 0.1 }, Vec2::new(0.0, 0.8), 0.0),
        0.5,
        Motion::Fixed,
    );
    let mut world = b.build();
    let r = frames(&mut world)[0].range_readings().to_vec();
    assert_eq!(r.len(), 20, "one reading per ray");
    assert!((r[0] - 0.5).abs() < 1e-5, "ray 0 points ahead: {}", r[0]);
    let slanted = 0.5 / 18f32.to_radians().cos();
    assert!(
        (r[1] - slanted).abs() < 1e-5,
        "ray 1 at 18 degrees: {}",
        r[1]
    );
    assert!((r[19] - slanted).abs() < 1e-5);
    assert!(
        (r[5] - 0.7).abs() < 1e-5,
        "ray 5 at 90 degrees meets the pillar: {}",
        r[5]
    );
    assert!(r[10].is_infinite(), "nothing behind within 1 m: {}", r[10]);
}

/// The range-finder readings of a disc robot at the origin facing +y, with a ring of `range` m, and a wall whose
/// face is 0.5 m away in +x (90 degrees to its right, ray 15 of 20).
fn facing_north_with_a_wall_east(range: f32) -> Vec<f32> {
    let mut b = builder();
    b.robot_with_body(
        DISC,
        "d",
        "c",
        Vec2::ZERO,
        std::f32::consts::FRAC_PI_2,
        ranging(20, range),
    );
    wall(&mut b, Vec2::new(0.55, 0.0), Vec2::new(0.1, 0.6));
    let mut world = b.build();
    frames(&mut world)[0].range_readings().to_vec()
}

#[test]
fn range_finder_ignores_what_lies_beyond_its_range_and_turns_with_the_robot() {
    assert!(facing_north_with_a_wall_east(0.4)[15].is_infinite());
    let r = facing_north_with_a_wall_east(1.0);
    assert!((r[15] - 0.5).abs() < 1e-5, "{r:?}");
}

#[test]
fn disc_robots_come_from_the_configuration_with_their_own_bodies() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/robots/disc_wander.argos"),
    )
    .expect("the disc robot example");
    let (exp, _) = Experiment::parse("configs/robots/disc_wander.argos", &text).expect("parses");
    let world = World::new(&exp, 7).expect("builds");
    let robots = &world.arena.robots;
    assert_eq!(robots.len(), 8);
    assert_eq!(robots[0].body, DISC, "scouts keep the default body");
    let hauler = robots[7].body;
    assert_eq!(
        (hauler.radius, hauler.mass, hauler.inter_wheel_distance),
        (0.15, 3.0, 0.25)
    );
    assert!((hauler.max_wheel_speed_cm_s - 10.0).abs() < 1e-5);
    assert_eq!(hauler.max_turn_rate, 1.0);
    let rf = robots[0]
        .devices
        .range_finder
        .expect("the controller declares it");
    assert_eq!((rf.rays, rf.range), (20, 1.0));
    let hauler_rf = robots[7]
        .devices
        .range_finder
        .expect("the controller declares it");
    assert_eq!(
        (hauler_rf.rays, hauler_rf.range),
        (20, 0.6),
        "a hauler's own range_finder_range replaces its controller's range"
    );
}

#[test]
fn a_disc_robot_with_a_bad_body_is_refused_where_it_is_written() {
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/robots/disc_wander.argos"),
    )
    .expect("the disc robot example")
    .replace(r#"max_speed="0.1""#, r#"max_speed="-0.1""#);
    let err = Experiment::parse("disc.argos", &text).expect_err("a negative speed is refused");
    let line = text
        .lines()
        .position(|l| l.contains("max_speed=\"-0.1\""))
        .expect("the line")
        + 1;
    assert!(
        err.to_string().contains(&format!("disc.argos:{line}:")),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains("'max_speed' in <disc-robot> must be greater than 0, got -0.1"),
        "{err}"
    );
}
