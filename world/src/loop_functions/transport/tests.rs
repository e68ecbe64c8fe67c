use std::collections::BTreeMap;

use rapier2d::prelude::ImpulseJointHandle;
use swarm_contract::bodies::FOOTBOT;
use swarm_contract::mail::TO_WORLD;
use swarm_navigation::planning::map::segment_distance;
use swarm_navigation::wire::transport::{
    Code, Ending, Outcome, Signal, encode_outcome, encode_path_request, encode_signal,
};

use super::*;
use crate::devices::{Devices, GripperOptions};
use crate::entities::ObstacleId;
use crate::geometry::{Placed, Shape, Vec2};
use crate::gripper::{DEFAULT_MAX_FORCE, Grip};
use crate::physics::Motion;
use crate::{World, WorldBuilder};

const LOCATION: &str = "e.argos:3:5";
/// The crate's index among the obstacles of [`world`].
const CRATE: usize = 0;
/// The crate's half size: 0.3 m x 0.6 m.
const HALF: Vec2 = Vec2::new(0.15, 0.3);
/// The formation's radius with a robot on a y face: the face's distance plus two foot-bot radii, plus the margin.
const R_Y_FACES: f32 = 0.3 + 2.0 * 0.085_036_76 + 0.1;

/// The formation's radius with robots on the x faces only: the crate's half-diagonal (0.335 m, more than
/// 0.15 + 0.17 m) plus the margin.
fn r_corner() -> f32 {
    V2::new(HALF.x, HALF.y).length() + 0.1
}

/// `<transport>` with `attrs`; `object` and `goal` have defaults unless given (an empty value leaves the attribute
/// out).
fn params_with_seed(attrs: &[(&str, &str)], seed: u64) -> LoopFunctionsParams {
    let mut attributes: BTreeMap<String, String> = [("object", "crate"), ("goal", "8,5,90")]
        .iter()
        .chain(attrs)
        .map(|&(k, v)| (format!("transport.{k}"), v.to_owned()))
        .collect();
    attributes.retain(|_, v| !v.is_empty());
    LoopFunctionsParams {
        label: LABEL.to_owned(),
        location: LOCATION.to_owned(),
        attributes,
        seed,
        ..LoopFunctionsParams::default()
    }
}

fn params(attrs: &[(&str, &str)]) -> LoopFunctionsParams {
    params_with_seed(attrs, 1)
}

fn gripping() -> Devices {
    Devices {
        gripper: Some(GripperOptions {
            max_force: DEFAULT_MAX_FORCE,
        }),
        ..Devices::PROXIMITY_ONLY
    }
}

/// A 10 x 10 m arena at 10 ticks per second with the movable crate (obstacle 0, centre (2, 5), heading
/// `crate_angle`, `lift_by` 2), fixed cylinders (x, y, radius) and `robots` foot-bots with grippers along y = 1.
fn world_with(robots: usize, crate_angle: f32, cylinders: &[(f32, f32, f32)]) -> World {
    let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1);
    let id = b.obstacle(
        "crate",
        Placed::new(Shape::Rect { half: HALF }, Vec2::new(2.0, 5.0), crate_angle),
        0.2,
        Motion::Movable { mass: 5.0 },
    );
    b.lift_by(id, 2);
    for (k, &(x, y, radius)) in cylinders.iter().enumerate() {
        b.obstacle(
            &format!("c{k}"),
            Placed::new(Shape::Disc { radius }, Vec2::new(x, y), 0.0),
            0.5,
            Motion::Fixed,
        );
    }
    for i in 0..robots {
        b.robot_with_body(
            FOOTBOT,
            &format!("fb{i}"),
            "carrier",
            Vec2::new(1.0 + 0.5 * i as f32, 1.0),
            0.0,
            gripping(),
        );
    }
    b.build()
}

fn world(robots: usize) -> World {
    world_with(robots, 0.0, &[])
}

/// Three cylinders across the straight way from the crate to (8, 5).
const WALL: [(f32, f32, f32); 3] = [(5.0, 5.0, 0.5), (5.0, 6.1, 0.3), (5.0, 3.9, 0.3)];

fn placed_in(mut w: World, params: &LoopFunctionsParams) -> (World, Transport) {
    let mut lf = Transport::new(params).unwrap();
    lf.place(&mut w.arena).unwrap();
    (w, lf)
}

fn placed(attrs: &[(&str, &str)], robots: usize) -> (World, Transport) {
    placed_in(world(robots), &params(attrs))
}

fn place_error(attrs: &[(&str, &str)], w: &mut World) -> String {
    let mut lf = Transport::new(&params(attrs)).unwrap();
    lf.place(&mut w.arena).unwrap_err().to_string()
}

fn error(message: &str) -> String {
    format!("{LOCATION}: <transport>: {message}")
}

fn step(w: &mut World, lf: &mut Transport) {
    w.arena.tick += 1;
    lf.post_step(&mut w.arena, &[], &[]);
}

fn to_world(from: u32, payload: &[u8]) -> Mail {
    Mail::new(from, Address::To(TO_WORLD), payload).unwrap()
}

fn request(from: u32) -> Mail {
    let mut payload = [0u8; PAYLOAD];
    let len = encode_path_request(&mut payload);
    to_world(from, &payload[..len])
}

fn outcome(from: u32, ending: Ending) -> Mail {
    let mut payload = [0u8; PAYLOAD];
    let len = encode_outcome(&Outcome { ending, step: 3 }, &mut payload);
    to_world(from, &payload[..len])
}

/// A letter from the world, decoded.
#[derive(Debug, Clone, PartialEq)]
enum Posted {
    Object(Object),
    Path {
        plan: u32,
        total: u16,
        first: u16,
        points: Vec<V2>,
    },
}

/// The letters posted after this tick, as (recipient, letter).
fn posted(w: &World, lf: &mut Transport) -> Vec<(u32, Posted)> {
    let mut letters = Vec::new();
    lf.post_mail(&w.arena, &mut letters);
    letters
        .iter()
        .map(|m| {
            assert_eq!(m.from, FROM_WORLD);
            let letter = match decode(m.payload()) {
                Ok(Letter::Object(object)) => Posted::Object(object),
                Ok(Letter::Path(chunk)) => Posted::Path {
                    plan: chunk.plan,
                    total: chunk.total,
                    first: chunk.first,
                    points: chunk.points().collect(),
                },
                other => panic!("the world posted {other:?}"),
            };
            (m.to, letter)
        })
        .collect()
}

/// Each recipient's whole path from the chunks in `letters`, with the plan number, checking that the chunks
/// follow each other and add up to their total.
fn paths(letters: &[(u32, Posted)]) -> BTreeMap<u32, (u32, Vec<V2>)> {
    let mut out: BTreeMap<u32, (u32, Vec<V2>, u16)> = BTreeMap::new();
    for (to, letter) in letters {
        if let Posted::Path {
            plan,
            total,
            first,
            points,
        } = letter
        {
            let entry = out.entry(*to).or_insert((*plan, Vec::new(), *total));
            assert_eq!((entry.0, entry.2), (*plan, *total));
            assert_eq!(usize::from(*first), entry.1.len());
            entry.1.extend(points);
        }
    }
    out.into_iter()
        .map(|(to, (plan, path, total))| {
            assert_eq!(path.len(), usize::from(total));
            (to, (plan, path))
        })
        .collect()
}

fn objects(letters: &[(u32, Posted)]) -> Vec<(u32, Object)> {
    letters
        .iter()
        .filter_map(|(to, letter)| match letter {
            Posted::Object(object) => Some((*to, *object)),
            Posted::Path { .. } => None,
        })
        .collect()
}

fn drained(lf: &mut Transport) -> String {
    let mut out = Vec::new();
    lf.drain_output(&mut out);
    String::from_utf8(out).unwrap()
}

fn rows<'a>(csv: &'a str, event: &str) -> Vec<&'a str> {
    csv.lines()
        .filter(|l| l.split(',').nth(1) == Some(event))
        .collect()
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() < 1e-5
}

#[test]
fn the_configuration_is_read_and_checked() {
    let lf = Transport::new(&params(&[])).unwrap();
    let s = &lf.settings;
    assert_eq!(
        (s.object.as_str(), s.goal, s.tolerance, s.margin, s.repeat_s),
        ("crate", V2::new(8.0, 5.0), 0.02, 0.1, 1.0)
    );
    assert!(close(s.goal_angle, std::f32::consts::FRAC_PI_2));
    assert!(close(s.angle_tolerance, 3f32.to_radians()));
    assert_eq!(s.tree, swarm_navigation::planning::tree::Tree::Ort);
    assert_eq!(
        s.params,
        swarm_navigation::planning::tree::TreeParams::default()
    );
    let lf = Transport::new(&params(&[
        ("goal", " 2, 2, 195 "),
        ("tolerance", "0.05"),
        ("angle_tolerance", "10"),
        ("planner", "rrt"),
        ("step", "0.1"),
        ("failures", "3"),
        ("iterations", "500"),
        ("reach", "0.5"),
        ("margin", "0"),
        ("repeat", "0.25"),
    ]))
    .unwrap();
    let s = &lf.settings;
    // 195 degrees is -165.
    assert!(
        close(s.goal_angle, (-165f32).to_radians()),
        "{}",
        s.goal_angle
    );
    assert!(close(s.angle_tolerance, 10f32.to_radians()));
    assert_eq!(
        (
            s.tree,
            s.params.step,
            s.params.failures,
            s.params.iterations,
            s.params.reach
        ),
        (
            swarm_navigation::planning::tree::Tree::Rrt,
            0.1,
            3,
            500,
            0.5
        )
    );
    assert_eq!((s.tolerance, s.margin, s.repeat_s), (0.05, 0.0, 0.25));
    let lf = Transport::new(&params(&[
        ("tolerance", "1e300"),
        ("angle_tolerance", "1e300"),
    ]))
    .unwrap();
    assert!(lf.settings.tolerance.is_finite() && lf.settings.angle_tolerance.is_finite());
    let err = |attrs: &[(&str, &str)]| Transport::new(&params(attrs)).err().unwrap().to_string();
    assert!(
        err(&[("speed", "1")]).starts_with("e.argos:3:5: <transport> has no attribute 'speed'"),
        "{}",
        err(&[("speed", "1")])
    );
    assert_eq!(
        err(&[("object", "")]),
        "e.argos:3:5: <transport> needs the attribute 'object'"
    );
    assert_eq!(
        err(&[("goal", "")]),
        "e.argos:3:5: <transport> needs the attribute 'goal'"
    );
    assert_eq!(
        err(&[("goal", "2,2")]),
        "e.argos:3:5: <transport goal=\"2,2\">: must be 3 numbers separated by `,`"
    );
    assert_eq!(
        err(&[("planner", "astar")]),
        "e.argos:3:5: <transport planner=\"astar\">: must be one of ort, rrt"
    );
    assert_eq!(
        err(&[("iterations", "2000000")]),
        "e.argos:3:5: <transport iterations=\"2000000\">: must be a whole number from 1 to 1000000"
    );
    assert_eq!(
        err(&[("failures", "0")]),
        "e.argos:3:5: <transport failures=\"0\">: must be a whole number from 1 to 4294967295"
    );
    assert_eq!(
        err(&[("tolerance", "0")]),
        "e.argos:3:5: <transport tolerance=\"0\">: must be a number > 0"
    );
    assert_eq!(
        err(&[("margin", "-0.1")]),
        "e.argos:3:5: <transport margin=\"-0.1\">: must be a number >= 0"
    );
}

#[test]
fn an_object_that_is_no_movable_liftable_box_is_refused() {
    let mut w = world_with(2, 0.0, &[(8.0, 8.0, 0.3)]);
    assert_eq!(
        place_error(&[("object", "crates")], &mut w),
        error("`object` names `crates`, which is no box of the arena")
    );
    assert_eq!(
        place_error(&[("object", "c0")], &mut w),
        error("`object` `c0` is a cylinder; the object to carry must be a box")
    );
    let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1);
    let rect = Placed::new(Shape::Rect { half: HALF }, Vec2::new(2.0, 5.0), 0.0);
    b.obstacle("fixed", rect, 0.2, Motion::Fixed);
    b.obstacle(
        "heavy",
        Placed::new(Shape::Rect { half: HALF }, Vec2::new(5.0, 2.0), 0.0),
        0.2,
        Motion::Movable { mass: 5.0 },
    );
    b.robot_with_body(FOOTBOT, "fb0", "c", Vec2::ONE, 0.0, gripping());
    let mut w = b.build();
    assert_eq!(
        place_error(&[("object", "fixed")], &mut w),
        error("box `fixed` is not movable: the object to carry needs `movable=\"true\"`")
    );
    assert_eq!(
        place_error(&[("object", "heavy")], &mut w),
        error(
            "box `heavy` has no `lift_by`: no number of grippers lifts it, so it cannot be carried"
        )
    );
}

#[test]
fn a_team_that_cannot_lift_the_box_is_refused() {
    assert_eq!(
        place_error(&[], &mut world(0)),
        error("the run has no robots to carry box `crate`")
    );
    assert_eq!(
        place_error(&[], &mut world(5)),
        error(
            "the run has 5 robots; every robot is in the team and a box has 4 faces, so at most 4"
        )
    );
    // Two robots, one of them without a gripper, for a box that two grips lift.
    let mut w = world(1);
    let mut b = WorldBuilder::new(Vec2::ZERO, Vec2::splat(10.0), 10, 1);
    let id = b.obstacle(
        "crate",
        Placed::new(Shape::Rect { half: HALF }, Vec2::new(2.0, 5.0), 0.0),
        0.2,
        Motion::Movable { mass: 5.0 },
    );
    b.lift_by(id, 2);
    b.robot_with_body(FOOTBOT, "fb0", "c", Vec2::ONE, 0.0, gripping());
    b.robot_with_body(
        FOOTBOT,
        "fb1",
        "c",
        Vec2::new(2.0, 1.0),
        0.0,
        Devices::PROXIMITY_ONLY,
    );
    let mut mixed = b.build();
    let expected = error(
        "box `crate` needs 2 grips to be lifted (`lift_by`), and the run has 1 robots with a `footbot_gripper`",
    );
    assert_eq!(place_error(&[], &mut mixed), expected);
    assert_eq!(place_error(&[], &mut w), expected);
    assert!(placed(&[], 4).1.site.is_some());
}

#[test]
fn a_goal_the_formation_cannot_stand_at_is_refused() {
    let mut w = world_with(2, 0.0, &[(8.0, 8.0, 0.3)]);
    // The formation's radius is 0.435 m: 0.7 m from the cylinder's centre overlaps it.
    assert_eq!(
        place_error(&[("goal", "8.7,8,0")], &mut w),
        error(&format!(
            "the goal (8.7, 8) is inside obstacle `c0` for the formation: a disc of radius {} m there overlaps it",
            r_corner()
        ))
    );
    assert_eq!(
        place_error(&[("goal", "9.7,2,0")], &mut w),
        error(&format!(
            "the goal (9.7, 2) is off the arena for the formation: a disc of radius {} m there would leave (0, 0) \
             to (10, 10)",
            r_corner()
        ))
    );
    let (_, lf) = placed_in(
        world_with(2, 0.0, &[(8.0, 8.0, 0.3)]),
        &params(&[("goal", "8.75,8,0")]),
    );
    assert!(lf.site.is_some());
}

#[test]
fn a_goal_walled_off_from_the_box_is_refused() {
    // A ring of cylinders round (8, 5), with gaps of 0.3 m: a point could pass, the formation cannot.
    let ring: Vec<(f32, f32, f32)> = (0..8)
        .map(|k| {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            (8.0 + 1.2 * a.cos(), 5.0 + 1.2 * a.sin(), 0.3)
        })
        .collect();
    let mut w = world_with(2, 0.0, &ring);
    assert_eq!(
        place_error(&[], &mut w),
        error(&format!(
            "the goal (8, 5) is unreachable for the formation (radius {} m) from the start (2, 5) of box \
             `crate`: static obstacles wall it off",
            r_corner()
        ))
    );
    // Half the ring: a way in.
    let (_, lf) = placed_in(world_with(2, 0.0, &ring[..4]), &params(&[]));
    assert!(lf.site.is_some());
}

#[test]
fn the_front_face_looks_at_the_goal_and_the_next_robot_takes_the_opposite_face() {
    let faces = |w: World, goal: &str| {
        let (_, lf) = placed_in(w, &params(&[("goal", goal)]));
        let site = lf.site.unwrap();
        (site.faces, site.radius)
    };
    // East of the crate: its +x face, then -x, then the clockwise one (-y), then +y.
    let (f, r) = faces(world(4), "8,5,0");
    assert_eq!(f, vec![0, 2, 3, 1]);
    assert!(close(r, R_Y_FACES), "{r}");
    let (f, r) = faces(world(2), "8,5,0");
    assert_eq!(f, vec![0, 2]);
    // Only x faces: the half-diagonal 0.335 m is larger than 0.32 m.
    assert!(close(r, r_corner()), "{r}");
    // North of it: the +y face, then -y.
    let (f, r) = faces(world(3), "2,8,0");
    assert_eq!(f, vec![1, 3, 0]);
    assert!(close(r, R_Y_FACES), "{r}");
    // The crate turned a quarter: its +x face looks north, its -y face east.
    let (f, _) = faces(world_with(2, std::f32::consts::FRAC_PI_2, &[]), "8,5,0");
    assert_eq!(f, vec![3, 1]);
    let (f, _) = faces(world_with(2, std::f32::consts::FRAC_PI_2, &[]), "2.5,8,0");
    assert_eq!(f, vec![0, 2]);
}

#[test]
fn every_robot_in_the_run_gets_the_object_with_its_face_every_repeat() {
    let (mut w, mut lf) = placed(&[("repeat", "0.5"), ("goal", "2,8,45")], 3);
    let csv = drained(&mut lf);
    assert!(
        csv.starts_with(&format!(
            "tick,event,x,y,angle_deg,detail\n0,start,2,5,0,front_face=1 formation_radius_m={R_Y_FACES}\n"
        )),
        "{csv}"
    );
    let letters = objects(&posted(&w, &mut lf));
    assert_eq!(
        letters
            .iter()
            .map(|(to, o)| (*to, o.face))
            .collect::<Vec<_>>(),
        vec![(0, 1), (1, 3), (2, 0)]
    );
    let o = letters[0].1;
    assert_eq!(
        (
            o.centre,
            o.angle,
            o.half,
            o.goal,
            o.team,
            o.lift_by,
            o.tolerance,
            o.plans
        ),
        (
            V2::new(2.0, 5.0),
            0.0,
            V2::new(0.15, 0.3),
            V2::new(2.0, 8.0),
            3,
            2,
            0.02,
            0
        )
    );
    assert!(close(o.goal_angle, std::f32::consts::FRAC_PI_4));
    assert!(close(o.angle_tolerance, 3f32.to_radians()));
    for _ in 0..4 {
        step(&mut w, &mut lf);
        assert_eq!(posted(&w, &mut lf), vec![], "no repeat within 0.5 s");
    }
    // Tick 5: again, with the box where it is now, to the robots in the run.
    w.arena.robots[1].alive = false;
    w.arena.robots[2].present = false;
    w.arena.obstacles[CRATE]
        .placed
        .set_pose(Vec2::new(2.5, 5.5), 0.3);
    step(&mut w, &mut lf);
    let letters = objects(&posted(&w, &mut lf));
    assert_eq!(letters.len(), 1);
    assert_eq!(
        (
            letters[0].0,
            letters[0].1.face,
            letters[0].1.centre,
            letters[0].1.angle
        ),
        (0, 1, V2::new(2.5, 5.5), 0.3)
    );
}

#[test]
fn a_path_request_gives_every_robot_the_path_round_the_obstacles_to_the_goal() {
    let (mut w, mut lf) = placed_in(world_with(3, 0.0, &WALL), &params(&[]));
    let radius = lf.site.as_ref().unwrap().radius;
    posted(&w, &mut lf);
    step(&mut w, &mut lf);
    // Two robots ask in the same tick, one twice: one plan.
    lf.read_mail(&w.arena, &[request(0), request(1)]);
    lf.read_mail(&w.arena, &[request(1)]);
    assert_eq!(lf.plans, 1);
    let letters = posted(&w, &mut lf);
    assert!(
        objects(&letters).is_empty(),
        "the Object waits for its second"
    );
    let paths = paths(&letters);
    assert_eq!(paths.keys().copied().collect::<Vec<_>>(), vec![0, 1, 2]);
    let (plan, path) = &paths[&0];
    assert_eq!(*plan, 1);
    assert!(paths.values().all(|p| p == &paths[&0]));
    assert!(path.len() > 31, "more than one chunk: {}", path.len());
    assert!((path[0] - V2::new(2.0, 5.0)).length() < 1e-6);
    assert_eq!(*path.last().unwrap(), V2::new(8.0, 5.0));
    for segment in path.windows(2) {
        for &(x, y, r) in &WALL {
            let d = segment_distance(segment[0], segment[1], V2::new(x, y));
            assert!(
                d >= r + radius - 1e-4,
                "{segment:?} comes {d} m from ({x}, {y})"
            );
        }
    }
    // Nothing more until the next request, which makes plan 2.
    assert_eq!(posted(&w, &mut lf), vec![]);
    step(&mut w, &mut lf);
    lf.read_mail(&w.arena, &[request(2)]);
    assert_eq!(lf.plans, 2);
    let second = self::paths(&posted(&w, &mut lf));
    assert_eq!(second.len(), 3);
    assert!(second.values().all(|(plan, _)| *plan == 2));
    let csv = drained(&mut lf);
    let plans = rows(&csv, "plan");
    assert_eq!(plans.len(), 2);
    assert!(
        plans[0].starts_with("1,plan,2,5,0,ort nodes="),
        "{}",
        plans[0]
    );
    let m = lf.metrics(&w.arena);
    assert_eq!(m["plans"], json!(2));
    let length = m["planned_path_m"].as_f64().unwrap();
    assert!(length > 6.5 && length < 10.0, "{length}");
    assert!(
        plans[1].ends_with(&format!("length_m={}", length as f32)),
        "{}",
        plans[1]
    );
    assert!(m["planner_nodes"].as_u64().unwrap() >= second[&0].1.len() as u64);
    assert!(m["planning_ms"].as_f64().unwrap() >= 0.0);
    // The next Object counts the plans.
    for _ in 0..8 {
        step(&mut w, &mut lf);
    }
    assert!(
        objects(&posted(&w, &mut lf))
            .iter()
            .all(|(_, o)| o.plans == 2)
    );
}

/// The path plan `plans` of the crate to (8, 5) round [`WALL`] with RRT, in a run of `seed`.
fn rrt_path(seed: u64, plans: u32) -> Vec<V2> {
    let (mut w, mut lf) = placed_in(
        world_with(2, 0.0, &WALL),
        &params_with_seed(&[("planner", "rrt")], seed),
    );
    posted(&w, &mut lf);
    let mut path = Vec::new();
    for _ in 0..plans {
        step(&mut w, &mut lf);
        lf.read_mail(&w.arena, &[request(0)]);
        path = paths(&posted(&w, &mut lf)).remove(&0).unwrap().1;
    }
    assert_eq!(lf.plans, plans);
    path
}

#[test]
fn a_plan_is_a_function_of_the_seed_and_its_number() {
    let first = rrt_path(7, 1);
    assert!(!first.is_empty());
    assert_eq!(first, rrt_path(7, 1));
    assert_ne!(first, rrt_path(8, 1), "another seed");
    assert_ne!(
        first,
        rrt_path(7, 2),
        "the second plan draws from its own stream"
    );
}

#[test]
fn a_failed_plan_sends_a_path_of_no_points() {
    let (mut w, mut lf) = placed_in(
        world_with(2, 0.0, &[(5.0, 5.0, 1.0)]),
        &params(&[("iterations", "1")]),
    );
    posted(&w, &mut lf);
    step(&mut w, &mut lf);
    lf.read_mail(&w.arena, &[request(1)]);
    assert_eq!(
        posted(&w, &mut lf),
        vec![
            (
                0,
                Posted::Path {
                    plan: 1,
                    total: 0,
                    first: 0,
                    points: vec![]
                }
            ),
            (
                1,
                Posted::Path {
                    plan: 1,
                    total: 0,
                    first: 0,
                    points: vec![]
                }
            )
        ]
    );
    assert_eq!(rows(&drained(&mut lf), "plan"), vec!["1,plan,2,5,0,failed"]);
    let m = lf.metrics(&w.arena);
    assert_eq!(
        (m["plans"].clone(), m["planned_path_m"].clone()),
        (json!(1), json!(null))
    );
    assert!(m["planner_nodes"].as_u64().unwrap() >= 1);
}

#[test]
fn a_box_close_to_an_obstacle_or_the_edge_is_planned_away_from_it() {
    // The cylinder's disc grown by the formation's radius (0.1 + 0.435 m) holds the crate's centre, 0.5 m away.
    let (mut w, mut lf) = placed_in(world_with(2, 0.0, &[(2.0, 5.5, 0.1)]), &params(&[]));
    posted(&w, &mut lf);
    step(&mut w, &mut lf);
    lf.read_mail(&w.arena, &[request(0)]);
    let path = paths(&posted(&w, &mut lf)).remove(&0).unwrap().1;
    assert_eq!(
        (path.first().copied(), path.last().copied()),
        (Some(V2::new(2.0, 5.0)), Some(V2::new(8.0, 5.0)))
    );
    // Nearer the arena's edge than the formation's radius: the path starts at the nearest point it may use.
    w.arena.obstacles[CRATE]
        .placed
        .set_pose(Vec2::new(0.2, 2.0), 0.0);
    step(&mut w, &mut lf);
    lf.read_mail(&w.arena, &[request(0)]);
    let path = paths(&posted(&w, &mut lf)).remove(&0).unwrap().1;
    assert_eq!(
        (path.first().copied(), path.last().copied()),
        (Some(V2::new(r_corner(), 2.0)), Some(V2::new(8.0, 5.0)))
    );
}

#[test]
fn hostile_letters_and_letters_from_no_robot_are_ignored() {
    let (mut w, mut lf) = placed(&[], 2);
    posted(&w, &mut lf);
    step(&mut w, &mut lf);
    let mut payload = [0u8; PAYLOAD];
    let len = encode_signal(
        &Signal {
            code: Code::Put,
            step: 1,
            value: V2::ZERO,
        },
        &mut payload,
    );
    let letters = [
        to_world(0, &[]),
        to_world(0, &[33, 0]),
        to_world(0, &[36, 9, 0, 0, 0, 0]),
        to_world(1, &[200, 1, 2]),
        to_world(0, &payload[..len]),
        // From a coordinator (participant 2) and from the world's own index.
        request(2),
        request(FROM_WORLD),
        outcome(2, Ending::NoPath),
        outcome(TO_WORLD, Ending::Dropped),
    ];
    lf.read_mail(&w.arena, &letters);
    assert_eq!(lf.plans, 0);
    assert_eq!(lf.judge.outcome, None);
    assert_eq!(posted(&w, &mut lf), vec![]);
    step(&mut w, &mut lf);
    assert!(!lf.is_finished(&w.arena));
}

/// Robot `robot` holds the crate, or lets go.
fn hold(w: &mut World, robot: usize, holds: bool) {
    w.arena.robots[robot].gripper.holding = holds.then(|| Grip {
        obstacle: ObstacleId(CRATE as u32),
        joint: ImpulseJointHandle::from_raw_parts(0, 0),
        passive: false,
        point_on_object: Vec2::ZERO,
    });
}

/// Moves the crate to (x, y) at `degrees`, lifted or not, and steps.
fn carry(w: &mut World, lf: &mut Transport, x: f32, y: f32, degrees: f32, lifted: bool) {
    let o = &mut w.arena.obstacles[CRATE];
    o.placed.set_pose(Vec2::new(x, y), degrees.to_radians());
    o.lifted = lifted;
    step(w, lf);
}

#[test]
fn the_judge_measures_the_box_put_down_after_it_was_carried() {
    let (mut w, mut lf) = placed(&[], 2);
    drained(&mut lf);
    step(&mut w, &mut lf);
    hold(&mut w, 0, true);
    hold(&mut w, 1, true);
    carry(&mut w, &mut lf, 2.0, 5.0, 0.0, true);
    for _ in 0..7 {
        carry(&mut w, &mut lf, 5.0, 5.0, 45.0, true);
    }
    // Tick 10: a whole second, lifted.
    carry(&mut w, &mut lf, 7.99, 5.0, 91.0, true);
    // Down, but robot 1 still holds it: not over.
    carry(&mut w, &mut lf, 7.99, 5.0, 91.0, false);
    hold(&mut w, 0, false);
    carry(&mut w, &mut lf, 7.99, 5.0, 91.0, false);
    assert!(!lf.is_finished(&w.arena));
    let m = lf.metrics(&w.arena);
    assert_eq!(
        (
            m["success"].clone(),
            m["position_error_m"].clone(),
            m["time_s"].clone()
        ),
        (json!(false), json!(null), json!(null))
    );
    hold(&mut w, 1, false);
    carry(&mut w, &mut lf, 7.99, 5.0, 91.0, false);
    // Every grip open, and no report: the judge waits for one a little.
    assert!(!lf.is_finished(&w.arena));
    for _ in 0..super::judge::SILENT_TICKS {
        carry(&mut w, &mut lf, 7.99, 5.0, 91.0, false);
    }
    assert!(lf.is_finished(&w.arena));
    // Nothing counts after the end.
    carry(&mut w, &mut lf, 1.0, 1.0, 0.0, true);
    let m = lf.metrics(&w.arena);
    assert_eq!(m["outcome"], json!(null));
    assert_eq!(m["success"], json!(true), "{m}");
    assert!(
        (m["position_error_m"].as_f64().unwrap() - 0.01).abs() < 1e-5,
        "{m}"
    );
    assert!(
        (m["angle_error_deg"].as_f64().unwrap() - 1.0).abs() < 1e-3,
        "{m}"
    );
    assert_eq!(m["time_s"], json!(3.3));
    assert!(
        (m["object_path_m"].as_f64().unwrap() - 5.99).abs() < 1e-5,
        "{m}"
    );
    assert_eq!(m["lifted_s"], json!(0.9));
    assert_eq!(m["collisions"], json!(0));
    let csv = drained(&mut lf);
    let events: Vec<&str> = csv.lines().map(|l| l.split(',').nth(1).unwrap()).collect();
    assert_eq!(events, vec!["lifted", "pose", "lowered", "final"]);
    assert!(
        rows(&csv, "lifted")[0].starts_with("2,lifted,2,5,0,"),
        "{csv}"
    );
    assert!(
        rows(&csv, "pose")[0].starts_with("10,pose,7.99,5,"),
        "{csv}"
    );
    assert!(
        rows(&csv, "lowered")[0].starts_with("11,lowered,7.99,5,"),
        "{csv}"
    );
    let last = rows(&csv, "final")[0];
    assert!(last.starts_with("33,final,7.99,5,"), "{last}");
    assert!(last.contains(",position_error_m=0.0100"), "{last}");
    assert!(last.contains(" angle_error_deg="), "{last}");
}

#[test]
fn a_box_put_down_out_of_tolerance_or_an_outcome_other_than_delivered_is_no_success() {
    // 5 cm off.
    let (mut w, mut lf) = placed(&[], 2);
    carry(&mut w, &mut lf, 5.0, 5.0, 90.0, true);
    lf.read_mail(&w.arena, &[outcome(0, Ending::Delivered)]);
    carry(&mut w, &mut lf, 7.95, 5.0, 90.0, false);
    let m = lf.metrics(&w.arena);
    assert!(lf.is_finished(&w.arena));
    assert_eq!(m["success"], json!(false));
    assert!((m["position_error_m"].as_f64().unwrap() - 0.05).abs() < 1e-5);
    // On the spot, turned 4 degrees too far (tolerance 3).
    let (mut w, mut lf) = placed(&[], 2);
    carry(&mut w, &mut lf, 5.0, 5.0, 90.0, true);
    lf.read_mail(&w.arena, &[outcome(0, Ending::Delivered)]);
    carry(&mut w, &mut lf, 8.0, 5.0, 94.0, false);
    assert_eq!(lf.metrics(&w.arena)["success"], json!(false));
    // Within 1 degree: -269 is 91.
    let (mut w, mut lf) = placed(&[], 2);
    carry(&mut w, &mut lf, 5.0, 5.0, 90.0, true);
    lf.read_mail(&w.arena, &[outcome(0, Ending::Delivered)]);
    carry(&mut w, &mut lf, 8.0, 5.0, -269.0, false);
    assert_eq!(lf.metrics(&w.arena)["success"], json!(true));
    // At the goal, but the team says it dropped the box.
    let (mut w, mut lf) = placed(&[], 2);
    carry(&mut w, &mut lf, 5.0, 5.0, 90.0, true);
    lf.read_mail(&w.arena, &[outcome(0, Ending::Dropped)]);
    carry(&mut w, &mut lf, 8.0, 5.0, 90.0, false);
    let m = lf.metrics(&w.arena);
    assert_eq!(
        (m["outcome"].clone(), m["success"].clone()),
        (json!("dropped"), json!(false))
    );
}

#[test]
fn an_outcome_ends_the_task_once_the_box_is_on_the_ground() {
    // No path: the box never left the ground, so the task is over at the next tick; the first report counts.
    let (mut w, mut lf) = placed(&[], 2);
    step(&mut w, &mut lf);
    lf.read_mail(
        &w.arena,
        &[outcome(1, Ending::NoPath), outcome(0, Ending::Delivered)],
    );
    assert!(!lf.is_finished(&w.arena));
    step(&mut w, &mut lf);
    assert!(lf.is_finished(&w.arena));
    let m = lf.metrics(&w.arena);
    assert_eq!(
        (
            m["outcome"].clone(),
            m["success"].clone(),
            m["time_s"].clone()
        ),
        (json!("no_path"), json!(false), json!(0.2))
    );
    let csv = drained(&mut lf);
    let lines: Vec<&str> = csv.lines().skip(2).collect();
    assert_eq!(lines.len(), 2, "{csv}");
    assert_eq!(lines[0], "1,outcome,2,5,0,no_path");
    assert!(
        lines[1].starts_with("2,final,2,5,0,position_error_m=6 angle_error_deg="),
        "{csv}"
    );
    // Delivered while the box is still up: over when it is down, even with grips held.
    let (mut w, mut lf) = placed(&[], 2);
    hold(&mut w, 0, true);
    carry(&mut w, &mut lf, 8.0, 5.0, 90.0, true);
    lf.read_mail(&w.arena, &[outcome(0, Ending::Delivered)]);
    carry(&mut w, &mut lf, 8.0, 5.0, 90.0, true);
    assert!(!lf.is_finished(&w.arena));
    carry(&mut w, &mut lf, 8.0, 5.0, 90.0, false);
    assert!(lf.is_finished(&w.arena));
    assert_eq!(lf.metrics(&w.arena)["success"], json!(true));
    // A request after the end makes no plan.
    lf.read_mail(&w.arena, &[request(0)]);
    assert_eq!(lf.plans, 0);
}

#[test]
fn the_registry_knows_the_label() {
    let registry = crate::loop_functions::LoopFunctionsRegistry::default();
    let lf = registry.create(Some(&params(&[]))).unwrap();
    assert_eq!(lf.output_name(), Some(OUTPUT));
    assert_eq!(
        lf.metrics(&world(2).arena),
        json!({
            "outcome": null,
            "success": false,
            "position_error_m": null,
            "angle_error_deg": null,
            "time_s": null,
            "object_path_m": 0.0,
            "planned_path_m": null,
            "plans": 0,
            "planner_nodes": null,
            "planning_ms": 0.0,
            "lifted_s": 0.0,
            "collisions": 0,
        })
    );
}
