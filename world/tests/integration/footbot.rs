//! The foot-bot's body and sensors against analytic geometry, with the numbers of docs/robots.md.

use crate::common::{builder, drive, frames, wall, wheels};
use swarm_contract::bodies::FOOTBOT;
use swarm_contract::messages::Rgb;
use swarm_world::devices::Devices;
use swarm_world::entities::{FloorRegion, Light};
use swarm_world::geometry::Vec2;
use swarm_world::sensors::light::intensity_at;
use swarm_world::sensors::proximity::footbot_curve;

const R: f32 = FOOTBOT.radius;

fn footbot_at(b: &mut swarm_world::WorldBuilder, position: Vec2, heading: f32) {
    b.robot_with_body(FOOTBOT, "fb", "c", position, heading, Devices::ALL);
}

/// Distance along a ray leaving the body edge at `angle_deg` to a wall whose face is `d` ahead of the edge.
fn ray_distance_to_face(d: f32, angle_deg: f32) -> f32 {
    let c = angle_deg.to_radians().cos();
    (R + d - R * c) / c
}

#[test]
fn footbot_curve_is_one_at_contact_and_a_tenth_at_its_range() {
    assert_eq!(footbot_curve(0.005), 1.0);
    assert!((footbot_curve(0.1) - 0.010_052_7 / (0.1 + 0.000_163_144)).abs() < 1e-6);
    assert!((footbot_curve(0.1) - 0.1).abs() < 1e-3);
    assert_eq!(footbot_curve(0.1001), 0.0);
}

#[test]
fn wall_ahead_is_seen_by_the_24_ring_symmetrically_and_within_10_cm_only() {
    let d = 0.03;
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    wall(&mut b, Vec2::new(R + d + 0.05, 0.0), Vec2::new(0.1, 2.0));
    let mut world = b.build();
    let frame = frames(&mut world).remove(0);
    let p = frame.proximity_readings();
    assert_eq!(p.len(), 24, "the foot-bot has 24 proximity sensors");
    for (i, angle) in [(0, 7.5f32), (1, 22.5), (2, 37.5)] {
        let want = footbot_curve(ray_distance_to_face(d, angle));
        assert!((p[i] - want).abs() < 1e-5, "sensor {i}: {} vs {want}", p[i]);
        assert!((p[23 - i] - want).abs() < 1e-5, "mirror of sensor {i}");
    }
    // At 52.5 degrees the ray needs 10.4 cm to reach a face 3 cm ahead of the body: beyond the 10 cm range.
    assert!(
        p[3..21].iter().all(|&v| v == 0.0),
        "only the six front sensors see it: {p:?}"
    );
}

#[test]
fn another_footbot_is_an_obstacle_to_the_ring() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    // A second foot-bot straight to the left, 2 cm between the bodies.
    footbot_at(&mut b, Vec2::new(0.0, 2.0 * R + 0.02), 0.0);
    let mut world = b.build();
    let p = frames(&mut world)[0].proximity_readings().to_vec();
    // Sensors 5 and 6 (82.5 and 97.5 degrees) flank the direction to the other robot.
    assert!(p[5] > 0.1 && (p[5] - p[6]).abs() < 1e-5, "{p:?}");
    assert!(
        p[5] < footbot_curve(0.02),
        "the ray is slanted, so longer than the gap"
    );
}

#[test]
fn light_sensors_follow_argos_foot_bot_model() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    b.light(Light {
        name: "l".into(),
        position: Vec2::new(0.0, 1.0),
        height: 0.5,
        intensity: 3.0,
        color: Rgb {
            r: 255,
            g: 255,
            b: 0,
        },
    });
    let mut world = b.build();
    let l = frames(&mut world)[0].light_readings().to_vec();
    assert_eq!(l.len(), 24);
    // Distance from the robot's origin on the ground to the light, as ARGoS measures it.
    let base = intensity_at((1.0f32 + 0.25).sqrt(), 3.0);
    let weight = |delta_deg: f32| 1.0 - 2.0 * delta_deg.to_radians() / std::f32::consts::PI;
    // The light is at 90 degrees: sensors 5 (82.5) and 6 (97.5) are 7.5 degrees off.
    assert!((l[5] - base * weight(7.5)).abs() < 1e-5, "{l:?}");
    assert!((l[6] - l[5]).abs() < 1e-6);
    assert!((l[0] - base * weight(82.5)).abs() < 1e-5);
    assert_eq!(l[18], 0.0, "sensor 18 at 277.5 degrees faces away");
}

#[test]
fn motor_ground_sensors_sit_under_the_wheel_axis_front_left_first() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    // Black floor where x > 0 and y > 0: only sensor 0 at (0.063, 0.0116) is over it.
    b.floor_region(FloorRegion {
        min: Vec2::new(0.0, 0.0),
        max: Vec2::new(2.0, 2.0),
        grey: 0.0,
    });
    let mut world = b.build();
    assert_eq!(
        frames(&mut world)[0].ground_readings(),
        [0.0, 1.0, 1.0, 1.0]
    );
}

#[test]
fn wheels_are_fourteen_centimetres_apart() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    let mut world = b.build();
    // One second of (-5, 5) cm/s: w = 0.1 / 0.14 rad/s, no translation.
    drive(&mut world, u64::from(crate::common::TPS), wheels(-5.0, 5.0));
    let robot = &world.arena.robots[0];
    assert!(robot.position.length() < 1e-3, "{:?}", robot.position);
    assert!(
        (robot.heading - 0.1 / 0.14).abs() < 1e-2,
        "{}",
        robot.heading
    );
}

#[test]
fn footbot_camera_sees_an_led_ring_half_a_metre_away() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    footbot_at(&mut b, Vec2::new(0.5, 0.0), 0.0);
    let mut world = b.build();
    let mut lit = crate::common::wheels(0.0, 0.0);
    lit.led = Rgb { r: 0, g: 0, b: 255 };
    drive(&mut world, 1, lit);
    let f = frames(&mut world);
    let blobs = f[0].camera_blobs();
    assert_eq!(blobs.len(), 1, "{blobs:?}");
    assert!((blobs[0].distance_cm - 50.0).abs() < 0.5);
    // The cone reaches (0.2887 - 0.085) tan 70 = 0.56 m: a robot at 0.6 m is out of view.
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    footbot_at(&mut b, Vec2::new(0.6, 0.0), 0.0);
    let mut world = b.build();
    drive(&mut world, 1, lit);
    assert_eq!(frames(&mut world)[0].camera_blobs().len(), 0);
}

#[test]
fn footbot_range_and_bearing_reports_centre_to_centre_range() {
    let mut b = builder();
    footbot_at(&mut b, Vec2::ZERO, 0.0);
    footbot_at(&mut b, Vec2::new(0.0, 1.0), 0.0);
    let mut world = b.build();
    let mut cmd = wheels(0.0, 0.0);
    cmd.rab_len = 2;
    cmd.rab_payload[..2].copy_from_slice(&[4, 2]);
    drive(&mut world, 1, cmd);
    let f = frames(&mut world);
    let got = f[0].rab_messages();
    assert_eq!(got.len(), 1);
    assert!((got[0].range_cm - 100.0).abs() < 0.1, "{}", got[0].range_cm);
    assert!((got[0].bearing - std::f32::consts::FRAC_PI_2).abs() < 1e-3);
}

#[test]
fn a_wider_camera_aperture_sees_farther() {
    // An LED ring 1 m away: beyond the default 70-degree cone (0.56 m), inside an 80-degree one (1.16 m).
    let seen = |aperture_deg: Option<f32>| {
        let mut b = builder();
        footbot_at(&mut b, Vec2::ZERO, 0.0);
        footbot_at(&mut b, Vec2::new(1.0, 0.0), 0.0);
        if let Some(a) = aperture_deg {
            b.camera_aperture(swarm_world::entities::RobotId(0), a.to_radians());
        }
        let mut world = b.build();
        let mut lit = wheels(0.0, 0.0);
        lit.led = Rgb { r: 0, g: 0, b: 255 };
        drive(&mut world, 1, lit);
        frames(&mut world)[0].camera_blobs().len()
    };
    assert_eq!(seen(None), 0);
    assert_eq!(seen(Some(80.0)), 1);
}
