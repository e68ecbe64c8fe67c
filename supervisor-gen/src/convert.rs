//! Conversion of validated models into the core model: one shared [`EventTable`] for the whole project and one
//! [`Automaton`] per file.
//!
//! Event ids are assigned in input order (file order, then declaration order), so the same inputs always give the
//! same ids. Weights follow rule A5 as decided by validation: plant and uncontrollable transitions carry 1.0 unless
//! thesis-literal probabilities were requested.

use crate::automaton::{Automaton, EventTable, ModelError, ModelKind, Project, StateId};
use crate::validate::CheckedModel;

/// Why validated models could not become a project.
#[derive(Debug, thiserror::Error)]
pub enum ConvertError {
    /// The core model refused the data (it repeats a validation rule that was skipped).
    #[error("model `{model}`: {source}")]
    Model {
        /// The model name.
        model: String,
        /// What the core model reported.
        source: ModelError,
    },
    /// A supervisor file was given where only plants and specifications make sense.
    #[error(
        "model `{model}` in {file} is a supervisor; synthesis takes only plants and specifications"
    )]
    SupervisorInProject {
        /// The model name.
        model: String,
        /// Its file.
        file: String,
    },
}

/// Builds the automaton of one validated model, interning its events into `events`.
pub fn to_automaton(
    model: &CheckedModel,
    events: &mut EventTable,
) -> Result<Automaton, ConvertError> {
    let wrap = |source| ConvertError::Model {
        model: model.name.clone(),
        source,
    };
    let mut automaton = Automaton::new(model.name.clone(), model.kind);
    let ids = model
        .events
        .iter()
        .map(|e| events.intern(&e.name, e.controllable))
        .collect::<Result<Vec<_>, _>>()
        .map_err(wrap)?;
    for &id in &ids {
        automaton.add_event(id);
    }
    let mut states: Vec<StateId> = Vec::with_capacity(model.states.len());
    for state in &model.states {
        let id = automaton
            .add_state(state.name.clone(), state.marked)
            .map_err(wrap)?;
        if state.initial {
            automaton.set_initial(id).map_err(wrap)?;
        }
        states.push(id);
    }
    for t in &model.transitions {
        automaton
            .add_transition(
                states[t.src],
                ids[t.event],
                states[t.dst],
                t.weight.unwrap_or(1.0),
                u32::from(t.time),
            )
            .map_err(wrap)?;
    }
    Ok(automaton)
}

/// Builds every model against one event table, in input order.
pub fn to_automata(models: &[CheckedModel]) -> Result<(EventTable, Vec<Automaton>), ConvertError> {
    let mut events = EventTable::new();
    let automata = models
        .iter()
        .map(|m| to_automaton(m, &mut events))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((events, automata))
}

/// Builds the synthesis project: plants and specifications in input order.
pub fn to_project(models: &[CheckedModel]) -> Result<Project, ConvertError> {
    if let Some(sup) = models.iter().find(|m| m.kind == ModelKind::Supervisor) {
        return Err(ConvertError::SupervisorInProject {
            model: sup.name.clone(),
            file: sup.file.clone(),
        });
    }
    let (events, automata) = to_automata(models)?;
    let (plants, specs) = automata
        .into_iter()
        .partition(|a| a.kind() == ModelKind::Plant);
    Ok(Project {
        events,
        plants,
        specs,
    })
}
