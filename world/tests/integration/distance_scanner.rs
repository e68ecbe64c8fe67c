//! The foot-bot's distance scanner against analytic geometry: held, turning, too close, too low, off.

use crate::common::{TPS, builder, drive, frames, wall};
use swarm_contract::bodies::{EPUCK, FOOTBOT};
use swarm_contract::messages::{ActuatorCommand, Scanner, SensorFrame};
use swarm_world::World;
use swarm_world::devices::Devices;
use swarm_world::geometry::Vec2;
use swarm_world::sensors::distance_scanner::SAMPLES_WHILE_TURNING;

const R: f32 = FOOTBOT.radius;

fn scanning() -> Devices {
    Devices {
        distance_scanner: true,
        ..Devices::PROXIMITY_ONLY
    }
}

/// A foot-bot at the origin facing +x and a 0.4 m tall wall whose face is `gap` m ahead of its body.
fn footbot_before_a_wall(gap: f32) -> World {
    let mut b = builder();
    b.robot_with_body(FOOTBOT, "fb", "c", Vec2::ZERO, 0.0, scanning());
    wall(&mut b, Vec2::new(R + gap + 0.05, 0.0), Vec2::new(0.1, 1.0));
    b.build()
}

fn scan(world: &mut World, mode: Scanner, setting: f32) -> SensorFrame {
    let mut c = ActuatorCommand::idle(0, 0);
    c.scanner = mode;
    c.scanner_setting = setting;
    drive(world, 1, c);
    frames(world).remove(0)
}

#[test]
fn held_ahead_the_short_ray_measures_the_wall_from_the_body_centre() {
    let mut world = footbot_before_a_wall(0.2);
    let f = scan(&mut world, Scanner::Angle, 0.0);
    assert_eq!((f.scan_start, f.scan_span), (0.0, 0.0));
    let r = f.range_readings();
    assert_eq!(r.len(), 4, "one reading per ray when held");
    assert!((r[0] - (R + 0.2)).abs() < 1e-5, "{r:?}");
    assert!(r[1..].iter().all(|v| v.is_infinite()), "{r:?}");
}

#[test]
fn a_long_ray_reads_zero_for_a_body_inside_its_blind_distance() {
    // Turned a quarter to the right, ray 1 (long range) points ahead.
    let mut world = footbot_before_a_wall(0.05);
    let f = scan(&mut world, Scanner::Angle, -std::f32::consts::FRAC_PI_2);
    assert_eq!(f.range_readings()[1], 0.0);
    let mut world = footbot_before_a_wall(0.5);
    let f = scan(&mut world, Scanner::Angle, -std::f32::consts::FRAC_PI_2);
    assert!((f.range_readings()[1] - (R + 0.5)).abs() < 1e-5);
    assert!(
        f.range_readings()[0].is_infinite(),
        "0.5 m is beyond the short ray"
    );
}

#[test]
fn bodies_lower_than_the_scanner_pass_under_its_rays() {
    let mut b = builder();
    b.robot_with_body(FOOTBOT, "fb", "c", Vec2::ZERO, 0.0, scanning());
    b.robot_with_body(
        EPUCK,
        "ep",
        "c",
        Vec2::new(R + 0.1 + EPUCK.radius, 0.0),
        0.0,
        Devices::PROXIMITY_ONLY,
    );
    let mut world = b.build();
    let f = scan(&mut world, Scanner::Angle, 0.0);
    assert!(
        f.range_readings()[0].is_infinite(),
        "an e-puck is 7.6 cm tall"
    );
}

#[test]
fn turning_gives_six_readings_per_ray_over_the_angle_swept() {
    let mut world = footbot_before_a_wall(0.2);
    // 60 rpm: a full turn per second, 2 pi / 20 per tick.
    scan(&mut world, Scanner::Speed, 60.0);
    let f = scan(&mut world, Scanner::Speed, 60.0);
    let step = std::f32::consts::TAU / TPS as f32;
    assert_eq!(f.range_readings().len(), 4 * SAMPLES_WHILE_TURNING);
    assert!((f.scan_span - step).abs() < 1e-5, "{}", f.scan_span);
    assert!((f.scan_start - step).abs() < 1e-5, "{}", f.scan_start);
}

#[test]
fn a_scanner_switched_off_reads_nothing() {
    let mut world = footbot_before_a_wall(0.2);
    let f = scan(&mut world, Scanner::Off, 0.0);
    assert!(f.range_readings().is_empty());
}
