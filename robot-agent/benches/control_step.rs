//! Cost of one agent control step (no transport): the ptSCT player with the bound `obstacle_avoidance` profile
//! on the built-in models, and the native ARGoS port, each over frames that alternate between clear and an
//! obstacle ahead. `cargo bench -p robot-agent --bench control_step`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use robot_agent::control::{self, Control};
use robot_agent::controller::{self, Plan};
use robot_agent::params::Params;
use swarm_contract::mail::Mailbox;
use swarm_contract::messages::{ActuatorCommand, SensorFrame};

fn frames() -> [SensorFrame; 2] {
    let clear = SensorFrame::empty(0);
    let mut obstacle = SensorFrame::empty(0);
    obstacle.proximity[0] = 0.5;
    [clear, obstacle]
}

fn bench_element(c: &mut Criterion, label: &str, element: &str) {
    let params = Params::default();
    let plan: Plan = controller::plan(element, &params, std::path::Path::new(".")).unwrap();
    let mut control: Control = control::build(&plan, &params, 124, 0).unwrap();
    let frames = frames();
    let mut command = ActuatorCommand::idle(0, 0);
    let inbox = Mailbox::empty(0);
    let mut outbox = Mailbox::empty(0);
    let mut tick = 0usize;
    c.bench_function(label, |b| {
        b.iter(|| {
            tick += 1;
            // An obstacle every 8th tick, as a robot in a sparse arena sees one now and then.
            let frame = &frames[usize::from(tick.is_multiple_of(8))];
            control.step(black_box(frame), &inbox, &mut outbox, &mut command);
            black_box(&command);
        })
    });
}

fn control_step(c: &mut Criterion) {
    bench_element(
        c,
        "ptsct_obstacle_avoidance_step",
        "epuck_obstacle_avoidance_sct_prob_controller",
    );
    bench_element(
        c,
        "native_epuck_obstacleavoidance_step",
        "epuck_obstacleavoidance_controller",
    );
}

criterion_group!(benches, control_step);
criterion_main!(benches);
