//! Accessible, coaccessible and trim parts (section 6.4), with the flat reverse adjacency SupC reuses.
//!
//! Reachability runs over a `removed` mask so SupC can re-run it every round without rebuilding graphs; the
//! worklists and the reverse adjacency are flat `Vec`s sized once per automaton.

use crate::automaton::{Automaton, EventId, StateId, Transition};

/// Incoming transitions of every state in compressed form: the transitions entering `y` are
/// `pairs[offsets[y]..offsets[y + 1]]`, each as (source, label). The label is the event unless built with
/// [`ReverseAdjacency::labelled`].
#[derive(Debug, Clone)]
pub struct ReverseAdjacency<L = EventId> {
    offsets: Vec<u32>,
    pairs: Vec<(u32, L)>,
}

impl ReverseAdjacency {
    /// Builds the reverse adjacency of `a`, labelled by events.
    pub fn new(a: &Automaton) -> Self {
        Self::labelled(a, |_, t| t.event)
    }

    /// The (source, event) pairs of the transitions entering `y`.
    pub fn incoming(&self, y: StateId) -> impl Iterator<Item = (StateId, EventId)> + '_ {
        self.entering(y.0).iter().map(|&(s, e)| (StateId(s), e))
    }
}

impl<L: Copy + Default> ReverseAdjacency<L> {
    /// Builds the reverse adjacency of `a` in two linear passes, labelling each transition by `label`, which is
    /// given the transition's number in source order (0 for the first transition of state 0) and the transition.
    pub fn labelled(a: &Automaton, label: impl Fn(usize, &Transition) -> L) -> Self {
        let n = a.state_count();
        let mut offsets = vec![0u32; n + 1];
        for x in a.states() {
            for t in a.transitions(x) {
                offsets[t.target.index() + 1] += 1;
            }
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let m = offsets[n] as usize;
        let mut fill = offsets.clone();
        let mut pairs = vec![(0u32, L::default()); m];
        let from = a
            .states()
            .flat_map(|x| a.transitions(x).iter().map(move |t| (x, t)));
        for (i, (x, t)) in from.enumerate() {
            let slot = &mut fill[t.target.index()];
            pairs[*slot as usize] = (x.0, label(i, t));
            *slot += 1;
        }
        Self { offsets, pairs }
    }

    /// The (source, label) pairs of the transitions entering state `y`.
    pub fn entering(&self, y: u32) -> &[(u32, L)] {
        &self.pairs[self.offsets[y as usize] as usize..self.offsets[y as usize + 1] as usize]
    }
}

/// States reachable from the initial state through states not in `removed`.
pub fn accessible_mask(a: &Automaton, removed: &[bool]) -> Vec<bool> {
    let start = (a.state_count() > 0).then(|| a.initial().0);
    search(removed, start, |x, next| {
        for t in a.transitions(StateId(x)) {
            next(t.target.0);
        }
    })
}

/// States from which a marked state is reachable through states not in `removed`.
pub fn coaccessible_mask(a: &Automaton, rev: &ReverseAdjacency, removed: &[bool]) -> Vec<bool> {
    let marked = a.states().filter(|&x| a.is_marked(x)).map(|x| x.0);
    search(removed, marked, |y, next| {
        for (x, _) in rev.incoming(StateId(y)) {
            next(x.0);
        }
    })
}

/// Breadth-first search from `starts` along `edges`, avoiding `removed`; returns the states found.
///
/// Products number their states breadth-first, so a breadth-first search reads the transitions nearly in order;
/// one status byte per state makes each visited edge a single random access.
fn search(
    removed: &[bool],
    starts: impl IntoIterator<Item = u32>,
    edges: impl Fn(u32, &mut dyn FnMut(u32)),
) -> Vec<bool> {
    const OPEN: u8 = 0;
    const FOUND: u8 = 1;
    const CLOSED: u8 = 2;
    let mut status: Vec<u8> = removed
        .iter()
        .map(|&r| if r { CLOSED } else { OPEN })
        .collect();
    let mut queue: Vec<u32> = Vec::new();
    for x in starts {
        if status[x as usize] == OPEN {
            status[x as usize] = FOUND;
            queue.push(x);
        }
    }
    let mut head = 0;
    while let Some(&x) = queue.get(head) {
        head += 1;
        edges(x, &mut |y| {
            if status[y as usize] == OPEN {
                status[y as usize] = FOUND;
                queue.push(y);
            }
        });
    }
    status.into_iter().map(|s| s == FOUND).collect()
}

/// The sub-automaton on the states where `keep` is true, renumbered in ascending old order, dropping transitions
/// into discarded states. Returns it with the old id of each new state. An automaton whose initial state is
/// discarded has no states.
pub fn restrict(a: &Automaton, keep: &[bool]) -> (Automaton, Vec<StateId>) {
    let mut r = Automaton::new(a.name(), a.kind());
    r.alphabet = a.alphabet.clone();
    if a.state_count() == 0 || !keep[a.initial().index()] {
        return (r, Vec::new());
    }
    let mut new_id = vec![u32::MAX; a.state_count()];
    let mut old_of = Vec::new();
    for x in a.states().filter(|x| keep[x.index()]) {
        new_id[x.index()] = old_of.len() as u32;
        old_of.push(x);
    }
    for &x in &old_of {
        let kept = a
            .transitions(x)
            .iter()
            .filter(|t| keep[t.target.index()])
            .map(|t| {
                let mut t = *t;
                t.target = StateId(new_id[t.target.index()]);
                t
            });
        r.push_state(a.state_name(x), a.is_marked(x), kept);
    }
    r.initial = StateId(new_id[a.initial().index()]);
    (r, old_of)
}

/// The accessible part of `a`.
pub fn accessible(a: &Automaton) -> Automaton {
    let keep = accessible_mask(a, &vec![false; a.state_count()]);
    restrict(a, &keep).0
}

/// The coaccessible part of `a` (empty if the initial state cannot reach a marked state).
pub fn coaccessible(a: &Automaton) -> Automaton {
    let keep = coaccessible_mask(a, &ReverseAdjacency::new(a), &vec![false; a.state_count()]);
    restrict(a, &keep).0
}

/// The trim part of `a`: accessible and coaccessible states only.
pub fn trim(a: &Automaton) -> Automaton {
    let none = vec![false; a.state_count()];
    let acc = accessible_mask(a, &none);
    let co = coaccessible_mask(a, &ReverseAdjacency::new(a), &none);
    let keep: Vec<bool> = acc.iter().zip(&co).map(|(&x, &y)| x && y).collect();
    restrict(a, &keep).0
}

/// Accessible states from which no marked state is reachable (empty iff `a` is nonblocking).
pub fn blocking_states(a: &Automaton) -> Vec<StateId> {
    let none = vec![false; a.state_count()];
    let acc = accessible_mask(a, &none);
    let co = coaccessible_mask(a, &ReverseAdjacency::new(a), &none);
    a.states()
        .filter(|x| acc[x.index()] && !co[x.index()])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automaton::ModelKind;

    /// q0 -a-> q1 (marked), q0 -b-> q2 (dead end), q3 unreachable -a-> q1.
    fn sample() -> Automaton {
        let mut g = Automaton::new("g", ModelKind::Spec);
        let q0 = g.add_state("q0", false).unwrap();
        let q1 = g.add_state("q1", true).unwrap();
        let q2 = g.add_state("q2", false).unwrap();
        let q3 = g.add_state("q3", false).unwrap();
        g.add_transition(q0, EventId(0), q1, 1.0, 0).unwrap();
        g.add_transition(q0, EventId(1), q2, 1.0, 0).unwrap();
        g.add_transition(q3, EventId(0), q1, 1.0, 0).unwrap();
        g
    }

    #[test]
    fn accessible_drops_unreachable_states() {
        let a = accessible(&sample());
        assert_eq!(a.state_count(), 3);
        assert!(a.state_by_name("q3").is_none());
    }

    #[test]
    fn coaccessible_drops_dead_ends() {
        let c = coaccessible(&sample());
        assert_eq!(c.state_count(), 3);
        assert!(c.state_by_name("q2").is_none());
        assert_eq!(c.transition_count(), 2);
    }

    #[test]
    fn trim_is_accessible_and_coaccessible() {
        let t = trim(&sample());
        let names: Vec<_> = t.states().map(|s| t.state_name(s).to_owned()).collect();
        assert_eq!(names, vec!["q0", "q1"]);
        assert_eq!(t.transition_count(), 1);
        assert_eq!(blocking_states(&sample()), vec![StateId(2)]);
        assert!(blocking_states(&t).is_empty());
    }
}
