//! The greedy merge of Su and Wonham: a supervisor's control data in closed loop with its plant, and the cells
//! of consistent states merged into a control congruence (see the parent module's documentation).

use crate::automaton::{Automaton, EventId, EventTable, ModelKind, StateId, Transition};
use crate::compiled::prob_to_q16;
use crate::product::{ProductOutput, product_with_tuples};

/// The control data of a supervisor in closed loop with its plant.
pub(super) struct ControlData<'a> {
    events: &'a EventTable,
    /// S restricted to the transitions the closed loop takes, in breadth-first order (initial state 0).
    sup: Automaton,
    /// Local index of each event id in Σ(S) (`usize::MAX` outside it).
    local: Vec<usize>,
    /// Number of events in Σ(S).
    width: usize,
    /// Bit sets over Σ(S), `words` words per state.
    words: usize,
    enabled: Vec<u64>,
    disabled: Vec<u64>,
    /// T(x): paired with a marked plant state.
    plant_marked: Vec<bool>,
    /// x has a controllable transition with a lower bound above 0.
    timed: Vec<bool>,
}

impl<'a> ControlData<'a> {
    /// The control data of `sup` for `plant`; `None` if the closed loop is empty.
    pub(super) fn new(events: &'a EventTable, plant: &Automaton, sup: &Automaton) -> Option<Self> {
        let closed =
            product_with_tuples("closed loop", ModelKind::Supervisor, events, &[plant, sup]);
        if closed.automaton.state_count() == 0 {
            return None;
        }
        let alphabet = sup.alphabet();
        let words = alphabet.len().div_ceil(64).max(1);
        let mut local = vec![usize::MAX; alphabet.last().map_or(0, |e| e.index() + 1)];
        for (i, e) in alphabet.iter().enumerate() {
            local[e.index()] = i;
        }
        let scan = Scan::new(&closed, plant, sup, words);
        let (restricted, old_of) = restrict_to_used(sup, &scan.used, words, &local);
        let remap = |bits: &[u64]| -> Vec<u64> {
            old_of
                .iter()
                .flat_map(|x| {
                    bits[x.index() * words..(x.index() + 1) * words]
                        .iter()
                        .copied()
                })
                .collect()
        };
        let timed = restricted
            .states()
            .map(|x| {
                restricted
                    .transitions(x)
                    .iter()
                    .any(|t| events.is_controllable(t.event) && t.lower_bound > 0)
            })
            .collect();
        Some(Self {
            events,
            enabled: remap(&scan.used),
            disabled: remap(&scan.disabled),
            plant_marked: old_of
                .iter()
                .map(|x| scan.plant_marked[x.index()])
                .collect(),
            timed,
            sup: restricted,
            local,
            width: alphabet.len(),
            words,
        })
    }

    pub(super) fn state_count(&self) -> usize {
        self.sup.state_count()
    }

    fn local_of(&self, event: EventId) -> usize {
        self.local[event.index()]
    }

    /// Whether x and y may share a cell (conditions 1-4 of the module documentation).
    fn consistent(&self, x: usize, y: usize) -> bool {
        self.control_consistent(x, y)
            && self.marking_consistent(x, y)
            && self.labels_agree(x, y)
            && self.timers_allow(x, y)
    }

    fn control_consistent(&self, x: usize, y: usize) -> bool {
        let w = self.words;
        let (ex, ey) = (
            &self.enabled[x * w..(x + 1) * w],
            &self.enabled[y * w..(y + 1) * w],
        );
        let (dx, dy) = (
            &self.disabled[x * w..(x + 1) * w],
            &self.disabled[y * w..(y + 1) * w],
        );
        (0..w).all(|i| ex[i] & dy[i] == 0 && ey[i] & dx[i] == 0)
    }

    fn marking_consistent(&self, x: usize, y: usize) -> bool {
        let marked = |s: usize| self.sup.is_marked(StateId(s as u32));
        !(self.plant_marked[x] && self.plant_marked[y] && marked(x) != marked(y))
    }

    fn labels_agree(&self, x: usize, y: usize) -> bool {
        let ty = self.sup.transitions(StateId(y as u32));
        self.sup
            .transitions(StateId(x as u32))
            .iter()
            .filter(|t| self.events.is_controllable(t.event))
            .all(|t| {
                ty.binary_search_by_key(&t.event, |u| u.event)
                    .map_or(true, |i| same_label(t, &ty[i]))
            })
    }

    fn timers_allow(&self, x: usize, y: usize) -> bool {
        !self.enters_timed(x, y) && !self.enters_timed(y, x)
    }

    /// Whether a transition leads from `from` to a different state `to` that has a timed transition.
    fn enters_timed(&self, from: usize, to: usize) -> bool {
        self.timed[to]
            && from != to
            && self
                .sup
                .transitions(StateId(from as u32))
                .iter()
                .any(|t| t.target.index() == to)
    }

    /// The quotient of the restricted supervisor by `class` (dense class ids, the initial state's class 0).
    pub(super) fn quotient(&self, class: &[u32]) -> Automaton {
        let count = class.iter().max().map_or(0, |&c| c as usize + 1);
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); count];
        for (x, &c) in class.iter().enumerate() {
            members[c as usize].push(x);
        }
        let mut r = Automaton::new(self.sup.name(), ModelKind::Supervisor);
        r.alphabet = self.sup.alphabet().to_vec();
        let mut slot: Vec<Option<Transition>> = vec![None; self.width];
        for cell in &members {
            let first = StateId(cell[0] as u32);
            // Members agree on marking wherever the plant is marked with them; elsewhere marking is free.
            let marked = cell
                .iter()
                .find(|&&x| self.plant_marked[x])
                .map_or(self.sup.is_marked(first), |&x| {
                    self.sup.is_marked(StateId(x as u32))
                });
            for &x in cell {
                for t in self.sup.transitions(StateId(x as u32)) {
                    let entry = &mut slot[self.local_of(t.event)];
                    if entry.is_none() {
                        *entry = Some(Transition {
                            target: StateId(class[t.target.index()]),
                            ..*t
                        });
                    }
                }
            }
            let transitions: Vec<Transition> = slot.iter_mut().filter_map(Option::take).collect();
            r.push_state(self.sup.state_name(first), marked, transitions);
        }
        r.initial = StateId(0);
        r
    }
}

/// What the closed loop G ∥ S says about each state of S (bit sets over Σ(S), `words` words per state).
struct Scan {
    /// Events defined in S and possible in a paired plant state: the transitions the closed loop takes.
    used: Vec<u64>,
    /// Events possible in a paired plant state but not defined in S: D(x).
    disabled: Vec<u64>,
    /// Paired with a marked plant state: T(x).
    plant_marked: Vec<bool>,
}

impl Scan {
    /// Scans every state of `closed` = `plant` ∥ `sup`.
    pub(super) fn new(
        closed: &ProductOutput,
        plant: &Automaton,
        sup: &Automaton,
        words: usize,
    ) -> Self {
        let n = sup.state_count();
        let mut scan = Self {
            used: vec![0; n * words],
            disabled: vec![0; n * words],
            plant_marked: vec![false; n],
        };
        for y in closed.automaton.states() {
            let (g, x) = pair(closed, y);
            scan.plant_marked[x.index()] |= plant.is_marked(g);
            for (i, &e) in sup.alphabet().iter().enumerate() {
                let possible = !plant.has_event(e) || plant.transition(g, e).is_some();
                match (possible, sup.transition(x, e).is_some()) {
                    (true, true) => set_bit(&mut scan.used, words, x.index(), i),
                    (true, false) => set_bit(&mut scan.disabled, words, x.index(), i),
                    (false, _) => {}
                }
            }
        }
        scan
    }
}

/// The plant and supervisor states of a closed-loop state.
fn pair(closed: &ProductOutput, y: StateId) -> (StateId, StateId) {
    let t = closed.tuple(y);
    (StateId(t[0]), StateId(t[1]))
}

fn set_bit(bits: &mut [u64], words: usize, x: usize, i: usize) {
    bits[x * words + i / 64] |= 1 << (i % 64);
}

fn get_bit(bits: &[u64], words: usize, x: usize, i: usize) -> bool {
    bits[x * words + i / 64] & (1 << (i % 64)) != 0
}

/// Equal P (in Q0.16) and T.
pub(super) fn same_label(a: &Transition, b: &Transition) -> bool {
    prob_to_q16(a.prob) == prob_to_q16(b.prob) && a.lower_bound == b.lower_bound
}

/// `sup` with only the transitions marked in `used`, restricted to the states they reach from the initial state,
/// numbered in breadth-first order; with the old id of each new state.
fn restrict_to_used(
    sup: &Automaton,
    used: &[u64],
    words: usize,
    local: &[usize],
) -> (Automaton, Vec<StateId>) {
    let kept = |x: StateId| {
        sup.transitions(x)
            .iter()
            .filter(move |t| get_bit(used, words, x.index(), local[t.event.index()]))
    };
    let mut new_id = vec![u32::MAX; sup.state_count()];
    let mut order = vec![sup.initial()];
    new_id[sup.initial().index()] = 0;
    let mut i = 0;
    while i < order.len() {
        for t in kept(order[i]) {
            if new_id[t.target.index()] == u32::MAX {
                new_id[t.target.index()] = order.len() as u32;
                order.push(t.target);
            }
        }
        i += 1;
    }
    let mut r = Automaton::new(sup.name(), sup.kind());
    r.alphabet = sup.alphabet().to_vec();
    for &x in &order {
        let transitions = kept(x).map(|t| Transition {
            target: StateId(new_id[t.target.index()]),
            ..*t
        });
        r.push_state(sup.state_name(x), sup.is_marked(x), transitions);
    }
    r.initial = StateId(0);
    (r, order)
}

/// One union, as recorded for undoing it.
struct Union {
    child: u32,
    root: u32,
    least_before: u32,
}

/// A partition of states into cells: union-find without path compression (so unions can be undone in reverse
/// order), each cell's members on a circular list, and each cell's least member.
pub(super) struct Cells {
    parent: Vec<u32>,
    size: Vec<u32>,
    least: Vec<u32>,
    next: Vec<u32>,
    trail: Vec<Union>,
}

impl Cells {
    pub(super) fn new(n: usize) -> Self {
        let ids: Vec<u32> = (0..n as u32).collect();
        Self {
            parent: ids.clone(),
            size: vec![1; n],
            least: ids.clone(),
            next: ids,
            trail: Vec::new(),
        }
    }

    pub(super) fn find(&self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            x = self.parent[x] as usize;
        }
        x
    }

    /// Whether `x` is the least member of its cell.
    pub(super) fn is_least(&self, x: usize) -> bool {
        self.least[self.find(x)] as usize == x
    }

    /// Replaces `out` by the members of the cell with root `root`.
    pub(super) fn members_into(&self, root: usize, out: &mut Vec<usize>) {
        out.clear();
        let mut x = root;
        loop {
            out.push(x);
            x = self.next[x] as usize;
            if x == root {
                break;
            }
        }
    }

    /// Joins the cells with roots `a` and `b`.
    pub(super) fn union(&mut self, a: usize, b: usize) {
        let (child, root) = if self.size[a] < self.size[b] {
            (a, b)
        } else {
            (b, a)
        };
        self.trail.push(Union {
            child: child as u32,
            root: root as u32,
            least_before: self.least[root],
        });
        self.parent[child] = root as u32;
        self.size[root] += self.size[child];
        self.least[root] = self.least[root].min(self.least[child]);
        self.next.swap(child, root);
    }

    /// The number of unions so far, to undo back to.
    pub(super) fn mark(&self) -> usize {
        self.trail.len()
    }

    /// Undoes the unions made since `mark`, latest first.
    pub(super) fn undo(&mut self, mark: usize) {
        while self.trail.len() > mark {
            let Some(u) = self.trail.pop() else { break };
            let (child, root) = (u.child as usize, u.root as usize);
            self.next.swap(child, root);
            self.size[root] -= self.size[child];
            self.least[root] = u.least_before;
            self.parent[child] = u.child;
        }
    }

    /// Dense cell ids, numbered in the order of each cell's least member.
    pub(super) fn classes(&self) -> Vec<u32> {
        let n = self.parent.len();
        let mut id_of_root = vec![u32::MAX; n];
        let mut next_id = 0;
        (0..n)
            .map(|x| {
                let r = self.find(x);
                if id_of_root[r] == u32::MAX {
                    id_of_root[r] = next_id;
                    next_id += 1;
                }
                id_of_root[r]
            })
            .collect()
    }
}

/// How a tentative merge ended.
enum Attempt {
    Merged,
    Inconsistent,
    OutOfBudget,
}

/// The greedy merge over the control data.
pub(super) struct Merger<'a> {
    data: &'a ControlData<'a>,
    pub(super) cells: Cells,
    budget: u64,
    left: Vec<usize>,
    right: Vec<usize>,
    /// The successor of the left cell under each local event (`u32::MAX` for none).
    successor: Vec<u32>,
}

impl<'a> Merger<'a> {
    pub(super) fn new(data: &'a ControlData<'a>, budget: u64) -> Self {
        Self {
            data,
            cells: Cells::new(data.state_count()),
            budget,
            left: Vec::new(),
            right: Vec::new(),
            successor: vec![u32::MAX; data.width],
        }
    }

    /// Tries every pair of cells in order; `false` if the budget ran out first.
    pub(super) fn run(&mut self) -> bool {
        let n = self.data.state_count();
        for i in 0..n {
            if !self.cells.is_least(i) {
                continue;
            }
            for j in i + 1..n {
                if !self.cells.is_least(j) {
                    continue;
                }
                let mark = self.cells.mark();
                match self.try_merge(i, j) {
                    Attempt::Merged => {}
                    Attempt::Inconsistent => self.cells.undo(mark),
                    Attempt::OutOfBudget => {
                        self.cells.undo(mark);
                        return false;
                    }
                }
            }
        }
        true
    }

    /// Merges the cells of i and j and, recursively, the cells of their common successors.
    fn try_merge(&mut self, i: usize, j: usize) -> Attempt {
        let mut pending = vec![(i, j)];
        while let Some((a, b)) = pending.pop() {
            let (ra, rb) = (self.cells.find(a), self.cells.find(b));
            if ra == rb {
                continue;
            }
            self.cells.members_into(ra, &mut self.left);
            self.cells.members_into(rb, &mut self.right);
            if let Some(stop) = self.check_members() {
                return stop;
            }
            self.successor_pairs(&mut pending);
            self.cells.union(ra, rb);
        }
        Attempt::Merged
    }

    /// Checks every pair of `left` × `right`; `None` if all are consistent.
    fn check_members(&mut self) -> Option<Attempt> {
        for &x in &self.left {
            for &y in &self.right {
                if self.budget == 0 {
                    return Some(Attempt::OutOfBudget);
                }
                self.budget -= 1;
                if !self.data.consistent(x, y) {
                    return Some(Attempt::Inconsistent);
                }
            }
        }
        None
    }

    /// Adds to `pending` the pair of successors of `left` and `right` under each event both define.
    fn successor_pairs(&mut self, pending: &mut Vec<(usize, usize)>) {
        let sup = &self.data.sup;
        for &x in &self.left {
            for t in sup.transitions(StateId(x as u32)) {
                let k = self.data.local_of(t.event);
                if self.successor[k] == u32::MAX {
                    self.successor[k] = t.target.0;
                }
            }
        }
        for &y in &self.right {
            for t in sup.transitions(StateId(y as u32)) {
                let k = self.data.local_of(t.event);
                if self.successor[k] != u32::MAX {
                    pending.push((self.successor[k] as usize, t.target.index()));
                }
            }
        }
        for &x in &self.left {
            for t in sup.transitions(StateId(x as u32)) {
                self.successor[self.data.local_of(t.event)] = u32::MAX;
            }
        }
    }
}
