//! Reducing a whole synthesis: which reductions to use, the plant observers they need at run time, and the check
//! of the chosen set against the unreduced one.

use crate::architecture::{Architecture, Difference, compare_languages, local_plants};
use crate::automaton::{Automaton, EventTable, ModelKind, StateId};
use crate::compiled::{CodegenError, SupervisorSet, mem_cons_of, prob_to_q16};
use crate::minimise::minimise;
use crate::pipeline::{SupervisorSynthesis, Synthesis};
use crate::product::{product, product_with_tuples};

use super::{
    MismatchProblem, ReduceError, ReduceLimits, ReductionMismatch, check_reduction, reduce,
};

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
pub(super) struct Dependencies<'a> {
    /// Indices of the components of each supervisor's plant.
    pub(super) parts: &'a [Vec<usize>],
    /// The components whose constraints each reduction relies on ([`observers_needed`]; empty for none).
    pub(super) needs: &'a [Vec<usize>],
}

/// The MemCons of each choice of reductions to run.
pub(super) struct Costs<'a> {
    /// `e`, the controllability flags.
    pub(super) flags: usize,
    /// Share of each original supervisor.
    pub(super) before: Vec<usize>,
    /// Share of each reduction (the original's when there is none).
    pub(super) after: Vec<usize>,
    pub(super) deps: Dependencies<'a>,
    /// Share of each plant's observer (0 for plants no reduction needs).
    pub(super) observer: Vec<usize>,
}

impl<'a> Costs<'a> {
    pub(super) fn new(
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
    pub(super) fn observers_of(&self, used: &[bool]) -> Vec<bool> {
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
    pub(super) fn total(&self, used: &[bool]) -> usize {
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
    pub(super) fn choose(&self) -> Vec<bool> {
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
    pub(super) fn greedy(&self, candidates: &[usize]) -> Vec<bool> {
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
