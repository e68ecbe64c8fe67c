//! SupC (section 6.5): the supremal controllable, nonblocking sub-automaton of K = G ∥ E.
//!
//! Bad states (6.3) are found once from the plant and then propagated backwards along uncontrollable plant events
//! with a worklist, so each round costs one closure plus one trim; rounds repeat while trimming uncovers new
//! bad states. The fixpoint is the one of the section 6.5 loop; only the round numbers differ, because a state
//! that the literal loop would find bad one round later (through an uncontrollable event into a state removed
//! this round) is caught by the closure of the same round. Every removal is recorded with its reason and round,
//! for the report and the drawings.
//! P and T labels of surviving transitions are never changed here.

use crate::automaton::{Automaton, EventId, EventTable, StateId};
use crate::trim::{ReverseAdjacency, accessible_mask, coaccessible_mask, restrict};

/// Why SupC removed a state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RemovalReason {
    /// Bad (6.3): the plant can generate the uncontrollable `event` here, and the candidate supervisor either has
    /// no such transition (`target` is `None`) or its transition leads to the removed state `target` (an id of K).
    Bad {
        /// The uncontrollable event.
        event: EventId,
        /// The removed target in K, or `None` if the specification does not allow the event here.
        target: Option<StateId>,
    },
    /// No marked state is reachable any more (blocking).
    NonCoaccessible,
    /// Not reachable from the initial state any more.
    Inaccessible,
}

/// One state of K removed by SupC.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RemovedState {
    /// The state id in K.
    pub state: StateId,
    /// The state name in K.
    pub name: String,
    /// Why it was removed.
    pub reason: RemovalReason,
    /// For a bad state whose uncontrollable event leads to a removed state, that state's name in K.
    pub leads_to: Option<String>,
    /// The SupC round (from 1) in which it was removed.
    pub round: u32,
}

/// The result of [`supc`].
#[derive(Debug, Clone)]
pub struct SupcResult {
    /// The supervisor; it has no states if the initial state was removed.
    pub supervisor: Automaton,
    /// For each supervisor state, its id in K.
    pub kept: Vec<StateId>,
    /// Every removed state of K, in removal order.
    pub removed: Vec<RemovedState>,
    /// Number of rounds until the fixpoint.
    pub rounds: u32,
}

impl SupcResult {
    /// Whether no nonblocking controllable supervisor exists.
    pub fn is_empty(&self) -> bool {
        self.supervisor.state_count() == 0
    }

    /// A sentence saying why the initial state of K was removed, if it was.
    pub fn empty_reason(&self, k: &Automaton, events: &EventTable) -> Option<String> {
        if !self.is_empty() {
            return None;
        }
        if k.state_count() == 0 {
            return Some("the product of plant and specification has no states".to_owned());
        }
        let rec = self.removed.iter().find(|r| r.state == k.initial())?;
        Some(match rec.reason {
            RemovalReason::Bad { event, target: None } => format!(
                "initial state removed: uncontrollable event `{}` is possible in the plant but the specification does not allow it there",
                events.name(event)
            ),
            RemovalReason::Bad { event, target: Some(t) } => format!(
                "initial state removed: uncontrollable event `{}` from the plant leads to the removed (bad or blocking) state `{}`",
                events.name(event),
                k.state_name(t)
            ),
            RemovalReason::NonCoaccessible => {
                "initial state removed: no marked state can be reached from it without risking a bad state (blocking)".to_owned()
            }
            RemovalReason::Inaccessible => "initial state removed as inaccessible".to_owned(),
        })
    }
}

/// Computes `SupC(K, G)`.
///
/// `g_of[x]` is the plant state g(x) of each state x of K (for K = G ∥ E built by
/// [`crate::product::product_with_tuples`], the first tuple component). Uncontrollable events outside Σ(G) never
/// make a state bad (A6). K is expected to be accessible, as products are.
pub fn supc(k: &Automaton, g: &Automaton, g_of: &[StateId], events: &EventTable) -> SupcResult {
    let n = k.state_count();
    crate::progress::stage(|| format!("SupC of {} ({n} states)", k.name()));
    let rev = ReverseAdjacency::new(k);
    let mut removed = vec![false; n];
    let mut records: Vec<RemovedState> = Vec::new();
    let mut work: Vec<StateId> = Vec::new();
    let record = |records: &mut Vec<RemovedState>, x: StateId, reason, round| {
        let leads_to = match reason {
            RemovalReason::Bad {
                target: Some(t), ..
            } => Some(k.state_name(t).to_owned()),
            _ => None,
        };
        records.push(RemovedState {
            state: x,
            name: k.state_name(x).to_owned(),
            reason,
            leads_to,
            round,
        });
    };

    // Round 1 seeds: uncontrollable events the plant allows but K does not.
    for x in k.states() {
        let gx = g_of.get(x.index()).copied().unwrap_or(StateId(u32::MAX));
        let missing = g
            .transitions(gx)
            .iter()
            .find(|t| !events.is_controllable(t.event) && k.transition(x, t.event).is_none());
        if let Some(t) = missing {
            removed[x.index()] = true;
            record(
                &mut records,
                x,
                RemovalReason::Bad {
                    event: t.event,
                    target: None,
                },
                1,
            );
            work.push(x);
        }
    }

    let mut round = 1;
    loop {
        // Uncontrollable backward closure: a predecessor through an uncontrollable plant event becomes bad.
        while let Some(y) = work.pop() {
            for (x, e) in rev.incoming(y) {
                if !removed[x.index()] && !events.is_controllable(e) && g.has_event(e) {
                    removed[x.index()] = true;
                    record(
                        &mut records,
                        x,
                        RemovalReason::Bad {
                            event: e,
                            target: Some(y),
                        },
                        round,
                    );
                    work.push(x);
                }
            }
        }
        let co = coaccessible_mask(k, &rev, &removed);
        for x in k.states() {
            if !removed[x.index()] && !co[x.index()] {
                removed[x.index()] = true;
                record(&mut records, x, RemovalReason::NonCoaccessible, round);
                work.push(x);
            }
        }
        let acc = accessible_mask(k, &removed);
        for x in k.states() {
            if !removed[x.index()] && !acc[x.index()] {
                removed[x.index()] = true;
                record(&mut records, x, RemovalReason::Inaccessible, round);
            }
        }
        crate::progress::round(round, records.len());
        if work.is_empty() {
            break;
        }
        round += 1;
    }
    let keep: Vec<bool> = removed.iter().map(|r| !r).collect();
    let (supervisor, kept) = restrict(k, &keep);
    SupcResult {
        supervisor,
        kept,
        removed: records,
        rounds: round,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automaton::ModelKind;
    use crate::product::product_with_tuples;

    fn run(events: &EventTable, g: &Automaton, e: &Automaton) -> (Automaton, SupcResult) {
        let k = product_with_tuples("K", ModelKind::Supervisor, events, &[g, e]);
        let g_of: Vec<StateId> = (0..k.automaton.state_count())
            .map(|x| StateId(k.tuple(StateId(x as u32))[0]))
            .collect();
        let r = supc(&k.automaton, g, &g_of, events);
        (k.automaton, r)
    }

    /// Plant: 0 -a-> 1 -u-> 2 -b-> 0, all marked at 0; spec forbids u after a (no u at all).
    #[test]
    fn uncontrollable_event_disallowed_by_spec_makes_its_source_bad_and_cuts_the_controllable_path()
    {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let u = ev.intern("u", false).unwrap();
        let b = ev.intern("b", true).unwrap();
        let mut g = Automaton::new("G", ModelKind::Plant);
        let s: Vec<_> = (0..3)
            .map(|i| g.add_state(format!("g{i}"), i == 0).unwrap())
            .collect();
        g.add_transition(s[0], a, s[1], 1.0, 0).unwrap();
        g.add_transition(s[1], u, s[2], 1.0, 0).unwrap();
        g.add_transition(s[2], b, s[0], 1.0, 0).unwrap();
        let mut e = Automaton::new("E", ModelKind::Spec);
        let t0 = e.add_state("e0", true).unwrap();
        e.add_transition(t0, a, t0, 1.0, 0).unwrap();
        e.add_transition(t0, b, t0, 1.0, 0).unwrap();
        e.add_event(u);
        let (k, r) = run(&ev, &g, &e);
        assert_eq!(k.state_count(), 2);
        assert!(!r.is_empty());
        assert_eq!(r.supervisor.state_count(), 1);
        assert_eq!(r.supervisor.transition_count(), 0);
        assert_eq!(r.removed.len(), 1);
        assert_eq!(r.removed[0].name, "(g1,e0)");
        assert_eq!(
            r.removed[0].reason,
            RemovalReason::Bad {
                event: u,
                target: None
            }
        );
    }

    /// Plant: 0 -u-> 1 (u uncontrollable); spec has no u: the initial state itself is bad.
    #[test]
    fn impossible_spec_gives_empty_supervisor_with_reason() {
        let mut ev = EventTable::new();
        let u = ev.intern("x", false).unwrap();
        let mut g = Automaton::new("G", ModelKind::Plant);
        let g0 = g.add_state("g0", true).unwrap();
        let g1 = g.add_state("g1", true).unwrap();
        g.add_transition(g0, u, g1, 1.0, 0).unwrap();
        let mut e = Automaton::new("E", ModelKind::Spec);
        e.add_state("e0", true).unwrap();
        e.add_event(u);
        let (k, r) = run(&ev, &g, &e);
        assert!(r.is_empty());
        let reason = r.empty_reason(&k, &ev).unwrap();
        assert!(reason.contains("uncontrollable event `x`"), "{reason}");
    }

    /// A blocking state reached by an uncontrollable event makes its source bad in the next round.
    #[test]
    fn non_coaccessible_target_of_uncontrollable_event_propagates_badness() {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let u = ev.intern("u", false).unwrap();
        // Plant: 0 -a-> 1 -u-> 2 (2 is a dead end, unmarked); 0 marked.
        let mut g = Automaton::new("G", ModelKind::Plant);
        let s: Vec<_> = (0..3)
            .map(|i| g.add_state(format!("g{i}"), i == 0).unwrap())
            .collect();
        g.add_transition(s[0], a, s[1], 1.0, 0).unwrap();
        g.add_transition(s[1], u, s[2], 1.0, 0).unwrap();
        let mut e = Automaton::new("E", ModelKind::Spec);
        let t0 = e.add_state("e0", true).unwrap();
        e.add_transition(t0, a, t0, 1.0, 0).unwrap();
        e.add_transition(t0, u, t0, 1.0, 0).unwrap();
        let (_, r) = run(&ev, &g, &e);
        let reasons: Vec<_> = r
            .removed
            .iter()
            .map(|x| (x.name.as_str(), x.reason, x.round))
            .collect();
        assert_eq!(reasons[0], ("(g1,e0)", RemovalReason::NonCoaccessible, 1));
        assert_eq!(reasons[1].0, "(g2,e0)");
        assert_eq!(reasons[1].1, RemovalReason::NonCoaccessible);
        assert_eq!(r.supervisor.state_count(), 1);
        assert_eq!(r.supervisor.transition_count(), 0);
    }

    /// A state reachable only through a bad state is recorded as inaccessible, not as bad.
    #[test]
    fn states_cut_off_by_a_bad_state_are_recorded_as_inaccessible() {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let b = ev.intern("b", true).unwrap();
        let c = ev.intern("c", true).unwrap();
        let u = ev.intern("u", false).unwrap();
        // Plant: g0 -a-> g1 -b-> g2 -c-> g0, and u is possible in g1; g0 and g2 are marked.
        let mut g = Automaton::new("G", ModelKind::Plant);
        let s: Vec<_> = (0..3)
            .map(|i| g.add_state(format!("g{i}"), i != 1).unwrap())
            .collect();
        g.add_transition(s[0], a, s[1], 1.0, 0).unwrap();
        g.add_transition(s[1], b, s[2], 1.0, 0).unwrap();
        g.add_transition(s[2], c, s[0], 1.0, 0).unwrap();
        g.add_transition(s[1], u, s[1], 1.0, 0).unwrap();
        // Spec: a, b, c are free; u is never allowed.
        let mut e = Automaton::new("E", ModelKind::Spec);
        let e0 = e.add_state("e0", true).unwrap();
        for ev_id in [a, b, c] {
            e.add_transition(e0, ev_id, e0, 1.0, 0).unwrap();
        }
        e.add_event(u);
        let (_, r) = run(&ev, &g, &e);
        let reasons: Vec<_> = r
            .removed
            .iter()
            .map(|x| (x.name.as_str(), x.reason))
            .collect();
        assert_eq!(
            reasons,
            vec![
                (
                    "(g1,e0)",
                    RemovalReason::Bad {
                        event: u,
                        target: None
                    }
                ),
                ("(g2,e0)", RemovalReason::Inaccessible),
            ]
        );
        assert_eq!(
            (r.supervisor.state_count(), r.supervisor.transition_count()),
            (1, 0)
        );
    }
}
