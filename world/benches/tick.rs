//! World cost per robot per tick at ARGoS' obstacle-avoidance density: 50 robots per 16 m^2, N/10 boxes
//! (0.1 x 0.1 m) and N/10 cylinders (r = 0.1 m) placed uniformly without overlap in a square walled arena,
//! proximity sensors and wheels only, driven by the in-process obstacle-avoidance rule.
//!
//! Groups: `tick` (sense + controller + act/physics/media), `sense` (the proximity rays) and `step`
//! (controller, actuators, physics and media); every group runs whole ticks and times only its part. Criterion reports elements = robots, so its throughput is robot-ticks/s.
//!
//! Every size is measured over the same stretch of a run: ticks 50 to 650, as in a 60-second experiment. When a
//! world reaches tick 650 it is replaced by a fresh one (not timed). Left to run for the whole benchmark, a world
//! at this density ages into jams whose sensing costs more per robot, and a small world ages many times faster
//! than a large one (a tick of 100 robots takes a fifteenth of a tick of 1,000), which made sizes incomparable.

use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::Rng;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_world::devices::Devices;
use swarm_world::geometry::{Placed, Shape, Vec2};
use swarm_world::in_process::avoid_obstacles;
use swarm_world::physics::Motion;
use swarm_world::rng::{Purpose, stream};
use swarm_world::{World, WorldBuilder};

const SIZES: [usize; 3] = [100, 1000, 5000];

/// Ticks a fresh world has run before it is measured.
const WARM_TICKS: u64 = 50;

/// The tick at which a world is replaced by a fresh one.
const LAST_TICK: u64 = 650;

/// The ARGoS-density world with `n` robots.
fn density_world(n: usize) -> World {
    let side = (n as f32 * 16.0 / 50.0).sqrt();
    let h = side / 2.0;
    let mut b = WorldBuilder::new(Vec2::splat(-h - 0.1), Vec2::splat(h + 0.1), 10, 42);
    let mut occupied: Vec<Placed> = Vec::new();
    for (i, (pos, size)) in [
        (Vec2::new(0.0, h + 0.05), Vec2::new(side + 0.2, 0.1)),
        (Vec2::new(0.0, -h - 0.05), Vec2::new(side + 0.2, 0.1)),
        (Vec2::new(h + 0.05, 0.0), Vec2::new(0.1, side + 0.2)),
        (Vec2::new(-h - 0.05, 0.0), Vec2::new(0.1, side + 0.2)),
    ]
    .into_iter()
    .enumerate()
    {
        let wall = Placed::new(Shape::Rect { half: size / 2.0 }, pos, 0.0);
        b.obstacle(&format!("wall{i}"), wall, 0.5, Motion::Fixed);
        occupied.push(wall);
    }
    let mut rng = stream(42, Purpose::Placement, 0);
    let mut free = |shape: Shape, rng: &mut rand_chacha::ChaCha8Rng| loop {
        let p = Vec2::new(rng.random_range(-h..h), rng.random_range(-h..h));
        let placed = Placed::new(shape, p, rng.random_range(0.0..std::f32::consts::TAU));
        if !occupied.iter().any(|o| o.overlaps(&placed)) {
            occupied.push(placed);
            return placed;
        }
    };
    for i in 0..n / 10 {
        let bx = free(
            Shape::Rect {
                half: Vec2::splat(0.05),
            },
            &mut rng,
        );
        b.obstacle(&format!("b{i}"), bx, 0.4, Motion::Fixed);
        let cy = free(Shape::Disc { radius: 0.1 }, &mut rng);
        b.obstacle(&format!("c{i}"), cy, 0.4, Motion::Fixed);
    }
    for i in 0..n {
        let r = free(Shape::Disc { radius: 0.035 }, &mut rng);
        b.robot(
            &format!("fb{i}"),
            "fdc",
            r.position,
            r.angle(),
            Devices::PROXIMITY_ONLY,
        );
    }
    let mut world = b.build();
    world.run_in_process(WARM_TICKS, avoid_obstacles);
    world
}

/// One full tick with the phases timed separately: (sense, controller + act/physics/media).
fn timed_tick(
    world: &mut World,
    frames: &mut [SensorFrame],
    commands: &mut [ActuatorCommand],
    has: &[bool],
) -> (Duration, Duration) {
    let t0 = Instant::now();
    world.sense(frames);
    let t1 = Instant::now();
    for (f, cmd) in frames.iter().zip(commands.iter_mut()) {
        avoid_obstacles(f, cmd);
    }
    world.act_and_step(commands, has);
    (t1 - t0, t1.elapsed())
}

fn bench(c: &mut Criterion) {
    for &n in &SIZES {
        let mut world = density_world(n);
        let mut age = WARM_TICKS;
        let mut frames: Vec<SensorFrame> = (0..n as u32).map(SensorFrame::empty).collect();
        let mut commands: Vec<ActuatorCommand> =
            (0..n as u32).map(|r| ActuatorCommand::idle(r, 0)).collect();
        let has = vec![true; n];
        // Every group runs whole ticks, so the world keeps evolving as in a run, and times only its part.
        for (group_name, part) in [("tick", 0), ("sense", 1), ("step", 2)] {
            let mut group = c.benchmark_group(group_name);
            group.throughput(Throughput::Elements(n as u64));
            group.bench_function(BenchmarkId::from_parameter(n), |b| {
                b.iter_custom(|iters| {
                    let mut total = Duration::ZERO;
                    for _ in 0..iters {
                        if age >= LAST_TICK {
                            world = density_world(n);
                            age = WARM_TICKS;
                        }
                        age += 1;
                        let (sense, step) =
                            timed_tick(&mut world, &mut frames, &mut commands, &has);
                        total += match part {
                            0 => sense + step,
                            1 => sense,
                            _ => step,
                        };
                    }
                    total
                })
            });
            group.finish();
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
