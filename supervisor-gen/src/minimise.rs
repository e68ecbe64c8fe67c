//! Language-preserving minimisation with P and T as labels (section 7).
//!
//! Moore partition refinement on the accessible part, starting from {marked, unmarked}. A transition's label is
//! the triple (event, P in Q0.16, T), so probabilities are compared by their stored encoding, never as raw floats.
//! Signatures live in one flat buffer and classes are found by sorting, so a round allocates nothing per state.
//! This is not supervisor reduction (control covers): only language-equivalent states with equal labels merge.

use crate::automaton::{Automaton, StateId};
use crate::compiled::prob_to_q16;
use crate::trim::accessible;

/// The minimal automaton with the same language, marked language and P/T labels as `a`'s accessible part.
///
/// State names are those of each class's first state; the initial state's class becomes state 0.
pub fn minimise(a: &Automaton) -> Automaton {
    let a = accessible(a);
    let n = a.state_count();
    if n == 0 {
        return a;
    }
    let mut class: Vec<u32> = (0..n).map(|x| u32::from(a.marked[x])).collect();
    let mut classes = renumber(&mut class);
    let mut offsets = vec![0usize; n + 1];
    let mut sig: Vec<u64> = Vec::new();
    let mut order: Vec<u32> = (0..n as u32).collect();
    loop {
        sig.clear();
        for x in 0..n {
            offsets[x] = sig.len();
            sig.push(u64::from(class[x]));
            for t in &a.out[x] {
                let label = (u64::from(t.event.0) << 48)
                    | (u64::from(prob_to_q16(t.prob)) << 32)
                    | u64::from(t.lower_bound);
                sig.push(label);
                sig.push(u64::from(class[t.target.index()]));
            }
        }
        offsets[n] = sig.len();
        let key = |x: u32| &sig[offsets[x as usize]..offsets[x as usize + 1]];
        order.sort_unstable_by(|&x, &y| key(x).cmp(key(y)));
        let mut next = vec![0u32; n];
        let mut id = 0u32;
        for (i, &x) in order.iter().enumerate() {
            if i > 0 && key(order[i - 1]) != key(x) {
                id += 1;
            }
            next[x as usize] = id;
        }
        let count = id as usize + 1;
        class = next;
        let stable = count == classes;
        classes = renumber(&mut class);
        if stable {
            break;
        }
    }
    quotient(&a, &class, classes)
}

/// Renumbers classes densely in order of first appearance by state id (so the initial state 0's class is 0),
/// returning the number of classes.
fn renumber(class: &mut [u32]) -> usize {
    let mut map = vec![u32::MAX; class.len() + 1];
    let mut next = 0u32;
    for c in class.iter_mut() {
        let slot = &mut map[*c as usize];
        if *slot == u32::MAX {
            *slot = next;
            next += 1;
        }
        *c = *slot;
    }
    next as usize
}

fn quotient(a: &Automaton, class: &[u32], classes: usize) -> Automaton {
    let mut r = Automaton::new(a.name(), a.kind());
    r.alphabet = a.alphabet.clone();
    let mut rep = vec![u32::MAX; classes];
    for (x, &c) in class.iter().enumerate() {
        if rep[c as usize] == u32::MAX {
            rep[c as usize] = x as u32;
        }
    }
    for &x in &rep {
        let x = StateId(x);
        r.state_names.push(a.state_name(x).to_owned());
        r.marked.push(a.is_marked(x));
        r.out.push(
            a.transitions(x)
                .iter()
                .map(|t| {
                    let mut t = *t;
                    t.target = StateId(class[t.target.index()]);
                    t
                })
                .collect(),
        );
    }
    r.initial = StateId(class[a.initial().index()]);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automaton::{EventId, ModelKind};

    /// A 4-cycle a,a,a,a with all states marked is the 1-state a-loop.
    #[test]
    fn equivalent_states_merge() {
        let mut g = Automaton::new("g", ModelKind::Supervisor);
        let s: Vec<_> = (0..4)
            .map(|i| g.add_state(format!("s{i}"), true).unwrap())
            .collect();
        for i in 0..4 {
            g.add_transition(s[i], EventId(0), s[(i + 1) % 4], 1.0, 0)
                .unwrap();
        }
        let m = minimise(&g);
        assert_eq!(m.state_count(), 1);
        assert_eq!(m.transition_count(), 1);
        assert_eq!(m.state_name(m.initial()), "s0");
    }

    #[test]
    fn different_time_labels_prevent_merging() {
        let mut g = Automaton::new("g", ModelKind::Supervisor);
        let s: Vec<_> = (0..2)
            .map(|i| g.add_state(format!("s{i}"), true).unwrap())
            .collect();
        g.add_transition(s[0], EventId(0), s[1], 1.0, 0).unwrap();
        g.add_transition(s[1], EventId(0), s[0], 1.0, 5).unwrap();
        assert_eq!(minimise(&g).state_count(), 2);
    }

    #[test]
    fn probabilities_equal_in_q16_merge_and_different_ones_do_not() {
        let build = |p: f64| {
            let mut g = Automaton::new("g", ModelKind::Supervisor);
            let s: Vec<_> = (0..2)
                .map(|i| g.add_state(format!("s{i}"), true).unwrap())
                .collect();
            g.add_transition(s[0], EventId(0), s[1], 0.5, 0).unwrap();
            g.add_transition(s[1], EventId(0), s[0], p, 0).unwrap();
            minimise(&g).state_count()
        };
        assert_eq!(build(0.5 + 1e-9), 1);
        assert_eq!(build(0.6), 2);
    }

    #[test]
    fn marking_separates_states() {
        let mut g = Automaton::new("g", ModelKind::Supervisor);
        let s0 = g.add_state("s0", true).unwrap();
        let s1 = g.add_state("s1", false).unwrap();
        g.add_transition(s0, EventId(0), s1, 1.0, 0).unwrap();
        g.add_transition(s1, EventId(0), s0, 1.0, 0).unwrap();
        assert_eq!(minimise(&g).state_count(), 2);
    }
}
