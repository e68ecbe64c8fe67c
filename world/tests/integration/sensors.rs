//! Sensor models against analytic geometry, with the numbers of docs/epuck-and-world.md section 1.

use crate::common::{builder, frames, wall};
use swarm_contract::bodies::EPUCK;
use swarm_contract::messages::Rgb;
use swarm_world::devices::{Devices, ProximityOptions};
use swarm_world::entities::{FloorRegion, Light, ROBOT_RADIUS};
use swarm_world::geometry::{Placed, Shape, Vec2};
use swarm_world::physics::Motion;
use swarm_world::sensors::light::intensity_at;
use swarm_world::sensors::proximity::iridia_curve;

const RED: Rgb = Rgb { r: 255, g: 0, b: 0 };
const GREEN: Rgb = Rgb { r: 0, g: 255, b: 0 };

/// Distance along a ray leaving the body edge at `angle_deg` to a wall whose face is `d` ahead of the edge.
fn ray_distance_to_face(d: f32, angle_deg: f32) -> f32 {
    let c = angle_deg.to_radians().cos();
    (ROBOT_RADIUS + d - ROBOT_RADIUS * c) / c
}

#[test]
fn iridia_curve_matches_the_calibration_polynomial() {
    assert!(
        (iridia_curve(0.0) - 1.0).abs() < 1e-6,
        "1.08212 clamps to 1 at contact"
    );
    assert!((iridia_curve(0.02) - (298.701 * 0.0004 - 36.8961 * 0.02 + 1.08212)).abs() < 1e-6);
    assert!(
        (iridia_curve(0.04) - 0.0842).abs() < 1e-3,
        "about 0.084 at 4 cm (theta_obs 0.1 is just under 4 cm)"
    );
    assert_eq!(iridia_curve(0.0501), 0.0);
}

#[test]
fn wall_straight_ahead_gives_the_iridia_value_at_front_sensors_0_and_7() {
    let d = 0.02;
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    wall(
        &mut b,
        Vec2::new(ROBOT_RADIUS + d + 0.05, 0.0),
        Vec2::new(0.1, 1.0),
    );
    let mut world = b.build();
    let p = frames(&mut world)[0].proximity;
    let expected = iridia_curve(ray_distance_to_face(d, 17.0));
    assert!(
        (p[0] - expected).abs() < 1e-5,
        "sensor 0: {} vs {expected}",
        p[0]
    );
    assert!(
        (p[7] - expected).abs() < 1e-5,
        "sensor 7: {} vs {expected}",
        p[7]
    );
    assert!(
        (p[0] - p[7]).abs() < 1e-6,
        "the physical layout is symmetric"
    );
    assert!(
        p[2..6].iter().all(|&v| v == 0.0),
        "side and rear sensors see nothing: {p:?}"
    );
}

#[test]
fn argos_uniform_ring_casts_sensor_0_at_11_25_degrees() {
    let d = 0.02;
    let mut b = builder();
    let ring = Devices {
        proximity: Some(ProximityOptions {
            noise_level: 0.0,
            noise_std_dev: 0.0,
            argos_uniform_ring: true,
        }),
        ..Devices::ALL
    };
    b.robot("r", "c", Vec2::ZERO, 0.0, ring);
    wall(
        &mut b,
        Vec2::new(ROBOT_RADIUS + d + 0.05, 0.0),
        Vec2::new(0.1, 1.0),
    );
    let mut world = b.build();
    let p = frames(&mut world)[0].proximity;
    assert!((p[0] - iridia_curve(ray_distance_to_face(d, 11.25))).abs() < 1e-5);
    // Sensor 7 sits at 326.25 deg (-33.75 deg): the ARGoS ring is not symmetric about the heading.
    assert!((p[7] - iridia_curve(ray_distance_to_face(d, 33.75))).abs() < 1e-5);
    assert!(p[7] < p[0]);
}

#[test]
fn proximity_reads_zero_beyond_five_centimetres_from_the_edge() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    wall(
        &mut b,
        Vec2::new(ROBOT_RADIUS + 0.06 + 0.05, 0.0),
        Vec2::new(0.1, 1.0),
    );
    let mut world = b.build();
    assert_eq!(frames(&mut world)[0].proximity_readings(), [0.0; 8]);
}

#[test]
fn proximity_sees_other_robots_at_the_physical_90_degree_sensor() {
    let mut b = builder();
    b.robot("a", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.robot(
        "b",
        "c",
        Vec2::new(0.0, 2.0 * ROBOT_RADIUS + 0.01),
        0.0,
        Devices::ALL,
    );
    let mut world = b.build();
    let f = frames(&mut world);
    assert!(
        (f[0].proximity[2] - iridia_curve(0.01)).abs() < 1e-5,
        "sensor 2 at +90 deg: {:?}",
        f[0].proximity
    );
    assert!(
        (f[1].proximity[5] - iridia_curve(0.01)).abs() < 1e-5,
        "sensor 5 at 270 deg: {:?}",
        f[1].proximity
    );
}

#[test]
fn proximity_uniform_noise_stays_within_noise_level() {
    let mut b = builder();
    let noisy = Devices {
        proximity: Some(ProximityOptions {
            noise_level: 0.05,
            noise_std_dev: 0.0,
            argos_uniform_ring: false,
        }),
        ..Devices::ALL
    };
    b.robot("r", "c", Vec2::ZERO, 0.0, noisy);
    wall(
        &mut b,
        Vec2::new(ROBOT_RADIUS + 0.02 + 0.05, 0.0),
        Vec2::new(0.1, 1.0),
    );
    let mut world = b.build();
    let clean = iridia_curve(ray_distance_to_face(0.02, 17.0));
    let mut differs = false;
    for _ in 0..50 {
        let p = frames(&mut world)[0].proximity;
        assert!((p[0] - clean).abs() <= 0.05 + 1e-6);
        assert!(p.iter().all(|v| (0.0..=1.0).contains(v)));
        differs |= p[0] != clean;
    }
    assert!(differs, "noise was applied");
}

fn light_world(light_height: f32, blocker: bool) -> swarm_world::World {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.light(Light {
        name: "l".into(),
        position: Vec2::new(1.0, 0.0),
        height: light_height,
        intensity: 3.0,
        color: RED,
    });
    if blocker {
        wall(&mut b, Vec2::new(0.5, 0.0), Vec2::new(0.1, 0.1));
    }
    b.build()
}

#[test]
fn light_reading_is_the_iridia_exponential_weighted_by_sensor_angle() {
    let mut world = light_world(0.5, false);
    let l = frames(&mut world)[0].light;
    let d = (1.0f32 + (0.5 - EPUCK.light_height).powi(2)).sqrt();
    let base = (-2.0 * d / 3.0).exp();
    assert!((intensity_at(d, 3.0) - base).abs() < 1e-7);
    let want0 = base * (1.0 - 2.0 * 17f32.to_radians() / std::f32::consts::PI);
    let want1 = base * (1.0 - 2.0 * 50f32.to_radians() / std::f32::consts::PI);
    assert!((l[0] - want0).abs() < 1e-5, "sensor 0: {} vs {want0}", l[0]);
    assert!((l[7] - want0).abs() < 1e-5);
    assert!((l[1] - want1).abs() < 1e-5);
    assert_eq!(l[2], 0.0, "90 deg from the light: weight 0");
    assert_eq!(l[4], 0.0, "behind: nothing");
}

#[test]
fn light_behind_a_taller_box_is_occluded() {
    let mut world = light_world(0.2, true);
    assert_eq!(frames(&mut world)[0].light_readings(), [0.0; 8]);
}

#[test]
fn light_high_above_a_box_is_not_occluded() {
    // The sight line to a light 3 m up crosses x = 0.45 at about 1.3 m, well over the 0.4 m box.
    let mut world = light_world(3.0, true);
    assert!(frames(&mut world)[0].light[0] > 0.0);
}

#[test]
fn light_farther_than_2_5_intensities_reads_zero() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.light(Light {
        name: "l".into(),
        position: Vec2::new(1.0, 0.0),
        height: 0.2,
        intensity: 0.3,
        color: RED,
    });
    let mut world = b.build();
    assert_eq!(frames(&mut world)[0].light_readings(), [0.0; 8]);
}

#[test]
fn ground_sensors_read_the_region_under_each_sensor_left_first() {
    let mut b = builder();
    b.robot("r", "c", Vec2::ZERO, 0.0, Devices::ALL);
    // Black floor for y > 0.005: only the left sensor at (0.03, 0.009) is over it.
    b.floor_region(FloorRegion {
        min: Vec2::new(-2.0, 0.005),
        max: Vec2::new(2.0, 2.0),
        grey: 0.0,
    });
    let mut world = b.build();
    assert_eq!(frames(&mut world)[0].ground_readings(), [0.0, 1.0, 1.0]);
}

#[test]
fn ground_sensors_turn_with_the_robot() {
    let mut b = builder();
    // Facing -X, the sensors are at x = -0.03; the grey region covers x < -0.02 only.
    b.robot("r", "c", Vec2::ZERO, std::f32::consts::PI, Devices::ALL);
    b.floor_region(FloorRegion {
        min: Vec2::new(-2.0, -2.0),
        max: Vec2::new(-0.02, 2.0),
        grey: 0.5,
    });
    let mut world = b.build();
    assert_eq!(frames(&mut world)[0].ground_readings(), [0.5, 0.5, 0.5]);
}

fn food(b: &mut swarm_world::WorldBuilder, at: Vec2) {
    b.target(
        "food",
        Placed::new(Shape::Disc { radius: 0.02 }, at, 0.0),
        0.05,
        RED,
        0.06,
    );
}

#[test]
fn camera_sees_leds_within_35_cm_nearest_first_and_not_its_own() {
    let mut b = builder();
    let me = b.robot("me", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.robot("other", "c", Vec2::new(0.0, 0.2), 0.0, Devices::ALL);
    food(&mut b, Vec2::new(0.3, 0.0));
    food(&mut b, Vec2::new(0.4, 0.0));
    let mut world = b.build();
    let mut cmds = vec![swarm_contract::messages::ActuatorCommand::idle(0, 1); 2];
    cmds[0].led = Rgb { r: 0, g: 0, b: 255 };
    cmds[1].led = GREEN;
    cmds[1].robot = 1;
    world.act_and_step(&cmds, &[true, true]);
    let f = frames(&mut world);
    let blobs = f[me.index()].camera_blobs();
    assert_eq!(blobs.len(), 2, "{blobs:?}");
    assert_eq!(blobs[0].color, GREEN);
    assert!((blobs[0].distance_cm - 20.0).abs() < 1e-3);
    assert!((blobs[0].bearing - std::f32::consts::FRAC_PI_2).abs() < 1e-4);
    assert_eq!(blobs[1].color, RED);
    assert!((blobs[1].distance_cm - 30.0).abs() < 1e-3);
    assert!(blobs[1].bearing.abs() < 1e-5);
}

#[test]
fn camera_does_not_see_an_led_hidden_behind_a_box() {
    let mut b = builder();
    b.robot("me", "c", Vec2::ZERO, 0.0, Devices::ALL);
    food(&mut b, Vec2::new(0.3, 0.0));
    wall(&mut b, Vec2::new(0.15, 0.0), Vec2::new(0.05, 0.05));
    let mut world = b.build();
    assert_eq!(frames(&mut world)[0].camera_len, 0);
}

#[test]
fn rab_reports_range_minus_two_radii_and_bearing_in_the_receiver_frame() {
    let mut b = builder();
    b.robot("a", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.robot(
        "b",
        "c",
        Vec2::new(0.5, 0.0),
        std::f32::consts::FRAC_PI_2,
        Devices::ALL,
    );
    b.robot("far", "c", Vec2::new(-0.9, 0.0), 0.0, Devices::ALL);
    let mut world = b.build();
    let mut cmds = vec![swarm_contract::messages::ActuatorCommand::idle(0, 1); 3];
    cmds[0].rab_len = 2;
    cmds[0].rab_payload[..2].copy_from_slice(&[7, 9]);
    world.act_and_step(&cmds, &[true, true, true]);
    let f = frames(&mut world);
    let got = f[1].rab_messages();
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].sender, 0);
    assert_eq!(&got[0].payload[..usize::from(got[0].len)], &[7, 9]);
    assert!(
        (got[0].range_cm - (50.0 - 7.0)).abs() < 1e-3,
        "{}",
        got[0].range_cm
    );
    // Robot b faces +Y, so robot a (along -X from b) is on its left: bearing +pi/2.
    assert!(
        (got[0].bearing - std::f32::consts::FRAC_PI_2).abs() < 1e-4,
        "{}",
        got[0].bearing
    );
    assert_eq!(f[2].rab_len, 0, "0.9 m is beyond the default 0.8 m range");
    assert_eq!(f[0].rab_len, 0, "a robot does not hear itself");
}

#[test]
fn rab_message_through_a_wall_is_lost() {
    let mut b = builder();
    b.robot("a", "c", Vec2::ZERO, 0.0, Devices::ALL);
    b.robot("b", "c", Vec2::new(0.5, 0.0), 0.0, Devices::ALL);
    b.obstacle(
        "w",
        Placed::new(
            Shape::Rect {
                half: Vec2::new(0.05, 0.5),
            },
            Vec2::new(0.25, 0.0),
            0.0,
        ),
        0.5,
        Motion::Fixed,
    );
    let mut world = b.build();
    let mut cmds = vec![swarm_contract::messages::ActuatorCommand::idle(0, 1); 2];
    cmds[0].rab_len = 1;
    world.act_and_step(&cmds, &[true, true]);
    assert_eq!(frames(&mut world)[1].rab_len, 0);
}

#[test]
fn pheromone_deposit_is_sensed_with_its_gradient_in_the_robot_frame() {
    let mut b = builder();
    b.robot(
        "r",
        "c",
        Vec2::ZERO,
        std::f32::consts::FRAC_PI_2,
        Devices::ALL,
    );
    b.pheromone(
        swarm_world::world::DEFAULT_PHEROMONE_CELL,
        [swarm_world::media::pheromone::ChannelRates::STILL;
            swarm_contract::messages::PHEROMONE_CHANNELS],
    );
    let mut world = b.build();
    let mut cmd = swarm_contract::messages::ActuatorCommand::idle(0, 1);
    cmd.pheromone_deposit = [1.0, 0.0];
    world.act_and_step(&[cmd], &[true]);
    let f = frames(&mut world);
    assert_eq!(f[0].pheromone, [1.0, 0.0]);
    // Facing +Y, the robot's left is arena -X. Four units one 5 cm cell to the left give an arena gradient of
    // (0 - 4) / 0.1 = -40 along X, that is +40 along the robot's left (y) axis and 0 ahead.
    world.arena.pheromone.deposit(0, Vec2::new(-0.05, 0.0), 4.0);
    let g = frames(&mut world)[0].pheromone_gradient[0];
    assert!(g[0].abs() < 1e-3 && (g[1] - 40.0).abs() < 1e-3, "{g:?}");
}

#[test]
fn rab_loss_probability_one_drops_every_message_and_zero_drops_none() {
    use swarm_world::devices::RabOptions;
    let run = |loss: f32| {
        let mut b = builder();
        let lossy = Devices {
            rab: Some(RabOptions {
                data_size: 2,
                loss_probability: loss,
            }),
            ..Devices::ALL
        };
        b.robot("a", "c", Vec2::ZERO, 0.0, Devices::ALL);
        b.robot("b", "c", Vec2::new(0.3, 0.0), 0.0, lossy);
        let mut world = b.build();
        let mut cmds = vec![swarm_contract::messages::ActuatorCommand::idle(0, 1); 2];
        cmds[0].rab_len = 1;
        let mut received = 0;
        for _ in 0..50 {
            world.act_and_step(&cmds, &[true, true]);
            received += usize::from(frames(&mut world)[1].rab_len);
        }
        received
    };
    assert_eq!(run(1.0), 0);
    assert_eq!(run(0.0), 50);
    let half = run(0.5);
    assert!((10..=40).contains(&half), "about half of 50 arrive: {half}");
}
