//! Language-preserving minimisation with P and T as labels (section 7).
//!
//! Partition refinement on the accessible part, starting from the classes of states with the same marking and the
//! same outgoing labels (which equivalent states always share). A transition's label is the triple (event, P in
//! Q0.16, T), so probabilities are compared by their stored encoding, never as raw floats.
//!
//! The refinement is Hopcroft's algorithm on the automaton completed by an implicit sink state. The sink sits in
//! a block of its own that never splits, so it is the one block Hopcroft's "all but one" rule leaves out as a
//! splitter, and the transitions into it are never enumerated: the work is O(m log n) over the real transitions.
//! A splitter block is taken with all its labels at once (its incoming transitions bucketed by label), and blocks
//! are processed in creation order: a split keeps the larger half under the old id, so a block processed earlier
//! gets only its smaller half back as a splitter. Every array the refinement touches at random is indexed by
//! state, so it stays in cache far longer than a partition of the transitions would.
//! This is not supervisor reduction (control covers): only language-equivalent states with equal labels merge.

use std::borrow::Cow;
use std::collections::HashMap;

use crate::automaton::{Automaton, StateId, Transition};
use crate::compiled::prob_to_q16;
use crate::trim::{ReverseAdjacency, accessible_mask, restrict};

/// The minimal automaton with the same language, marked language and P/T labels as `a`'s accessible part.
///
/// State names are those of each class's first state; the initial state's class becomes state 0.
pub fn minimise(a: &Automaton) -> Automaton {
    minimise_accessible(&accessible_part(a))
}

/// [`minimise`] of an automaton whose states are all accessible, as SupC's result is: it skips the reachability
/// pass (an inaccessible state would be kept, in a class of its own or merged with its equals).
pub fn minimise_accessible(a: &Automaton) -> Automaton {
    let n = a.state_count();
    if n == 0 {
        return a.clone();
    }
    let mut letters = Letters::new();
    let letter: Vec<u32> = a
        .states()
        .flat_map(|x| a.transitions(x))
        .map(|t| letters.of(t))
        .collect();
    let incoming = ReverseAdjacency::labelled(a, |i, _| letter[i]);
    let (signature, signatures) = signatures(a, &letter);
    drop(letter);
    let mut blocks = Partition::of_classes(&signature, signatures);
    let mut buckets = Buckets::new(letters.count());
    let mut b = 0;
    while b < blocks.sets.len() {
        let range = blocks.sets[b];
        buckets.gather(
            blocks.elems[range.first as usize..range.past as usize]
                .iter()
                .flat_map(|&s| incoming.entering(s).iter().copied()),
        );
        for group in buckets.groups() {
            for &p in group {
                blocks.mark(p);
            }
            blocks.split();
        }
        b += 1;
    }
    let mut class: Vec<u32> = blocks.places.iter().map(|p| p.set & !ALONE).collect();
    let classes = renumber(&mut class);
    quotient(a, &class, classes)
}

/// `a` itself when every state is accessible (as after SupC), else its accessible part.
fn accessible_part(a: &Automaton) -> Cow<'_, Automaton> {
    let keep = accessible_mask(a, &vec![false; a.state_count()]);
    if keep.iter().all(|&k| k) {
        Cow::Borrowed(a)
    } else {
        Cow::Owned(restrict(a, &keep).0)
    }
}

/// Each state's signature id: states with the same marking and the same outgoing letters share one, in order
/// of first appearance. States that differ in either are never equivalent, so refinement may start from these
/// classes instead of {marked, unmarked}; it then has far fewer splits left to do. `letter` holds every
/// transition's letter in source order. Returns the ids and their count.
fn signatures(a: &Automaton, letter: &[u32]) -> (Vec<u32>, usize) {
    let mut ids: Vec<u32> = Vec::with_capacity(a.state_count());
    // Signature hash -> (id, a state that has it), checked letter by letter against that state.
    let mut seen: HashMap<u64, Vec<(u32, StateId)>> = HashMap::new();
    let mut count = 0u32;
    let mut first = vec![0usize; a.state_count() + 1];
    for x in a.states() {
        first[x.index() + 1] = first[x.index()] + a.transitions(x).len();
    }
    let letters_of = |x: StateId| &letter[first[x.index()]..first[x.index() + 1]];
    for x in a.states() {
        let mine = letters_of(x);
        let mut h = u64::from(a.is_marked(x)) ^ 0x9E37_79B9_7F4A_7C15;
        for &l in mine {
            h = (h ^ u64::from(l)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            h ^= h >> 29;
        }
        let candidates = seen.entry(h).or_default();
        let found = candidates
            .iter()
            .find(|&&(_, rep)| a.is_marked(rep) == a.is_marked(x) && letters_of(rep) == mine);
        let id = match found {
            Some(&(id, _)) => id,
            None => {
                candidates.push((count, x));
                count += 1;
                count - 1
            }
        };
        ids.push(id);
    }
    (ids, count as usize)
}

/// Dense ids of the distinct labels (event, P in Q0.16, T) of an automaton's transitions, the letters the
/// refinement splits by.
struct Letters {
    ids: HashMap<u64, u32>,
    /// Most automata have a handful of labels: a small direct-mapped cache in front of the map.
    recent: [Option<(u64, u32)>; 64],
}

impl Letters {
    fn new() -> Self {
        Self {
            ids: HashMap::new(),
            recent: [None; 64],
        }
    }

    fn of(&mut self, t: &Transition) -> u32 {
        let key = (u64::from(t.event.0) << 48)
            | (u64::from(prob_to_q16(t.prob)) << 32)
            | u64::from(t.lower_bound);
        let cached = &mut self.recent[(key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 58) as usize];
        match *cached {
            Some((k, letter)) if k == key => letter,
            _ => {
                let next = self.ids.len() as u32;
                let letter = *self.ids.entry(key).or_insert(next);
                *cached = Some((key, letter));
                letter
            }
        }
    }

    fn count(&self) -> usize {
        self.ids.len()
    }
}

/// A counting sort of a splitter's incoming pairs by letter, touching only the letters that occur.
struct Buckets {
    pairs: Vec<(u32, u32)>,
    count: Vec<u32>,
    used: Vec<u32>,
    sources: Vec<u32>,
}

impl Buckets {
    fn new(letters: usize) -> Self {
        Self {
            pairs: Vec::new(),
            count: vec![0; letters],
            used: Vec::new(),
            sources: Vec::new(),
        }
    }

    /// Takes the (source, letter) pairs of one splitter and sorts their sources by letter.
    fn gather(&mut self, pairs: impl Iterator<Item = (u32, u32)>) {
        for &l in &self.used {
            self.count[l as usize] = 0;
        }
        self.used.clear();
        self.pairs.clear();
        self.pairs.extend(pairs);
        for &(_, l) in &self.pairs {
            if self.count[l as usize] == 0 {
                self.used.push(l);
            }
            self.count[l as usize] += 1;
        }
        // `count` becomes each used letter's end offset while the sources are placed back to front.
        let mut total = 0;
        for &l in &self.used {
            total += self.count[l as usize];
            self.count[l as usize] = total;
        }
        self.sources.resize(self.pairs.len(), 0);
        for &(p, l) in self.pairs.iter().rev() {
            let end = &mut self.count[l as usize];
            *end -= 1;
            self.sources[*end as usize] = p;
        }
        // Now `count` holds each used letter's start offset.
    }

    /// The sources of each letter's pairs, one group per letter.
    fn groups(&self) -> impl Iterator<Item = &[u32]> + '_ {
        let ends = self
            .used
            .iter()
            .skip(1)
            .map(|&l| self.count[l as usize] as usize)
            .chain(std::iter::once(self.sources.len()));
        self.used
            .iter()
            .zip(ends)
            .map(|(&l, end)| &self.sources[self.count[l as usize] as usize..end])
    }
}

/// Where an element is: its set and its index in `elems`.
#[derive(Clone, Copy)]
struct Place {
    /// The set's id, with [`ALONE`] added while the element is alone in it.
    set: u32,
    loc: u32,
}

/// Flags a [`Place`] whose set has one element. Such a set never splits, so marking its element is skipped
/// without looking the set up: once the partition is nearly final most marks land on such sets. Set ids stay
/// below this bit because an automaton of 2^31 states would need tens of gigabytes before reaching here.
const ALONE: u32 = 1 << 31;

/// A set's range `elems[first..past]`, its marked elements first (`marked` of them).
#[derive(Clone, Copy)]
struct Range {
    first: u32,
    past: u32,
    marked: u32,
}

/// A refinable partition of the states `0..n`. Each record an operation touches at random is one struct, so a
/// mark costs few cache misses.
struct Partition {
    elems: Vec<u32>,
    places: Vec<Place>,
    sets: Vec<Range>,
    touched: Vec<u32>,
}

impl Partition {
    /// The partition of `0..class.len()` into the classes `class` numbers `0..classes` (each used at least once).
    fn of_classes(class: &[u32], classes: usize) -> Self {
        let mut sets = vec![
            Range {
                first: 0,
                past: 0,
                marked: 0,
            };
            classes
        ];
        for &c in class {
            sets[c as usize].past += 1;
        }
        let mut first = 0;
        for set in &mut sets {
            let size = set.past;
            set.first = first;
            set.past = first;
            first += size;
        }
        let mut elems = vec![0; class.len()];
        let mut places = vec![Place { set: 0, loc: 0 }; class.len()];
        for (e, &c) in class.iter().enumerate() {
            let set = &mut sets[c as usize];
            elems[set.past as usize] = e as u32;
            places[e] = Place {
                set: c,
                loc: set.past,
            };
            set.past += 1;
        }
        for set in &sets {
            if set.past - set.first == 1 {
                places[elems[set.first as usize] as usize].set |= ALONE;
            }
        }
        Self {
            elems,
            places,
            sets,
            touched: Vec::new(),
        }
    }

    /// Marks element `e` (each element at most once between splits: a deterministic automaton has at most one
    /// transition per state and label).
    fn mark(&mut self, e: u32) {
        let Place { set, loc } = self.places[e as usize];
        if set & ALONE != 0 {
            return;
        }
        let range = &mut self.sets[set as usize];
        let j = range.first + range.marked;
        if range.marked == 0 {
            self.touched.push(set);
        }
        range.marked += 1;
        let other = self.elems[j as usize];
        self.elems[loc as usize] = other;
        self.places[other as usize].loc = loc;
        self.elems[j as usize] = e;
        self.places[e as usize].loc = j;
    }

    /// Splits every touched set into its marked and unmarked parts; the smaller part becomes a new set.
    fn split(&mut self) {
        while let Some(s) = self.touched.pop() {
            let z = self.sets.len() as u32;
            let range = &mut self.sets[s as usize];
            let j = range.first + range.marked;
            let marked = std::mem::take(&mut range.marked);
            if j == range.past {
                continue;
            }
            let new = if marked <= range.past - j {
                let new = Range {
                    first: range.first,
                    past: j,
                    marked: 0,
                };
                range.first = j;
                new
            } else {
                let new = Range {
                    first: j,
                    past: range.past,
                    marked: 0,
                };
                range.past = j;
                new
            };
            let moved = &self.elems[new.first as usize..new.past as usize];
            let z = if moved.len() == 1 { z | ALONE } else { z };
            for &e in moved {
                self.places[e as usize].set = z;
            }
            if range.past - range.first == 1 {
                self.places[self.elems[range.first as usize] as usize].set |= ALONE;
            }
            self.sets.push(new);
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
