//! Supervisor reduction by control congruence (Su and Wonham, "Supervisor reduction for discrete-event systems",
//! Discrete Event Dynamic Systems 14, 2004), keeping ptSCT probabilities and timers.
//!
//! Minimisation (section 7) merges only states with the same future. Reduction also merges states whose futures
//! differ where the plant decides anyway: an event the plant cannot generate in a state is neither enabled nor
//! disabled there ("don't care"). The reduced supervisor S_red is correct only **in closed loop with the plant**:
//! G ∥ S_red has the same language, marked language and labels as G ∥ S.
//!
//! **Control data.** In the closed loop G ∥ S, a state x of S has its enabled events E(x) (taken in the closed loop),
//! its disabled events D(x) (in Σ(S), possible in a plant state paired with x, not defined at x; events outside
//! Σ(G) are always possible), M(x) (x is marked) and T(x) (x is paired with a marked plant state). Transitions
//! of S the plant never lets happen are dropped first; they do not change the closed loop.
//!
//! **Consistency.** States x and y may share a cell only if
//! 1. E(x) ∩ D(y) = ∅ = E(y) ∩ D(x) (control);
//! 2. T(x) ∧ T(y) ⇒ M(x) = M(y) (marking);
//! 3. every controllable event defined at both has the same P (in Q0.16) and the same T (labels);
//! 4. neither enters the other by a state-changing transition while the entered state has a timed (T > 0)
//!    controllable transition (timers: the player restarts a supervisor's counters when its state changes, and a
//!    transition inside a cell is a self-loop of the reduced supervisor, which restarts only its own counter).
//!
//! **Greedy merge** (Su and Wonham's polynomial algorithm): states in breadth-first order; for each state i that is
//! the least of its cell and each later state j that is the least of its cell, tentatively merge the two cells,
//! and with them, recursively, the cells of their successors under every common event; keep the merge if every
//! pair of states brought together is consistent, undo it otherwise. The result is a partition whose cells have
//! one successor cell per event (a control congruence), and S_red is the quotient.
//!
//! **Limits.** Supervisors of more than [`MAX_REDUCE_STATES`] states are not reduced ([`ReduceError::TooLarge`];
//! [`reduce_synthesis`] keeps them unreduced with a warning). Each reduction may spend [`MERGE_BUDGET`] pair checks;
//! when they run out the merging stops and the partition found so far (itself a control congruence) is used.
//!
//! **Checked.** [`check_reduction`] compares G ∥ S with G ∥ S_red directly (not through the algorithm): same
//! events at every reachable pair, same marking, the same P and T on every transition, and timed transitions
//! only where both supervisors' counters were restarted alike. [`reduce_synthesis`] runs it on every reduction, and
//! [`check_set`] on the set it chooses to run (observers included) against the unreduced set, as the player runs
//! them without plants.
//!
//! **At runtime** the player executes supervisors without plants. A reduced supervisor may enable, in a cell, an
//! event that the plant cannot generate in the current plant state; the unreduced supervisor tracked the plant and
//! blocked it. So a plant component whose constraint a reduced supervisor relies on must be enforced by another
//! member of the set: a supervisor run unreduced whose plant contains it, a reduced one that does not rely on it,
//! or a *plant observer* (the plant with P = 1 and T = 0, minimised) that [`reduce_synthesis`] adds. Observers
//! change no weight and no timer; with them the compiled set generates what the unreduced set generated.
//! [`reduce_synthesis`] uses a reduction only where the set, observers included, gets smaller.

use std::collections::HashSet;
use std::fmt;

use crate::architecture::{Architecture, Difference, compare_languages, local_plants};
use crate::automaton::{Automaton, EventId, EventTable, ModelKind, StateId, Transition};
use crate::compiled::{CodegenError, SupervisorSet, mem_cons_of, prob_to_q16};
use crate::minimise::minimise;
use crate::pipeline::{SupervisorSynthesis, Synthesis};
use crate::product::{ProductOutput, product, product_with_tuples};

/// Supervisors with more states than this are not reduced: the greedy merge is O(n⁴) pair checks in the worst
/// case, so a larger supervisor is kept as it is (with a warning) rather than reduced for hours.
pub const MAX_REDUCE_STATES: usize = 5_000;

/// Pair checks one reduction may spend (about 20 s of a release build, over a minute of a debug build); then
/// merging stops with the cells found so far.
pub const MERGE_BUDGET: u64 = 200_000_000;

/// Bounds of one reduction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReduceLimits {
    /// Largest supervisor (in states) that is reduced.
    pub max_states: usize,
    /// Pair checks the greedy merge may spend.
    pub merge_budget: u64,
}

impl Default for ReduceLimits {
    fn default() -> Self {
        Self {
            max_states: MAX_REDUCE_STATES,
            merge_budget: MERGE_BUDGET,
        }
    }
}

/// Why a supervisor was not reduced, or a reduction was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReduceError {
    /// The supervisor is larger than [`ReduceLimits::max_states`].
    #[error(
        "supervisor `{supervisor}` has {states} states, more than the {limit} that reduction accepts; it is kept unreduced"
    )]
    TooLarge {
        /// The supervisor.
        supervisor: String,
        /// Its states.
        states: usize,
        /// The limit.
        limit: usize,
    },
    /// The closed loop of the plant and the supervisor has no state (one of them has none).
    #[error(
        "supervisor `{supervisor}` and plant `{plant}` have an empty closed loop: nothing to reduce"
    )]
    EmptyClosedLoop {
        /// The supervisor.
        supervisor: String,
        /// The plant.
        plant: String,
    },
    /// The set to run (reduced supervisors and observers) does not generate, as the player runs it, what the
    /// unreduced set generates, or with other weights or bounds ([`check_set`]); it must not be used.
    #[error(
        "the reduced supervisor set, run without plants as the player runs it, differs from the unreduced set, so it is refused: {0}"
    )]
    SetCheckFailed(ReductionMismatch),
    /// The reduced supervisor failed [`check_reduction`]; it must not be used.
    #[error(
        "the reduction of supervisor `{supervisor}` failed its equivalence check, so it is refused: {mismatch}"
    )]
    CheckFailed {
        /// The supervisor.
        supervisor: String,
        /// The first difference found.
        mismatch: ReductionMismatch,
    },
}

/// The result of [`reduce`].
#[derive(Debug, Clone)]
pub struct Reduced {
    /// The reduced supervisor: same name, kind and alphabet as the original; each state is named after the first
    /// state of its cell.
    pub supervisor: Automaton,
    /// `false` if [`ReduceLimits::merge_budget`] ran out and merging stopped early (the result is still correct).
    pub complete: bool,
}

/// Reduces `supervisor` for `plant` (both over `events`): the closed loop keeps its language, marked language,
/// labels and timer behaviour (see the module documentation).
pub fn reduce(
    events: &EventTable,
    plant: &Automaton,
    supervisor: &Automaton,
    limits: ReduceLimits,
) -> Result<Reduced, ReduceError> {
    let states = supervisor.state_count();
    if states > limits.max_states {
        return Err(ReduceError::TooLarge {
            supervisor: supervisor.name().to_owned(),
            states,
            limit: limits.max_states,
        });
    }
    crate::progress::stage(|| format!("reduction of {} ({states} states)", supervisor.name()));
    let data = ControlData::new(events, plant, supervisor).ok_or_else(|| {
        ReduceError::EmptyClosedLoop {
            supervisor: supervisor.name().to_owned(),
            plant: plant.name().to_owned(),
        }
    })?;
    let mut merger = Merger::new(&data, limits.merge_budget);
    let complete = merger.run();
    Ok(Reduced {
        supervisor: data.quotient(&merger.cells.classes()),
        complete,
    })
}

/// The control data of a supervisor in closed loop with its plant.
struct ControlData<'a> {
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
    fn new(events: &'a EventTable, plant: &Automaton, sup: &Automaton) -> Option<Self> {
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

    fn state_count(&self) -> usize {
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
    fn quotient(&self, class: &[u32]) -> Automaton {
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
    fn new(closed: &ProductOutput, plant: &Automaton, sup: &Automaton, words: usize) -> Self {
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
fn same_label(a: &Transition, b: &Transition) -> bool {
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
struct Cells {
    parent: Vec<u32>,
    size: Vec<u32>,
    least: Vec<u32>,
    next: Vec<u32>,
    trail: Vec<Union>,
}

impl Cells {
    fn new(n: usize) -> Self {
        let ids: Vec<u32> = (0..n as u32).collect();
        Self {
            parent: ids.clone(),
            size: vec![1; n],
            least: ids.clone(),
            next: ids,
            trail: Vec::new(),
        }
    }

    fn find(&self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            x = self.parent[x] as usize;
        }
        x
    }

    /// Whether `x` is the least member of its cell.
    fn is_least(&self, x: usize) -> bool {
        self.least[self.find(x)] as usize == x
    }

    /// Replaces `out` by the members of the cell with root `root`.
    fn members_into(&self, root: usize, out: &mut Vec<usize>) {
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
    fn union(&mut self, a: usize, b: usize) {
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
    fn mark(&self) -> usize {
        self.trail.len()
    }

    /// Undoes the unions made since `mark`, latest first.
    fn undo(&mut self, mark: usize) {
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
    fn classes(&self) -> Vec<u32> {
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
struct Merger<'a> {
    data: &'a ControlData<'a>,
    cells: Cells,
    budget: u64,
    left: Vec<usize>,
    right: Vec<usize>,
    /// The successor of the left cell under each local event (`u32::MAX` for none).
    successor: Vec<u32>,
}

impl<'a> Merger<'a> {
    fn new(data: &'a ControlData<'a>, budget: u64) -> Self {
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
    fn run(&mut self) -> bool {
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

/// The first difference between two closed loops, with a shortest string leading to it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionMismatch {
    /// The events of the string (empty for the initial state).
    pub string: Vec<String>,
    /// What differs after it.
    pub problem: MismatchProblem,
}

/// What differs between G ∥ S and G ∥ S_red.
#[derive(Debug, Clone, PartialEq)]
pub enum MismatchProblem {
    /// The supervisors have different alphabets (so they would own different events at runtime).
    AlphabetDiffers,
    /// Exactly one of the closed loops is empty.
    EmptyClosedLoop {
        /// Whether it is the original's closed loop that is empty.
        original_empty: bool,
    },
    /// The event is possible with the original supervisor only.
    OnlyOriginal {
        /// The event.
        event: String,
    },
    /// The event is possible with the reduced supervisor only.
    OnlyReduced {
        /// The event.
        event: String,
    },
    /// The string is marked by one closed loop only.
    Marking {
        /// Whether the original closed loop marks it.
        original: bool,
    },
    /// The transition's P (Q0.16) or T differ.
    Label {
        /// The event.
        event: String,
        /// (P in Q0.16, T) with the original supervisor.
        original: (u16, u32),
        /// (P in Q0.16, T) with the reduced supervisor.
        reduced: (u16, u32),
    },
    /// A timed transition is reachable after one supervisor restarted its counters and the other did not.
    Timer {
        /// The timed event.
        event: String,
    },
}

impl fmt::Display for ReductionMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.string.is_empty() {
            write!(f, "initially, ")?;
        } else {
            write!(f, "after `{}`, ", self.string.join(" "))?;
        }
        match &self.problem {
            MismatchProblem::AlphabetDiffers => write!(f, "the alphabets differ"),
            MismatchProblem::EmptyClosedLoop { original_empty } => write!(
                f,
                "only the {} supervisor's closed loop is empty",
                if *original_empty {
                    "original"
                } else {
                    "reduced"
                }
            ),
            MismatchProblem::OnlyOriginal { event } => {
                write!(f, "`{event}` is possible with the original supervisor only")
            }
            MismatchProblem::OnlyReduced { event } => {
                write!(f, "`{event}` is possible with the reduced supervisor only")
            }
            MismatchProblem::Marking { original } => write!(
                f,
                "the string is marked with the {} supervisor only",
                if *original { "original" } else { "reduced" }
            ),
            MismatchProblem::Label {
                event,
                original,
                reduced,
            } => write!(
                f,
                "`{event}` has P = {}/65535, T = {} originally but P = {}/65535, T = {} reduced",
                original.0, original.1, reduced.0, reduced.1
            ),
            MismatchProblem::Timer { event } => write!(
                f,
                "timed `{event}` is reachable where only one supervisor restarted its counters"
            ),
        }
    }
}

/// Checks that `reduced` can replace `original` for `plant`: G ∥ S and G ∥ S_red have the same language and
/// marked language, the same P (Q0.16) and T on every reachable transition, and no timed transition reachable
/// after a step that changed the state of only one of the two supervisors (their counters then differ).
/// Returns the first difference along a shortest string.
pub fn check_reduction(
    events: &EventTable,
    plant: &Automaton,
    original: &Automaton,
    reduced: &Automaton,
) -> Result<(), ReductionMismatch> {
    let fail = |problem| {
        Err(ReductionMismatch {
            string: Vec::new(),
            problem,
        })
    };
    if original.alphabet() != reduced.alphabet() {
        return fail(MismatchProblem::AlphabetDiffers);
    }
    let kind = ModelKind::Supervisor;
    let a = product_with_tuples("G ∥ S", kind, events, &[plant, original]);
    let b = product_with_tuples("G ∥ S_red", kind, events, &[plant, reduced]);
    match (a.automaton.state_count(), b.automaton.state_count()) {
        (0, 0) => Ok(()),
        (0, _) => fail(MismatchProblem::EmptyClosedLoop {
            original_empty: true,
        }),
        (_, 0) => fail(MismatchProblem::EmptyClosedLoop {
            original_empty: false,
        }),
        _ => Walk::new(events, &a, &b).run(),
    }
}

/// A node of the breadth-first walk over pairs of closed-loop states.
struct Node {
    a: StateId,
    b: StateId,
    /// Both supervisors' counters were restarted alike (all stamps equal).
    same: bool,
    parent: u32,
    event: EventId,
}

/// The walk of [`check_reduction`].
struct Walk<'a> {
    events: &'a EventTable,
    a: &'a ProductOutput,
    b: &'a ProductOutput,
    nodes: Vec<Node>,
    seen: HashSet<(StateId, StateId, bool)>,
}

impl<'a> Walk<'a> {
    fn new(events: &'a EventTable, a: &'a ProductOutput, b: &'a ProductOutput) -> Self {
        let (a0, b0) = (a.automaton.initial(), b.automaton.initial());
        Self {
            events,
            a,
            b,
            nodes: vec![Node {
                a: a0,
                b: b0,
                same: true,
                parent: u32::MAX,
                event: EventId(0),
            }],
            seen: HashSet::from([(a0, b0, true)]),
        }
    }

    fn run(mut self) -> Result<(), ReductionMismatch> {
        let mut i = 0;
        while i < self.nodes.len() {
            if let Err(problem) = self.visit(i) {
                return Err(ReductionMismatch {
                    string: self.string(i),
                    problem,
                });
            }
            i += 1;
        }
        Ok(())
    }

    /// Compares node `i`'s states and queues its successors.
    fn visit(&mut self, i: usize) -> Result<(), MismatchProblem> {
        let Node {
            a: x, b: y, same, ..
        } = self.nodes[i];
        let (ga, gb) = (&self.a.automaton, &self.b.automaton);
        if ga.is_marked(x) != gb.is_marked(y) {
            return Err(MismatchProblem::Marking {
                original: ga.is_marked(x),
            });
        }
        let (ta, tb) = (ga.transitions(x), gb.transitions(y));
        if let Some(problem) = self.enabled_difference(ta, tb) {
            return Err(problem);
        }
        for (t, u) in ta.iter().zip(tb) {
            self.compare_step(t, u, same)?;
            let moved_a = self.a.tuple(t.target)[1] != self.a.tuple(x)[1];
            let moved_b = self.b.tuple(u.target)[1] != self.b.tuple(y)[1];
            let same_next = match (moved_a, moved_b) {
                (true, true) => true,
                (false, false) => same,
                _ => false,
            };
            if self.seen.insert((t.target, u.target, same_next)) {
                self.nodes.push(Node {
                    a: t.target,
                    b: u.target,
                    same: same_next,
                    parent: i as u32,
                    event: t.event,
                });
            }
        }
        Ok(())
    }

    /// The first event enabled on one side only.
    fn enabled_difference(&self, ta: &[Transition], tb: &[Transition]) -> Option<MismatchProblem> {
        let name = |e: EventId| self.events.name(e).to_owned();
        let first_only = |p: &[Transition], q: &[Transition]| {
            p.iter()
                .find(|t| q.binary_search_by_key(&t.event, |u| u.event).is_err())
                .map(|t| t.event)
        };
        match (first_only(ta, tb), first_only(tb, ta)) {
            (Some(e), Some(f)) if f < e => Some(MismatchProblem::OnlyReduced { event: name(f) }),
            (Some(e), _) => Some(MismatchProblem::OnlyOriginal { event: name(e) }),
            (None, Some(f)) => Some(MismatchProblem::OnlyReduced { event: name(f) }),
            (None, None) => None,
        }
    }

    /// Labels of one common step, and its timer when the counters may differ.
    fn compare_step(
        &self,
        t: &Transition,
        u: &Transition,
        same: bool,
    ) -> Result<(), MismatchProblem> {
        if !self.events.is_controllable(t.event) {
            return Ok(());
        }
        let name = self.events.name(t.event).to_owned();
        if !same_label(t, u) {
            return Err(MismatchProblem::Label {
                event: name,
                original: (prob_to_q16(t.prob), t.lower_bound),
                reduced: (prob_to_q16(u.prob), u.lower_bound),
            });
        }
        if !same && t.lower_bound > 0 {
            return Err(MismatchProblem::Timer { event: name });
        }
        Ok(())
    }

    /// The string leading to node `i`.
    fn string(&self, mut i: usize) -> Vec<String> {
        let mut s = Vec::new();
        while self.nodes[i].parent != u32::MAX {
            s.push(self.events.name(self.nodes[i].event).to_owned());
            i = self.nodes[i].parent as usize;
        }
        s.reverse();
        s
    }
}

/// A plant component as the runtime observes it: the plant with P = 1 and T = 0 on every transition, minimised.
/// It only blocks the events its plant cannot generate in its current state; it changes no weight and no timer.
pub fn observer(plant: &Automaton) -> Automaton {
    let mut o = plant.clone();
    for t in o.all_transitions_mut() {
        t.prob = 1.0;
        t.lower_bound = 0;
    }
    o.set_kind(ModelKind::Plant);
    minimise(&o)
}

/// Which of `parts` (the components of the plant `reduced` was reduced for) the runtime must run as observers:
/// those that cannot generate, in a reachable closed-loop state, an event the reduced supervisor defines there.
pub fn observers_needed(
    events: &EventTable,
    parts: &[&Automaton],
    reduced: &Automaton,
) -> Vec<bool> {
    let mut all = parts.to_vec();
    all.push(reduced);
    let closed = product_with_tuples("observed loop", ModelKind::Supervisor, events, &all);
    let mut needed = vec![false; parts.len()];
    for y in closed.automaton.states() {
        let tuple = closed.tuple(y);
        let cell = StateId(tuple[parts.len()]);
        for t in reduced.transitions(cell) {
            for (k, part) in parts.iter().enumerate() {
                let state = StateId(tuple[k]);
                needed[k] |= part.has_event(t.event) && part.transition(state, t.event).is_none();
            }
        }
    }
    needed
}

/// The bytes one supervisor adds to MemCons (section 9): `(s + 3t) + 2(s + 2·t_c)` for its arrays, `e` for its
/// row of the membership matrix and 2 for its current state. The shares of a set plus `e` (the controllability
/// flags) are the set's MemCons.
pub fn mem_cons_share(events: &EventTable, a: &Automaton) -> usize {
    mem_cons_of(events, &[a]) - events.len()
}

/// What [`reduce_synthesis`] did with one supervisor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReductionOutcome {
    /// The reduced supervisor replaces the original.
    Reduced,
    /// The reduction is no smaller (in MemCons) than the original, which is kept.
    NoGain,
    /// The reduction is smaller, but the plant observers it needs would make the set larger; the original is
    /// kept.
    ObserversCostMore,
    /// The supervisor was not reduced; the reason is a warning for the designer.
    Skipped {
        /// Why.
        reason: String,
    },
}

/// One supervisor and its reduction.
#[derive(Debug, Clone)]
pub struct SupervisorReduction {
    /// The supervisor name.
    pub name: String,
    /// The minimised supervisor of the synthesis.
    pub original: Automaton,
    /// Its checked reduction, whether used or not (`None` when skipped).
    pub reduced: Option<Automaton>,
    /// What happened.
    pub outcome: ReductionOutcome,
    /// `false` if the merge budget ran out (the reduction is correct but may not be as small as it could be).
    pub complete: bool,
}

impl SupervisorReduction {
    /// The supervisor to run: the reduction when [`ReductionOutcome::Reduced`], the original otherwise.
    pub fn supervisor(&self) -> &Automaton {
        match (&self.outcome, &self.reduced) {
            (ReductionOutcome::Reduced, Some(reduced)) => reduced,
            _ => &self.original,
        }
    }
}

/// The reduced supervisor set of a synthesis.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// One entry per supervisor of the synthesis, in order.
    pub supervisors: Vec<SupervisorReduction>,
    /// Plant observers the runtime needs next to the reduced supervisors (see the module documentation).
    pub observers: Vec<Automaton>,
    /// MemCons of the unreduced set.
    pub mem_cons_before: usize,
    /// MemCons of the set to run: supervisors and observers (never more than `mem_cons_before`).
    pub mem_cons_after: usize,
}

impl Reduction {
    /// The automata to compile, in order: every supervisor to run, then the observers.
    pub fn final_automata(&self) -> Vec<Automaton> {
        self.supervisors
            .iter()
            .map(|s| s.supervisor().clone())
            .chain(self.observers.iter().cloned())
            .collect()
    }

    /// Compiles [`Self::final_automata`] (fails on the limits of V15).
    pub fn compile(&self, events: &EventTable) -> Result<SupervisorSet, CodegenError> {
        SupervisorSet::from_supervisors(events, &self.final_automata())
    }

    /// Sentences for the designer: supervisors not reduced and reductions cut short.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        for s in &self.supervisors {
            if let ReductionOutcome::Skipped { reason } = &s.outcome {
                out.push(reason.clone());
            }
            if !s.complete {
                out.push(format!(
                    "the reduction of `{}` ran out of its pair checks; it is correct but may not be minimal",
                    s.name
                ));
            }
        }
        out
    }
}

/// Reduces every supervisor of `synthesis` for its plant (the local plant in local-modular mode, all plants
/// otherwise) and checks each reduction with [`check_reduction`]. Then chooses which reductions to run: among
/// the reductions smaller in MemCons, the subset whose set, with the plant observers it needs, has the least
/// MemCons (every subset when there are at most 12 such reductions; beyond, starting from all of them,
/// reductions are given up one at a time while that shrinks the set, and the unreduced set is taken if it is
/// smaller still). The empty subset is a candidate, so the set never grows; ties keep fewer reductions.
///
/// Fails only if a check fails ([`ReduceError::CheckFailed`]) or a closed loop is empty; supervisors too large to
/// reduce are kept with [`ReductionOutcome::Skipped`].
pub fn reduce_synthesis(
    synthesis: &Synthesis,
    limits: ReduceLimits,
) -> Result<Reduction, ReduceError> {
    let events = &synthesis.normalised.events;
    let plants = &synthesis.normalised.plants;
    let mut supervisors = Vec::with_capacity(synthesis.supervisors.len());
    let mut parts = Vec::with_capacity(synthesis.supervisors.len());
    let mut needs = Vec::with_capacity(synthesis.supervisors.len());
    for s in &synthesis.supervisors {
        let entry = reduce_one(events, s, limits)?;
        let own = plant_parts(synthesis, s);
        needs.push(match (&entry.outcome, &entry.reduced) {
            (ReductionOutcome::Reduced, Some(reduced)) => {
                let refs: Vec<&Automaton> = own.iter().map(|&k| &plants[k]).collect();
                let needed = observers_needed(events, &refs, reduced);
                own.iter()
                    .zip(needed)
                    .filter(|(_, n)| *n)
                    .map(|(&k, _)| k)
                    .collect()
            }
            _ => Vec::new(),
        });
        parts.push(own);
        supervisors.push(entry);
    }
    let observers: Vec<Option<Automaton>> = (0..plants.len())
        .map(|k| {
            needs
                .iter()
                .any(|n| n.contains(&k))
                .then(|| observer(&plants[k]))
        })
        .collect();
    let costs = Costs::new(
        events,
        &supervisors,
        Dependencies {
            parts: &parts,
            needs: &needs,
        },
        &observers,
    );
    let used = costs.choose();
    for (entry, &use_it) in supervisors.iter_mut().zip(&used) {
        if entry.outcome == ReductionOutcome::Reduced && !use_it {
            entry.outcome = ReductionOutcome::ObserversCostMore;
        }
    }
    let needed = costs.observers_of(&used);
    let observers: Vec<Automaton> = observers
        .into_iter()
        .zip(needed)
        .filter_map(|(o, n)| o.filter(|_| n))
        .collect();
    let reduction = Reduction {
        mem_cons_before: synthesis.mem_cons,
        mem_cons_after: costs.total(&used),
        supervisors,
        observers,
    };
    if used.contains(&true) {
        let before = synthesis.final_supervisors();
        check_set(events, &before, &reduction.final_automata())
            .map_err(ReduceError::SetCheckFailed)?;
    }
    Ok(reduction)
}

/// Checks a supervisor set to run (`after`) against the unreduced set (`before`) as the player runs them, without
/// plants: their products generate the same language, and every common transition has the same P (normalised
/// over the enabled controllable events, as the player draws) and the same T. Marking is not compared (the player
/// has none; [`check_reduction`] compares it in closed loop), nor timers (a product takes the largest bound and
/// loses the per-supervisor counters; [`check_reduction`] checks them per supervisor).
pub fn check_set(
    events: &EventTable,
    before: &[Automaton],
    after: &[Automaton],
) -> Result<(), ReductionMismatch> {
    let product_of = |set: &[Automaton], name| {
        let refs: Vec<&Automaton> = set.iter().collect();
        product(name, ModelKind::Supervisor, events, &refs)
    };
    let cmp = compare_languages(
        events,
        &product_of(before, "unreduced set"),
        &product_of(after, "reduced set"),
    );
    if let Some(ce) = cmp.counterexample.filter(|_| !cmp.same_language) {
        let mut string = ce.string;
        let event = string.pop().unwrap_or_default();
        let problem = match ce.difference {
            Difference::GeneratedOnlyBySecond => MismatchProblem::OnlyReduced { event },
            _ => MismatchProblem::OnlyOriginal { event },
        };
        return Err(ReductionMismatch { string, problem });
    }
    match cmp.label_mismatches.into_iter().next() {
        None => Ok(()),
        Some(m) => Err(ReductionMismatch {
            string: m.string,
            problem: MismatchProblem::Label {
                event: m.event,
                original: (prob_to_q16(m.first.0), m.first.1),
                reduced: (prob_to_q16(m.second.0), m.second.1),
            },
        }),
    }
}

/// Which plant components each supervisor is synthesised for, and which of them its reduction relies on.
#[derive(Clone, Copy)]
struct Dependencies<'a> {
    /// Indices of the components of each supervisor's plant.
    parts: &'a [Vec<usize>],
    /// The components whose constraints each reduction relies on ([`observers_needed`]; empty for none).
    needs: &'a [Vec<usize>],
}

/// The MemCons of each choice of reductions to run.
struct Costs<'a> {
    /// `e`, the controllability flags.
    flags: usize,
    /// Share of each original supervisor.
    before: Vec<usize>,
    /// Share of each reduction (the original's when there is none).
    after: Vec<usize>,
    deps: Dependencies<'a>,
    /// Share of each plant's observer (0 for plants no reduction needs).
    observer: Vec<usize>,
}

impl<'a> Costs<'a> {
    fn new(
        events: &EventTable,
        supervisors: &[SupervisorReduction],
        deps: Dependencies<'a>,
        observers: &[Option<Automaton>],
    ) -> Self {
        let share = |a: &Automaton| mem_cons_share(events, a);
        Self {
            flags: events.len(),
            before: supervisors.iter().map(|s| share(&s.original)).collect(),
            after: supervisors
                .iter()
                .map(|s| s.reduced.as_ref().map_or_else(|| share(&s.original), share))
                .collect(),
            deps,
            observer: observers
                .iter()
                .map(|o| o.as_ref().map_or(0, share))
                .collect(),
        }
    }

    /// The plants whose observers the set running the reductions in `used` needs: those a used reduction relies
    /// on and no other supervisor enforces. A supervisor enforces every component of its plant when it runs
    /// unreduced (its language lies in the plant's), and those its reduction does not rely on when it runs
    /// reduced; it owns all their events, so an event a component cannot generate stays disabled.
    fn observers_of(&self, used: &[bool]) -> Vec<bool> {
        let Dependencies { parts, needs } = self.deps;
        let enforces =
            |j: usize, k: usize| parts[j].contains(&k) && !(used[j] && needs[j].contains(&k));
        let mut needed = vec![false; self.observer.len()];
        for i in (0..used.len()).filter(|&i| used[i]) {
            for &k in &needs[i] {
                needed[k] |= !(0..used.len()).any(|j| enforces(j, k));
            }
        }
        needed
    }

    /// MemCons of the set that runs the reductions in `used`, with their observers.
    fn total(&self, used: &[bool]) -> usize {
        let supervisors: usize = (0..used.len())
            .map(|i| {
                if used[i] {
                    self.after[i]
                } else {
                    self.before[i]
                }
            })
            .sum();
        let observers: usize = self
            .observers_of(used)
            .iter()
            .zip(&self.observer)
            .filter(|(n, _)| **n)
            .map(|(_, c)| c)
            .sum();
        self.flags + supervisors + observers
    }

    /// Which reductions to run (see [`reduce_synthesis`]): among the smaller reductions, the cheapest subset when
    /// there are at most [`EXHAUSTIVE_CHOICE`] of them, otherwise a greedy one.
    fn choose(&self) -> Vec<bool> {
        let candidates: Vec<usize> = (0..self.before.len())
            .filter(|&i| self.after[i] < self.before[i])
            .collect();
        if candidates.len() <= EXHAUSTIVE_CHOICE {
            self.cheapest(&candidates)
        } else {
            self.greedy(&candidates)
        }
    }

    /// The subset of `candidates` to use with the least total (fewer reductions on ties), trying every subset.
    fn cheapest(&self, candidates: &[usize]) -> Vec<bool> {
        let pick = |mask: u64| -> Vec<bool> {
            let mut used = vec![false; self.before.len()];
            for (bit, &i) in candidates.iter().enumerate() {
                used[i] = mask & (1 << bit) != 0;
            }
            used
        };
        let best = (0..1u64 << candidates.len())
            .min_by_key(|&mask| (self.total(&pick(mask)), mask.count_ones()))
            .unwrap_or(0);
        pick(best)
    }

    /// Starting from every candidate, gives up the one whose loss shrinks the set most while that shrinks it; then
    /// the unreduced set if that is no larger.
    fn greedy(&self, candidates: &[usize]) -> Vec<bool> {
        let mut used = vec![false; self.before.len()];
        for &i in candidates {
            used[i] = true;
        }
        loop {
            let current = self.total(&used);
            let best = candidates
                .iter()
                .filter(|&&i| used[i])
                .map(|&i| {
                    let mut without = used.clone();
                    without[i] = false;
                    (self.total(&without), i)
                })
                .min();
            match best {
                Some((total, i)) if total < current => used[i] = false,
                _ => break,
            }
        }
        let none = vec![false; used.len()];
        if self.total(&none) <= self.total(&used) {
            return none;
        }
        used
    }
}

/// Up to this many smaller reductions, [`reduce_synthesis`] tries every subset of them (2^12 totals to compare).
const EXHAUSTIVE_CHOICE: usize = 12;

/// Reduces and checks one supervisor of a synthesis; the outcome is [`ReductionOutcome::Reduced`] whenever the
/// reduction is smaller (the set-level choice comes later).
fn reduce_one(
    events: &EventTable,
    s: &SupervisorSynthesis,
    limits: ReduceLimits,
) -> Result<SupervisorReduction, ReduceError> {
    let original = &s.supervisor;
    let reduced = match reduce(events, &s.plant, original, limits) {
        Ok(reduced) => reduced,
        Err(skip @ ReduceError::TooLarge { .. }) => {
            return Ok(SupervisorReduction {
                name: s.name.clone(),
                original: original.clone(),
                reduced: None,
                outcome: ReductionOutcome::Skipped {
                    reason: skip.to_string(),
                },
                complete: true,
            });
        }
        Err(err) => return Err(err),
    };
    check_reduction(events, &s.plant, original, &reduced.supervisor).map_err(|mismatch| {
        ReduceError::CheckFailed {
            supervisor: s.name.clone(),
            mismatch,
        }
    })?;
    let smaller = mem_cons_share(events, &reduced.supervisor) < mem_cons_share(events, original);
    Ok(SupervisorReduction {
        name: s.name.clone(),
        original: original.clone(),
        reduced: Some(reduced.supervisor),
        outcome: if smaller {
            ReductionOutcome::Reduced
        } else {
            ReductionOutcome::NoGain
        },
        complete: reduced.complete,
    })
}

/// Indices (into the normalised plants) of the components of `s`'s plant.
fn plant_parts(synthesis: &Synthesis, s: &SupervisorSynthesis) -> Vec<usize> {
    let plants = &synthesis.normalised.plants;
    match synthesis.architecture {
        Architecture::LocalModular => {
            let locals = local_plants(plants, &s.spec);
            (0..plants.len())
                .filter(|&k| locals.iter().any(|p| std::ptr::eq(*p, &plants[k])))
                .collect()
        }
        Architecture::Monolithic | Architecture::Modular => (0..plants.len()).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Events: acquire0/1 controllable, release0/1 uncontrollable.
    fn mutex_parts() -> (EventTable, Vec<Automaton>, Automaton) {
        let p = crate::families::mutex(2);
        let mut plants = p.plants.iter();
        let (u0, u1) = (plants.next().unwrap(), plants.next().unwrap());
        let g = crate::product::product("G", ModelKind::Plant, &p.events, &[u0, u1]);
        let k = crate::product::product("K", ModelKind::Supervisor, &p.events, &[&g, &p.specs[0]]);
        (p.events.clone(), vec![g], minimise(&k))
    }

    #[test]
    fn mutual_exclusion_reduces_to_free_and_busy() {
        let (ev, g, s) = mutex_parts();
        assert_eq!(s.state_count(), 3);
        let r = reduce(&ev, &g[0], &s, ReduceLimits::default()).unwrap();
        assert!(r.complete);
        assert_eq!(r.supervisor.state_count(), 2);
        assert_eq!(check_reduction(&ev, &g[0], &s, &r.supervisor), Ok(()));
    }

    #[test]
    fn the_check_finds_a_supervisor_that_merges_inconsistent_states() {
        let (ev, g, s) = mutex_parts();
        // Everything in one cell: acquire is then enabled while the resource is busy.
        let data = ControlData::new(&ev, &g[0], &s).unwrap();
        let wrong = data.quotient(&vec![0; data.state_count()]);
        let err = check_reduction(&ev, &g[0], &s, &wrong).unwrap_err();
        assert_eq!(
            err.problem,
            MismatchProblem::OnlyReduced {
                event: "acquire1".into()
            }
        );
        assert_eq!(err.string, vec!["acquire0"]);
        assert!(
            err.to_string()
                .starts_with("after `acquire0`, `acquire1` is possible"),
            "{err}"
        );
    }

    #[test]
    fn a_timed_state_is_not_merged_with_a_state_that_enters_it() {
        // Plant: one state, a and b free. S: s0 -a-> s1 -b(T=3)-> s0 with s1 the only timed state. Control
        // would allow merging, the timer forbids it.
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let b = ev.intern("b", true).unwrap();
        let mut g = Automaton::new("G", ModelKind::Plant);
        let g0 = g.add_state("g", true).unwrap();
        g.add_transition(g0, a, g0, 1.0, 0).unwrap();
        g.add_transition(g0, b, g0, 1.0, 0).unwrap();
        let mut s = Automaton::new("S", ModelKind::Supervisor);
        let s0 = s.add_state("s0", true).unwrap();
        let s1 = s.add_state("s1", true).unwrap();
        s.add_transition(s0, a, s1, 1.0, 0).unwrap();
        s.add_transition(s0, b, s0, 1.0, 3).unwrap();
        s.add_transition(s1, a, s1, 1.0, 0).unwrap();
        s.add_transition(s1, b, s0, 1.0, 3).unwrap();
        // Same language and labels in both states, so minimisation alone would merge them.
        assert_eq!(minimise(&s).state_count(), 1);
        let r = reduce(&ev, &g, &s, ReduceLimits::default()).unwrap();
        assert_eq!(r.supervisor.state_count(), 2);
        let merged = ControlData::new(&ev, &g, &s).unwrap().quotient(&[0, 0]);
        let err = check_reduction(&ev, &g, &s, &merged).unwrap_err();
        assert_eq!(err.problem, MismatchProblem::Timer { event: "b".into() });
    }

    #[test]
    fn differing_probabilities_keep_states_apart() {
        // s0 and s1 differ only in P of the shared event a: no merge, although control would allow it.
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let c = ev.intern("c", true).unwrap();
        let mut g = Automaton::new("G", ModelKind::Plant);
        let g0 = g.add_state("g", true).unwrap();
        g.add_transition(g0, a, g0, 1.0, 0).unwrap();
        g.add_transition(g0, c, g0, 1.0, 0).unwrap();
        let mut s = Automaton::new("S", ModelKind::Supervisor);
        let s0 = s.add_state("s0", true).unwrap();
        let s1 = s.add_state("s1", true).unwrap();
        s.add_transition(s0, a, s1, 0.5, 0).unwrap();
        s.add_transition(s0, c, s0, 0.5, 0).unwrap();
        s.add_transition(s1, a, s0, 0.25, 0).unwrap();
        s.add_transition(s1, c, s1, 0.75, 0).unwrap();
        let r = reduce(&ev, &g, &s, ReduceLimits::default()).unwrap();
        assert_eq!(r.supervisor.state_count(), 2);
    }

    #[test]
    fn too_large_supervisors_and_empty_closed_loops_are_reported() {
        let (ev, g, s) = mutex_parts();
        let tight = ReduceLimits {
            max_states: 2,
            ..ReduceLimits::default()
        };
        assert!(matches!(
            reduce(&ev, &g[0], &s, tight),
            Err(ReduceError::TooLarge {
                states: 3,
                limit: 2,
                ..
            })
        ));
        let empty = Automaton::new("nothing", ModelKind::Plant);
        assert!(matches!(
            reduce(&ev, &empty, &s, ReduceLimits::default()),
            Err(ReduceError::EmptyClosedLoop { .. })
        ));
    }

    #[test]
    fn an_exhausted_budget_stops_merging_with_a_correct_result() {
        let (ev, g, s) = mutex_parts();
        let none = ReduceLimits {
            merge_budget: 0,
            ..ReduceLimits::default()
        };
        let r = reduce(&ev, &g[0], &s, none).unwrap();
        assert!(!r.complete);
        assert_eq!(r.supervisor.state_count(), 3);
        assert_eq!(check_reduction(&ev, &g[0], &s, &r.supervisor), Ok(()));
    }

    /// A chain like a transfer line: supervisor i is synthesised for plants i and i + 1 and its reduction, 25
    /// bytes smaller, relies on both; an observer costs 50.
    fn chain<'a>(n: usize, parts: &'a [Vec<usize>]) -> Costs<'a> {
        Costs {
            flags: 10,
            before: vec![60; n],
            after: vec![35; n],
            deps: Dependencies {
                parts,
                needs: parts,
            },
            observer: vec![50; n + 1],
        }
    }

    #[test]
    fn reductions_are_chosen_so_that_neighbours_enforce_their_plants() {
        let parts: Vec<Vec<usize>> = (0..14).map(|i| vec![i, i + 1]).collect();
        // Ten: every subset is tried. Reducing supervisors 1, 3, 5, 7 leaves every plant they rely on to an
        // unreduced neighbour (supervisor 9 would need plant 10 observed): 4 x 25 bytes saved.
        let ten = chain(10, &parts[..10]);
        let nothing = vec![false; 10];
        let best = ten.choose();
        assert_eq!(ten.total(&nothing) - ten.total(&best), 100);
        assert_eq!(ten.observers_of(&best), vec![false; 11]);
        let greedy = ten.greedy(&(0..10).collect::<Vec<_>>());
        assert!(ten.total(&greedy) >= ten.total(&best));
        assert!(ten.total(&greedy) < ten.total(&nothing));
        // Fourteen: greedy, and still smaller than the unreduced set.
        let fourteen = chain(14, &parts);
        let nothing = vec![false; 14];
        let used = fourteen.choose();
        assert!(fourteen.total(&used) < fourteen.total(&nothing), "{used:?}");
        // Where no reduction pays for its observers, none is used.
        let costly = Costs {
            observer: vec![500; 15],
            ..chain(14, &parts)
        };
        let isolated: Vec<Vec<usize>> = (0..14).map(|i| vec![i]).collect();
        let alone = Costs {
            deps: Dependencies {
                parts: &isolated,
                needs: &isolated,
            },
            ..costly
        };
        assert_eq!(alone.choose(), nothing);
    }

    #[test]
    fn undo_restores_cells_members_and_least_members() {
        let mut cells = Cells::new(4);
        cells.union(0, 1);
        let mark = cells.mark();
        let r = cells.find(2);
        cells.union(cells.find(1), r);
        cells.union(cells.find(0), 3);
        let mut members = Vec::new();
        cells.members_into(cells.find(3), &mut members);
        members.sort_unstable();
        assert_eq!(members, vec![0, 1, 2, 3]);
        cells.undo(mark);
        assert_eq!(cells.classes(), vec![0, 0, 1, 2]);
        assert!(cells.is_least(2) && cells.is_least(3) && !cells.is_least(1));
        cells.members_into(cells.find(1), &mut members);
        members.sort_unstable();
        assert_eq!(members, vec![0, 1]);
    }
}
