//! Pipeline rules on probabilities: input normalisation (5.1), rule A5, raw weights, and the monolithic offline
//! renormalisation that local supervisors must not get (5.2).

use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::{Automaton, EventTable, ModelKind, Project};
use supervisor_gen::pipeline::{SynthesisOptions, synthesize};

/// Plant: g0 -a-> g1 -u-> g0 (u uncontrollable), g0 -b-> g0. Spec: weights a = 3, b = `b_weight` at e0, and u
/// is never allowed, so SupC must cut `a` and leave only `b` at the initial state.
fn project_with(b_weight: f64) -> Project {
    let mut ev = EventTable::new();
    let a = ev.intern("a", true).unwrap();
    let b = ev.intern("b", true).unwrap();
    let u = ev.intern("u", false).unwrap();
    let mut g = Automaton::new("G", ModelKind::Plant);
    let g0 = g.add_state("g0", true).unwrap();
    let g1 = g.add_state("g1", false).unwrap();
    g.add_transition(g0, a, g1, 1.0, 0).unwrap();
    g.add_transition(g0, b, g0, 1.0, 0).unwrap();
    g.add_transition(g1, u, g0, 1.0, 0).unwrap();
    let mut e = Automaton::new("E", ModelKind::Spec);
    let e0 = e.add_state("e0", true).unwrap();
    e.add_transition(e0, a, e0, 3.0, 0).unwrap();
    e.add_transition(e0, b, e0, b_weight, 4).unwrap();
    e.add_event(u);
    Project {
        events: ev,
        plants: vec![g],
        specs: vec![e],
    }
}

fn project() -> Project {
    project_with(1.0)
}

fn initial_labels(a: &Automaton) -> Vec<(f64, u32)> {
    a.transitions(a.initial())
        .iter()
        .map(|t| (t.prob, t.lower_bound))
        .collect()
}

#[test]
fn monolithic_supervisor_is_renormalised_after_synthesis() {
    let s = synthesize(
        &project(),
        Architecture::Monolithic,
        SynthesisOptions::default(),
    )
    .unwrap();
    let sup = &s.supervisors[0];
    // Before: b kept its normalised input probability 1/4; after renormalisation it is the only choice.
    assert_eq!(initial_labels(&sup.unminimised), vec![(0.25, 4)]);
    assert_eq!(initial_labels(&sup.supervisor), vec![(1.0, 4)]);
}

#[test]
fn local_modular_supervisors_keep_their_per_state_probabilities() {
    let s = synthesize(
        &project(),
        Architecture::LocalModular,
        SynthesisOptions::default(),
    )
    .unwrap();
    assert_eq!(
        initial_labels(&s.supervisors[0].supervisor),
        vec![(0.25, 4)]
    );
}

#[test]
fn raw_weights_are_kept_through_synthesis() {
    let raw = SynthesisOptions {
        raw_weights: true,
        ..SynthesisOptions::default()
    };
    let s = synthesize(&project_with(0.5), Architecture::Monolithic, raw).unwrap();
    let k = s.supervisors[0].target.as_ref().expect("kept by default");
    assert_eq!(initial_labels(k), vec![(3.0, 0), (0.5, 4)]);
    // No renormalisation either: the surviving weight is stored as given.
    assert_eq!(initial_labels(&s.supervisors[0].supervisor), vec![(0.5, 4)]);
}

#[test]
fn a5_plant_factors_count_only_with_thesis_literal_probabilities() {
    let p = project();
    let default = synthesize(&p, Architecture::LocalModular, SynthesisOptions::default()).unwrap();
    // K at the initial state: a = 1 × 3/4, b = 1 × 1/4 (plant factors are 1).
    assert_eq!(
        initial_labels(default.supervisors[0].target.as_ref().expect("kept")),
        vec![(0.75, 0), (0.25, 4)]
    );
    let literal = SynthesisOptions {
        thesis_literal_probabilities: true,
        ..SynthesisOptions::default()
    };
    let s = synthesize(&p, Architecture::LocalModular, literal).unwrap();
    // The plant's two controllable transitions at g0 get 1/2 each, multiplied into the product.
    assert_eq!(
        initial_labels(s.supervisors[0].target.as_ref().expect("kept")),
        vec![(0.375, 0), (0.125, 4)]
    );
}
