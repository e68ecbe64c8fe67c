//! Property tests of the compiled supervisor-set format (section 9): round trips and hostile bytes.

use proptest::prelude::*;
use supervisor_gen::automaton::{Automaton, EventId, EventTable, ModelKind, StateId};
use supervisor_gen::compiled::SupervisorSet;

/// A random project event table plus random deterministic supervisors over it.
fn arb_set() -> impl Strategy<Value = SupervisorSet> {
    (1usize..8, proptest::collection::vec(any::<bool>(), 8))
        .prop_flat_map(|(n_events, ctrl)| {
            let sup = (1usize..6).prop_flat_map(move |n_states| {
                (
                    Just(n_states),
                    0..n_states,
                    proptest::collection::vec(any::<bool>(), n_states),
                    proptest::collection::vec(
                        (
                            0..n_states,
                            0..n_events,
                            0..n_states,
                            0.0f64..=1.0,
                            0u32..70,
                        ),
                        0..20,
                    ),
                    proptest::collection::vec(0..n_events, 0..3),
                )
            });
            (
                Just(n_events),
                Just(ctrl),
                proptest::collection::vec(sup, 0..4),
            )
        })
        .prop_map(|(n_events, ctrl, sups)| {
            let mut events = EventTable::new();
            for (i, &c) in ctrl.iter().enumerate().take(n_events) {
                events.intern(&format!("ev_{i}"), c).unwrap();
            }
            let automata: Vec<Automaton> = sups
                .into_iter()
                .enumerate()
                .map(|(k, (n_states, init, marked, trs, extra))| {
                    let mut a = Automaton::new(format!("sup{k}"), ModelKind::Supervisor);
                    for (s, m) in marked.iter().enumerate().take(n_states) {
                        a.add_state(format!("q{s}"), *m).unwrap();
                    }
                    a.set_initial(StateId(init as u32)).unwrap();
                    for (from, ev, to, p, lb) in trs {
                        // Duplicates (non-determinism) are rejected by the builder; skip them.
                        let _ = a.add_transition(
                            StateId(from as u32),
                            EventId(ev as u16),
                            StateId(to as u32),
                            p,
                            lb,
                        );
                    }
                    for ev in extra {
                        a.add_event(EventId(ev as u16));
                    }
                    a
                })
                .collect();
            SupervisorSet::from_supervisors(&events, &automata).unwrap()
        })
}

proptest! {
    #[test]
    fn byte_layout_round_trips(set in arb_set()) {
        let bytes = set.to_bytes();
        let back = SupervisorSet::from_bytes(&bytes).unwrap();
        prop_assert_eq!(&back, &set);
        prop_assert_eq!(back.to_bytes(), bytes);
    }

    #[test]
    fn payload_length_equals_memcons(set in arb_set()) {
        let header: usize = 10
            + set.events.iter().map(|e| 2 + e.name.len()).sum::<usize>()
            + set.supervisors.iter().map(|s| 4 + s.name.len()).sum::<usize>();
        prop_assert_eq!(set.to_bytes().len() - header, set.mem_cons());
    }

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let _ = SupervisorSet::from_bytes(&bytes);
    }

    #[test]
    fn mutated_valid_files_never_panic(set in arb_set(), edits in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..6), cut in any::<usize>()) {
        let mut bytes = set.to_bytes();
        for (at, v) in edits {
            let i = at % bytes.len();
            bytes[i] = v;
        }
        let keep = bytes.len() - cut % (bytes.len() / 4 + 1);
        bytes.truncate(keep);
        if let Ok(parsed) = SupervisorSet::from_bytes(&bytes) {
            // Whatever parses must serialise back to exactly the same bytes.
            prop_assert_eq!(parsed.to_bytes(), bytes);
        }
    }
}
