//! The world's own hot path allocates nothing: once warmed up, `sense` makes no heap allocation at all. (The
//! rapier2d step inside `act_and_step` allocates about ten small buffers per tick internally; everything of ours
//! around it reuses preallocated buffers.) Counted with swarm_contract's counting global allocator (this thread only); this file is its own test
//! binary, so the allocator affects nothing else.

mod common;

use common::config::thesis_example;
use swarm_contract::alloc_count::{CountingAllocator, thread_allocations};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_world::World;
use swarm_world::in_process::avoid_obstacles;

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn sensing_allocates_nothing_after_warm_up() {
    let mut world = World::new(&thesis_example(), 124).expect("builds");
    let n = world.robot_count();
    let mut frames: Vec<SensorFrame> = (0..n as u32).map(SensorFrame::empty).collect();
    let mut commands: Vec<ActuatorCommand> =
        (0..n as u32).map(|r| ActuatorCommand::idle(r, 0)).collect();
    let has = vec![true; n];
    let mut sensing = 0;
    for tick in 0..500 {
        let before = thread_allocations();
        world.sense(&mut frames);
        if tick >= 400 {
            sensing += thread_allocations() - before;
        }
        for (f, c) in frames.iter().zip(commands.iter_mut()) {
            avoid_obstacles(f, c);
        }
        world.act_and_step(&commands, &has);
    }
    assert_eq!(
        sensing, 0,
        "{sensing} allocations while sensing 100 ticks of 40 robots"
    );
}
