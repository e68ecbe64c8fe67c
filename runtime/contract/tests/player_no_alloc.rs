//! The player's step is on the per-tick hot path: it must not allocate (style.md, "The hot path allocates nothing").

use supervisor_gen::compiled::{
    CompiledEvent, CompiledState, CompiledSupervisor, CompiledTransition, SupervisorSet,
};
use swarm_contract::alloc_count::{CountingAllocator, thread_allocations};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::{EventCallbacks, Player};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

struct Toggle;

impl EventCallbacks for Toggle {
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool {
        frame.tick % 3 == u64::from(event) % 3
    }
    fn act(&mut self, event: u8, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        command.wheels = [f32::from(event), 1.0];
    }
}

fn transition(event: u8, target: u16, prob_q16: u16, lower_bound: u16) -> CompiledTransition {
    CompiledTransition {
        event,
        target,
        prob_q16,
        lower_bound,
    }
}

#[test]
fn player_step_allocates_nothing() {
    let set = SupervisorSet {
        events: vec![
            CompiledEvent {
                name: "go".into(),
                controllable: true,
            },
            CompiledEvent {
                name: "turn".into(),
                controllable: true,
            },
            CompiledEvent {
                name: "hit".into(),
                controllable: false,
            },
            CompiledEvent {
                name: "zero".into(),
                controllable: true,
            },
        ],
        supervisors: vec![
            CompiledSupervisor {
                name: "motion".into(),
                alphabet: vec![0, 1, 2],
                states: vec![
                    CompiledState {
                        transitions: vec![
                            transition(0, 1, 40_000, 0),
                            transition(1, 0, 20_000, 2),
                            transition(2, 1, 0xFFFF, 0),
                        ],
                    },
                    CompiledState {
                        transitions: vec![transition(1, 0, 0xFFFF, 1), transition(2, 1, 0xFFFF, 0)],
                    },
                ],
            },
            CompiledSupervisor {
                name: "idle".into(),
                alphabet: vec![3],
                states: vec![CompiledState {
                    transitions: vec![transition(3, 0, 0, 0)],
                }],
            },
        ],
    };
    let mut player = Player::new(set, 1, 0).expect("player");
    let mut frame = SensorFrame::empty(0);
    let mut command = ActuatorCommand::idle(0, 0);
    let mut callbacks = Toggle;
    // Warm up (the zero-weight warning is logged once, outside the measured ticks).
    for tick in 1..=10 {
        frame.tick = tick;
        player.step(&frame, &mut callbacks, &mut command);
    }
    let before = thread_allocations();
    for tick in 11..=1_000 {
        frame.tick = tick;
        player.step(&frame, &mut callbacks, &mut command);
    }
    assert_eq!(thread_allocations() - before, 0);
}
