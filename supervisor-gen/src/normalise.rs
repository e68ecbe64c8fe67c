//! Offline probability normalisation (section 5.1) and the plant-probability rule A5.
//!
//! Input models carry non-negative weights; [`normalise_project`] turns every specification's per-state controllable
//! weights into probabilities and sets plant factors to 1 (A5), unless options ask for raw weights or the thesis'
//! literal plant factors. [`normalise`] is also the monolithic offline renormalisation after synthesis.
//! Local and modular supervisors must never be renormalised per state (5.2): this module offers no shortcut for it.

use crate::automaton::{Automaton, EventTable, ModelKind, Project, StateId};

/// How input weights become probabilities.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NormaliseOptions {
    /// Keep specification weights unchanged (`--raw-weights`, section 13).
    pub raw_weights: bool,
    /// Keep plant probabilities, normalised per state, instead of treating them as 1 (A5 compatibility switch).
    pub thesis_literal_probabilities: bool,
}

/// A state whose outgoing controllable weights are all zero (validation V12), which cannot be normalised.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "model `{automaton}`, state `{state}`: every outgoing controllable transition has weight 0 (V12)"
)]
pub struct ZeroWeights {
    /// The model name.
    pub automaton: String,
    /// The state name.
    pub state: String,
}

/// Normalises each state's outgoing controllable probabilities to sum to 1 (R3) and sets uncontrollable ones to 1.
///
/// States whose controllable weights sum to 0 are left unchanged and returned, so the caller decides whether that
/// is an input error (V12) or a post-synthesis state the runtime handles by uniform choice (5.2).
pub fn normalise(a: &mut Automaton, events: &EventTable) -> Vec<StateId> {
    let mut zero = Vec::new();
    for i in 0..a.state_count() {
        let list = a.transitions_mut(StateId(i as u32));
        let mut sum = 0.0;
        for t in list.iter_mut() {
            if events.is_controllable(t.event) {
                sum += t.prob;
            } else {
                t.prob = 1.0;
            }
        }
        let has_ctrl = list.iter().any(|t| events.is_controllable(t.event));
        if !has_ctrl {
            continue;
        }
        if sum > 0.0 && sum.is_finite() {
            for t in list.iter_mut().filter(|t| events.is_controllable(t.event)) {
                t.prob /= sum;
            }
        } else {
            zero.push(StateId(i as u32));
        }
    }
    zero
}

/// Sets every probability of a model to 1 (plain factors, rule A5 for plants).
pub fn set_unit_probabilities(a: &mut Automaton) {
    for t in a.all_transitions_mut() {
        t.prob = 1.0;
    }
}

/// Applies the input normalisation of section 5.1 with rule A5 to a whole project, returning the normalised copy.
pub fn normalise_project(
    project: &Project,
    options: NormaliseOptions,
) -> Result<Project, ZeroWeights> {
    let mut out = project.clone();
    for a in out.plants.iter_mut().chain(out.specs.iter_mut()) {
        let normalise_it = match a.kind() {
            ModelKind::Plant => options.thesis_literal_probabilities,
            _ => !options.raw_weights,
        };
        if normalise_it {
            if let Some(&s) = normalise(a, &project.events).first() {
                return Err(ZeroWeights {
                    automaton: a.name().to_owned(),
                    state: a.state_name(s).to_owned(),
                });
            }
        } else if a.kind() == ModelKind::Plant {
            set_unit_probabilities(a);
        } else {
            for t in a.all_transitions_mut() {
                if !project.events.is_controllable(t.event) {
                    t.prob = 1.0;
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn four_self_loops(kind: ModelKind) -> (EventTable, Automaton) {
        let mut ev = EventTable::new();
        let mut a = Automaton::new("m", kind);
        let q = a.add_state("q", true).unwrap();
        for (i, w) in [1.0, 1.0, 3.0, 5.0].into_iter().enumerate() {
            let e = ev.intern(&format!("e{i}"), true).unwrap();
            a.add_transition(q, e, q, w, 0).unwrap();
        }
        let u = ev.intern("u", false).unwrap();
        a.add_transition(q, u, q, 7.0, 0).unwrap();
        (ev, a)
    }

    fn probs(a: &Automaton) -> Vec<f64> {
        a.transitions(StateId(0)).iter().map(|t| t.prob).collect()
    }

    #[test]
    fn spec_weights_are_normalised_per_state_and_uncontrollable_set_to_one() {
        let (ev, a) = four_self_loops(ModelKind::Spec);
        let p = Project {
            events: ev,
            plants: vec![],
            specs: vec![a],
        };
        let n = normalise_project(&p, NormaliseOptions::default()).unwrap();
        assert_eq!(probs(&n.specs[0]), vec![0.1, 0.1, 0.3, 0.5, 1.0]);
    }

    #[test]
    fn a5_plant_probabilities_are_one_unless_thesis_literal() {
        let (ev, mut a) = four_self_loops(ModelKind::Plant);
        for t in a.transitions_mut(StateId(0)) {
            t.prob = 1.0;
        }
        let p = Project {
            events: ev,
            plants: vec![a],
            specs: vec![],
        };
        let n = normalise_project(&p, NormaliseOptions::default()).unwrap();
        assert_eq!(probs(&n.plants[0]), vec![1.0; 5]);
        let literal = NormaliseOptions {
            thesis_literal_probabilities: true,
            ..Default::default()
        };
        let n = normalise_project(&p, literal).unwrap();
        // The thesis' example: a one-state plant with four self-loops gets 0.25 on each.
        assert_eq!(probs(&n.plants[0]), vec![0.25, 0.25, 0.25, 0.25, 1.0]);
    }

    #[test]
    fn raw_weights_keep_spec_weights() {
        let (ev, a) = four_self_loops(ModelKind::Spec);
        let p = Project {
            events: ev,
            plants: vec![],
            specs: vec![a],
        };
        let raw = NormaliseOptions {
            raw_weights: true,
            ..Default::default()
        };
        let n = normalise_project(&p, raw).unwrap();
        assert_eq!(probs(&n.specs[0]), vec![1.0, 1.0, 3.0, 5.0, 1.0]);
    }

    #[test]
    fn v12_all_zero_weights_are_rejected() {
        let (ev, mut a) = four_self_loops(ModelKind::Spec);
        for t in a.transitions_mut(StateId(0)) {
            t.prob = 0.0;
        }
        let p = Project {
            events: ev,
            plants: vec![],
            specs: vec![a],
        };
        let err = normalise_project(&p, NormaliseOptions::default()).unwrap_err();
        assert_eq!(err.state, "q");
    }
}
