//! The n-ary synchronous product of ptSCT generators (section 4), accessible part only (C2).
//!
//! States are tuples of component states, stored flat and indexed during construction only: by direct addressing
//! when the full tuple space is at most [`DENSE_LIMIT`] tuples, otherwise by an open-addressing hash table. The
//! direct-address table starts as zeroed pages the kernel maps on first touch, so a large space whose reachable
//! part is small costs only the pages that part lands on. Shared controllable events multiply P and take the maximum T; private events keep
//! their component's labels; uncontrollable transitions carry P = 1 and T = 0. Plant factors are whatever the
//! caller's normalisation left in them (1 under rule A5). The product of an empty list is the identity (C3).

use crate::automaton::{Automaton, EventId, EventTable, ModelKind, StateId, Transition};
use crate::progress;

/// A product together with the component-state tuple of each of its states.
#[derive(Debug, Clone)]
pub struct ProductOutput {
    /// The accessible product.
    pub automaton: Automaton,
    /// Number of components (tuple length).
    pub arity: usize,
    /// Flat tuples: state `x` is `tuples[x * arity .. (x + 1) * arity]`.
    pub tuples: Vec<u32>,
}

impl ProductOutput {
    /// The component-state tuple of product state `x`.
    pub fn tuple(&self, x: StateId) -> &[u32] {
        &self.tuples[x.index() * self.arity..(x.index() + 1) * self.arity]
    }
}

/// The accessible synchronous product `parts[0] ∥ … ∥ parts[n-1]`, named `name` and of kind `kind`.
pub fn product(
    name: &str,
    kind: ModelKind,
    events: &EventTable,
    parts: &[&Automaton],
) -> Automaton {
    product_with_tuples(name, kind, events, parts).automaton
}

/// Like [`product`], also returning each product state's component tuple (used to find g(x) in SupC).
pub fn product_with_tuples(
    name: &str,
    kind: ModelKind,
    events: &EventTable,
    parts: &[&Automaton],
) -> ProductOutput {
    let arity = parts.len();
    if arity == 0 {
        return ProductOutput {
            automaton: Automaton::identity(name, kind),
            arity,
            tuples: Vec::new(),
        };
    }
    let mut result = Automaton::new(name, kind);
    let mut alphabet: Vec<EventId> = parts
        .iter()
        .flat_map(|p| p.alphabet().iter().copied())
        .collect();
    alphabet.sort_unstable();
    alphabet.dedup();
    result.alphabet = alphabet;
    if parts.iter().any(|p| p.state_count() == 0) {
        return ProductOutput {
            automaton: result,
            arity,
            tuples: Vec::new(),
        };
    }
    // owners[e] lists the components whose alphabet contains e, in component order.
    let max_event = result.alphabet.last().map_or(0, |e| e.index() + 1);
    let mut owners: Vec<Vec<usize>> = vec![Vec::new(); max_event];
    for (c, p) in parts.iter().enumerate() {
        for e in p.alphabet() {
            owners[e.index()].push(c);
        }
    }
    let sizes: Vec<usize> = parts.iter().map(|p| p.state_count()).collect();
    let mut index = TupleIndex::new(&sizes);
    let start: Vec<u32> = parts.iter().map(|p| p.initial().0).collect();
    index.find_or_insert(&start);
    let mut cur = vec![0u32; arity];
    let mut next = vec![0u32; arity];
    let mut buf: Vec<Transition> = Vec::new();
    let mut name = String::new();
    // Components moved by the transition being built: (component, new state).
    let mut moved: Vec<(usize, u32)> = Vec::with_capacity(arity);
    let strides: Option<Vec<usize>> = index.strides().map(<[usize]>::to_vec);
    progress::stage(|| format!("product {}", result.name()));
    let mut x = 0usize;
    while x < index.len() {
        if x > 0 && x.is_multiple_of(progress::STATES_PER_REPORT) {
            progress::states(x);
        }
        cur.copy_from_slice(index.tuple(x));
        let cur_key: usize = strides.as_ref().map_or(0, |st| {
            cur.iter().zip(st).map(|(&q, &w)| q as usize * w).sum()
        });
        buf.clear();
        for (c, part) in parts.iter().enumerate() {
            for tr in part.transitions(StateId(cur[c])) {
                let own = &owners[tr.event.index()];
                if own[0] != c {
                    continue;
                }
                moved.clear();
                moved.push((c, tr.target.0));
                let (mut prob, mut lb) = (tr.prob, tr.lower_bound);
                let mut enabled = true;
                for &o in &own[1..] {
                    match parts[o].transition(StateId(cur[o]), tr.event) {
                        Some(t2) => {
                            moved.push((o, t2.target.0));
                            prob *= t2.prob;
                            lb = lb.max(t2.lower_bound);
                        }
                        None => {
                            enabled = false;
                            break;
                        }
                    }
                }
                if !enabled {
                    continue;
                }
                let target = match &strides {
                    // Direct addressing: update the key by the moved components only, and build the tuple
                    // only when it is new.
                    Some(st) => {
                        let key = moved.iter().fold(cur_key, |k, &(i, q)| {
                            k - cur[i] as usize * st[i] + q as usize * st[i]
                        });
                        match index.dense_get(key) {
                            Some(id) => id,
                            None => {
                                next.copy_from_slice(&cur);
                                for &(i, q) in &moved {
                                    next[i] = q;
                                }
                                index.dense_insert(key, &next)
                            }
                        }
                    }
                    None => {
                        next.copy_from_slice(&cur);
                        for &(i, q) in &moved {
                            next[i] = q;
                        }
                        index.find_or_insert(&next)
                    }
                };
                let ctrl = events.is_controllable(tr.event);
                buf.push(Transition {
                    event: tr.event,
                    target: StateId(target),
                    prob: if ctrl { prob } else { 1.0 },
                    lower_bound: if ctrl { lb } else { 0 },
                });
            }
        }
        buf.sort_unstable_by_key(|t| t.event);
        name.clear();
        if arity == 1 {
            name.push_str(parts[0].state_name(StateId(cur[0])));
        } else {
            name.push('(');
            for (i, (&q, p)) in cur.iter().zip(parts).enumerate() {
                if i > 0 {
                    name.push(',');
                }
                name.push_str(p.state_name(StateId(q)));
            }
            name.push(')');
        }
        let marked = cur.iter().zip(parts).all(|(&s, p)| p.is_marked(StateId(s)));
        result.push_state(&name, marked, buf.iter().copied());
        x += 1;
    }
    result.initial = StateId(0);
    ProductOutput {
        automaton: result,
        arity,
        tuples: index.tuples,
    }
}

const EMPTY: u32 = u32::MAX;

/// Tuple spaces up to this size are indexed by a direct-address table (4 bytes per possible tuple, 256 MiB at
/// most, of which only the touched pages are resident).
pub const DENSE_LIMIT: usize = 1 << 26;

/// How tuples are looked up.
enum Lookup {
    /// `slots[Σ t_i · stride_i]` is the id of tuple t plus one, or 0 if t is not yet indexed.
    Dense {
        slots: Vec<u32>,
        strides: Vec<usize>,
    },
    /// Open addressing over ids; the table length is a power of two, at most half full.
    Hashed { table: Vec<u32> },
}

/// Map from state tuples (stored flat) to dense ids, in discovery order.
struct TupleIndex {
    arity: usize,
    tuples: Vec<u32>,
    lookup: Lookup,
}

impl TupleIndex {
    /// An empty index for tuples whose component i ranges over `0..sizes[i]`.
    fn new(sizes: &[usize]) -> Self {
        let space = sizes
            .iter()
            .try_fold(1usize, |acc, &n| acc.checked_mul(n.max(1)));
        let lookup = match space {
            Some(space) if space <= DENSE_LIMIT => {
                let mut strides = vec![1usize; sizes.len()];
                for i in (0..sizes.len().saturating_sub(1)).rev() {
                    strides[i] = strides[i + 1] * sizes[i + 1].max(1);
                }
                Lookup::Dense {
                    slots: vec![0; space],
                    strides,
                }
            }
            _ => Lookup::Hashed {
                table: vec![EMPTY; 1024],
            },
        };
        Self {
            arity: sizes.len(),
            tuples: Vec::new(),
            lookup,
        }
    }

    fn len(&self) -> usize {
        self.tuples.len() / self.arity
    }

    fn tuple(&self, x: usize) -> &[u32] {
        &self.tuples[x * self.arity..(x + 1) * self.arity]
    }

    /// The strides of the direct-address key, if this index uses direct addressing.
    fn strides(&self) -> Option<&[usize]> {
        match &self.lookup {
            Lookup::Dense { strides, .. } => Some(strides),
            Lookup::Hashed { .. } => None,
        }
    }

    /// The id stored under a direct-address key, if any (`None` also for a hashed index).
    fn dense_get(&self, key: usize) -> Option<u32> {
        match &self.lookup {
            Lookup::Dense { slots, .. } => slots[key].checked_sub(1),
            Lookup::Hashed { .. } => None,
        }
    }

    /// Adds tuple `t`, whose direct-address key is `key` and which is not yet present, and returns its id.
    fn dense_insert(&mut self, key: usize, t: &[u32]) -> u32 {
        let id = self.len() as u32;
        if let Lookup::Dense { slots, .. } = &mut self.lookup {
            slots[key] = id + 1;
        }
        self.tuples.extend_from_slice(t);
        id
    }

    fn hash(t: &[u32]) -> usize {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for &v in t {
            h = (h ^ u64::from(v)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            h ^= h >> 29;
        }
        h as usize
    }

    fn equal(tuples: &[u32], arity: usize, id: u32, t: &[u32]) -> bool {
        let base = id as usize * arity;
        tuples[base..base + arity]
            .iter()
            .zip(t)
            .all(|(a, b)| a == b)
    }

    fn find_or_insert(&mut self, t: &[u32]) -> u32 {
        let id = self.len() as u32;
        match &mut self.lookup {
            Lookup::Dense { slots, strides } => {
                let key: usize = t
                    .iter()
                    .zip(strides.iter())
                    .map(|(&v, &s)| v as usize * s)
                    .sum();
                if let Some(found) = slots[key].checked_sub(1) {
                    return found;
                }
                slots[key] = id + 1;
            }
            Lookup::Hashed { table } => {
                let mask = table.len() - 1;
                let mut slot = Self::hash(t) & mask;
                loop {
                    let found = table[slot];
                    if found == EMPTY {
                        break;
                    }
                    if Self::equal(&self.tuples, self.arity, found, t) {
                        return found;
                    }
                    slot = (slot + 1) & mask;
                }
                table[slot] = id;
            }
        }
        self.tuples.extend_from_slice(t);
        if let Lookup::Hashed { table } = &self.lookup
            && self.len() * 2 > table.len()
        {
            self.grow();
        }
        id
    }

    fn grow(&mut self) {
        if let Lookup::Hashed { table } = &mut self.lookup {
            let mut bigger = vec![EMPTY; table.len() * 2];
            let mask = bigger.len() - 1;
            for x in 0..self.tuples.len() / self.arity {
                let mut slot =
                    Self::hash(&self.tuples[x * self.arity..(x + 1) * self.arity]) & mask;
                while bigger[slot] != EMPTY {
                    slot = (slot + 1) & mask;
                }
                bigger[slot] = x as u32;
            }
            *table = bigger;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example of section 4.
    #[test]
    fn section_4_example_multiplies_shared_probabilities_and_takes_max_time() {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let b = ev.intern("b", true).unwrap();
        let c = ev.intern("c", true).unwrap();
        let mut ga = Automaton::new("Ga", ModelKind::Spec);
        let qa = ga.add_state("qa", true).unwrap();
        ga.add_transition(qa, a, qa, 0.5, 2).unwrap();
        ga.add_transition(qa, b, qa, 0.5, 0).unwrap();
        let mut gb = Automaton::new("Gb", ModelKind::Spec);
        let qb = gb.add_state("qb", true).unwrap();
        gb.add_transition(qb, a, qb, 0.4, 5).unwrap();
        gb.add_transition(qb, c, qb, 0.6, 0).unwrap();
        let k = product("K", ModelKind::Spec, &ev, &[&ga, &gb]);
        assert_eq!(k.state_count(), 1);
        assert_eq!(k.state_name(StateId(0)), "(qa,qb)");
        let labels: Vec<_> = k
            .transitions(StateId(0))
            .iter()
            .map(|t| (t.event, t.prob, t.lower_bound))
            .collect();
        assert_eq!(labels.len(), 3);
        assert_eq!(labels[0].0, a);
        assert!((labels[0].1 - 0.2).abs() < 1e-12);
        assert_eq!(labels[0].2, 5);
        assert_eq!((labels[1].0, labels[1].1, labels[1].2), (b, 0.5, 0));
        assert_eq!((labels[2].0, labels[2].1, labels[2].2), (c, 0.6, 0));
    }

    #[test]
    fn c3_product_of_empty_list_is_identity() {
        let ev = EventTable::new();
        let id = product("I", ModelKind::Plant, &ev, &[]);
        assert_eq!(id.state_count(), 1);
        assert!(id.is_marked(StateId(0)));
        assert!(id.alphabet().is_empty());
    }

    #[test]
    fn c2_only_accessible_states_are_built() {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let mut g = Automaton::new("g", ModelKind::Plant);
        let s0 = g.add_state("s0", true).unwrap();
        let s1 = g.add_state("s1", false).unwrap();
        let _unreached = g.add_state("s2", false).unwrap();
        g.add_transition(s0, a, s1, 1.0, 0).unwrap();
        let mut h = Automaton::new("h", ModelKind::Spec);
        let t0 = h.add_state("t0", true).unwrap();
        h.add_transition(t0, a, t0, 1.0, 0).unwrap();
        let k = product("k", ModelKind::Spec, &ev, &[&g, &h]);
        // (s0,t0) -a-> (s1,t0); s1 has no a, so a is blocked there; s2 is never reached.
        assert_eq!(k.state_count(), 2);
        assert_eq!(k.transition_count(), 1);
        assert!(k.is_marked(StateId(0)) && !k.is_marked(StateId(1)));
    }

    #[test]
    fn hashed_and_dense_tuple_indexes_agree() {
        // 9000 x 9000 exceeds DENSE_LIMIT (hashed, growing); 100 x 100 does not (dense).
        for n in [9000u32, 100] {
            let mut idx = TupleIndex::new(&[n as usize, n as usize]);
            assert_eq!(matches!(idx.lookup, Lookup::Dense { .. }), n == 100);
            for i in 0..n {
                assert_eq!(idx.find_or_insert(&[i, (i * 7 + 3) % n]), i);
            }
            for i in 0..n {
                assert_eq!(idx.find_or_insert(&[i, (i * 7 + 3) % n]), i);
                assert_eq!(idx.tuple(i as usize), &[i, (i * 7 + 3) % n]);
            }
            assert_eq!(idx.len(), n as usize);
        }
    }

    /// Two components of 9000 states (a tuple space above DENSE_LIMIT) whose reachable parts are two-state
    /// cycles give the same product through the hashed index as their accessible parts give through the dense one.
    #[test]
    fn hashed_and_dense_products_agree() {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let b = ev.intern("b", false).unwrap();
        let c = ev.intern("c", true).unwrap();
        let build = |name: &str, own: EventId, states: usize| {
            let mut g = Automaton::new(name, ModelKind::Spec);
            for i in 0..states {
                g.add_state(format!("s{i}"), i == 0).unwrap();
            }
            g.add_transition(StateId(0), own, StateId(1), 0.5, 1)
                .unwrap();
            g.add_transition(StateId(1), a, StateId(0), 0.5, 2).unwrap();
            g
        };
        let (g, h) = (build("g", b, 9000), build("h", c, 9000));
        assert!(TupleIndex::new(&[9000, 9000]).strides().is_none());
        let hashed = product_with_tuples("k", ModelKind::Spec, &ev, &[&g, &h]);
        let (gs, hs) = (build("g", b, 2), build("h", c, 2));
        let dense = product_with_tuples("k", ModelKind::Spec, &ev, &[&gs, &hs]);
        assert_eq!(hashed.automaton, dense.automaton);
        assert_eq!(hashed.tuples, dense.tuples);
        assert_eq!(dense.automaton.state_count(), 4);
    }
}
