//! The synthesis pipeline of section 12, steps 3-6: normalise, synthesise (per architecture), check, minimise.
//!
//! [`synthesize`] is the single entry point for the CLI and the report: it returns every intermediate generator
//! (G, E, K), the SupC result before minimisation and the final supervisor, every removed state, statistics,
//! MemCons and the architecture checks. Validation (section 11) happens before this and is not repeated here;
//! drawing, XML output and code generation consume the returned [`Synthesis`].

use tracing::{debug, info};

use crate::architecture::{
    Architecture, LocalModularValidation, NonConflict, check_non_conflict, local_plants,
    validate_local_modular,
};
use crate::automaton::{Automaton, EventTable, ModelKind, Project, StateId};
use crate::compiled::{CodegenError, SupervisorSet, mem_cons_of};
use crate::minimise::minimise_accessible;
use crate::normalise::{NormaliseOptions, ZeroWeights, normalise, normalise_project};
use crate::product::{product, product_with_tuples};
use crate::supc::{RemovedState, supc};

/// Options of [`synthesize`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SynthesisOptions {
    /// Keep specification weights unchanged and skip the monolithic renormalisation (`--raw-weights`).
    pub raw_weights: bool,
    /// Keep plant probability factors (A5 compatibility switch, `--thesis-literal-probabilities`).
    pub thesis_literal_probabilities: bool,
    /// In local-modular mode, also synthesise the monolithic supervisor and validate against it (section 12,
    /// step 5). Default `true`; turning it off avoids the monolithic product for very large projects.
    pub validate: bool,
    /// Keep each K = G ∥ E in [`SupervisorSynthesis::target`] (drawings need it). Default `true`; without it K
    /// is dropped once SupC is done, before minimisation, which is where a large synthesis peaks in memory.
    pub keep_targets: bool,
}

impl Default for SynthesisOptions {
    fn default() -> Self {
        Self {
            raw_weights: false,
            thesis_literal_probabilities: false,
            validate: true,
            keep_targets: true,
        }
    }
}

/// Size statistics of one supervisor (section 12, step 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SupervisorStats {
    /// Number of states.
    pub states: usize,
    /// Number of transitions.
    pub transitions: usize,
    /// Number of controllable transitions (t_c of section 9).
    pub controllable_transitions: usize,
    /// Size of the alphabet.
    pub events: usize,
}

impl SupervisorStats {
    /// Statistics of `a`.
    pub fn of(a: &Automaton, events: &EventTable) -> Self {
        let all = a.states().flat_map(|s| a.transitions(s));
        Self {
            states: a.state_count(),
            transitions: a.transition_count(),
            controllable_transitions: all.filter(|t| events.is_controllable(t.event)).count(),
            events: a.alphabet().len(),
        }
    }
}

/// Everything produced while synthesising one supervisor.
#[derive(Debug, Clone)]
pub struct SupervisorSynthesis {
    /// The supervisor name: `S_<spec>` per specification, `S_mon` for the monolithic one.
    pub name: String,
    /// Names of the specifications this supervisor enforces.
    pub specs: Vec<String>,
    /// G: the plant (Gmon, or the local plant G_i^loc).
    pub plant: Automaton,
    /// E: the specification (Emon, or E_i).
    pub spec: Automaton,
    /// K = G ∥ E, unless [`SynthesisOptions::keep_targets`] was off.
    pub target: Option<Automaton>,
    /// Statistics of K.
    pub target_stats: SupervisorStats,
    /// Every state of K removed by SupC, with its reason (ids refer to K).
    pub removed: Vec<RemovedState>,
    /// Number of SupC rounds.
    pub rounds: u32,
    /// SupC(K, G) before minimisation.
    pub unminimised: Automaton,
    /// The final supervisor: minimised, and renormalised if monolithic (5.1).
    pub supervisor: Automaton,
    /// Statistics before minimisation.
    pub stats_unminimised: SupervisorStats,
    /// Statistics of the final supervisor.
    pub stats: SupervisorStats,
}

/// The result of [`synthesize`].
#[derive(Debug, Clone)]
pub struct Synthesis {
    /// The architecture used.
    pub architecture: Architecture,
    /// The options used.
    pub options: SynthesisOptions,
    /// The input project after normalisation (section 5.1 and A5).
    pub normalised: Project,
    /// The supervisors, one per specification (modular, local-modular) or one (monolithic).
    pub supervisors: Vec<SupervisorSynthesis>,
    /// The monolithic supervisor computed for the local-modular validation, if requested.
    pub monolithic_reference: Option<SupervisorSynthesis>,
    /// Non-conflict of the supervisor set (modular and local-modular).
    pub non_conflict: Option<NonConflict>,
    /// The local-modular validation against the monolithic supervisor (local-modular with `validate`).
    pub local_modular_validation: Option<LocalModularValidation>,
    /// MemCons of the final supervisor set (section 9).
    pub mem_cons: usize,
}

impl Synthesis {
    /// The final supervisors, in order.
    pub fn final_supervisors(&self) -> Vec<Automaton> {
        finals(&self.supervisors)
    }

    /// Compiles the final supervisors into the section 9 byte layout (fails on V15 limits).
    pub fn compile(&self) -> Result<SupervisorSet, CodegenError> {
        SupervisorSet::from_supervisors(
            &self.normalised.events,
            self.supervisors.iter().map(|s| &s.supervisor),
        )
    }
}

/// Why synthesis could not produce a supervisor set.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SynthesisError {
    /// A state whose controllable weights are all zero (V12) reached normalisation.
    #[error(transparent)]
    ZeroWeights(#[from] ZeroWeights),
    /// The project has no specification.
    #[error("the project has no specification: there is nothing to synthesise")]
    NoSpecifications,
    /// No nonblocking controllable supervisor exists for a specification.
    #[error("no nonblocking controllable supervisor exists for specification `{spec}`: {reason}")]
    EmptySupervisor {
        /// The specification (or, for monolithic synthesis, all of them).
        spec: String,
        /// Why the initial state was removed.
        reason: String,
    },
}

/// Runs normalisation, synthesis, checks and minimisation for `project` in the given architecture.
pub fn synthesize(
    project: &Project,
    mode: Architecture,
    options: SynthesisOptions,
) -> Result<Synthesis, SynthesisError> {
    if project.specs.is_empty() {
        return Err(SynthesisError::NoSpecifications);
    }
    let normalised = normalise_project(
        project,
        NormaliseOptions {
            raw_weights: options.raw_weights,
            thesis_literal_probabilities: options.thesis_literal_probabilities,
        },
    )?;
    let events = &normalised.events;
    info!(architecture = %mode, plants = normalised.plants.len(), specs = normalised.specs.len(), "synthesis");
    let all_plants: Vec<&Automaton> = normalised.plants.iter().collect();
    let mut monolithic_reference = None;
    let mut non_conflict = None;
    let mut local_modular_validation = None;
    let supervisors = match mode {
        Architecture::Monolithic => vec![monolithic(&normalised, options)?],
        Architecture::Modular => {
            let gmon = product("G_mon", ModelKind::Plant, events, &all_plants);
            let sups = normalised
                .specs
                .iter()
                .map(|e| {
                    require(one(
                        events,
                        format!("S_{}", e.name()),
                        vec![e.name().to_owned()],
                        gmon.clone(),
                        e.clone(),
                        false,
                        options.keep_targets,
                    ))
                })
                .collect::<Result<Vec<_>, _>>()?;
            non_conflict = Some(check_non_conflict(events, &finals(&sups)));
            sups
        }
        Architecture::LocalModular => {
            let sups = normalised
                .specs
                .iter()
                .map(|e| {
                    let locals = local_plants(&normalised.plants, e);
                    let g = product(
                        &format!("G_loc_{}", e.name()),
                        ModelKind::Plant,
                        events,
                        &locals,
                    );
                    require(one(
                        events,
                        format!("S_{}", e.name()),
                        vec![e.name().to_owned()],
                        g,
                        e.clone(),
                        false,
                        options.keep_targets,
                    ))
                })
                .collect::<Result<Vec<_>, _>>()?;
            let locals = finals(&sups);
            non_conflict = Some(check_non_conflict(events, &locals));
            if options.validate {
                let (mon, _) = monolithic_unchecked(&normalised, options);
                local_modular_validation =
                    Some(validate_local_modular(events, &locals, &mon.supervisor));
                monolithic_reference = Some(mon);
            }
            sups
        }
    };
    let finals_ref: Vec<&Automaton> = supervisors.iter().map(|s| &s.supervisor).collect();
    let mem_cons = mem_cons_of(events, &finals_ref);
    Ok(Synthesis {
        architecture: mode,
        options,
        normalised,
        supervisors,
        monolithic_reference,
        non_conflict,
        local_modular_validation,
        mem_cons,
    })
}

fn finals(sups: &[SupervisorSynthesis]) -> Vec<Automaton> {
    sups.iter().map(|s| s.supervisor.clone()).collect()
}

fn monolithic(
    project: &Project,
    options: SynthesisOptions,
) -> Result<SupervisorSynthesis, SynthesisError> {
    require(monolithic_unchecked(project, options))
}

fn monolithic_unchecked(
    project: &Project,
    options: SynthesisOptions,
) -> (SupervisorSynthesis, Option<String>) {
    let events = &project.events;
    let plants: Vec<&Automaton> = project.plants.iter().collect();
    let specs: Vec<&Automaton> = project.specs.iter().collect();
    let g = product("G_mon", ModelKind::Plant, events, &plants);
    let e = product("E_mon", ModelKind::Spec, events, &specs);
    let names = project.specs.iter().map(|s| s.name().to_owned()).collect();
    one(
        events,
        "S_mon".to_owned(),
        names,
        g,
        e,
        !options.raw_weights,
        options.keep_targets,
    )
}

/// Turns an empty supervisor into [`SynthesisError::EmptySupervisor`].
fn require(
    (s, empty): (SupervisorSynthesis, Option<String>),
) -> Result<SupervisorSynthesis, SynthesisError> {
    match empty {
        None => Ok(s),
        Some(reason) => Err(SynthesisError::EmptySupervisor {
            spec: s.specs.join(", "),
            reason,
        }),
    }
}

/// K = G ∥ E, SupC, minimisation and (for monolithic supervisors) renormalisation. Returns the reason if empty.
fn one(
    events: &EventTable,
    name: String,
    specs: Vec<String>,
    g: Automaton,
    e: Automaton,
    renormalise: bool,
    keep_target: bool,
) -> (SupervisorSynthesis, Option<String>) {
    let k = product_with_tuples(
        &format!("K_{}", name.trim_start_matches("S_")),
        ModelKind::Supervisor,
        events,
        &[&g, &e],
    );
    let g_of: Vec<StateId> = k.tuples.chunks_exact(2).map(|t| StateId(t[0])).collect();
    let target = k.automaton;
    let result = supc(&target, &g, &g_of, events);
    debug!(supervisor = %name, k_states = target.state_count(), removed = result.removed.len(), rounds = result.rounds, "SupC");
    let empty = result.empty_reason(&target, events);
    let target_stats = SupervisorStats::of(&target, events);
    let target = keep_target.then_some(target);
    let mut unminimised = result.supervisor;
    unminimised.set_name(name.clone());
    unminimised.set_kind(ModelKind::Supervisor);
    crate::progress::stage(|| format!("minimising {name} ({} states)", unminimised.state_count()));
    // SupC's result has only accessible states.
    let mut supervisor = minimise_accessible(&unminimised);
    if renormalise {
        // Zero-sum states (only possible with zero weights) are left for the runtime's uniform choice (5.2).
        normalise(&mut supervisor, events);
    }
    let stats_unminimised = SupervisorStats::of(&unminimised, events);
    let stats = SupervisorStats::of(&supervisor, events);
    info!(supervisor = %name, states = stats.states, transitions = stats.transitions, "supervisor ready");
    (
        SupervisorSynthesis {
            name,
            specs,
            plant: g,
            spec: e,
            target,
            target_stats,
            removed: result.removed,
            rounds: result.rounds,
            unminimised,
            supervisor,
            stats_unminimised,
            stats,
        },
        empty,
    )
}
