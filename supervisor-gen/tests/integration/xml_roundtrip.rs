//! The reader and writer of the thesis XML format (docs/ptsct.md section 10): the section 10.3 worked example parses
//! with its defaults, and what the writer produces reads back to the same automaton.

use std::path::PathBuf;

use supervisor_gen::architecture::Architecture;
use supervisor_gen::automaton::{Automaton, EventTable, ModelKind};
use supervisor_gen::convert::{to_automaton, to_project};
use supervisor_gen::pipeline::{SynthesisOptions, synthesize};
use supervisor_gen::validate::{CheckedModel, ValidateOptions, validate};
use supervisor_gen::xml_read::read_model;
use supervisor_gen::xml_write::to_xml;

fn fixture(name: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name);
    std::fs::read_to_string(&path).expect("fixture is readable")
}

/// Reads and validates one model text; panics with the diagnostics if it has errors.
fn checked(file: &str, text: &str, role: Option<ModelKind>) -> CheckedModel {
    let source = read_model(file, text, role).unwrap_or_else(|d| panic!("{d:#?}"));
    let validation = validate(&[source], ValidateOptions::default());
    let mut models = validation
        .models
        .unwrap_or_else(|| panic!("{:#?}", validation.diagnostics));
    models.remove(0)
}

/// Writes `automaton`, reads the text back against a copy of the same event table and returns the result.
fn round_trip(automaton: &Automaton, events: &EventTable) -> (String, Automaton) {
    let text = to_xml(automaton, events);
    let model = checked("written.xml", &text, None);
    let mut table = events.clone();
    let back = to_automaton(&model, &mut table).expect("converts");
    assert_eq!(&table, events, "reading back must not add events");
    (text, back)
}

#[test]
fn worked_example_10_3_parses_with_its_defaults() {
    let model = checked("example_10_3.xml", &fixture("example_10_3.xml"), None);
    assert_eq!(model.name, "example");
    assert_eq!(model.kind, ModelKind::Spec);
    let mut events = EventTable::new();
    let a = to_automaton(&model, &mut events).expect("converts");
    let id = |n: &str| events.lookup(n).expect("declared");
    let q = |n: &str| a.state_by_name(n).expect("declared");
    assert_eq!(a.state_count(), 3);
    assert_eq!(a.transition_count(), 6);
    assert_eq!(a.initial(), q("q0"));
    assert!(a.is_marked(q("q0")) && !a.is_marked(q("q1")) && !a.is_marked(q("q2")));
    assert!(events.is_controllable(id("a")) && !events.is_controllable(id("u")));
    let label = |s: &str, e: &str| {
        let t = a.transition(q(s), id(e)).expect("transition exists");
        (a.state_name(t.target).to_owned(), t.prob, t.lower_bound)
    };
    assert_eq!(label("q0", "a"), ("q1".into(), 0.8, 2));
    assert_eq!(
        label("q0", "b"),
        ("q2".into(), 0.2, 0),
        "time defaults to 0"
    );
    assert_eq!(
        label("q1", "a"),
        ("q1".into(), 1.0, 0),
        "prob defaults to 1"
    );
    assert_eq!(label("q1", "u"), ("q0".into(), 1.0, 0));
    assert_eq!(label("q2", "b"), ("q0".into(), 1.0, 0));
    assert_eq!(
        label("q2", "c"),
        ("q1".into(), 3.0, 0),
        "weights need not sum to 1"
    );
}

#[test]
fn worked_example_round_trip_is_stable() {
    let model = checked("example_10_3.xml", &fixture("example_10_3.xml"), None);
    let mut events = EventTable::new();
    let original = to_automaton(&model, &mut events).expect("converts");
    let (first_text, back) = round_trip(&original, &events);
    assert_eq!(back, original);
    let (second_text, _) = round_trip(&back, &events);
    assert_eq!(second_text, first_text, "writing is deterministic");
    assert!(
        first_text.contains(r#"<state name="q0" i="1" m="1"/>"#),
        "canonical 1/0 flags"
    );
    assert!(
        first_text.contains(r#"<transition src="q1" dst="q0" event="u"/>"#),
        "no prob/time on uncontrollable"
    );
    let order: Vec<usize> = ["<states>", "<events>", "<transitions>"]
        .iter()
        .map(|tag| first_text.find(tag).expect("section written"))
        .collect();
    assert!(order.is_sorted(), "DTD child order");
}

#[test]
fn children_in_any_order_and_long_type_names_are_accepted() {
    let text = r#"<automata name="m" type="free-behaviour">
  <transitions><transition src="a" dst="a" event="e"/></transitions>
  <events><event name="e" con="true"/></events>
  <states><state name="a" i="true" m="TRUE"/></states>
</automata>"#;
    let model = checked("m.xml", text, None);
    assert_eq!(model.kind, ModelKind::Plant);
    assert!(model.states[0].initial && model.states[0].marked && model.events[0].controllable);
}

#[test]
fn synthesised_supervisors_are_written_as_type_supervisor_and_read_back_identically() {
    let models: Vec<CheckedModel> = [
        ("factory/machine1.xml", ModelKind::Plant),
        ("factory/machine2.xml", ModelKind::Plant),
        ("factory/buffer.xml", ModelKind::Spec),
    ]
    .iter()
    .map(|(f, role)| checked(f, &fixture(f), Some(*role)))
    .collect();
    let project = to_project(&models).expect("converts");
    for mode in [Architecture::Monolithic, Architecture::LocalModular] {
        let synthesis =
            synthesize(&project, mode, SynthesisOptions::default()).expect("synthesises");
        let events = &synthesis.normalised.events;
        for s in &synthesis.supervisors {
            let (text, back) = round_trip(&s.supervisor, events);
            assert!(text.contains(r#"type="supervisor""#));
            assert_eq!(back, s.supervisor, "{mode}: {}", s.name);
        }
    }
}

#[test]
fn normalised_probabilities_survive_the_round_trip_exactly() {
    let text = r#"<automata name="w" type="supervisor">
  <states><state name="s" i="1" m="1"/></states>
  <events><event name="a" con="1"/><event name="b" con="1"/><event name="c" con="1"/></events>
  <transitions>
    <transition src="s" dst="s" event="a" prob="0.3333333333333333" time="65535"/>
    <transition src="s" dst="s" event="b" prob="0.1"/>
    <transition src="s" dst="s" event="c" prob="0.5666666666666667"/>
  </transitions>
</automata>"#;
    let model = checked("w.xml", text, None);
    let mut events = EventTable::new();
    let a = to_automaton(&model, &mut events).expect("converts");
    let (_, back) = round_trip(&a, &events);
    assert_eq!(back, a);
    let probs: Vec<f64> = back
        .transitions(back.initial())
        .iter()
        .map(|t| t.prob)
        .collect();
    assert_eq!(probs, [1.0 / 3.0, 0.1, 0.5666666666666667]);
}

#[test]
fn nadzoru_import_equals_the_same_machine_in_thesis_format() {
    let nadzoru = checked(
        "machine.xml",
        &fixture("nadzoru/machine.xml"),
        Some(ModelKind::Plant),
    );
    let thesis = checked(
        "machine1.xml",
        &fixture("factory/machine1.xml"),
        Some(ModelKind::Plant),
    );
    let mut events = EventTable::new();
    let mut from_nadzoru = to_automaton(&nadzoru, &mut events).expect("converts");
    let from_thesis = to_automaton(&thesis, &mut events).expect("converts");
    assert_eq!(
        from_nadzoru.name(),
        "machine",
        "Nadzoru2 models are named after the file stem"
    );
    from_nadzoru.set_name("machine1");
    assert_eq!(from_nadzoru, from_thesis);
}

mod generated {
    use super::*;
    use proptest::prelude::*;

    /// A random deterministic supervisor: names with XML special characters, random controllability, positive
    /// weights and lower bounds up to 65 535.
    fn supervisor() -> impl Strategy<Value = (Automaton, EventTable)> {
        let states = 1..6usize;
        let events = prop::collection::vec(any::<bool>(), 1..5);
        (states, events)
            .prop_flat_map(|(n, controllable)| {
                let edges = prop::collection::vec(
                    (
                        0..n,
                        0..controllable.len(),
                        0..n,
                        0.001f64..10.0,
                        0u32..=65_535,
                    ),
                    0..12,
                );
                let marked = prop::collection::vec(any::<bool>(), n);
                (Just(controllable), edges, marked)
            })
            .prop_map(|(controllable, edges, marked)| {
                let mut events = EventTable::new();
                let ids: Vec<_> = controllable
                    .iter()
                    .enumerate()
                    .map(|(i, &c)| {
                        events
                            .intern(&format!("e{i}<&\"'>"), c)
                            .expect("few events")
                    })
                    .collect();
                let mut a = Automaton::new("gen & <sup>", ModelKind::Supervisor);
                let states: Vec<_> = marked
                    .iter()
                    .enumerate()
                    .map(|(i, &m)| {
                        a.add_state(format!("s{i} \"q\" & <x>"), m || i == 0)
                            .expect("few states")
                    })
                    .collect();
                for &id in &ids {
                    a.add_event(id);
                }
                for (from, e, to, p, t) in edges {
                    let (p, t) = if events.is_controllable(ids[e]) {
                        (p, t)
                    } else {
                        (1.0, 0)
                    };
                    // A second edge on the same (state, event) is simply not added: automata are deterministic.
                    let _ = a.add_transition(states[from], ids[e], states[to], p, t);
                }
                (a, events)
            })
    }

    proptest! {
        #[test]
        fn writing_then_reading_gives_the_same_automaton((a, events) in supervisor()) {
            let (_, back) = round_trip(&a, &events);
            prop_assert_eq!(back, a);
        }
    }
}
