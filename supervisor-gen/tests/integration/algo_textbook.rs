//! Textbook SCT examples derived by hand: the small factory, mutual exclusion and an impossible specification,
//! run through the whole synthesis pipeline.

use supervisor_gen::architecture::{Architecture, Difference};
use supervisor_gen::automaton::{Automaton, EventId, EventTable, ModelKind, Project, StateId};
use supervisor_gen::pipeline::{SynthesisError, SynthesisOptions, synthesize};
use supervisor_gen::supc::RemovalReason;

/// A machine: idle (marked) -start-> working -finish-> idle; start controllable, finish uncontrollable.
fn machine(ev: &mut EventTable, i: usize) -> Automaton {
    let start = ev.intern(&format!("start{i}"), true).unwrap();
    let finish = ev.intern(&format!("finish{i}"), false).unwrap();
    let mut m = Automaton::new(format!("M{i}"), ModelKind::Plant);
    let idle = m.add_state("I", true).unwrap();
    let work = m.add_state("W", false).unwrap();
    m.add_transition(idle, start, work, 1.0, 0).unwrap();
    m.add_transition(work, finish, idle, 1.0, 0).unwrap();
    m
}

/// A one-slot buffer between machine i and machine i+1: finish_i fills it, start_{i+1} empties it.
fn buffer(ev: &mut EventTable, i: usize) -> Automaton {
    let fill = ev.intern(&format!("finish{i}"), false).unwrap();
    let take = ev.intern(&format!("start{}", i + 1), true).unwrap();
    let mut b = Automaton::new(format!("B{i}"), ModelKind::Spec);
    let empty = b.add_state("empty", true).unwrap();
    let full = b.add_state("full", false).unwrap();
    b.add_transition(empty, fill, full, 1.0, 0).unwrap();
    b.add_transition(full, take, empty, 1.0, 0).unwrap();
    b
}

fn run(a: &Automaton, ev: &EventTable, word: &[&str]) -> Option<StateId> {
    let mut s = a.initial();
    for w in word {
        let e: EventId = ev.lookup(w).unwrap();
        s = a.transition(s, e)?.target;
    }
    Some(s)
}

fn small_factory() -> Project {
    let mut ev = EventTable::new();
    let m1 = machine(&mut ev, 1);
    let m2 = machine(&mut ev, 2);
    let b = buffer(&mut ev, 1);
    Project {
        events: ev,
        plants: vec![m1, m2],
        specs: vec![b],
    }
}

#[test]
fn small_factory_supervisor_prevents_buffer_overflow_with_six_states_and_eight_transitions() {
    let p = small_factory();
    let s = synthesize(&p, Architecture::Monolithic, SynthesisOptions::default()).unwrap();
    let sup = &s.supervisors[0];
    assert_eq!(
        (sup.plant.state_count(), sup.plant.transition_count()),
        (4, 8)
    );
    assert_eq!(
        (sup.target_stats.states, sup.target_stats.transitions),
        (8, 12)
    );
    // ((W,I),full) and ((W,W),full) are bad: finish1 would overflow the buffer.
    let bad: Vec<_> = sup
        .removed
        .iter()
        .map(|r| (r.name.as_str(), r.reason))
        .collect();
    let finish1 = p.events.lookup("finish1").unwrap();
    assert_eq!(
        bad,
        vec![
            (
                "((W,I),full)",
                RemovalReason::Bad {
                    event: finish1,
                    target: None
                }
            ),
            (
                "((W,W),full)",
                RemovalReason::Bad {
                    event: finish1,
                    target: None
                }
            ),
        ]
    );
    assert_eq!(
        (
            sup.unminimised.state_count(),
            sup.unminimised.transition_count()
        ),
        (6, 8)
    );
    assert_eq!(
        (
            sup.supervisor.state_count(),
            sup.supervisor.transition_count()
        ),
        (6, 8)
    );
    let ev = &p.events;
    assert!(
        run(
            &sup.supervisor,
            ev,
            &["start1", "finish1", "start2", "start1", "finish1"]
        )
        .is_some()
    );
    // The second start1 before the buffer is emptied is disabled.
    assert!(run(&sup.supervisor, ev, &["start1", "finish1", "start1"]).is_none());
    assert!(
        run(
            &sup.supervisor,
            ev,
            &["start1", "finish1", "start2", "start1", "finish1", "start1"]
        )
        .is_none()
    );
    // start1 at (I,I,empty), start2 at (I,I,full), start1 at (I,W,empty); the other five are finish events.
    assert_eq!(sup.stats.controllable_transitions, 3);
}

#[test]
fn mutual_exclusion_allows_one_user_at_a_time() {
    let mut ev = EventTable::new();
    let mut plants = Vec::new();
    let mut spec = Automaton::new("mutex", ModelKind::Spec);
    let free = spec.add_state("free", true).unwrap();
    for i in 1..=2 {
        let acq = ev.intern(&format!("acquire{i}"), true).unwrap();
        let rel = ev.intern(&format!("release{i}"), false).unwrap();
        let mut u = Automaton::new(format!("U{i}"), ModelKind::Plant);
        let idle = u.add_state("idle", true).unwrap();
        let using = u.add_state("using", false).unwrap();
        u.add_transition(idle, acq, using, 1.0, 0).unwrap();
        u.add_transition(using, rel, idle, 1.0, 0).unwrap();
        plants.push(u);
        let busy = spec.add_state(format!("busy{i}"), false).unwrap();
        spec.add_transition(free, acq, busy, 1.0, 0).unwrap();
        spec.add_transition(busy, rel, free, 1.0, 0).unwrap();
    }
    let p = Project {
        events: ev,
        plants,
        specs: vec![spec],
    };
    let s = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default()).unwrap();
    let sup = &s.supervisors[0];
    assert_eq!(
        (sup.plant.state_count(), sup.plant.transition_count()),
        (4, 8)
    );
    assert_eq!(
        (
            sup.supervisor.state_count(),
            sup.supervisor.transition_count()
        ),
        (3, 4)
    );
    assert!(sup.removed.is_empty());
    assert!(
        run(
            &sup.supervisor,
            &p.events,
            &["acquire1", "release1", "acquire2"]
        )
        .is_some()
    );
    assert!(run(&sup.supervisor, &p.events, &["acquire1", "acquire2"]).is_none());
    // Each free-state choice gets P = 1/2 (two controllable transitions of weight 1).
    let probs: Vec<f64> = sup
        .supervisor
        .transitions(sup.supervisor.initial())
        .iter()
        .map(|t| t.prob)
        .collect();
    assert_eq!(probs, vec![0.5, 0.5]);
    let v = s.local_modular_validation.as_ref().unwrap();
    assert!(v.passed(), "{v:?}");
    assert!(v.timer_note.contains("not covered"));
}

#[test]
fn spec_forbidding_an_initial_uncontrollable_event_has_empty_supc() {
    let mut ev = EventTable::new();
    let x = ev.intern("x", false).unwrap();
    let mut g = Automaton::new("sensor", ModelKind::Plant);
    let g0 = g.add_state("g0", true).unwrap();
    g.add_transition(g0, x, g0, 1.0, 0).unwrap();
    let mut e = Automaton::new("never_x", ModelKind::Spec);
    e.add_state("e0", true).unwrap();
    e.add_event(x);
    let p = Project {
        events: ev,
        plants: vec![g],
        specs: vec![e],
    };
    for mode in [
        Architecture::Monolithic,
        Architecture::LocalModular,
        Architecture::Modular,
    ] {
        match synthesize(&p, mode, SynthesisOptions::default()) {
            Err(SynthesisError::EmptySupervisor { spec, reason }) => {
                assert_eq!(spec, "never_x");
                assert!(
                    reason.contains("initial state removed") && reason.contains("`x`"),
                    "{reason}"
                );
            }
            other => panic!("{mode}: expected an empty supervisor, got {other:?}"),
        }
    }
}

/// Three machines, two buffers: the classic non-conflicting local-modular design.
fn transfer_line(extra_free_machine: bool) -> Project {
    let mut ev = EventTable::new();
    let mut plants: Vec<Automaton> = (1..=3).map(|i| machine(&mut ev, i)).collect();
    if extra_free_machine {
        plants.push(machine(&mut ev, 4));
    }
    let specs = vec![buffer(&mut ev, 1), buffer(&mut ev, 2)];
    Project {
        events: ev,
        plants,
        specs,
    }
}

#[test]
fn local_modular_transfer_line_equals_monolithic() {
    let p = transfer_line(false);
    let s = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default()).unwrap();
    assert_eq!(s.supervisors.len(), 2);
    // Each local plant is the product of two machines.
    for sup in &s.supervisors {
        assert_eq!(sup.plant.state_count(), 4);
    }
    assert!(s.non_conflict.as_ref().unwrap().nonblocking);
    let v = s.local_modular_validation.as_ref().unwrap();
    assert!(v.passed(), "{v:?}");
    let mono = s.monolithic_reference.as_ref().unwrap();
    assert_eq!(mono.plant.state_count(), 8);
    // Same language: the modular product and the monolithic supervisor agree state for state after minimisation.
    assert_eq!(v.comparison.counterexample, None);
    let m = synthesize(&p, Architecture::Modular, SynthesisOptions::default()).unwrap();
    assert!(m.non_conflict.unwrap().nonblocking);
}

#[test]
fn w6_plant_without_specification_fails_local_modular_validation_with_shortest_string() {
    let p = transfer_line(true);
    let s = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default()).unwrap();
    let v = s.local_modular_validation.unwrap();
    assert!(!v.passed());
    let ce = v.comparison.counterexample.unwrap();
    // The monolithic supervisor (second) leaves machine 4 free; no local supervisor owns start4.
    assert_eq!(ce.string, vec!["start4"]);
    assert_eq!(ce.difference, Difference::GeneratedOnlyBySecond);
}

#[test]
fn mem_cons_of_the_synthesis_matches_the_compiled_set() {
    let p = transfer_line(false);
    let s = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default()).unwrap();
    let set = s.compile().unwrap();
    assert_eq!(set.mem_cons(), s.mem_cons);
    assert_eq!(set.supervisors.len(), 2);
}
