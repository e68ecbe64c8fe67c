//! Robots beyond the e-puck, end to end with real processes: ARGoS' foot-bot example configurations run unchanged
//! from any folder, and the ported foot-bot controllers behave as ARGoS' examples do.

use std::collections::BTreeMap;
use std::path::Path;

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;
use swarm_system_tests::{
    assert_clean, assert_nothing_left, follow_lines, spawn_swarm_in, swarm_in, wait_for_line,
    wipe_runs, workspace_file,
};

fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("a temporary directory")
}

fn summary(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json exists");
    serde_json::from_str(&text).expect("summary.json is JSON")
}

/// Runs an ARGoS example from a folder that is not the workspace, as a user who keeps configs elsewhere does.
fn run_example_elsewhere(example: &str, out: &Path, extra: &[&str]) {
    let config = workspace_file(&format!("configs/argos_examples/{example}"));
    run_in(temp_dir().path(), &config, out, extra);
}

/// Runs `config` to completion into `out` from the folder `cwd`; the run must succeed and leave nothing behind.
fn run_in(cwd: &Path, config: &Path, out: &Path, extra: &[&str]) {
    let config = config.display().to_string();
    let out_arg = out.display().to_string();
    let mut args = vec!["run", &config, "--out", &out_arg, "--no-progress"];
    args.extend_from_slice(extra);
    let outcome = swarm_in(cwd, &args);
    assert!(
        outcome.output.status.success(),
        "swarm run {config} failed:\n{}",
        outcome.stderr()
    );
    assert_clean(&outcome);
}

/// Each robot's positions by tick, from `trajectory.csv`.
fn positions(out: &Path) -> BTreeMap<u32, Vec<(u64, f64, f64)>> {
    let text = swarm_system_tests::run_text(out, "trajectory.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (tick, robot, x, y) = (col("tick"), col("robot"), col("x"), col("y"));
    let mut by_robot: BTreeMap<u32, Vec<(u64, f64, f64)>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        by_robot
            .entry(f[robot].parse().expect("robot"))
            .or_default()
            .push((
                f[tick].parse().expect("tick"),
                f[x].parse().expect("x"),
                f[y].parse().expect("y"),
            ));
    }
    by_robot
}

#[test]
fn argos_footbot_examples_run_unchanged_from_any_folder() {
    for (example, robots) in [
        ("diffusion_1.argos", 1),
        ("diffusion_10.argos", 10),
        ("flocking.argos", 10),
        ("synchronization.argos", 16),
        ("foraging.argos", 20),
        ("gripping.argos", 1),
    ] {
        let out = temp_dir();
        run_example_elsewhere(example, out.path(), &["--ticks", "20"]);
        let summary = summary(out.path());
        assert_eq!(summary["robots"], robots, "{example}");
        assert_eq!(summary["ticks"], 20, "{example}");
    }
}

#[test]
fn footbot_diffusion_keeps_every_robot_moving() {
    let out = temp_dir();
    run_example_elsewhere("diffusion_10.argos", out.path(), &["--ticks", "600"]);
    let by_robot = positions(out.path());
    assert_eq!(by_robot.len(), 10);
    for (robot, track) in &by_robot {
        // Over the second half of the minute: a robot that drove into a wall or another robot and stayed there
        // would cover almost nothing; a diffusing one turns away and keeps going at 5 cm/s.
        let late: f64 = track
            .windows(2)
            .filter(|w| w[0].0 >= 300)
            .map(|w| (w[1].1 - w[0].1).hypot(w[1].2 - w[0].2))
            .sum();
        assert!(
            late > 0.5,
            "foot-bot {robot} covered only {late:.2} m in its last 30 s"
        );
    }
}

#[test]
fn a_footbot_example_without_a_length_runs_until_interrupted() {
    let out = temp_dir();
    let elsewhere = temp_dir();
    let config = workspace_file("configs/argos_examples/diffusion_1.argos");
    let mut child = spawn_swarm_in(
        elsewhere.path(),
        &[
            "run",
            &config.display().to_string(),
            "--no-progress",
            "--out",
            &out.path().display().to_string(),
        ],
    );
    let pid = child.id();
    let prefix = format!("sw{pid:x}-");
    let lines = follow_lines(child.stderr.take());
    let mut seen = Vec::new();
    let ticked = wait_for_line(
        &lines,
        &mut seen,
        "first tick completed",
        std::time::Duration::from_secs(120),
    );
    if !ticked {
        wipe_runs(&prefix);
        let _ = child.kill();
        panic!("the run never ticked:\n{}", seen.join("\n"));
    }
    kill(Pid::from_raw(pid as i32), Signal::SIGINT).expect("interrupt the launcher");
    let status = child.wait().expect("the launcher exits");
    let rest: Vec<String> = lines.iter().collect();
    assert_eq!(
        status.code(),
        Some(130),
        "an interrupted run exits 130:\n{}\n{}",
        seen.join("\n"),
        rest.join("\n")
    );
    assert!(
        seen.iter().any(|l| l.contains("it runs until Ctrl-C")),
        "a length of 0 runs until interrupted, and says so:\n{}",
        seen.join("\n")
    );
    assert_eq!(summary(out.path())["interrupted"], true);
    assert_nothing_left(pid);
}

/// Runs `config` (a workspace path) to completion into `out` from the workspace root.
fn run_config(config: &Path, out: &Path, extra: &[&str]) {
    run_in(&swarm_system_tests::workspace_root(), config, out, extra);
}

#[test]
fn disc_robots_follow_velocity_commands_within_their_limits() {
    // The example asks for 1 m/s and 10 rad/s: far beyond both bodies' limits.
    let text = std::fs::read_to_string(workspace_file("configs/robots/disc_wander.argos"))
        .expect("the disc robot example");
    let original = r#"<params speed="0.2" turn_rate="1.5""#;
    assert!(text.contains(original), "the example's params changed");
    let dir = temp_dir();
    let config = dir.path().join("fast.argos");
    std::fs::write(
        &config,
        text.replace(original, r#"<params speed="1.0" turn_rate="10""#),
    )
    .expect("write the variant");
    let out = temp_dir();
    run_config(&config, out.path(), &["--ticks", "300"]);
    let by_robot = positions(out.path());
    assert_eq!(by_robot.len(), 8);
    for (robot, track) in &by_robot {
        // Robots 0-5 are scouts (0.22 m/s), 6-7 haulers (0.1 m/s); 10 ticks per second.
        let limit = if *robot < 6 { 0.22 } else { 0.1 };
        let speeds: Vec<f64> = track
            .windows(2)
            .map(|w| (w[1].1 - w[0].1).hypot(w[1].2 - w[0].2) * 10.0)
            .collect();
        let top = speeds.iter().copied().fold(0.0, f64::max);
        // Contacts can push a robot a little faster than it drives; never anywhere near the 1 m/s asked for.
        assert!(
            top <= limit * 1.1,
            "robot {robot} reached {top:.3} m/s, its limit is {limit}"
        );
        assert!(
            top >= limit * 0.95,
            "robot {robot} never drove at its limit {limit} (top {top:.3} m/s)"
        );
    }
}

#[test]
fn a_mixed_swarm_runs_every_kind_with_its_own_controller() {
    let out = temp_dir();
    run_config(
        &workspace_file("configs/robots/mixed.argos"),
        out.path(),
        &["--ticks", "100"],
    );
    let trajectory = swarm_system_tests::run_text(out.path(), "trajectory.csv");
    for id in ["ep0", "ep5", "fb0", "fb2", "disc0", "disc1"] {
        assert!(
            trajectory.contains(&format!(",{id},")),
            "robot {id} is in the records"
        );
    }
    let by_robot = positions(out.path());
    assert_eq!(by_robot.len(), 11, "6 e-pucks, 3 foot-bots, 2 disc robots");
    for (robot, track) in &by_robot {
        let path: f64 = track
            .windows(2)
            .map(|w| (w[1].1 - w[0].1).hypot(w[1].2 - w[0].2))
            .sum();
        assert!(path > 0.2, "robot {robot} hardly moved ({path:.2} m)");
    }
}

/// The LED ring's red component per robot per tick, from `trajectory.csv`: the ticks at which each robot
/// flashed.
fn flash_ticks(out: &Path) -> BTreeMap<u64, Vec<u32>> {
    let text = swarm_system_tests::run_text(out, "trajectory.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let (tick, robot, red) = (col("tick"), col("robot"), col("led_r"));
    let mut flashes: BTreeMap<u64, Vec<u32>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        if f[red] == "255" {
            flashes
                .entry(f[tick].parse().expect("tick"))
                .or_default()
                .push(f[robot].parse().expect("robot"));
        }
    }
    flashes
}

#[test]
fn footbot_flocking_moves_the_group_towards_the_light_together() {
    let out = temp_dir();
    run_example_elsewhere("flocking.argos", out.path(), &["--ticks", "1200"]);
    let by_robot = positions(out.path());
    assert_eq!(by_robot.len(), 10);
    let light = (8.9, 2.7);
    let at = |tick: u64| -> Vec<(f64, f64)> {
        by_robot
            .values()
            .map(|track| {
                let row = track
                    .iter()
                    .find(|r| r.0 == tick)
                    .expect("every tick is recorded");
                (row.1, row.2)
            })
            .collect()
    };
    let centroid = |p: &[(f64, f64)]| {
        let n = p.len() as f64;
        (
            p.iter().map(|q| q.0).sum::<f64>() / n,
            p.iter().map(|q| q.1).sum::<f64>() / n,
        )
    };
    let (start, end) = (at(0), at(1200));
    let dist = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
    let (c0, c1) = (centroid(&start), centroid(&end));
    assert!(
        dist(c1, light) < dist(c0, light) - 2.0,
        "the group's centre went from {:.2} m to {:.2} m from the light",
        dist(c0, light),
        dist(c1, light)
    );
    let spread = end.iter().map(|&p| dist(p, c1)).fold(0.0, f64::max);
    assert!(
        spread < 2.0,
        "the group fell apart: a robot is {spread:.2} m from its centre"
    );
    let closest = end
        .iter()
        .enumerate()
        .flat_map(|(i, &a)| end[i + 1..].iter().map(move |&b| dist(a, b)))
        .fold(f64::INFINITY, f64::min);
    assert!(
        closest > 0.4,
        "flocking keeps neighbours near the 0.75 m target distance, not piled up ({closest:.2} m)"
    );
}

#[test]
fn footbot_synchronization_converges_to_one_flash_per_period() {
    let out = temp_dir();
    run_example_elsewhere("synchronization.argos", out.path(), &["--ticks", "3000"]);
    let flashes = flash_ticks(out.path());
    // Group the flashes into bursts of consecutive ticks.
    let mut bursts: Vec<(u64, u64, usize)> = Vec::new();
    for (&tick, robots) in &flashes {
        match bursts.last_mut() {
            Some((_, last, count)) if tick <= *last + 1 => {
                *last = tick;
                *count += robots.len();
            }
            _ => bursts.push((tick, tick, robots.len())),
        }
    }
    let early: Vec<_> = bursts.iter().filter(|b| b.0 < 300).collect();
    assert!(
        early.iter().all(|b| b.2 < 16),
        "the counters start spread out, so no early burst holds every robot: {early:?}"
    );
    let late: Vec<_> = bursts.iter().filter(|b| b.0 >= 2500).collect();
    assert!(late.len() >= 4, "{late:?}");
    for (first, last, count) in late {
        assert_eq!(
            *count, 16,
            "late on, every burst holds one flash of each robot: ticks {first}-{last}"
        );
        assert!(
            last - first <= 5,
            "a burst spans at most half a second: ticks {first}-{last}"
        );
    }
}

#[test]
fn footbot_foraging_brings_items_to_the_nest_and_writes_its_output_in_the_run_folder() {
    let out = temp_dir();
    run_example_elsewhere("foraging.argos", out.path(), &["--ticks", "3000"]);
    let text = std::fs::read_to_string(out.path().join("foraging.txt"))
        .expect("the loop functions' output is in the run folder");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("# clock\twalking\tresting\tcollected_food\tenergy")
    );
    let rows: Vec<Vec<i64>> = lines
        .map(|l| {
            l.split('\t')
                .map(|v| v.parse().expect("a number"))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 3000, "one row per tick");
    for row in &rows {
        assert_eq!(row[1] + row[2], 20, "every robot walks or rests: {row:?}");
    }
    let collected = rows.last().expect("rows")[3];
    assert!(
        collected >= 5,
        "only {collected} items reached the nest in 300 s"
    );
    let summary = summary(out.path());
    assert_eq!(summary["metrics"]["collected_food"], collected);
}

/// The `gripper:*` and `fault:*` rows of `events.csv` as (tick, robot, event).
fn gripper_and_fault_events(out: &Path) -> Vec<(u64, u32, String)> {
    let text = swarm_system_tests::run_text(out, "events.csv");
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let event = f.last()?;
            (event.starts_with("gripper:") || event.starts_with("fault:")).then(|| {
                (
                    f[0].parse().expect("tick"),
                    f[1].parse().expect("robot"),
                    (*event).to_owned(),
                )
            })
        })
        .collect()
}

/// The final x of the movable object `id`, from `summary.json`.
fn final_x(out: &Path, id: &str) -> f64 {
    summary(out)["movable_objects"]
        .as_array()
        .expect("movable_objects")
        .iter()
        .find(|o| o["id"] == id)
        .and_then(|o| o["x"].as_f64())
        .expect("the object is listed")
}

#[test]
fn footbot_gripping_grips_pulls_and_lets_go() {
    let out = temp_dir();
    run_example_elsewhere("gripping.argos", out.path(), &[]);
    assert_eq!(
        gripper_and_fault_events(out.path()),
        [
            (70, 0, "gripper:grip".to_owned()),
            (120, 0, "gripper:release".to_owned())
        ]
    );
    // The cylinder started 0.5 m out; the robot pulled it back for 4.9 s at 5 cm/s.
    let x = final_x(out.path(), "c");
    assert!(x < 0.35, "the cylinder was pulled back to x = {x:.3}");
}

#[test]
fn two_footbots_pull_one_box_and_one_dying_lets_go() {
    let out = temp_dir();
    run_config(
        &workspace_file("configs/robots/two_footbots_pull_a_box.argos"),
        out.path(),
        &[],
    );
    let events = gripper_and_fault_events(out.path());
    for robot in [0, 1] {
        for (tick, event) in [
            (70, "gripper:grip"),
            (70, "gripper:lifted"),
            (120, "gripper:lowered"),
        ] {
            assert!(
                events.contains(&(tick, robot, event.to_owned())),
                "robot {robot} lacks {event} at {tick}: {events:?}"
            );
        }
    }
    let x = final_x(out.path(), "crate");
    assert!(x < 0.4, "the box was pulled from x = 0.57 to {x:.3}");

    let out = temp_dir();
    run_config(
        &workspace_file("configs/robots/two_footbots_pull_a_box.argos"),
        out.path(),
        &["--fault", "kill robots=0 tick=90"],
    );
    let events = gripper_and_fault_events(out.path());
    assert!(
        events.contains(&(90, 1, "gripper:lowered".to_owned())),
        "one grip left is not enough to hold the box up: {events:?}"
    );
    assert!(
        events.contains(&(90, 0, "gripper:release_on_death".to_owned())),
        "{events:?}"
    );
    assert!(
        events.contains(&(120, 1, "gripper:release".to_owned())),
        "the survivor holds on until its own script lets go: {events:?}"
    );
}

#[test]
fn runs_of_every_kind_are_a_pure_function_of_configuration_and_seed() {
    let read = |out: &Path, file: &str| swarm_system_tests::run_text(out, file);
    // A mixed swarm (all three bodies, three controllers) and the foraging example (random draws in the
    // controller and in the loop functions, range and bearing between robots).
    for (config, files, ticks) in [
        (
            workspace_file("configs/robots/mixed.argos"),
            &["trajectory.csv", "events.csv"][..],
            "200",
        ),
        (
            workspace_file("configs/argos_examples/foraging.argos"),
            &["trajectory.csv", "foraging.txt"][..],
            "600",
        ),
    ] {
        let (first, second) = (temp_dir(), temp_dir());
        for out in [&first, &second] {
            run_config(&config, out.path(), &["--ticks", ticks, "--seed", "42"]);
        }
        for file in files {
            assert_eq!(
                read(first.path(), file),
                read(second.path(), file),
                "{} differs between two runs of {}",
                file,
                config.display()
            );
        }
    }
}

/// A foot-bot before a wall, under a light, on a half-black floor, and a disc robot before another wall, each
/// showing three of its readings on its LEDs (`sensor_probe`).
const PROBES: &str = r#"<?xml version="1.0" ?>
<argos-configuration>
  <framework>
    <experiment length="1" ticks_per_second="10" random_seed="3" />
  </framework>
  <controllers>
    <sensor_probe id="footbot_probe" library="native">
      <actuators><differential_steering implementation="default" /><leds implementation="default" medium="leds" /></actuators>
      <sensors>
        <footbot_proximity implementation="default" />
        <footbot_light implementation="rot_z_only" />
        <footbot_motor_ground implementation="rot_z_only" />
      </sensors>
      <params red="proximity:0" green="light:5" blue="ground:1" />
    </sensor_probe>
    <sensor_probe id="disc_probe" library="native">
      <actuators><differential_steering implementation="default" /><leds implementation="default" medium="leds" /></actuators>
      <sensors><range_finder implementation="default" rays="20" range="1.0" /></sensors>
      <params red="range:0" green="range:5" blue="range:1" />
    </sensor_probe>
  </controllers>
  <arena size="4,4,1" center="0,0,0.5">
    <floor id="floor" source="regions" pixels_per_meter="50">
      <region min="0,0" max="2,2" color="black" />
    </floor>
    <foot-bot id="fb"><body position="0,0,0" orientation="0,0,0" /><controller config="footbot_probe" /></foot-bot>
    <box id="wall_fb" size="0.1,0.6,0.5" movable="false"><body position="FB_WALL_X,0,0" orientation="0,0,0" /></box>
    <light id="light" position="0,1,0.5" orientation="0,0,0" color="yellow" intensity="3" medium="leds" />
    <disc-robot id="disc"><body position="-1,-1,0" orientation="0,0,0" /><controller config="disc_probe" /></disc-robot>
    <box id="wall_disc" size="0.1,0.4,0.5" movable="false"><body position="-0.55,-1,0" orientation="0,0,0" /></box>
  </arena>
  <physics_engines><dynamics2d id="dyn2d" /></physics_engines>
  <media><led id="leds" /></media>
</argos-configuration>
"#;

#[test]
fn footbot_and_range_finder_readings_reach_the_controllers_as_geometry_says() {
    // The foot-bot's wall face is 3 cm ahead of its body; the disc robot's 0.4 m ahead of its centre.
    let r = f64::from(swarm_contract::bodies::FOOTBOT.radius);
    let config = PROBES.replace("FB_WALL_X", &format!("{}", r + 0.03 + 0.05));
    let dir = temp_dir();
    let path = dir.path().join("probes.argos");
    std::fs::write(&path, config).expect("write the configuration");
    let out = temp_dir();
    run_config(&path, out.path(), &["--ticks", "3"]);
    let text = swarm_system_tests::run_text(out.path(), "trajectory.csv");
    let led = |id: &str| -> [i64; 3] {
        let row = text
            .lines()
            .find(|l| l.starts_with("2,") && l.contains(&format!(",{id},")))
            .expect("the robot's row at tick 2");
        let f: Vec<&str> = row.split(',').collect();
        [6, 7, 8].map(|i| f[i].parse().expect("a colour channel"))
    };
    let level = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as i64;
    // Foot-bot proximity sensor 0, 7.5 degrees left: its ray leaves the body edge and meets the face at x = r + 0.03.
    let a = 7.5f64.to_radians();
    let t = (r + 0.03 - r * a.cos()) / a.cos();
    let proximity = 0.0100527 / (t + 0.000163144);
    // Light sensor 5 at 82.5 degrees, 7.5 degrees off the light straight to the left, 1.118 m away (from the
    // robot's origin on the ground), intensity 3.
    let d = (1.0f64 + 0.25).sqrt();
    let light = (-2.0 * d / 3.0).exp() * (1.0 - 2.0 * 7.5 / 180.0);
    // Motor-ground sensor 1 at (-0.063, 0.0116): white floor (the black region starts at x = 0).
    let expected_footbot = [level(proximity), level(light), 255];
    let got = led("fb");
    for (channel, (g, e)) in got.iter().zip(expected_footbot).enumerate() {
        assert!(
            (g - e).abs() <= 1,
            "foot-bot channel {channel}: {got:?} vs {expected_footbot:?}"
        );
    }
    // Disc range finder: ray 0 meets the wall 0.4 m ahead; ray 1 (18 degrees) meets it 0.4 / cos 18 m away, 0.13 m
    // to the side, inside its 0.2 m half-width; ray 5 (90 degrees) meets nothing within its 1 m.
    let ray1 = 0.4 / 18f64.to_radians().cos();
    let expected_disc = [level(0.4), 255, level(ray1)];
    let got = led("disc");
    for (channel, (g, e)) in got.iter().zip(expected_disc).enumerate() {
        assert!(
            (g - e).abs() <= 1,
            "disc channel {channel}: {got:?} vs {expected_disc:?}"
        );
    }
}
