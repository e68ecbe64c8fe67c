//! The thesis' example experiment (docs/epuck-and-world.md 5) built as a typed model, plus builders for variants.

use std::path::PathBuf;

use swarm_contract::config::*;

/// A location on `line` (column 5), so items sort in file order.
pub fn at(line: u32) -> Location {
    Location { line, column: 5 }
}

fn device(name: &str, kind: DeviceKind, role: DeviceRole, line: u32) -> Device {
    Device {
        name: name.into(),
        kind,
        role,
        implementation: "default".into(),
        noise_level: 0.0,
        noise_std_dev: 0.0,
        medium: None,
        body: None,
        attributes: Element {
            name: name.into(),
            location: at(line),
            ..Element::default()
        },
        location: at(line),
    }
}

fn wall(id: &str, size: Vec3, x: f64, y: f64, line: u32) -> PlacedEntity {
    PlacedEntity {
        pose: Pose {
            position: Vec3::new(x, y, 0.0),
            orientation: Euler::default(),
        },
        entity: Entity::Box(BoxEntity {
            id: id.into(),
            size,
            movable: false,
            mass: None,
            lift_by: None,
            leds: None,
            location: at(line),
        }),
    }
}

/// A `<distribute>` of `quantity` copies of `template`, uniform over `min..max` with uniform heading.
pub fn uniform(
    template: Entity,
    quantity: u32,
    min: (f64, f64),
    max: (f64, f64),
    line: u32,
) -> Distribute {
    Distribute {
        position: PositionMethod::Uniform {
            min: Vec3::new(min.0, min.1, 0.0),
            max: Vec3::new(max.0, max.1, 0.0),
        },
        orientation: OrientationMethod::Uniform {
            min: Euler::default(),
            max: Euler {
                z_deg: 360.0,
                y_deg: 0.0,
                x_deg: 0.0,
            },
        },
        quantity,
        max_trials: 100,
        base_num: 0,
        template,
        location: at(line),
        position_location: at(line + 1),
        orientation_location: at(line + 2),
        entity_location: at(line + 3),
    }
}

/// The e-puck template `<e-puck id="fb"><controller config="fdc"/></e-puck>`.
pub fn epuck(id: &str, line: u32) -> Entity {
    Entity::Robot(RobotEntity {
        kind: swarm_contract::bodies::RobotKind::EPuck,
        id: id.into(),
        controller: "fdc".into(),
        rab_range: None,
        rab_data_size: None,
        camera_aperture_deg: None,
        range_finder_range: None,
        shape: DiscShape::default(),
        arrival: Default::default(),
        location: at(line),
    })
}

/// The thesis' example: 3 x 3 m arena with walls, 40 e-pucks in the central 2 x 2 m, 10 boxes and 10 cylinders
/// anywhere, 20 ticks/s, proximity sensors and wheels only.
pub fn thesis_example() -> Experiment {
    let boxes = Entity::Box(BoxEntity {
        id: "b".into(),
        size: Vec3::new(0.1, 0.1, 0.4),
        movable: false,
        mass: None,
        lift_by: None,
        leds: None,
        location: at(48),
    });
    let cylinders = Entity::Cylinder(CylinderEntity {
        id: "c".into(),
        radius: 0.1,
        height: 0.4,
        movable: false,
        mass: None,
        lift_by: None,
        leds: None,
        location: at(58),
    });
    let mut cyl = uniform(cylinders, 10, (-1.5, -1.5), (1.5, 1.5), 54);
    cyl.orientation = OrientationMethod::Constant {
        values: Euler::default(),
    };
    Experiment {
        path: PathBuf::from("configs/obstacle_avoidance/thesis_example.argos"),
        framework: Framework {
            threads: 0,
            pin_agents: true,
            realtime_priority: true,
            limits: Default::default(),
            hosts: None,
            length_seconds: 0.0,
            ticks_per_second: 20,
            random_seed: Some(124),
            location: at(5),
        },
        controllers: vec![Controller {
            tag: "epuck_obstacle_avoidance_sct_prob_controller".into(),
            id: "fdc".into(),
            library: "build/controllers/libepuck_obstacleavoidance_sct.so".into(),
            actuators: vec![device(
                "epuck_wheels",
                DeviceKind::Wheels,
                DeviceRole::Actuator,
                13,
            )],
            sensors: vec![device(
                "epuck_proximity",
                DeviceKind::Proximity,
                DeviceRole::Sensor,
                16,
            )],
            params: Element::default(),
            location: at(10),
        }],
        loop_functions: None,
        arena: Arena {
            size: Vec3::new(3.0, 3.0, 1.0),
            center: Vec3::new(0.0, 0.0, 0.5),
            floor: None,
            entities: vec![
                wall("wall_north", Vec3::new(3.0, 0.1, 0.5), 0.0, 1.5, 24),
                wall("wall_south", Vec3::new(3.0, 0.1, 0.5), 0.0, -1.5, 25),
                wall("wall_east", Vec3::new(0.1, 3.0, 0.5), 1.5, 0.0, 26),
                wall("wall_west", Vec3::new(0.1, 3.0, 0.5), -1.5, 0.0, 27),
            ],
            distributions: vec![
                uniform(epuck("fb", 34), 40, (-1.0, -1.0), (1.0, 1.0), 29),
                uniform(boxes, 10, (-1.5, -1.5), (1.5, 1.5), 44),
                cyl,
            ],
            location: at(22),
        },
        physics_engine: PhysicsEngine {
            id: "dyn2d".into(),
            iterations: 10,
            location: at(66),
        },
        media: Media::default(),
        coordinators: Vec::new(),
        faults: Default::default(),
    }
}
