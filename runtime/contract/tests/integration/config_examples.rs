//! The shipped configurations and the good fixtures load with the values the references give.

use std::path::{Path, PathBuf};

use swarm_contract::config::{
    DeviceKind, Diagnostic, Entity, Euler, Experiment, FloorSource, OrientationMethod,
    PositionMethod, Vec2, Vec3,
};
use swarm_contract::messages::Rgb;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

fn load(path: &str) -> (Experiment, Vec<Diagnostic>) {
    match Experiment::load(repo(path)) {
        Ok(loaded) => loaded,
        Err(errors) => panic!("{path} must load, got:\n{errors}"),
    }
}

fn messages(warnings: &[Diagnostic]) -> Vec<String> {
    warnings
        .iter()
        .map(|w| format!("{}: {}", w.location, w.message))
        .collect()
}

#[test]
fn thesis_example_loads_with_section_5_values() {
    let (exp, warnings) = load("configs/obstacle_avoidance/thesis_example.argos");
    assert_eq!(exp.framework.ticks_per_second, 20);
    assert_eq!(exp.framework.random_seed, Some(124));
    assert_eq!(exp.framework.length_seconds, 0.0);
    assert_eq!(exp.framework.max_ticks(), None);
    assert_eq!(exp.framework.threads, 0);

    assert_eq!(exp.controllers.len(), 1);
    let c = &exp.controllers[0];
    assert_eq!(c.tag, "epuck_obstacle_avoidance_sct_prob_controller");
    assert_eq!(c.id, "fdc");
    assert_eq!(
        c.library,
        "build/controllers/libepuck_obstacleavoidance_sct.so"
    );
    assert_eq!(c.actuators.len(), 1);
    assert_eq!(c.actuators[0].kind, DeviceKind::Wheels);
    assert_eq!(c.actuators[0].noise_std_dev, 0.0);
    assert_eq!(c.sensors.len(), 1);
    assert_eq!(c.sensors[0].kind, DeviceKind::Proximity);
    assert_eq!(c.sensors[0].name, "epuck_proximity");
    assert_eq!(c.params.get("velocity"), Some("12.8"));
    assert_eq!(
        c.profile(),
        None,
        "the thesis names no profile: the agent maps the controller tag"
    );
    assert!(c.supervisors().is_empty());
    assert_eq!(c.params.parse::<f64>("velocity"), Ok(Some(12.8)));

    assert_eq!(exp.arena.size, Vec3::new(3.0, 3.0, 1.0));
    assert_eq!(exp.arena.center, Vec3::new(0.0, 0.0, 0.5));
    assert_eq!(exp.arena.entities.len(), 4, "four walls");
    let north = &exp.arena.entities[0];
    assert_eq!(north.entity.id(), "wall_north");
    assert_eq!(north.pose.position, Vec3::new(0.0, 1.5, 0.0));
    match &north.entity {
        Entity::Box(b) => {
            assert_eq!(b.size, Vec3::new(3.0, 0.1, 0.5));
            assert!(!b.movable);
        }
        other => panic!("wall_north is a box, got {other:?}"),
    }

    let d = &exp.arena.distributions;
    assert_eq!(d.len(), 3);
    assert_eq!((d[0].quantity, d[1].quantity, d[2].quantity), (40, 10, 10));
    assert_eq!(d[0].max_trials, 100);
    assert_eq!(
        d[0].position,
        PositionMethod::Uniform {
            min: Vec3::new(-1.0, -1.0, 0.0),
            max: Vec3::new(1.0, 1.0, 0.0)
        }
    );
    assert_eq!(
        d[0].orientation,
        OrientationMethod::Gaussian {
            mean: Euler::default(),
            std_dev: Euler {
                z_deg: 360.0,
                y_deg: 0.0,
                x_deg: 0.0
            }
        }
    );
    assert_eq!(d[0].entity_id(0), "fb0");
    assert_eq!(d[0].entity_id(39), "fb39");
    match &d[0].template {
        Entity::Robot(e) => assert_eq!(e.controller, "fdc"),
        other => panic!("first distribution places e-pucks, got {other:?}"),
    }
    match &d[2].template {
        Entity::Cylinder(c) => assert_eq!((c.radius, c.height), (0.1, 0.4)),
        other => panic!("third distribution places cylinders, got {other:?}"),
    }
    assert_eq!(
        d[2].orientation,
        OrientationMethod::Constant {
            values: Euler::default()
        }
    );

    assert_eq!(exp.physics_engine.id, "dyn2d");
    assert_eq!(exp.media.leds, None);
    assert!(exp.loop_functions.is_none());
    assert_eq!(
        messages(&warnings),
        [
            "17:51: 'show_rays' is ignored: there is no GUI to draw rays in",
            "69:3: <visualization> is ignored: runs are headless",
        ]
    );
}

#[test]
fn arena_items_come_back_in_file_order() {
    let (exp, _) = load("configs/obstacle_avoidance/thesis_example.argos");
    let lines: Vec<u32> = exp
        .arena
        .items()
        .iter()
        .map(|item| match item {
            swarm_contract::config::ArenaItem::Placed(p) => p.entity.location().line,
            swarm_contract::config::ArenaItem::Distribute(d) => d.location.line,
        })
        .collect();
    assert_eq!(lines, [25, 26, 27, 28, 30, 41, 51]);
}

#[test]
fn robots_are_numbered_in_file_order_with_generated_ids() {
    let (exp, _) = load("configs/obstacle_avoidance/thesis_example.argos");
    let robots = exp.arena.robots();
    assert_eq!(robots.len(), 40);
    assert_eq!((robots[0].index, robots[0].id.as_str()), (0, "fb0"));
    assert_eq!((robots[39].index, robots[39].id.as_str()), (39, "fb39"));
    assert!(robots.iter().all(|r| r.entity.controller == "fdc"));

    let (grid, _) = load("runtime/contract/tests/fixtures/good/grid_and_rab.argos");
    let ids: Vec<String> = grid.arena.robots().into_iter().map(|r| r.id).collect();
    assert_eq!(
        ids.first().map(String::as_str),
        Some("r100"),
        "base_num 100"
    );
    assert_eq!(ids.last().map(String::as_str), Some("r111"));
}

#[test]
fn argos_example_loads_with_core_device_names() {
    let (exp, warnings) = load("configs/argos_examples/epuck_obstacleavoidance.argos");
    assert_eq!(exp.framework.ticks_per_second, 10);
    let c = exp.controller("fdc").expect("controller fdc");
    assert_eq!(c.actuators[0].name, "differential_steering");
    assert_eq!(c.actuators[0].kind, DeviceKind::Wheels);
    assert_eq!(
        c.sensor(DeviceKind::Proximity).map(|d| d.name.as_str()),
        Some("proximity")
    );
    assert_eq!(c.params.parse::<f64>("velocity"), Ok(Some(5.0)));
    assert_eq!(exp.arena.size, Vec3::new(5.0, 5.0, 1.0));
    let quantities: Vec<u32> = exp.arena.distributions.iter().map(|d| d.quantity).collect();
    assert_eq!(quantities, [50, 5, 5]);
    match &exp.arena.distributions[1].template {
        Entity::Box(b) => assert_eq!(b.size, Vec3::new(0.3, 0.3, 0.5)),
        other => panic!("boxes expected, got {other:?}"),
    }
    // The newer camera syntax (<placements>) is accepted like the older one.
    assert!(
        warnings
            .iter()
            .any(|w| w.message == "<visualization> is ignored: runs are headless")
    );
}

#[test]
fn density_configs_keep_argos_density_of_50_robots_per_16_square_metres() {
    for n in [10u32, 100, 1000] {
        let (exp, warnings) = load(&format!("configs/obstacle_avoidance/density_N{n}.argos"));
        assert!(
            warnings.is_empty(),
            "density_N{n}: {:?}",
            messages(&warnings)
        );
        let side = (f64::from(n) * 16.0 / 50.0).sqrt();
        let north = exp
            .arena
            .entities
            .iter()
            .find(|e| e.entity.id() == "wall_north")
            .expect("north wall");
        let inner = north.pose.position.y - 0.05;
        assert!(
            (inner - side / 2.0).abs() < 1e-3,
            "N={n}: inner wall at {inner}, expected {}",
            side / 2.0
        );
        let d = &exp.arena.distributions;
        assert_eq!(
            (d[0].quantity, d[1].quantity, d[2].quantity),
            (n, n / 10, n / 10)
        );
        let c = exp.controller("oa").expect("controller oa");
        assert_eq!(c.params.get("profile"), Some("obstacle_avoidance"));
        assert_eq!(c.params.get("supervisors"), Some("models/ptsct"));
        assert_eq!(
            exp.resolve("models/ptsct"),
            repo("configs/obstacle_avoidance/models/ptsct")
        );
        assert!(
            exp.resolve("models/ptsct").is_dir(),
            "the ptSCT models ship with the configs"
        );
    }
}

#[test]
fn foraging_fixture_reads_every_extension() {
    let (exp, warnings) = load("runtime/contract/tests/fixtures/good/foraging.argos");
    assert!(warnings.is_empty(), "{:?}", messages(&warnings));
    assert_eq!(exp.framework.max_ticks(), Some(144_000));
    let c = exp.controller("fc").expect("controller fc");
    assert_eq!(c.sensors.len(), 6);
    assert_eq!(c.actuators.len(), 4);
    let ground = c.sensor(DeviceKind::Ground).expect("ground sensor");
    assert_eq!(
        (ground.implementation.as_str(), ground.noise_level),
        ("rot_z_only", 0.02)
    );
    let camera = c.sensor(DeviceKind::OmnidirectionalCamera).expect("camera");
    assert_eq!(camera.medium.as_deref(), Some("leds"));
    assert!(c.sensor(DeviceKind::VirtualGripper).is_some());
    assert!(c.actuator(DeviceKind::VirtualGripper).is_some());
    assert_eq!(
        c.actuator(DeviceKind::PheromoneDeposit)
            .and_then(|d| d.attributes.get("channels")),
        Some("food,home")
    );
    assert_eq!(
        c.params.child("thresholds").and_then(|t| t.get("light")),
        Some("0.05")
    );

    let lf = exp.loop_functions.as_ref().expect("loop functions");
    assert_eq!(lf.label, "foraging_loop_functions");
    assert_eq!(
        lf.params
            .child("foraging")
            .and_then(|f| f.get("home_y_max")),
        Some("-2.0")
    );

    let floor = exp.arena.floor.as_ref().expect("floor");
    match &floor.source {
        FloorSource::Regions {
            background,
            regions,
        } => {
            assert_eq!(
                *background,
                Rgb {
                    r: 255,
                    g: 255,
                    b: 255
                }
            );
            assert_eq!(regions.len(), 1);
            assert_eq!(regions[0].min, Vec2 { x: -5.0, y: -5.0 });
            assert_eq!(regions[0].max, Vec2 { x: 5.0, y: -2.0 });
            assert_eq!(regions[0].color, Rgb { r: 0, g: 0, b: 0 });
        }
        other => panic!("regions floor expected, got {other:?}"),
    }
    let lights: Vec<_> = exp
        .arena
        .entities
        .iter()
        .filter(|e| matches!(e.entity, Entity::Light(_)))
        .collect();
    assert_eq!(lights.len(), 4);
    assert_eq!(lights[0].pose.position, Vec3::new(-3.75, -3.5, 1.0));
    match &lights[0].entity {
        Entity::Light(l) => assert_eq!(
            (l.intensity, l.color),
            (
                3.0,
                Rgb {
                    r: 255,
                    g: 255,
                    b: 0
                }
            )
        ),
        other => panic!("light expected, got {other:?}"),
    }
    match &exp.arena.distributions[1].template {
        Entity::Target(t) => {
            assert_eq!((t.radius, t.height, t.led_height), (0.02, 0.05, 0.06));
            assert_eq!(t.color, Rgb { r: 255, g: 0, b: 0 });
        }
        other => panic!("targets expected, got {other:?}"),
    }
    let field = exp.media.pheromone.as_ref().expect("pheromone field");
    assert_eq!(field.cell_size, 0.05);
    assert_eq!(field.channels.len(), 2);
    assert_eq!(
        (field.channels[0].evaporation, field.channels[0].diffusion),
        (0.001, 0.05)
    );
    assert_eq!(field.channels[1].diffusion, 0.0);
}

#[test]
fn grid_fixture_reads_core_names_rab_and_grid() {
    let (exp, warnings) = load("runtime/contract/tests/fixtures/good/grid_and_rab.argos");
    assert_eq!(
        exp.framework.random_seed, None,
        "absent seed is left to the launcher"
    );
    assert_eq!(
        messages(&warnings),
        ["6:5: no random_seed (absent or 0): the launcher draws one from the clock and prints it"]
    );
    let c = exp.controller("rt").expect("controller rt");
    let rab = c
        .actuator(DeviceKind::RangeAndBearing)
        .expect("rab actuator");
    assert_eq!(rab.attributes.parse::<u32>("data_size"), Ok(Some(4)));
    assert_eq!(
        c.sensor(DeviceKind::RangeAndBearing)
            .map(|d| d.implementation.as_str()),
        Some("medium")
    );
    assert!(c.sensor(DeviceKind::Positioning).is_some());
    assert_eq!(exp.physics_engine.iterations, 20);
    assert_eq!(
        exp.media.leds.as_ref().and_then(|m| m.grid_size),
        Some([10, 10, 1])
    );
    assert_eq!(
        exp.media.range_and_bearing.as_ref().map(|m| m.id.as_str()),
        Some("rab")
    );
    match &exp.arena.floor.as_ref().expect("floor").source {
        FloorSource::Image { path } => assert_eq!(path, "floor.png"),
        other => panic!("image floor expected, got {other:?}"),
    }
    let crate_box = &exp.arena.entities[0];
    assert!((crate_box.pose.orientation.yaw_radians() - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
    match &crate_box.entity {
        Entity::Box(b) => assert_eq!((b.movable, b.mass), (true, Some(0.5))),
        other => panic!("box expected, got {other:?}"),
    }
    match &exp.arena.entities[1].entity {
        Entity::Cylinder(c) => {
            let leds = c.leds.as_ref().expect("leds");
            assert_eq!(leds.medium, "leds");
            assert_eq!(leds.leds[0].offset, Vec3::new(0.0, 0.0, 0.06));
            assert_eq!(leds.leds[0].color, Rgb { r: 255, g: 0, b: 0 });
        }
        other => panic!("cylinder expected, got {other:?}"),
    }
    let grid = &exp.arena.distributions[0];
    assert_eq!(
        grid.position,
        PositionMethod::Grid {
            center: Vec3::default(),
            distances: Vec3::new(0.2, 0.2, 0.0),
            layout: [4, 3, 1]
        }
    );
    assert_eq!(grid.entity_id(0), "r100");
    match &grid.template {
        Entity::Robot(e) => assert_eq!((e.rab_range, e.rab_data_size), (Some(1.5), Some(4))),
        other => panic!("e-puck expected, got {other:?}"),
    }
    assert!(matches!(
        exp.arena.distributions[1].template,
        Entity::Light(_)
    ));
}

#[test]
fn tasks_4_15_sketch_loads_unchanged() {
    let (exp, warnings) = load("runtime/contract/tests/fixtures/good/tasks_4_15_sketch.argos");
    assert!(warnings.is_empty(), "{:?}", messages(&warnings));
    assert!(matches!(
        exp.arena.floor.as_ref().map(|f| &f.source),
        Some(FloorSource::LoopFunctions)
    ));
    match &exp.arena.distributions[1].template {
        Entity::Cylinder(food) => {
            let leds = food.leds.as_ref().expect("food carries an LED");
            assert_eq!(leds.leds[0].offset, Vec3::new(0.0, 0.0, 0.06));
            assert_eq!(leds.leds[0].color, Rgb { r: 255, g: 0, b: 0 });
        }
        other => panic!("food cylinders expected, got {other:?}"),
    }
}

#[test]
fn shipped_foraging_config_has_the_section_4_9_world() {
    let (exp, warnings) = load("configs/foraging/foraging.argos");
    assert!(warnings.is_empty(), "{:?}", messages(&warnings));
    assert_eq!(exp.framework.ticks_per_second, 20);
    assert_eq!(
        exp.framework.max_ticks(),
        Some(144_000),
        "2 h cap at 20 ticks/s"
    );
    let c = exp.controller("fc").expect("controller fc");
    assert_eq!(c.profile(), Some("foraging"));
    for kind in [DeviceKind::Proximity, DeviceKind::Light, DeviceKind::Ground] {
        assert_eq!(
            c.sensor(kind).map(|d| d.noise_level),
            Some(0.02),
            "{kind:?}"
        );
    }
    let lights: Vec<Vec3> = exp
        .arena
        .entities
        .iter()
        .filter(|p| matches!(p.entity, Entity::Light(_)))
        .map(|p| p.pose.position)
        .collect();
    assert_eq!(
        lights,
        [-3.75, -1.25, 1.25, 3.75].map(|x| Vec3::new(x, -3.5, 1.0)),
        "four home lights at 1 m"
    );
    match &exp.arena.floor.as_ref().expect("floor").source {
        FloorSource::Regions { regions, .. } => {
            assert_eq!(
                (regions[0].min.y, regions[0].max.y),
                (-5.1, -2.0),
                "home strip up to y = -2"
            );
            assert_eq!(regions[0].color, Rgb { r: 0, g: 0, b: 0 });
        }
        other => panic!("regions floor expected, got {other:?}"),
    }
    let d = &exp.arena.distributions;
    let quantities: Vec<u32> = d.iter().map(|d| d.quantity).collect();
    assert_eq!(
        quantities,
        [40, 40, 5, 5],
        "40 robots, 40 targets, 5 boxes and 5 cylinders"
    );
    assert!(matches!(d[1].template, Entity::Target(_)));
    match &d[0].position {
        PositionMethod::Uniform { max, .. } => assert!(max.y < -2.0, "robots start in home"),
        other => panic!("uniform robots expected, got {other:?}"),
    }
}

#[test]
fn hand_placed_robots_take_their_place_in_file_order() {
    let text = r#"<argos-configuration>
  <framework><experiment ticks_per_second="10" random_seed="3"/></framework>
  <controllers><c id="k"/></controllers>
  <arena size="4,4,1">
    <e-puck id="first"><body position="0,0,0"/><controller config="k"/></e-puck>
    <distribute>
      <position method="uniform" min="-1,-1,0" max="1,1,0"/>
      <orientation method="constant" values="0,0,0"/>
      <entity quantity="2" max_trials="10"><e-puck id="d"><controller config="k"/></e-puck></entity>
    </distribute>
    <e-puck id="last"><body position="1,1,0"/><controller config="k"/></e-puck>
  </arena>
  <physics_engines><dynamics2d id="p"/></physics_engines>
</argos-configuration>"#;
    let (exp, _) = Experiment::parse("mixed.argos", text).expect("valid");
    let robots: Vec<(u32, String)> = exp
        .arena
        .robots()
        .into_iter()
        .map(|r| (r.index, r.id))
        .collect();
    assert_eq!(
        robots,
        [
            (0, "first".to_string()),
            (1, "d0".to_string()),
            (2, "d1".to_string()),
            (3, "last".to_string())
        ]
    );
}

#[test]
fn agents_are_pinned_and_real_time_unless_the_system_element_says_false() {
    let with_system = |system: &str| {
        let text = format!(
            r#"<argos-configuration>
  <framework>{system}<experiment ticks_per_second="10" random_seed="3"/></framework>
  <controllers><c id="k"/></controllers>
  <arena size="4,4,1"><e-puck id="e"><body position="0,0,0"/><controller config="k"/></e-puck></arena>
  <physics_engines><dynamics2d id="p"/></physics_engines>
</argos-configuration>"#
        );
        let (exp, _) = Experiment::parse("system.argos", &text).expect("valid");
        (exp.framework.pin_agents, exp.framework.realtime_priority)
    };
    assert_eq!(with_system(""), (true, true));
    assert_eq!(with_system(r#"<system threads="0"/>"#), (true, true));
    assert_eq!(
        with_system(r#"<system pin_threads_to_cores="false"/>"#),
        (false, true)
    );
    assert_eq!(
        with_system(r#"<system realtime_priority="false"/>"#),
        (true, false)
    );
}
