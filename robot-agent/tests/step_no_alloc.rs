//! A control step is on the per-tick hot path: with the player and the bound profile, or a native controller,
//! it must not allocate (style.md, "The hot path allocates nothing").

use std::path::Path;

use robot_agent::control;
use robot_agent::controller;
use robot_agent::params::Params;
use swarm_contract::alloc_count::{CountingAllocator, thread_allocations};
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn allocations_in_1000_steps(element: &str) -> u64 {
    let params = Params::default();
    let plan = controller::plan(element, &params, Path::new(".")).unwrap();
    let mut control = control::build(&plan, &params, 124, 0).unwrap();
    let clear = SensorFrame::empty(0);
    let mut obstacle = SensorFrame::empty(0);
    obstacle.proximity[7] = 0.6;
    let mut command = ActuatorCommand::idle(0, 0);
    let inbox = Mailbox::empty(0);
    let mut outbox = Mailbox::empty(0);
    let before = thread_allocations();
    for tick in 0..1000u64 {
        let frame = if tick % 7 == 0 { &obstacle } else { &clear };
        control.step(frame, &inbox, &mut outbox, &mut command);
    }
    thread_allocations() - before
}

#[test]
fn supervised_and_native_steps_allocate_nothing() {
    assert_eq!(
        allocations_in_1000_steps("epuck_obstacle_avoidance_sct_prob_controller"),
        0
    );
    assert_eq!(
        allocations_in_1000_steps("epuck_obstacleavoidance_controller"),
        0
    );
}
