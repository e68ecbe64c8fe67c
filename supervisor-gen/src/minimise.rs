//! Language-preserving minimisation with P and T as labels (section 7).
//!
//! Partition refinement on the accessible part, starting from {marked, unmarked}. A transition's label is the
//! triple (event, P in Q0.16, T), so probabilities are compared by their stored encoding, never as raw floats.
//! The refinement is Valmari and Lehtinen's O(m log n) algorithm for partial transition functions ("Efficient
//! minimization of DFAs with partial transition functions", STACS 2008): states and transitions live in two
//! refinable partitions over flat arrays, so nothing is allocated per state or per round.
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
    // Flat transition arrays: tail (source), head (target), label.
    let m = a.transition_count();
    let mut tail = Vec::with_capacity(m);
    let mut head = Vec::with_capacity(m);
    let mut label = Vec::with_capacity(m);
    for x in a.states() {
        for t in a.transitions(x) {
            tail.push(x.0);
            head.push(t.target.0);
            label.push(
                (u64::from(t.event.0) << 48)
                    | (u64::from(prob_to_q16(t.prob)) << 32)
                    | u64::from(t.lower_bound),
            );
        }
    }
    // Incoming transitions of each state: in_trans[in_first[s]..in_first[s + 1]].
    let mut in_first = vec![0usize; n + 1];
    for &h in &head {
        in_first[h as usize + 1] += 1;
    }
    for i in 0..n {
        in_first[i + 1] += in_first[i];
    }
    let mut fill = in_first.clone();
    let mut in_trans = vec![0u32; m];
    for (t, &h) in head.iter().enumerate() {
        in_trans[fill[h as usize]] = t as u32;
        fill[h as usize] += 1;
    }

    let mut marks = Marks::new(n.max(m) + 1);
    let mut blocks = Partition::new(n);
    for x in 0..n {
        if a.is_marked(StateId(x as u32)) {
            blocks.mark(x, &mut marks);
        }
    }
    blocks.split(&mut marks);
    let mut cords = Partition::new(m);
    if m > 0 {
        cords.elems.sort_unstable_by_key(|&t| label[t as usize]);
        cords.sets = 0;
        let mut current = label[cords.elems[0] as usize];
        cords.first[0] = 0;
        for i in 0..m {
            let t = cords.elems[i] as usize;
            if label[t] != current {
                current = label[t];
                cords.past[cords.sets] = i;
                cords.sets += 1;
                cords.first[cords.sets] = i;
            }
            cords.set_of[t] = cords.sets as u32;
            cords.loc[t] = i as u32;
        }
        cords.past[cords.sets] = m;
        cords.sets += 1;
    }
    // Block 0 never needs to act as a splitter (Hopcroft's "all but one" argument; cords cover the rest).
    let (mut b, mut c) = (1usize, 0usize);
    while c < cords.sets {
        for i in cords.first[c]..cords.past[c] {
            blocks.mark(tail[cords.elems[i] as usize] as usize, &mut marks);
        }
        blocks.split(&mut marks);
        c += 1;
        while b < blocks.sets {
            for i in blocks.first[b]..blocks.past[b] {
                let s = blocks.elems[i] as usize;
                for &t in &in_trans[in_first[s]..in_first[s + 1]] {
                    cords.mark(t as usize, &mut marks);
                }
            }
            cords.split(&mut marks);
            b += 1;
        }
    }
    let mut class: Vec<u32> = blocks.set_of.clone();
    let classes = renumber(&mut class);
    quotient(&a, &class, classes)
}

/// Per-set mark counts and the worklist of touched sets, shared by both partitions (used one at a time).
struct Marks {
    count: Vec<usize>,
    touched: Vec<usize>,
}

impl Marks {
    fn new(capacity: usize) -> Self {
        Self {
            count: vec![0; capacity],
            touched: Vec::with_capacity(capacity),
        }
    }
}

/// A refinable partition of `0..n`: set s holds `elems[first[s]..past[s]]`, marked elements first.
struct Partition {
    sets: usize,
    elems: Vec<u32>,
    loc: Vec<u32>,
    set_of: Vec<u32>,
    first: Vec<usize>,
    past: Vec<usize>,
}

impl Partition {
    fn new(n: usize) -> Self {
        let mut past = vec![0; n.max(1)];
        past[0] = n;
        Self {
            sets: usize::from(n > 0),
            elems: (0..n as u32).collect(),
            loc: (0..n as u32).collect(),
            set_of: vec![0; n],
            first: vec![0; n.max(1)],
            past,
        }
    }

    /// Marks element `e` (each element at most once between splits; a DFA guarantees this for both partitions).
    fn mark(&mut self, e: usize, marks: &mut Marks) {
        let s = self.set_of[e] as usize;
        let i = self.loc[e] as usize;
        let j = self.first[s] + marks.count[s];
        self.elems[i] = self.elems[j];
        self.loc[self.elems[i] as usize] = i as u32;
        self.elems[j] = e as u32;
        self.loc[e] = j as u32;
        if marks.count[s] == 0 {
            marks.touched.push(s);
        }
        marks.count[s] += 1;
    }

    /// Splits every touched set into its marked and unmarked parts; the smaller part becomes a new set.
    fn split(&mut self, marks: &mut Marks) {
        while let Some(s) = marks.touched.pop() {
            let j = self.first[s] + marks.count[s];
            if j == self.past[s] {
                marks.count[s] = 0;
                continue;
            }
            let z = self.sets;
            if marks.count[s] <= self.past[s] - j {
                self.first[z] = self.first[s];
                self.past[z] = j;
                self.first[s] = j;
            } else {
                self.past[z] = self.past[s];
                self.first[z] = j;
                self.past[s] = j;
            }
            for i in self.first[z]..self.past[z] {
                self.set_of[self.elems[i] as usize] = z as u32;
            }
            marks.count[s] = 0;
            marks.count[z] = 0;
            self.sets += 1;
        }
    }
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
        let merged = a.transitions(x).iter().map(|t| {
            let mut t = *t;
            t.target = StateId(class[t.target.index()]);
            t
        });
        r.push_state(a.state_name(x), a.is_marked(x), merged);
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
