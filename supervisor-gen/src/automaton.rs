//! The in-memory ptSCT generator model (section 2) shared by every stage of the toolchain.
//!
//! A [`Project`] holds one [`EventTable`] (global event ids and controllability, shared by all automata of the
//! project) and the plant and specification [`Automaton`]s. Automata are deterministic: at most one transition per
//! (state, event), kept sorted by event id so lookups are binary searches.
//!
//! This module only stores models; it never validates user input with locations (that is the parser's job) and
//! never normalises or synthesises. Builder methods return [`ModelError`] instead of panicking, so a caller that
//! skipped validation still gets a typed error.

use std::collections::HashMap;
use std::fmt;

/// A global event id, an index into the project's [`EventTable`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EventId(pub u16);

impl EventId {
    /// The id as a `usize` index.
    pub fn index(self) -> usize {
        usize::from(self.0)
    }
}

/// A state id, an index into one automaton's state vectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StateId(pub u32);

impl StateId {
    /// The id as a `usize` index.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Errors raised by the model builders when they are called with inconsistent data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// An event was interned twice with different controllability (rule C1, validation V10).
    #[error("event `{event}` is declared {} here but {} elsewhere in the project", ctrl_word(*.requested), ctrl_word(*.existing))]
    ControllabilityConflict {
        /// The event name.
        event: String,
        /// Controllability already recorded in the table.
        existing: bool,
        /// Controllability requested by the new declaration.
        requested: bool,
    },
    /// More distinct events than an [`EventId`] can address.
    #[error("too many events: at most {limit} distinct events are supported")]
    TooManyEvents {
        /// The maximum number of events.
        limit: usize,
    },
    /// More states than a [`StateId`] can address.
    #[error("automaton `{automaton}` has too many states: at most {limit} are supported")]
    TooManyStates {
        /// The automaton name.
        automaton: String,
        /// The maximum number of states.
        limit: usize,
    },
    /// A state id that does not exist in the automaton.
    #[error("automaton `{automaton}` has no state with id {state}")]
    UnknownState {
        /// The automaton name.
        automaton: String,
        /// The offending id.
        state: u32,
    },
    /// Two transitions with the same source state and event (validation V8).
    #[error(
        "automaton `{automaton}` is non-deterministic: state `{state}` has two transitions on event id {event}"
    )]
    Nondeterministic {
        /// The automaton name.
        automaton: String,
        /// The source state name.
        state: String,
        /// The event id.
        event: u16,
    },
}

fn ctrl_word(controllable: bool) -> &'static str {
    if controllable {
        "controllable"
    } else {
        "uncontrollable"
    }
}

/// The global event table of a project: names, controllability flags and a name index.
///
/// Every automaton of a project refers to events by [`EventId`] into one table, so products and supervisors of
/// different models agree on ids without translation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EventTable {
    names: Vec<String>,
    controllable: Vec<bool>,
    index: HashMap<String, EventId>,
}

impl EventTable {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Returns the id of `name`, adding it with the given controllability if it is new.
    ///
    /// Fails if the event exists with the other controllability (rule C1) or the table is full.
    pub fn intern(&mut self, name: &str, controllable: bool) -> Result<EventId, ModelError> {
        if let Some(&id) = self.index.get(name) {
            let existing = self.controllable[id.index()];
            if existing != controllable {
                return Err(ModelError::ControllabilityConflict {
                    event: name.to_owned(),
                    existing,
                    requested: controllable,
                });
            }
            return Ok(id);
        }
        let raw = u16::try_from(self.names.len()).map_err(|_| ModelError::TooManyEvents {
            limit: usize::from(u16::MAX) + 1,
        })?;
        let id = EventId(raw);
        self.names.push(name.to_owned());
        self.controllable.push(controllable);
        self.index.insert(name.to_owned(), id);
        Ok(id)
    }

    /// The id of an event name, if it is in the table.
    pub fn lookup(&self, name: &str) -> Option<EventId> {
        self.index.get(name).copied()
    }

    /// The name of an event. Ids come from this table, so an unknown id yields `"?"` rather than a panic.
    pub fn name(&self, id: EventId) -> &str {
        self.names.get(id.index()).map_or("?", String::as_str)
    }

    /// Whether an event is controllable (`false` for an unknown id).
    pub fn is_controllable(&self, id: EventId) -> bool {
        self.controllable.get(id.index()).copied().unwrap_or(false)
    }

    /// Number of events in the table.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the table has no events.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// All ids in ascending order.
    pub fn ids(&self) -> impl Iterator<Item = EventId> + '_ {
        (0..self.names.len()).map(|i| EventId(i as u16))
    }
}

/// The role of an automaton in a project (XML `automata/@type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ModelKind {
    /// A free-behaviour model G_i: what the robot can do.
    Plant,
    /// A control specification E_i: what the robot should do.
    Spec,
    /// A synthesised supervisor (tool output).
    Supervisor,
}

impl ModelKind {
    /// The XML `type` attribute value of this kind.
    pub fn as_str(self) -> &'static str {
        match self {
            ModelKind::Plant => "plant",
            ModelKind::Spec => "spec",
            ModelKind::Supervisor => "supervisor",
        }
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One outgoing transition of a state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transition {
    /// The event labelling the transition.
    pub event: EventId,
    /// The target state.
    pub target: StateId,
    /// P for controllable transitions: the raw weight in an input model, the normalised probability after
    /// normalisation (section 5). Always 1.0 for uncontrollable transitions and in plants (rule A5).
    pub prob: f64,
    /// T: the lower time bound in ticks (section 3). Always 0 for uncontrollable transitions.
    pub lower_bound: u32,
}

/// A deterministic ptSCT generator `(Q, Σ, δ, q0, Qm, P, T)` (section 2).
///
/// Storage is flat so that million-state products cost no per-state allocation: all state names live in one
/// string, and all transitions in one vector grouped by source state (compressed sparse rows), each group sorted
/// by event id.
#[derive(Debug, Clone, PartialEq)]
pub struct Automaton {
    pub(crate) name: String,
    pub(crate) kind: ModelKind,
    /// Sorted, deduplicated alphabet.
    pub(crate) alphabet: Vec<EventId>,
    /// All state names, concatenated; state x's name ends at `name_end[x]`.
    names: String,
    name_end: Vec<usize>,
    marked: Vec<bool>,
    pub(crate) initial: StateId,
    /// Transitions of state x are `trans[first[x]..first[x + 1]]`; `first` has one entry more than there are states.
    first: Vec<usize>,
    trans: Vec<Transition>,
}

impl Automaton {
    /// An automaton with no states and an empty alphabet. Its initial state is id 0 once that state is added.
    pub fn new(name: impl Into<String>, kind: ModelKind) -> Self {
        Self {
            name: name.into(),
            kind,
            alphabet: Vec::new(),
            names: String::new(),
            name_end: Vec::new(),
            marked: Vec::new(),
            initial: StateId(0),
            first: vec![0],
            trans: Vec::new(),
        }
    }

    /// The identity of the synchronous product (rule C3): one marked state and an empty alphabet.
    pub fn identity(name: impl Into<String>, kind: ModelKind) -> Self {
        let mut a = Self::new(name, kind);
        a.push_state("id", true, []);
        a
    }

    /// Appends a state with its outgoing transitions, which must be sorted by event id and target existing or
    /// later-appended states. Used by the algorithms, which build automata state by state.
    pub(crate) fn push_state(
        &mut self,
        name: &str,
        marked: bool,
        transitions: impl IntoIterator<Item = Transition>,
    ) {
        self.names.push_str(name);
        self.name_end.push(self.names.len());
        self.marked.push(marked);
        self.trans.extend(transitions);
        self.first.push(self.trans.len());
    }

    /// Mutable access to one state's transitions (labels only: event and target order must be kept).
    pub(crate) fn transitions_mut(&mut self, state: StateId) -> &mut [Transition] {
        let i = state.index();
        &mut self.trans[self.first[i]..self.first[i + 1]]
    }

    /// Mutable access to every transition (labels only).
    pub(crate) fn all_transitions_mut(&mut self) -> &mut [Transition] {
        &mut self.trans
    }

    /// Adds a state and returns its id. Ids are dense and assigned in insertion order.
    pub fn add_state(
        &mut self,
        name: impl Into<String>,
        marked: bool,
    ) -> Result<StateId, ModelError> {
        let id = u32::try_from(self.marked.len()).map_err(|_| ModelError::TooManyStates {
            automaton: self.name.clone(),
            limit: u32::MAX as usize,
        })?;
        self.push_state(&name.into(), marked, []);
        Ok(StateId(id))
    }

    /// Adds an event to the alphabet (no effect if present). Events used by transitions are added automatically.
    pub fn add_event(&mut self, event: EventId) {
        if let Err(pos) = self.alphabet.binary_search(&event) {
            self.alphabet.insert(pos, event);
        }
    }

    /// Adds the transition `from --event--> to` with probability/weight `prob` and lower bound `lower_bound`.
    ///
    /// Fails if either state does not exist or `from` already has a transition on `event`.
    pub fn add_transition(
        &mut self,
        from: StateId,
        event: EventId,
        to: StateId,
        prob: f64,
        lower_bound: u32,
    ) -> Result<(), ModelError> {
        self.check_state(to)?;
        self.check_state(from)?;
        let (lo, hi) = (self.first[from.index()], self.first[from.index() + 1]);
        match self.trans[lo..hi].binary_search_by_key(&event, |t| t.event) {
            Ok(_) => Err(ModelError::Nondeterministic {
                automaton: self.name.clone(),
                state: self.state_name(from).to_owned(),
                event: event.0,
            }),
            Err(pos) => {
                // Builders add few transitions; shifting the later rows keeps the storage flat.
                self.trans.insert(
                    lo + pos,
                    Transition {
                        event,
                        target: to,
                        prob,
                        lower_bound,
                    },
                );
                for f in &mut self.first[from.index() + 1..] {
                    *f += 1;
                }
                self.add_event(event);
                Ok(())
            }
        }
    }

    /// Sets the initial state q0.
    pub fn set_initial(&mut self, state: StateId) -> Result<(), ModelError> {
        self.check_state(state)?;
        self.initial = state;
        Ok(())
    }

    /// Sets whether a state is marked.
    pub fn set_marked(&mut self, state: StateId, marked: bool) -> Result<(), ModelError> {
        self.check_state(state)?;
        self.marked[state.index()] = marked;
        Ok(())
    }

    fn check_state(&self, state: StateId) -> Result<(), ModelError> {
        if state.index() < self.marked.len() {
            Ok(())
        } else {
            Err(ModelError::UnknownState {
                automaton: self.name.clone(),
                state: state.0,
            })
        }
    }

    /// The model name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Renames the model.
    pub fn set_name(&mut self, name: impl Into<String>) {
        self.name = name.into();
    }

    /// The model kind.
    pub fn kind(&self) -> ModelKind {
        self.kind
    }

    /// Changes the model kind (e.g. a synthesised result becomes a [`ModelKind::Supervisor`]).
    pub fn set_kind(&mut self, kind: ModelKind) {
        self.kind = kind;
    }

    /// The sorted alphabet Σ.
    pub fn alphabet(&self) -> &[EventId] {
        &self.alphabet
    }

    /// Whether `event` is in the alphabet.
    pub fn has_event(&self, event: EventId) -> bool {
        self.alphabet.binary_search(&event).is_ok()
    }

    /// Number of states |Q|.
    pub fn state_count(&self) -> usize {
        self.marked.len()
    }

    /// Total number of transitions.
    pub fn transition_count(&self) -> usize {
        self.trans.len()
    }

    /// All state ids in ascending order.
    pub fn states(&self) -> impl Iterator<Item = StateId> + '_ {
        (0..self.marked.len()).map(|i| StateId(i as u32))
    }

    /// The name of a state (`"?"` for an unknown id).
    pub fn state_name(&self, state: StateId) -> &str {
        let i = state.index();
        match self.name_end.get(i) {
            Some(&end) => {
                let start = if i == 0 { 0 } else { self.name_end[i - 1] };
                &self.names[start..end]
            }
            None => "?",
        }
    }

    /// The id of the state with this name, by linear search.
    pub fn state_by_name(&self, name: &str) -> Option<StateId> {
        self.states().find(|&s| self.state_name(s) == name)
    }

    /// Whether a state is marked (`false` for an unknown id).
    pub fn is_marked(&self, state: StateId) -> bool {
        self.marked.get(state.index()).copied().unwrap_or(false)
    }

    /// The initial state q0. Meaningless while the automaton has no states.
    pub fn initial(&self) -> StateId {
        self.initial
    }

    /// Outgoing transitions of a state, sorted by event id (empty for an unknown id).
    pub fn transitions(&self, state: StateId) -> &[Transition] {
        let i = state.index();
        if i < self.marked.len() {
            &self.trans[self.first[i]..self.first[i + 1]]
        } else {
            &[]
        }
    }

    /// δ(state, event) with its labels, if defined.
    pub fn transition(&self, state: StateId, event: EventId) -> Option<&Transition> {
        let list = self.transitions(state);
        list.binary_search_by_key(&event, |t| t.event)
            .ok()
            .map(|i| &list[i])
    }
}

/// A ptSCT project: the global event table plus the plant and specification models.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Project {
    /// Global event ids shared by all models.
    pub events: EventTable,
    /// Free-behaviour models G_1..G_m.
    pub plants: Vec<Automaton>,
    /// Control specifications E_1..E_n.
    pub specs: Vec<Automaton>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interning_is_idempotent_and_rejects_controllability_conflict() {
        let mut t = EventTable::new();
        let a = t.intern("a", true).unwrap();
        assert_eq!(t.intern("a", true).unwrap(), a);
        let u = t.intern("u", false).unwrap();
        assert_eq!(u, EventId(1));
        assert!(matches!(
            t.intern("a", false),
            Err(ModelError::ControllabilityConflict { .. })
        ));
        assert_eq!(t.name(u), "u");
        assert!(t.is_controllable(a));
        assert!(!t.is_controllable(u));
    }

    #[test]
    fn transitions_stay_sorted_and_deterministic() {
        let mut g = Automaton::new("g", ModelKind::Plant);
        let q0 = g.add_state("q0", true).unwrap();
        let q1 = g.add_state("q1", false).unwrap();
        g.add_transition(q0, EventId(3), q1, 1.0, 0).unwrap();
        g.add_transition(q0, EventId(1), q0, 1.0, 2).unwrap();
        let events: Vec<_> = g.transitions(q0).iter().map(|t| t.event).collect();
        assert_eq!(events, vec![EventId(1), EventId(3)]);
        assert_eq!(g.alphabet(), &[EventId(1), EventId(3)]);
        assert!(matches!(
            g.add_transition(q0, EventId(1), q1, 1.0, 0),
            Err(ModelError::Nondeterministic { .. })
        ));
        assert!(matches!(
            g.add_transition(q0, EventId(0), StateId(9), 1.0, 0),
            Err(ModelError::UnknownState { state: 9, .. })
        ));
        assert_eq!(g.transition(q0, EventId(1)).map(|t| t.lower_bound), Some(2));
        assert_eq!(g.transition_count(), 2);
    }

    #[test]
    fn adding_to_an_earlier_state_keeps_later_rows_and_names() {
        let mut g = Automaton::new("g", ModelKind::Spec);
        let s: Vec<_> = ["alpha", "", "gamma"]
            .iter()
            .map(|n| g.add_state(*n, false).unwrap())
            .collect();
        g.add_transition(s[2], EventId(0), s[0], 1.0, 0).unwrap();
        g.add_transition(s[1], EventId(1), s[2], 1.0, 0).unwrap();
        g.add_transition(s[0], EventId(2), s[1], 1.0, 0).unwrap();
        let rows: Vec<Vec<(u16, u32)>> = g
            .states()
            .map(|x| {
                g.transitions(x)
                    .iter()
                    .map(|t| (t.event.0, t.target.0))
                    .collect()
            })
            .collect();
        assert_eq!(rows, vec![vec![(2, 1)], vec![(1, 2)], vec![(0, 0)]]);
        let names: Vec<_> = g.states().map(|x| g.state_name(x)).collect();
        assert_eq!(names, vec!["alpha", "", "gamma"]);
        assert_eq!(g.state_by_name("gamma"), Some(s[2]));
        assert_eq!(g.state_name(StateId(7)), "?");
        assert!(g.transitions(StateId(7)).is_empty());
    }
}
