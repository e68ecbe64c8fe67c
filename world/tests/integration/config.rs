//! Building worlds from configurations: the thesis example, `<distribute>` semantics and located errors.

use crate::common::config::{at, epuck, thesis_example, uniform};
use swarm_contract::config::{Element, Entity, LightEntity, LoopFunctions, PositionMethod, Vec3};
use swarm_contract::messages::Rgb;
use swarm_world::entities::ROBOT_RADIUS;
use swarm_world::geometry::{Placed, Shape};
use swarm_world::{World, WorldError};

#[test]
fn thesis_example_places_40_robots_10_boxes_and_10_cylinders_without_overlap() {
    let exp = thesis_example();
    let world = World::new(&exp, 124).expect("the thesis example builds");
    let arena = &world.arena;
    assert_eq!(arena.robots.len(), 40);
    assert_eq!(arena.obstacles.len(), 4 + 10 + 10);
    let names: Vec<&str> = arena.robots.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names[0], "fb0");
    assert_eq!(names[39], "fb39");
    assert_eq!(arena.obstacles[4].name, "b0");
    assert_eq!(arena.obstacles[23].name, "c9");
    let mut bodies: Vec<(String, Placed)> = arena
        .robots
        .iter()
        .map(|r| {
            (
                r.name.clone(),
                Placed::new(
                    Shape::Disc {
                        radius: ROBOT_RADIUS,
                    },
                    r.position,
                    r.heading,
                ),
            )
        })
        .collect();
    bodies.extend(arena.obstacles.iter().map(|o| (o.name.clone(), o.placed)));
    for (i, (a, pa)) in bodies.iter().enumerate() {
        for (b, pb) in &bodies[i + 1..] {
            let both_walls = a.starts_with("wall") && b.starts_with("wall");
            assert!(both_walls || !pa.overlaps(pb), "{a} overlaps {b}");
        }
    }
    for r in &arena.robots {
        assert!(
            r.position.x.abs() <= 1.0 && r.position.y.abs() <= 1.0,
            "robots stay in the central 2 x 2 m"
        );
    }
}

#[test]
fn crowded_distribute_fails_with_the_location_and_the_number_placed() {
    let mut exp = thesis_example();
    exp.arena.distributions[0] = uniform(epuck("fb", 34), 200, (-0.2, -0.2), (0.2, 0.2), 29);
    exp.arena.distributions[0].max_trials = 5;
    let err = World::new(&exp, 124)
        .err()
        .expect("200 robots cannot fit in 0.4 x 0.4 m");
    let WorldError::Placement {
        placed, quantity, ..
    } = &err
    else {
        panic!("unexpected error {err}")
    };
    assert_eq!(*quantity, 200);
    assert!(*placed > 0 && *placed < 200);
    let text = err.to_string();
    assert!(
        text.starts_with(
            "configs/obstacle_avoidance/thesis_example.argos:29:5: <distribute> placed only"
        ),
        "{text}"
    );
    assert!(
        text.contains(&format!("placed only {placed} of 200 'fb'")),
        "{text}"
    );
}

#[test]
fn distributed_ids_are_base_id_then_index_from_base_num() {
    let mut exp = thesis_example();
    exp.arena.distributions[0].base_num = 5;
    exp.arena.distributions[0].quantity = 3;
    let world = World::new(&exp, 1).expect("builds");
    let names: Vec<&str> = world.arena.robots.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["fb5", "fb6", "fb7"]);
}

#[test]
fn grid_distribute_fills_the_lattice_x_first_around_its_centre() {
    let mut exp = thesis_example();
    exp.arena.distributions.truncate(1);
    let d = &mut exp.arena.distributions[0];
    d.quantity = 5;
    d.position = PositionMethod::Grid {
        center: Vec3::new(0.0, 0.0, 0.0),
        distances: Vec3::new(0.2, 0.3, 0.0),
        layout: [3, 2, 1],
    };
    let world = World::new(&exp, 1).expect("builds");
    let got: Vec<(f32, f32)> = world
        .arena
        .robots
        .iter()
        .map(|r| (r.position.x, r.position.y))
        .collect();
    let want = [
        (-0.2, -0.15),
        (0.0, -0.15),
        (0.2, -0.15),
        (-0.2, 0.15),
        (0.0, 0.15),
    ];
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.0 - w.0).abs() < 1e-6 && (g.1 - w.1).abs() < 1e-6,
            "{got:?}"
        );
    }
    exp.arena.distributions[0].quantity = 7;
    let err = World::new(&exp, 1)
        .err()
        .expect("7 do not fit a 3 x 2 lattice");
    assert!(
        matches!(
            err,
            WorldError::GridTooSmall {
                room: 6,
                quantity: 7,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn grid_distribute_onto_an_occupied_point_fails_with_the_location() {
    let mut exp = thesis_example();
    exp.arena.distributions.truncate(1);
    let d = &mut exp.arena.distributions[0];
    d.quantity = 2;
    // Spacing of 5 cm is less than an e-puck's diameter.
    d.position = PositionMethod::Grid {
        center: Vec3::new(0.0, 0.0, 0.0),
        distances: Vec3::new(0.05, 0.05, 0.0),
        layout: [2, 1, 1],
    };
    let err = World::new(&exp, 1)
        .err()
        .expect("robots 5 cm apart overlap");
    assert!(
        err.to_string()
            .starts_with("configs/obstacle_avoidance/thesis_example.argos:29:5: grid position"),
        "{err}"
    );
}

#[test]
fn bodiless_lights_are_never_collision_checked() {
    let mut exp = thesis_example();
    let light = Entity::Light(LightEntity {
        id: "l".into(),
        color: Rgb {
            r: 255,
            g: 255,
            b: 0,
        },
        intensity: 3.0,
        medium: "leds".into(),
        location: at(70),
    });
    let mut d = uniform(light, 5, (0.0, 0.0), (0.0, 0.0), 69);
    d.max_trials = 0;
    exp.arena.distributions.push(d);
    let world = World::new(&exp, 1).expect("five lights on one point are fine");
    assert_eq!(world.arena.lights.len(), 5);
    assert_eq!(world.arena.lights[4].name, "l4");
}

#[test]
fn unknown_loop_functions_label_is_a_located_error_listing_the_known_ones() {
    let mut exp = thesis_example();
    exp.loop_functions = Some(LoopFunctions {
        label: "forage_lf".into(),
        library: String::new(),
        params: Element::default(),
        location: at(20),
    });
    let err = World::new(&exp, 1).err().expect("unknown label");
    let text = err.to_string();
    assert!(text.starts_with("configs/obstacle_avoidance/thesis_example.argos:20:5: unknown loop functions 'forage_lf'"), "{text}");
    assert!(text.contains("obstacle_avoidance_loop_functions"), "{text}");
}

#[test]
fn controller_devices_and_noise_come_from_the_configuration() {
    let mut exp = thesis_example();
    exp.controllers[0].sensors[0].noise_level = 0.02;
    exp.controllers[0].actuators[0].noise_std_dev = 0.1;
    let world = World::new(&exp, 1).expect("builds");
    let d = world.arena.robots[0].devices;
    assert_eq!(d.proximity.map(|p| p.noise_level), Some(0.02));
    assert_eq!(d.wheel_noise_std_dev, 0.1);
    assert_eq!(
        d.light, None,
        "the thesis example declares no light sensors"
    );
    assert_eq!(d.camera, None);
}

#[test]
fn a_pheromone_grid_too_large_for_memory_is_a_located_error_and_no_grid_without_pheromones() {
    let mut exp = thesis_example();
    exp.arena.size = Vec3::new(9000.0, 9000.0, 1.0);
    let world = World::new(&exp, 1).expect("a huge arena without pheromones costs no grid");
    assert_eq!(world.arena.pheromone.dimensions().0, 1);
    exp.media.pheromone = Some(swarm_contract::config::PheromoneField {
        id: "pheromones".into(),
        cell_size: 0.05,
        channels: Vec::new(),
        location: at(30),
    });
    let err = World::new(&exp, 1).err().expect("a grid of 3.2e10 cells");
    let text = err.to_string();
    assert!(
        text.starts_with(
            "configs/obstacle_avoidance/thesis_example.argos:30:5: the pheromone grid would have"
        ),
        "{text}"
    );
}
