//! The ptSCT player against the rules of docs/ptsct.md sections 3, 4, 5.2, 8.4 and 13, with the reference's numbers.

use supervisor_gen::compiled::{
    CompiledEvent, CompiledState, CompiledSupervisor, CompiledTransition, SupervisorSet,
    prob_to_q16,
};
use swarm_contract::messages::{ActuatorCommand, SensorFrame};
use swarm_contract::player::{EventCallbacks, Player};

const SEED: u64 = 20_190_101;

/// (event, target, probability, lower bound); uncontrollable transitions ignore the last two.
type Edge = (u8, u16, f64, u16);

fn events(spec: &[(&str, bool)]) -> Vec<CompiledEvent> {
    spec.iter()
        .map(|&(name, controllable)| CompiledEvent {
            name: name.to_owned(),
            controllable,
        })
        .collect()
}

fn supervisor(name: &str, alphabet: &[u8], states: &[&[Edge]]) -> CompiledSupervisor {
    CompiledSupervisor {
        name: name.to_owned(),
        alphabet: alphabet.to_vec(),
        states: states
            .iter()
            .map(|edges| CompiledState {
                transitions: edges
                    .iter()
                    .map(|&(event, target, p, lower_bound)| CompiledTransition {
                        event,
                        target,
                        prob_q16: prob_to_q16(p),
                        lower_bound,
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// Check callbacks driven by a per-tick script; actions are recorded.
struct Script<F: FnMut(u64, u8) -> bool> {
    occurs: F,
    tick: u64,
    acted: Vec<u8>,
}

impl<F: FnMut(u64, u8) -> bool> EventCallbacks for Script<F> {
    fn check(&mut self, event: u8, frame: &SensorFrame) -> bool {
        self.tick = frame.tick;
        (self.occurs)(frame.tick, event)
    }
    fn act(&mut self, event: u8, _frame: &SensorFrame, command: &mut ActuatorCommand) {
        self.acted.push(event);
        command.wheels = [f32::from(event), 0.0];
    }
}

fn script<F: FnMut(u64, u8) -> bool>(occurs: F) -> Script<F> {
    Script {
        occurs,
        tick: 0,
        acted: Vec::new(),
    }
}

/// Steps the player once and returns the events fired, in order.
fn step(player: &mut Player, callbacks: &mut impl EventCallbacks) -> Vec<u8> {
    let mut frame = SensorFrame::empty(0);
    frame.tick = player.tick() + 1;
    let mut command = ActuatorCommand::idle(0, frame.tick);
    player.step(&frame, callbacks, &mut command);
    command.fired_events().to_vec()
}

fn never(_: u64, _: u8) -> bool {
    false
}

/// Counts of the event fired in tick `tick` over `robots` independent robots of one run.
fn tally(set: &SupervisorSet, robots: u32, tick: u64) -> Vec<u32> {
    let mut counts = vec![0u32; set.events.len()];
    for robot in 0..robots {
        let mut player = Player::new(set.clone(), SEED, robot).expect("player");
        let mut callbacks = script(never);
        let mut fired = Vec::new();
        for _ in 0..tick {
            fired = step(&mut player, &mut callbacks);
        }
        assert_eq!(
            fired.len(),
            1,
            "robot {robot} fired {fired:?} in tick {tick}"
        );
        counts[usize::from(fired[0])] += 1;
    }
    counts
}

/// Asserts a frequency within 5 standard deviations of a binomial proportion (false failure rate < 1e-6).
fn assert_proportion(count: u32, samples: u32, p: f64, what: &str) {
    let observed = f64::from(count) / f64::from(samples);
    let tolerance = 5.0 * (p * (1.0 - p) / f64::from(samples)).sqrt();
    assert!(
        (observed - p).abs() <= tolerance,
        "{what}: observed {observed:.4}, expected {p:.4} ± {tolerance:.4} ({count}/{samples})"
    );
}

#[test]
fn uncontrollable_events_fire_before_controllable() {
    // a=0, b=1 controllable, u=2 uncontrollable. q0 -a-> q1, q0 -u-> q2, q2 -b-> q0 (T 0).
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true), ("u", false)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1, 2],
            &[&[(0, 1, 1.0, 0), (2, 2, 0.0, 0)], &[], &[(1, 0, 1.0, 0)]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(|tick, event| tick == 1 && event == 2);
    // u is applied first, so a (enabled in q0 before u) is no longer possible; b reacts in the same tick
    // because a state entered by an uncontrollable event has counter 0 and b's bound is 0.
    assert_eq!(step(&mut player, &mut callbacks), vec![2, 1]);
    assert_eq!(player.states(), &[0]);
    assert_eq!(callbacks.acted, vec![1]);
}

#[test]
fn at_most_one_controllable_event_fires_per_tick() {
    // Three controllable self-loops, all always enabled.
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true), ("c", true)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1, 2],
            &[&[(0, 0, 1.0, 0), (1, 0, 1.0, 0), (2, 0, 1.0, 0)]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(never);
    for tick in 1..=200 {
        assert_eq!(step(&mut player, &mut callbacks).len(), 1, "tick {tick}");
    }
    assert_eq!(callbacks.acted.len(), 200);
}

#[test]
fn state_entered_by_controllable_event_has_counter_one_next_tick() {
    // q0 -a-> q1 (T 0); q1 -b-> q0 with T 2: entered at tick 1, counter 1 at tick 2, 2 at tick 3.
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1],
            &[&[(0, 1, 1.0, 0)], &[(1, 0, 1.0, 2)]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(never);
    assert_eq!(step(&mut player, &mut callbacks), vec![0]);
    assert_eq!(step(&mut player, &mut callbacks), Vec::<u8>::new());
    assert_eq!(step(&mut player, &mut callbacks), vec![1]);
}

#[test]
fn state_entered_by_uncontrollable_event_has_counter_zero_in_the_same_tick() {
    // q0 -u-> q1; q1 -b-> q0 with T 1: u at tick 1 gives counter 0 (b waits), counter 1 at tick 2.
    let set = SupervisorSet {
        events: events(&[("b", true), ("u", false)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1],
            &[&[(1, 1, 0.0, 0)], &[(0, 0, 1.0, 1)]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(|tick, event| tick == 1 && event == 1);
    assert_eq!(step(&mut player, &mut callbacks), vec![1]);
    assert_eq!(step(&mut player, &mut callbacks), vec![0]);
}

#[test]
fn self_loop_restarts_only_its_own_counter() {
    // q0 with self-loops a (T 2) and b (T 3), entered at tick 0.
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1],
            &[&[(0, 0, 1.0, 2), (1, 0, 1.0, 3)]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(never);
    let fired: Vec<Vec<u8>> = (1..=5).map(|_| step(&mut player, &mut callbacks)).collect();
    // t1: nothing; t2: a (counter 2); t3: b (counter 3, not restarted by a); t4: a (2 since t2); t5: nothing.
    assert_eq!(fired, vec![vec![], vec![0], vec![1], vec![0], vec![]]);
}

#[test]
fn section_4_product_probabilities_before_and_after_the_lower_bound() {
    // Section 4: Ga has a (P 0.5, T 2), b (P 0.5, T 0); Gb has a (P 0.4, T 5), c (P 0.6, T 0); all self-loops.
    // Before counter 5: Φ = {b, c} with 0.5/1.1 and 0.6/1.1. At tick 5: Φ = {a, b, c} with 0.2/1.3, 0.5/1.3,
    // 0.6/1.3 (b and c firing as self-loops never restart a's counter).
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true), ("c", true)]),
        supervisors: vec![
            supervisor("Ga", &[0, 1], &[&[(0, 0, 0.5, 2), (1, 0, 0.5, 0)]]),
            supervisor("Gb", &[0, 2], &[&[(0, 0, 0.4, 5), (2, 0, 0.6, 0)]]),
        ],
    };
    let robots = 20_000;
    let early = tally(&set, robots, 1);
    assert_eq!(early[0], 0, "a must wait for its lower bound 5");
    assert_proportion(early[1], robots, 0.5 / 1.1, "b before the bound");
    assert_proportion(early[2], robots, 0.6 / 1.1, "c before the bound");
    let late = tally(&set, robots, 5);
    assert_proportion(late[0], robots, 0.2 / 1.3, "a at the bound");
    assert_proportion(late[1], robots, 0.5 / 1.3, "b at the bound");
    assert_proportion(late[2], robots, 0.6 / 1.3, "c at the bound");
}

#[test]
fn event_is_disabled_if_any_owner_lacks_its_transition() {
    // a is owned by S1 and S2; only S1 has it in its current state, so only b can ever fire.
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true)]),
        supervisors: vec![
            supervisor("S1", &[0], &[&[(0, 0, 1.0, 0)]]),
            supervisor("S2", &[0, 1], &[&[(1, 0, 1.0, 0)]]),
        ],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(never);
    for _ in 0..100 {
        assert_eq!(step(&mut player, &mut callbacks), vec![1]);
    }
}

#[test]
fn uncontrollable_event_not_enabled_in_every_owner_is_skipped_and_counted() {
    // A7: u1=0 and u2=1 occur together. S: q0 -u1-> q1, q0 -u2-> q2; q1 has no u2. Ascending id applies u1
    // first, then u2 is undefined in q1: skipped and counted, the supervisor stays in q1.
    let set = SupervisorSet {
        events: events(&[("u1", false), ("u2", false)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1],
            &[&[(0, 1, 0.0, 0), (1, 2, 0.0, 0)], &[], &[]],
        )],
    };
    let mut player = Player::new(set, SEED, 0).expect("player");
    let mut callbacks = script(|tick, _| tick == 1);
    assert_eq!(step(&mut player, &mut callbacks), vec![0]);
    assert_eq!(player.states(), &[1]);
    assert_eq!(player.mismatches(), 1);
}

#[test]
fn zero_weights_fall_back_to_a_uniform_choice() {
    let set = SupervisorSet {
        events: events(&[("a", true), ("b", true)]),
        supervisors: vec![supervisor(
            "S",
            &[0, 1],
            &[&[(0, 0, 0.0, 0), (1, 0, 0.0, 0)]],
        )],
    };
    let robots = 10_000;
    let counts = tally(&set, robots, 1);
    assert_proportion(counts[0], robots, 0.5, "a with weight 0");
    assert_proportion(counts[1], robots, 0.5, "b with weight 0");
}

#[test]
fn raw_weights_one_and_no_timers_reproduce_nadzoru2_uniform_choice() {
    // Section 13: weights all 1, T 0. S1 owns a, b, d; S2 owns a, c, e but lacks e in its state, so e is
    // disabled and the choice is uniform over {a, b, c, d}, the shared a included (weight 1 × 1).
    let set = SupervisorSet {
        events: events(&[
            ("a", true),
            ("b", true),
            ("c", true),
            ("d", true),
            ("e", true),
        ]),
        supervisors: vec![
            supervisor(
                "S1",
                &[0, 1, 3, 4],
                &[&[
                    (0, 0, 1.0, 0),
                    (1, 0, 1.0, 0),
                    (3, 0, 1.0, 0),
                    (4, 0, 1.0, 0),
                ]],
            ),
            supervisor("S2", &[0, 2, 4], &[&[(0, 0, 1.0, 0), (2, 0, 1.0, 0)]]),
        ],
    };
    let robots = 20_000;
    let counts = tally(&set, robots, 1);
    assert_eq!(counts[4], 0, "e lacks a transition in S2");
    for (event, name) in [(0, "a"), (1, "b"), (2, "c"), (3, "d")] {
        assert_proportion(counts[event], robots, 0.25, name);
    }
}

/// A set with timers, self-loops, uncontrollable events and random choices, for whole-run comparisons.
fn busy_set() -> SupervisorSet {
    SupervisorSet {
        events: events(&[
            ("go", true),
            ("turn", true),
            ("wait", true),
            ("hit", false),
            ("free", false),
        ]),
        supervisors: vec![
            supervisor(
                "motion",
                &[0, 1, 2, 3, 4],
                &[
                    &[(0, 1, 0.7, 0), (1, 0, 0.3, 1), (3, 2, 0.0, 0)],
                    &[(1, 0, 0.5, 2), (2, 1, 0.5, 0), (3, 2, 0.0, 0)],
                    &[(2, 2, 1.0, 1), (4, 0, 0.0, 0)],
                ],
            ),
            supervisor("pace", &[1, 2], &[&[(1, 0, 0.6, 3), (2, 0, 0.4, 0)]]),
        ],
    }
}

fn busy_sensor(tick: u64, event: u8) -> bool {
    (event == 3 && tick % 7 == 3) || (event == 4 && tick % 5 == 1)
}

#[test]
fn snapshot_and_restore_continue_exactly_like_an_uninterrupted_player() {
    let mut original = Player::new(busy_set(), SEED, 7).expect("player");
    let mut callbacks = script(busy_sensor);
    for _ in 0..40 {
        step(&mut original, &mut callbacks);
    }
    let snapshot = original.snapshot();
    let mut restored = Player::new(busy_set(), SEED, 7).expect("player");
    restored.restore(&snapshot, 40).expect("restore");
    let mut other_callbacks = script(busy_sensor);
    for tick in 41..=200 {
        let a = step(&mut original, &mut callbacks);
        let b = step(&mut restored, &mut other_callbacks);
        assert_eq!(a, b, "tick {tick}");
        assert_eq!(original.snapshot(), restored.snapshot(), "tick {tick}");
    }
}

#[test]
fn a_fixed_seed_gives_the_same_run_and_another_seed_a_different_one() {
    let run = |seed: u64| -> Vec<Vec<u8>> {
        let mut player = Player::new(busy_set(), seed, 3).expect("player");
        let mut callbacks = script(busy_sensor);
        (0..300)
            .map(|_| step(&mut player, &mut callbacks))
            .collect()
    };
    assert_eq!(run(SEED), run(SEED));
    assert_ne!(run(SEED), run(SEED + 1));
}

#[test]
fn restoring_a_snapshot_of_another_set_is_rejected() {
    let mut player = Player::new(busy_set(), SEED, 0).expect("player");
    let mut snapshot = player.snapshot();
    snapshot.states[0] = 3;
    let error = player
        .restore(&snapshot, 0)
        .expect_err("state 3 does not exist");
    assert!(
        error
            .to_string()
            .contains("supervisor 0 is in state 3, it has 3 states"),
        "{error}"
    );
}
