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

use crate::automaton::{Automaton, EventTable};

mod check;
mod merge;
mod set;

pub use check::{MismatchProblem, ReductionMismatch, check_reduction};
use merge::{ControlData, Merger};
pub use set::{
    Reduction, ReductionOutcome, SupervisorReduction, check_set, mem_cons_share, observer,
    observers_needed, reduce_synthesis,
};

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

#[cfg(test)]
mod tests {
    use super::merge::Cells;
    use super::set::{Costs, Dependencies};
    use super::*;
    use crate::automaton::ModelKind;
    use crate::minimise::minimise;

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
