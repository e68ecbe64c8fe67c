//! `report.json`: the designer-facing summary of one synthesis run (docs/ptsct.md section 12, step 9).
//!
//! Per supervisor: size, events, every state SupC removed and why; the whole set's MemCons by the section 9 formula
//! and the bytes actually written; the architecture checks; every validation warning. With `synth --reduce`, each
//! supervisor's size before and after reduction and the plant observers the reduced set needs. The report mirrors
//! the pipeline's result in serialisable form and computes nothing new.

use serde::Serialize;

use crate::architecture::{Difference, LocalModularValidation, NonConflict};
use crate::automaton::{Automaton, EventTable};
use crate::compiled::mem_cons_of;
use crate::diagnostics::Diagnostic;
use crate::pipeline::{SupervisorStats, SupervisorSynthesis, Synthesis};
use crate::reduce::{
    ReduceLimits, Reduction, ReductionOutcome, SupervisorReduction, mem_cons_share,
};
use crate::supc::RemovalReason;

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// `monolithic`, `modular` or `local-modular`.
    pub architecture: String,
    /// `--raw-weights` was given.
    pub raw_weights: bool,
    /// `--thesis-literal-probabilities` was given.
    pub thesis_literal_probabilities: bool,
    /// One entry per final supervisor, in order (the order of the compiled set).
    pub supervisors: Vec<SupervisorReport>,
    /// Memory of the compiled set.
    pub mem_cons: MemConsReport,
    /// Non-conflict and local-modular validation.
    pub architecture_checks: ArchitectureChecks,
    /// Every validation warning (code, severity, file, line, column, message).
    pub warnings: Vec<Diagnostic>,
    /// Outputs that were not written, and why (a supervisor set too large for the compiled format, a drawing
    /// too large to draw); empty when everything was written.
    pub skipped: Vec<SkippedOutput>,
    /// The reduction of the set (`synth --reduce` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reduction: Option<ReductionReport>,
}

/// The reduction of the whole set (`synth --reduce`).
#[derive(Debug, Clone, Serialize)]
pub struct ReductionReport {
    /// MemCons of the unreduced set.
    pub mem_cons_before: usize,
    /// MemCons of the set written: supervisors and plant observers (what `mem_cons` describes; never more than
    /// `mem_cons_before`).
    pub mem_cons_after: usize,
    /// Plant observers compiled after the supervisors (the plants the reduced supervisors rely on).
    pub observers: Vec<ObserverReport>,
    /// What was checked for every reduction before anything was written.
    pub check: String,
    /// Supervisors with more states are not reduced.
    pub max_states: usize,
    /// Pair checks one reduction may spend.
    pub merge_budget: u64,
    /// Supervisors not reduced, reductions cut short.
    pub warnings: Vec<String>,
}

/// The XML files `synth --reduce` wrote besides the supervisors', relative to the output directory.
#[derive(Debug, Clone, Copy)]
pub struct ReductionFiles<'a> {
    /// One per computed reduction (every supervisor not skipped), in order.
    pub reduced: &'a [String],
    /// One per plant observer, in order.
    pub observers: &'a [String],
}

/// A plant observer of the reduced set.
#[derive(Debug, Clone, Serialize)]
pub struct ObserverReport {
    /// The plant's name.
    pub name: String,
    /// The XML file written for it, relative to the output directory.
    pub file: String,
    /// States.
    pub states: usize,
    /// Transitions.
    pub transitions: usize,
    /// Its share of MemCons (arrays, membership row, current state).
    pub mem_cons: usize,
}

/// One supervisor before and after reduction.
#[derive(Debug, Clone, Serialize)]
pub struct SupervisorReductionReport {
    /// `reduced` (the reduction is written and compiled), `no gain` (the reduction is not smaller),
    /// `observers cost more` (it is smaller, but the plant observers it needs are not) or `skipped` (too large);
    /// in all but the first the minimised supervisor is written.
    pub outcome: String,
    /// Why the reduction was skipped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// `false` if the merge budget ran out (the reduction is correct but may not be minimal).
    pub complete: bool,
    /// The minimised supervisor.
    pub before: ReductionSize,
    /// The checked reduction (absent when skipped), whether it is used or not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub after: Option<ReductionSize>,
    /// The reduction's XML file (`<supervisor>.reduced.xml`), written whether it is used or not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reduced_file: Option<String>,
}

/// Size of one supervisor for the reduction report.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ReductionSize {
    /// States.
    pub states: usize,
    /// Transitions.
    pub transitions: usize,
    /// Controllable transitions.
    pub controllable_transitions: usize,
    /// The supervisor's share of MemCons: `(s + 3t) + 2(s + 2·t_c) + e + 2` bytes.
    pub mem_cons: usize,
}

/// An output that was not written.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SkippedOutput {
    /// The file, relative to the output directory.
    pub output: String,
    /// Why it was not written.
    pub reason: String,
}

/// One supervisor.
#[derive(Debug, Clone, Serialize)]
pub struct SupervisorReport {
    /// Supervisor name (`S_<spec>` or `S_mon`).
    pub name: String,
    /// The specifications it enforces.
    pub specs: Vec<String>,
    /// The XML file written for it, relative to the output directory.
    pub file: String,
    /// States of the final (minimised) supervisor.
    pub states: usize,
    /// Transitions of the final supervisor.
    pub transitions: usize,
    /// Controllable transitions of the final supervisor.
    pub controllable_transitions: usize,
    /// Alphabet of the final supervisor, by name, in event-id order.
    pub events: Vec<String>,
    /// The same counts before minimisation.
    pub before_minimisation: Counts,
    /// States and transitions of K = G ∥ E.
    pub target: Counts,
    /// SupC rounds.
    pub supc_rounds: u32,
    /// States of K removed as bad.
    pub removed_bad: Vec<RemovedBad>,
    /// States of K removed as unreachable.
    pub removed_unreachable: Vec<RemovedOther>,
    /// States of K removed as non-coaccessible (blocking).
    pub removed_non_coaccessible: Vec<RemovedOther>,
    /// Before and after reduction (`synth --reduce` only; `states`, `transitions` and `controllable_transitions`
    /// above then describe the supervisor written, the reduced one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reduction: Option<SupervisorReductionReport>,
}

/// Size counts of one automaton.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Counts {
    /// States.
    pub states: usize,
    /// Transitions.
    pub transitions: usize,
}

/// A state of K removed because an uncontrollable event could not be prevented.
#[derive(Debug, Clone, Serialize)]
pub struct RemovedBad {
    /// Name of the K state.
    pub state: String,
    /// The uncontrollable event the plant can generate there.
    pub event: String,
    /// The removed state the event would lead to, or `None` if the specification forbids the event there.
    pub leads_to: Option<String>,
    /// SupC round, from 1.
    pub round: u32,
}

/// A state of K removed by trimming.
#[derive(Debug, Clone, Serialize)]
pub struct RemovedOther {
    /// Name of the K state.
    pub state: String,
    /// SupC round, from 1.
    pub round: u32,
}

/// MemCons of the compiled set.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct MemConsReport {
    /// `(s + 3t) + 2(s + 2·t_c) + e + (e + 2)·N` over the final supervisors.
    pub formula_bytes: usize,
    /// Total states s.
    pub s: usize,
    /// Total transitions t.
    pub t: usize,
    /// Total controllable transitions t_c.
    pub t_c: usize,
    /// Events e.
    pub e: usize,
    /// Supervisors N.
    pub n: usize,
    /// Size of `supervisors.ptsct` as written (formula payload plus the file header with names).
    pub bytes_written: usize,
}

/// Architecture checks.
#[derive(Debug, Clone, Serialize)]
pub struct ArchitectureChecks {
    /// Non-conflict of the set (modular and local-modular only).
    pub non_conflict: Option<NonConflictReport>,
    /// Local-modular validation against the monolithic supervisor (local-modular only).
    pub local_modular_validation: Option<ValidationReport>,
}

/// Non-conflict result.
#[derive(Debug, Clone, Serialize)]
pub struct NonConflictReport {
    /// The product of the supervisors is nonblocking.
    pub nonblocking: bool,
    /// States of the accessible product.
    pub product_states: usize,
    /// Transitions of the accessible product.
    pub product_transitions: usize,
    /// Total blocking product states.
    pub blocking_count: usize,
    /// Some blocking product states, by name.
    pub blocking_states: Vec<String>,
}

/// Local-modular validation result.
#[derive(Debug, Clone, Serialize)]
pub struct ValidationReport {
    /// Nonblocking, same languages and no P/T mismatch.
    pub passed: bool,
    /// Non-conflict of the local product.
    pub non_conflict: NonConflictReport,
    /// L(local product) = L(monolithic).
    pub same_language: bool,
    /// Lm(local product) = Lm(monolithic).
    pub same_marked_language: bool,
    /// A shortest distinguishing string, if any.
    pub counterexample: Option<CounterexampleReport>,
    /// P/T mismatches on common transitions.
    pub label_mismatches: Vec<LabelMismatchReport>,
    /// What the check cannot see (timers, A4).
    pub note: String,
}

/// A distinguishing string.
#[derive(Debug, Clone, Serialize)]
pub struct CounterexampleReport {
    /// The events of the string.
    pub string: Vec<String>,
    /// Which side generates or marks it.
    pub difference: String,
}

/// A P/T mismatch.
#[derive(Debug, Clone, Serialize)]
pub struct LabelMismatchReport {
    /// A shortest string to the state pair.
    pub string: Vec<String>,
    /// The event.
    pub event: String,
    /// (P, T) in the local product.
    pub local: (f64, u32),
    /// (P, T) in the monolithic supervisor.
    pub monolithic: (f64, u32),
}

impl Report {
    /// Builds the report of `synthesis`. `files` names the XML file of each supervisor; `bytes_written` is the
    /// size of the compiled set file; `diagnostics` are the validation results (warnings are copied).
    pub fn new(
        synthesis: &Synthesis,
        files: &[String],
        bytes_written: usize,
        diagnostics: &[Diagnostic],
    ) -> Self {
        let events = &synthesis.normalised.events;
        let supervisors = synthesis
            .supervisors
            .iter()
            .zip(files)
            .map(|(s, file)| supervisor_report(s, file, events))
            .collect();
        let finals: Vec<&Automaton> = synthesis
            .supervisors
            .iter()
            .map(|s| &s.supervisor)
            .collect();
        Report {
            architecture: synthesis.architecture.to_string(),
            raw_weights: synthesis.options.raw_weights,
            thesis_literal_probabilities: synthesis.options.thesis_literal_probabilities,
            supervisors,
            mem_cons: mem_cons_report(events, &finals, bytes_written),
            architecture_checks: ArchitectureChecks {
                non_conflict: synthesis.non_conflict.as_ref().map(non_conflict),
                local_modular_validation: synthesis
                    .local_modular_validation
                    .as_ref()
                    .map(validation),
            },
            warnings: diagnostics
                .iter()
                .filter(|d| !d.is_error())
                .cloned()
                .collect(),
            skipped: Vec::new(),
            reduction: None,
        }
    }

    /// Describes the reduced set of `synth --reduce`: each supervisor's size before and after, the XML `files`
    /// of the reductions and observers, and `mem_cons` recomputed for the set written, whose compiled file has
    /// `bytes_written` bytes.
    pub fn with_reduction(
        mut self,
        reduction: &Reduction,
        events: &EventTable,
        files: ReductionFiles<'_>,
        limits: ReduceLimits,
        bytes_written: usize,
    ) -> Self {
        let mut reduced_files = files.reduced.iter();
        for (entry, r) in self.supervisors.iter_mut().zip(&reduction.supervisors) {
            let written = SupervisorStats::of(r.supervisor(), events);
            entry.states = written.states;
            entry.transitions = written.transitions;
            entry.controllable_transitions = written.controllable_transitions;
            let mut report = supervisor_reduction(r, events);
            if r.reduced.is_some() {
                report.reduced_file = reduced_files.next().cloned();
            }
            entry.reduction = Some(report);
        }
        let finals = reduction.final_automata();
        let refs: Vec<&Automaton> = finals.iter().collect();
        self.mem_cons = mem_cons_report(events, &refs, bytes_written);
        self.reduction = Some(ReductionReport {
            mem_cons_before: reduction.mem_cons_before,
            mem_cons_after: reduction.mem_cons_after,
            observers: reduction
                .observers
                .iter()
                .zip(files.observers)
                .map(|(o, file)| ObserverReport {
                    name: o.name().to_owned(),
                    file: file.clone(),
                    states: o.state_count(),
                    transitions: o.transition_count(),
                    mem_cons: mem_cons_share(events, o),
                })
                .collect(),
            check: "G ∥ S_red equals G ∥ S for every reduced supervisor: the same language and marked language, \
                    the same P and T on every reachable transition, and timed transitions only where both \
                    supervisors restarted their counters alike"
                .to_owned(),
            max_states: limits.max_states,
            merge_budget: limits.merge_budget,
            warnings: reduction.warnings(),
        });
        self
    }

    /// Pretty JSON (non-finite numbers become `null`).
    /// Writes the report as pretty JSON to `out` as it goes.
    pub fn write_json(&self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        serde_json::to_writer_pretty(&mut *out, self)?;
        Ok(())
    }
}

/// MemCons of `finals` by the formula, with its terms and the bytes written.
fn mem_cons_report(
    events: &EventTable,
    finals: &[&Automaton],
    bytes_written: usize,
) -> MemConsReport {
    let mut mem = MemConsReport {
        formula_bytes: mem_cons_of(events, finals),
        s: 0,
        t: 0,
        t_c: 0,
        e: events.len(),
        n: finals.len(),
        bytes_written,
    };
    for a in finals {
        let stats = SupervisorStats::of(a, events);
        mem.s += stats.states;
        mem.t += stats.transitions;
        mem.t_c += stats.controllable_transitions;
    }
    mem
}

fn supervisor_reduction(r: &SupervisorReduction, events: &EventTable) -> SupervisorReductionReport {
    let size = |a: &Automaton| {
        let stats = SupervisorStats::of(a, events);
        ReductionSize {
            states: stats.states,
            transitions: stats.transitions,
            controllable_transitions: stats.controllable_transitions,
            mem_cons: mem_cons_share(events, a),
        }
    };
    let (outcome, reason) = match &r.outcome {
        ReductionOutcome::Reduced => ("reduced", None),
        ReductionOutcome::NoGain => ("no gain", None),
        ReductionOutcome::ObserversCostMore => ("observers cost more", None),
        ReductionOutcome::Skipped { reason } => ("skipped", Some(reason.clone())),
    };
    SupervisorReductionReport {
        outcome: outcome.to_owned(),
        reason,
        complete: r.complete,
        before: size(&r.original),
        after: r.reduced.as_ref().map(size),
        reduced_file: None,
    }
}

fn supervisor_report(s: &SupervisorSynthesis, file: &str, events: &EventTable) -> SupervisorReport {
    let mut removed_bad = Vec::new();
    let mut removed_unreachable = Vec::new();
    let mut removed_non_coaccessible = Vec::new();
    for r in &s.removed {
        match r.reason {
            RemovalReason::Bad { event, .. } => removed_bad.push(RemovedBad {
                state: r.name.clone(),
                event: events.name(event).to_owned(),
                leads_to: r.leads_to.clone(),
                round: r.round,
            }),
            RemovalReason::Inaccessible => removed_unreachable.push(RemovedOther {
                state: r.name.clone(),
                round: r.round,
            }),
            RemovalReason::NonCoaccessible => removed_non_coaccessible.push(RemovedOther {
                state: r.name.clone(),
                round: r.round,
            }),
        }
    }
    SupervisorReport {
        name: s.name.clone(),
        specs: s.specs.clone(),
        file: file.to_owned(),
        states: s.stats.states,
        transitions: s.stats.transitions,
        controllable_transitions: s.stats.controllable_transitions,
        events: s
            .supervisor
            .alphabet()
            .iter()
            .map(|&e| events.name(e).to_owned())
            .collect(),
        before_minimisation: Counts {
            states: s.stats_unminimised.states,
            transitions: s.stats_unminimised.transitions,
        },
        target: Counts {
            states: s.target_stats.states,
            transitions: s.target_stats.transitions,
        },
        supc_rounds: s.rounds,
        removed_bad,
        removed_unreachable,
        removed_non_coaccessible,
        reduction: None,
    }
}

fn non_conflict(n: &NonConflict) -> NonConflictReport {
    NonConflictReport {
        nonblocking: n.nonblocking,
        product_states: n.product_states,
        product_transitions: n.product_transitions,
        blocking_count: n.blocking_count,
        blocking_states: n.blocking_states.clone(),
    }
}

fn validation(v: &LocalModularValidation) -> ValidationReport {
    ValidationReport {
        passed: v.passed(),
        non_conflict: non_conflict(&v.non_conflict),
        same_language: v.comparison.same_language,
        same_marked_language: v.comparison.same_marked_language,
        counterexample: v
            .comparison
            .counterexample
            .as_ref()
            .map(|c| CounterexampleReport {
                string: c.string.clone(),
                difference: match c.difference {
                    Difference::GeneratedOnlyByFirst => "generated only by the local product",
                    Difference::GeneratedOnlyBySecond => {
                        "generated only by the monolithic supervisor"
                    }
                    Difference::MarkedOnlyByFirst => "marked only by the local product",
                    Difference::MarkedOnlyBySecond => "marked only by the monolithic supervisor",
                }
                .to_owned(),
            }),
        label_mismatches: v
            .comparison
            .label_mismatches
            .iter()
            .map(|m| LabelMismatchReport {
                string: m.string.clone(),
                event: m.event.clone(),
                local: m.first,
                monolithic: m.second,
            })
            .collect(),
        note: v.timer_note.to_owned(),
    }
}
