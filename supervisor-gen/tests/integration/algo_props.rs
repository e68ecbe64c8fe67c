//! Property tests of the algorithms on random small automata: SupC against a brute-force reference, product
//! laws, and minimisation.

use proptest::prelude::*;
use supervisor_gen::architecture::compare_languages;
use supervisor_gen::automaton::{Automaton, EventId, EventTable, ModelKind, StateId};
use supervisor_gen::minimise::minimise;
use supervisor_gen::product::{product, product_with_tuples};
use supervisor_gen::supc::supc;
use supervisor_gen::trim::{accessible, blocking_states};

/// Events 0,1 controllable (a, b); 2,3 uncontrollable (u, v).
fn table() -> EventTable {
    let mut ev = EventTable::new();
    for (n, c) in [("a", true), ("b", true), ("u", false), ("v", false)] {
        ev.intern(n, c).unwrap();
    }
    ev
}

/// A random deterministic automaton with 1..=max_states states over the given events.
fn arb_automaton(
    kind: ModelKind,
    max_states: usize,
    events: Vec<u16>,
) -> impl Strategy<Value = Automaton> {
    (1..=max_states).prop_flat_map(move |n| {
        let evs = events.clone();
        (
            proptest::collection::vec(any::<bool>(), n),
            proptest::collection::vec((0..n, 0..evs.len(), 0..n, 1u32..4, 0u32..3), 0..(3 * n)),
            proptest::collection::vec(0..evs.len(), 0..2),
        )
            .prop_map(move |(marked, trs, extra)| {
                let mut a = Automaton::new("m", kind);
                for (i, &m) in marked.iter().enumerate() {
                    a.add_state(format!("s{i}"), m || i == 0 && kind == ModelKind::Plant)
                        .unwrap();
                }
                for (from, e, to, w, lb) in trs {
                    let _ = a.add_transition(
                        StateId(from as u32),
                        EventId(evs[e]),
                        StateId(to as u32),
                        f64::from(w) / 4.0,
                        lb,
                    );
                }
                for e in extra {
                    a.add_event(EventId(evs[e]));
                }
                a
            })
    })
}

/// Is the set `q` (over K's states) a valid supervisor: contains q0, all states accessible and coaccessible
/// within `q`, and closed under uncontrollable events the plant allows?
fn valid(k: &Automaton, g: &Automaton, g_of: &[StateId], ev: &EventTable, q: &[bool]) -> bool {
    if !q[k.initial().index()] {
        return false;
    }
    for x in k.states().filter(|x| q[x.index()]) {
        for t in g
            .transitions(g_of[x.index()])
            .iter()
            .filter(|t| !ev.is_controllable(t.event))
        {
            match k.transition(x, t.event) {
                Some(kt) if q[kt.target.index()] => {}
                _ => return false,
            }
        }
    }
    // Independent fixpoints (not the library's trim code): reachable from q0 and reaching a marked state, in q.
    let n = k.state_count();
    let mut acc = vec![false; n];
    acc[k.initial().index()] = true;
    let mut co: Vec<bool> = (0..n)
        .map(|x| q[x] && k.is_marked(StateId(x as u32)))
        .collect();
    loop {
        let mut changed = false;
        for x in k.states().filter(|x| q[x.index()]) {
            for t in k.transitions(x).iter().filter(|t| q[t.target.index()]) {
                if acc[x.index()] && !acc[t.target.index()] {
                    acc[t.target.index()] = true;
                    changed = true;
                }
                if co[t.target.index()] && !co[x.index()] {
                    co[x.index()] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    k.states()
        .filter(|x| q[x.index()])
        .all(|x| acc[x.index()] && co[x.index()])
}

/// Number of classes of the coarsest relation where equivalent states agree on marking and, for every
/// (event, P in Q0.16, T) label, both lack it or both have it into equivalent states (naive pair fixpoint).
fn naive_class_count(a: &Automaton) -> usize {
    let n = a.state_count();
    let label = |t: &supervisor_gen::automaton::Transition| {
        (
            t.event,
            supervisor_gen::compiled::prob_to_q16(t.prob),
            t.lower_bound,
        )
    };
    let mut distinct: Vec<Vec<bool>> = (0..n)
        .map(|x| {
            (0..n)
                .map(|y| a.is_marked(StateId(x as u32)) != a.is_marked(StateId(y as u32)))
                .collect()
        })
        .collect();
    loop {
        let mut changed = false;
        for x in 0..n {
            for y in 0..n {
                if distinct[x][y] {
                    continue;
                }
                let (tx, ty) = (
                    a.transitions(StateId(x as u32)),
                    a.transitions(StateId(y as u32)),
                );
                let differ = tx.len() != ty.len()
                    || tx.iter().zip(ty).any(|(p, q)| {
                        label(p) != label(q) || distinct[p.target.index()][q.target.index()]
                    });
                if differ {
                    distinct[x][y] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    (0..n).filter(|&x| (0..x).all(|y| distinct[x][y])).count()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn supc_is_controllable_nonblocking_and_maximally_permissive(
        g in arb_automaton(ModelKind::Plant, 3, vec![0, 1, 2, 3]),
        e in arb_automaton(ModelKind::Spec, 4, vec![0, 1, 2, 3]),
    ) {
        let ev = table();
        let k = product_with_tuples("K", ModelKind::Supervisor, &ev, &[&g, &e]);
        let n = k.automaton.state_count();
        prop_assume!(n <= 14);
        let g_of: Vec<StateId> = k.tuples.chunks_exact(2).map(|t| StateId(t[0])).collect();
        let r = supc(&k.automaton, &g, &g_of, &ev);
        let mut kept = vec![false; n];
        for &x in &r.kept {
            kept[x.index()] = true;
        }
        // Brute force: the union of all valid state subsets of K.
        let mut union = vec![false; n];
        let mut any = false;
        for mask in 0u32..(1 << n) {
            let q: Vec<bool> = (0..n).map(|i| mask & (1 << i) != 0).collect();
            if valid(&k.automaton, &g, &g_of, &ev, &q) {
                any = true;
                for i in 0..n {
                    union[i] |= q[i];
                }
            }
        }
        if any {
            prop_assert!(valid(&k.automaton, &g, &g_of, &ev, &union));
            prop_assert_eq!(&kept, &union);
            prop_assert!(!r.is_empty());
            prop_assert!(blocking_states(&r.supervisor).is_empty());
            // Controllability on the result itself, through the kept mapping.
            for (s, &x) in r.kept.iter().enumerate() {
                for t in g.transitions(g_of[x.index()]).iter().filter(|t| !ev.is_controllable(t.event)) {
                    prop_assert!(r.supervisor.transition(StateId(s as u32), t.event).is_some());
                }
            }
        } else {
            prop_assert!(r.is_empty());
        }
        // Every removed state is recorded exactly once.
        prop_assert_eq!(r.removed.len() + r.kept.len(), n);
    }

    #[test]
    fn product_is_commutative_and_associative_up_to_renaming(
        a in arb_automaton(ModelKind::Spec, 3, vec![0, 1, 2]),
        b in arb_automaton(ModelKind::Spec, 3, vec![1, 2, 3]),
        c in arb_automaton(ModelKind::Spec, 3, vec![0, 3]),
    ) {
        let ev = table();
        let ab = product("ab", ModelKind::Spec, &ev, &[&a, &b]);
        let ba = product("ba", ModelKind::Spec, &ev, &[&b, &a]);
        let cmp = compare_languages(&ev, &ab, &ba);
        prop_assert!(cmp.same_language && cmp.same_marked_language && cmp.label_mismatches.is_empty());
        prop_assert_eq!((ab.state_count(), ab.transition_count()), (ba.state_count(), ba.transition_count()));
        let ab_c = product("ab_c", ModelKind::Spec, &ev, &[&ab, &c]);
        let bc = product("bc", ModelKind::Spec, &ev, &[&b, &c]);
        let a_bc = product("a_bc", ModelKind::Spec, &ev, &[&a, &bc]);
        let abc = product("abc", ModelKind::Spec, &ev, &[&a, &b, &c]);
        for other in [&a_bc, &abc] {
            let cmp = compare_languages(&ev, &ab_c, other);
            prop_assert!(cmp.same_language && cmp.same_marked_language && cmp.label_mismatches.is_empty());
            prop_assert_eq!(ab_c.state_count(), other.state_count());
            prop_assert_eq!(ab_c.transition_count(), other.transition_count());
        }
    }

    #[test]
    fn minimisation_preserves_language_and_labels(a in arb_automaton(ModelKind::Spec, 6, vec![0, 1, 2, 3])) {
        let ev = table();
        let acc = accessible(&a);
        let m = minimise(&a);
        let cmp = compare_languages(&ev, &acc, &m);
        prop_assert!(cmp.same_language && cmp.same_marked_language, "{:?}", cmp.counterexample);
        prop_assert!(cmp.label_mismatches.is_empty());
        prop_assert_eq!(m.state_count(), naive_class_count(&acc));
        prop_assert_eq!(minimise(&m).state_count(), m.state_count());
    }
}
