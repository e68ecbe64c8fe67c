//! The closed-loop check of a reduction: G ∥ S against G ∥ S_red, walked side by side, independent of how the
//! reduction was found.

use std::collections::HashSet;
use std::fmt;

use crate::automaton::{Automaton, EventId, EventTable, ModelKind, StateId, Transition};
use crate::compiled::prob_to_q16;
use crate::product::{ProductOutput, product_with_tuples};

use super::merge::same_label;

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
