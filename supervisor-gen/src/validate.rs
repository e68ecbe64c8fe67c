//! Structural validation of docs/ptsct.md section 11: the per-file rules V1-V9, V11, V12, V14, V15 and W1-W4, and the
//! project rules V10, V13, V15 (event count), W5 and W6. Supervisor files (tool output read back) are exempt from
//! V6 and V7.
//!
//! Every problem of every file is reported in one pass; nothing here stops early. A project with any error yields no
//! models, so it can never reach synthesis. This module never reads files and never prints.

use std::collections::{HashMap, HashSet, VecDeque};

use crate::automaton::ModelKind;
use crate::compiled::{MAX_EVENTS, MAX_STATES, MAX_TRANSITIONS_PER_STATE};
use crate::diagnostics::{Code, Diagnostic, Position, has_errors};
use crate::source::{Located, SourceFormat, SourceModel, parse_kind};

/// Choices that change which rules apply.
#[derive(Debug, Clone, Copy, Default)]
pub struct ValidateOptions {
    /// Keep plant probabilities (`--thesis-literal-probabilities`): no W4, and V12 applies to plants too.
    pub thesis_literal_probabilities: bool,
    /// Weights are stored as written (`--raw-weights`), so a weight above 1 cannot be compiled (V15).
    pub raw_weights: bool,
}

/// A validated state.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedState {
    /// Unique name within the model.
    pub name: String,
    /// The single initial state has this set.
    pub initial: bool,
    /// Marked ("safe" or "task complete").
    pub marked: bool,
}

/// A validated event of one model.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedEvent {
    /// Unique name within the model (never `tick`).
    pub name: String,
    /// Controllable (an omitted `con` is uncontrollable).
    pub controllable: bool,
}

/// A validated transition; indices refer to the model's `states` and `events`.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedTransition {
    /// Source state index.
    pub src: usize,
    /// Target state index.
    pub dst: usize,
    /// Event index.
    pub event: usize,
    /// The weight as written (`None` when omitted, meaning 1). Always `None` on uncontrollable transitions (W3) and,
    /// unless thesis-literal probabilities are on, on plant transitions (W4).
    pub weight: Option<f64>,
    /// Lower bound in ticks (0 when omitted; always 0 on uncontrollable transitions).
    pub time: u16,
}

/// One model that passed every rule.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedModel {
    /// The file it came from.
    pub file: String,
    /// Unique model name in the project.
    pub name: String,
    /// Plant, specification or supervisor.
    pub kind: ModelKind,
    /// States in file order; exactly one is initial.
    pub states: Vec<CheckedState>,
    /// Events in file order.
    pub events: Vec<CheckedEvent>,
    /// Transitions in file order; deterministic.
    pub transitions: Vec<CheckedTransition>,
}

/// The outcome of validating a project.
#[derive(Debug, Clone)]
pub struct Validation {
    /// Every error and warning, sorted by file and position.
    pub diagnostics: Vec<Diagnostic>,
    /// The validated models, in input order, or `None` if there is any error.
    pub models: Option<Vec<CheckedModel>>,
}

/// Validates the models of one project together.
pub fn validate(sources: &[SourceModel], options: ValidateOptions) -> Validation {
    let mut diagnostics = Vec::new();
    let mut models = Vec::new();
    for source in sources {
        let mut file_diagnostics = Vec::new();
        let model = check_file(source, options, &mut file_diagnostics);
        if let Some(model) = model.filter(|_| !has_errors(&file_diagnostics)) {
            models.push(model);
        }
        diagnostics.append(&mut file_diagnostics);
    }
    check_project(sources, &mut diagnostics);
    crate::diagnostics::sort(&mut diagnostics);
    let models = (!has_errors(&diagnostics)).then_some(models);
    Validation {
        diagnostics,
        models,
    }
}

/// The kind a model is treated as: its declared type if valid.
fn declared_kind(source: &SourceModel) -> Option<ModelKind> {
    source.kind.as_ref().and_then(|k| parse_kind(&k.value))
}

/// Per-file rules. Returns the typed model when the file could be resolved (errors may still have been reported).
fn check_file(
    source: &SourceModel,
    options: ValidateOptions,
    out: &mut Vec<Diagnostic>,
) -> Option<CheckedModel> {
    let mut check = FileCheck {
        source,
        options,
        out,
    };
    let kind = check.kind();
    let weights_count = match kind {
        Some(ModelKind::Plant) => options.thesis_literal_probabilities,
        _ => true,
    };
    let states = check.states();
    let events = check.events();
    let transitions = check.transitions(&states, &events, kind, weights_count);
    if kind != Some(ModelKind::Supervisor) {
        // A supervisor's alphabet is meaningful even for events it never enables (they stay disabled at runtime),
        // so tool output is exempt from V6 and V7.
        check.unused(&states, &events, &transitions);
    }
    check.per_state(&states, &events, &transitions, weights_count);
    check.reachability(&states, &transitions);
    let kind = kind?;
    transitions.complete.then(|| CheckedModel {
        file: source.file.clone(),
        name: source.name.value.clone(),
        kind,
        states: states.list,
        events: events.list,
        transitions: transitions.list,
    })
}

/// Declared names of one kind (states or events) with their positions, duplicates dropped.
struct Declared<'a, T> {
    index: HashMap<&'a str, usize>,
    at: Vec<Position>,
    list: Vec<T>,
}

impl<T> Declared<'_, T> {
    fn new() -> Self {
        Declared {
            index: HashMap::new(),
            at: Vec::new(),
            list: Vec::new(),
        }
    }
}

/// Transitions of one file, with what they use.
struct Resolved {
    list: Vec<CheckedTransition>,
    used_states: Vec<bool>,
    used_events: Vec<bool>,
    /// Every transition resolved (no V4, V5 or V8).
    complete: bool,
}

/// The rules of one file, reporting into `out`.
struct FileCheck<'a> {
    source: &'a SourceModel,
    options: ValidateOptions,
    out: &'a mut Vec<Diagnostic>,
}

impl<'a> FileCheck<'a> {
    fn report(&mut self, code: Code, at: Position, message: String) {
        self.out
            .push(Diagnostic::new(code, &self.source.file, at, message));
    }

    fn model(&self) -> &'a str {
        &self.source.name.value
    }

    /// V13: a known `type` that agrees with the role the file was passed with.
    fn kind(&mut self) -> Option<ModelKind> {
        let source = self.source;
        let Some(k) = &source.kind else {
            let message = match source.format {
                SourceFormat::Thesis => {
                    format!(
                        "model `{}` has no `type` (expected plant or spec)",
                        self.model()
                    )
                }
                SourceFormat::Nadzoru => format!(
                    "Nadzoru2 model `{}` carries no type: pass it with --plant or --spec",
                    self.model()
                ),
            };
            self.report(Code::V13, source.root, message);
            return None;
        };
        let Some(kind) = parse_kind(&k.value) else {
            let message = format!(
                "unknown model type `{}` (expected plant, spec, free-behaviour, specification or supervisor)",
                k.value
            );
            self.report(Code::V13, k.at, message);
            return None;
        };
        if let Some(role) = source.role.filter(|&r| r != kind) {
            let message = format!(
                "model `{}` declares type `{kind}` but was passed as --{role}",
                self.model()
            );
            self.report(Code::V13, k.at, message);
        }
        Some(kind)
    }

    /// V9, V2, V1, V3 and the state-count limit of V15.
    fn states(&mut self) -> Declared<'a, CheckedState> {
        let source = self.source;
        let mut states = Declared::new();
        let mut first_initial: Option<Position> = None;
        for decl in &source.states {
            if let Some(&first) = states.index.get(decl.name.value.as_str()) {
                let message = format!(
                    "duplicate state name `{}` (first at line {})",
                    decl.name.value, states.at[first].line
                );
                self.report(Code::V9, decl.name.at, message);
                continue;
            }
            let mut initial = decl.initial;
            if initial {
                match first_initial {
                    Some(first) => {
                        let message = format!(
                            "state `{}` is a second initial state (first at line {})",
                            decl.name.value, first.line
                        );
                        self.report(Code::V2, decl.at, message);
                        initial = false;
                    }
                    None => first_initial = Some(decl.at),
                }
            }
            states.index.insert(&decl.name.value, states.list.len());
            states.at.push(decl.at);
            states.list.push(CheckedState {
                name: decl.name.value.clone(),
                initial,
                marked: decl.marked,
            });
        }
        if first_initial.is_none() {
            let message = format!("model `{}` has no initial state", self.model());
            self.report(Code::V1, source.root, message);
        }
        if !states.list.iter().any(|s| s.marked) {
            let message = format!("model `{}` has no marked state", self.model());
            self.report(Code::V3, source.root, message);
        }
        if states.list.len() > MAX_STATES {
            let message = format!(
                "model `{}` has {} states; a compiled supervisor holds at most {}",
                self.model(),
                states.list.len(),
                MAX_STATES
            );
            self.report(Code::V15, source.root, message);
        }
        states
    }

    /// V9, V14, W1.
    fn events(&mut self) -> Declared<'a, CheckedEvent> {
        let mut events = Declared::new();
        for decl in &self.source.events {
            if let Some(&first) = events.index.get(decl.name.value.as_str()) {
                let message = format!(
                    "duplicate event name `{}` (first at line {})",
                    decl.name.value, events.at[first].line
                );
                self.report(Code::V9, decl.name.at, message);
                continue;
            }
            if decl.name.value == "tick" {
                let message =
                    "event name `tick` is reserved for the global clock and must not be declared"
                        .into();
                self.report(Code::V14, decl.name.at, message);
            }
            if decl.controllable.is_none() {
                let message = format!(
                    "event `{}` has no `con` attribute; it is treated as uncontrollable",
                    decl.name.value
                );
                self.report(Code::W1, decl.at, message);
            }
            events.index.insert(&decl.name.value, events.list.len());
            events.at.push(decl.at);
            events.list.push(CheckedEvent {
                name: decl.name.value.clone(),
                controllable: decl.controllable.unwrap_or(false),
            });
        }
        events
    }

    /// V4, V5, V8, V11, the lower-bound limit of V15, W3, W4.
    fn transitions(
        &mut self,
        states: &Declared<'_, CheckedState>,
        events: &Declared<'_, CheckedEvent>,
        kind: Option<ModelKind>,
        weights_count: bool,
    ) -> Resolved {
        let mut resolved = Resolved {
            list: Vec::new(),
            used_states: vec![false; states.list.len()],
            used_events: vec![false; events.list.len()],
            complete: true,
        };
        let mut first_on: HashMap<(usize, usize), Position> = HashMap::new();
        for decl in &self.source.transitions {
            let event = events.index.get(decl.event.value.as_str()).copied();
            if event.is_none() {
                let message = format!(
                    "transition uses event `{}`, which is not declared in `<events>`",
                    decl.event.value
                );
                self.report(Code::V4, decl.event.at, message);
            }
            let src = self.state(states, &decl.src, "source");
            let dst = self.state(states, &decl.dst, "target");
            let weight = decl.prob.as_ref().and_then(|p| self.weight(p));
            let time = decl.time.as_ref().and_then(|t| self.time(t));
            match event.map(|e| events.list[e].controllable) {
                Some(false) => {
                    for (key, attr) in [("prob", &decl.prob), ("time", &decl.time)] {
                        if let Some(attr) = attr {
                            let message = format!(
                                "`{key}` on a transition of uncontrollable event `{}` is ignored",
                                decl.event.value
                            );
                            self.report(Code::W3, attr.at, message);
                        }
                    }
                }
                Some(true) if kind == Some(ModelKind::Plant) && !weights_count => {
                    if let Some(p) = &decl.prob {
                        let message =
                            "`prob` in a plant model is ignored (probabilities belong in specifications)".into();
                        self.report(Code::W4, p.at, message);
                    }
                }
                _ => {}
            }
            for s in [src, dst].into_iter().flatten() {
                resolved.used_states[s] = true;
            }
            if let Some(e) = event {
                resolved.used_events[e] = true;
            }
            let (Some(src), Some(dst), Some(event)) = (src, dst, event) else {
                resolved.complete = false;
                continue;
            };
            if let Some(first) = first_on.get(&(src, event)) {
                let message = format!(
                    "state `{}` has two transitions on event `{}` (first at line {})",
                    states.list[src].name, events.list[event].name, first.line
                );
                self.report(Code::V8, decl.at, message);
                resolved.complete = false;
                continue;
            }
            first_on.insert((src, event), decl.at);
            let controllable = events.list[event].controllable;
            resolved.list.push(CheckedTransition {
                src,
                dst,
                event,
                weight: weight.filter(|_| controllable && weights_count),
                time: if controllable { time.unwrap_or(0) } else { 0 },
            });
        }
        resolved
    }

    /// The index of a state named by a transition, or V5.
    fn state(
        &mut self,
        states: &Declared<'_, CheckedState>,
        name: &Located<String>,
        role: &str,
    ) -> Option<usize> {
        let found = states.index.get(name.value.as_str()).copied();
        if found.is_none() {
            let message = format!(
                "transition {role} `{}` is not declared in `<states>`",
                name.value
            );
            self.report(Code::V5, name.at, message);
        }
        found
    }

    /// A `prob` value, or V11.
    fn weight(&mut self, p: &Located<String>) -> Option<f64> {
        match p.value.parse::<f64>() {
            Ok(w) if w > 1.0 && w.is_finite() && self.options.raw_weights => {
                let message = format!(
                    "`prob` is {w}; with --raw-weights weights are stored as probabilities and must be at most 1"
                );
                self.report(Code::V15, p.at, message);
                None
            }
            Ok(w) if w.is_finite() && w >= 0.0 => Some(w),
            _ => {
                let message = format!(
                    "`prob` is `{}`; expected a finite real number >= 0",
                    p.value
                );
                self.report(Code::V11, p.at, message);
                None
            }
        }
    }

    /// A `time` value, or V11 / V15.
    fn time(&mut self, t: &Located<String>) -> Option<u16> {
        match t.value.parse::<u64>() {
            Ok(n) => {
                let fits = u16::try_from(n).ok();
                if fits.is_none() {
                    let message = format!(
                        "`time` is {n} ticks; a compiled supervisor stores at most {}",
                        u16::MAX
                    );
                    self.report(Code::V15, t.at, message);
                }
                fits
            }
            Err(_) => {
                let message = format!(
                    "`time` is `{}`; expected an integer number of ticks >= 0",
                    t.value
                );
                self.report(Code::V11, t.at, message);
                None
            }
        }
    }

    /// V6, V7.
    fn unused(
        &mut self,
        states: &Declared<'_, CheckedState>,
        events: &Declared<'_, CheckedEvent>,
        transitions: &Resolved,
    ) {
        for (s, used) in transitions.used_states.iter().enumerate() {
            if !used {
                let message = format!("state `{}` is used by no transition", states.list[s].name);
                self.report(Code::V6, states.at[s], message);
            }
        }
        for (e, used) in transitions.used_events.iter().enumerate() {
            if !used {
                let message = format!("event `{}` is used by no transition", events.list[e].name);
                self.report(Code::V7, events.at[e], message);
            }
        }
    }

    /// V12 and the transitions-per-state limit of V15.
    fn per_state(
        &mut self,
        states: &Declared<'_, CheckedState>,
        events: &Declared<'_, CheckedEvent>,
        transitions: &Resolved,
        weights_count: bool,
    ) {
        let mut outgoing = vec![0usize; states.list.len()];
        let mut controllable = vec![(0usize, false); states.list.len()];
        for t in &transitions.list {
            outgoing[t.src] += 1;
            if events.list[t.event].controllable {
                let (count, positive) = &mut controllable[t.src];
                *count += 1;
                *positive |= t.weight.unwrap_or(1.0) > 0.0;
            }
        }
        for (s, &(count, positive)) in controllable.iter().enumerate() {
            let name = &states.list[s].name;
            if weights_count && count > 0 && !positive {
                let message = format!(
                    "all {count} outgoing controllable transitions of state `{name}` have weight 0"
                );
                self.report(Code::V12, states.at[s], message);
            }
            if outgoing[s] > MAX_TRANSITIONS_PER_STATE {
                let message = format!(
                    "state `{name}` has {} outgoing transitions; a compiled supervisor allows at most {}",
                    outgoing[s], MAX_TRANSITIONS_PER_STATE
                );
                self.report(Code::V15, states.at[s], message);
            }
        }
    }

    /// W2: states unreachable from the single initial state (states without transitions already have V6).
    fn reachability(&mut self, states: &Declared<'_, CheckedState>, transitions: &Resolved) {
        let Some(initial) = states.list.iter().position(|s| s.initial) else {
            return;
        };
        let reached = reachable(initial, states.list.len(), &transitions.list);
        for (s, reached) in reached.iter().enumerate() {
            if !reached && transitions.used_states[s] {
                let message = format!(
                    "state `{}` is unreachable from the initial state `{}`",
                    states.list[s].name, states.list[initial].name
                );
                self.report(Code::W2, states.at[s], message);
            }
        }
    }
}

/// States reachable from `initial` along `transitions`.
fn reachable(initial: usize, states: usize, transitions: &[CheckedTransition]) -> Vec<bool> {
    let mut successors = vec![Vec::new(); states];
    for t in transitions {
        successors[t.src].push(t.dst);
    }
    let mut seen = vec![false; states];
    seen[initial] = true;
    let mut queue = VecDeque::from([initial]);
    while let Some(s) = queue.pop_front() {
        for &d in &successors[s] {
            if !seen[d] {
                seen[d] = true;
                queue.push_back(d);
            }
        }
    }
    seen
}

/// Project rules: V13 (duplicate names), V10, V15 (event count), W5, W6.
fn check_project(sources: &[SourceModel], out: &mut Vec<Diagnostic>) {
    let mut names: HashMap<&str, &SourceModel> = HashMap::new();
    for source in sources {
        let name = source.name.value.as_str();
        match names.get(name) {
            Some(first) => out.push(Diagnostic::new(
                Code::V13,
                &source.file,
                source.name.at,
                format!(
                    "duplicate model name `{name}` (first in {}:{})",
                    first.file, first.name.at
                ),
            )),
            None => {
                names.insert(name, source);
            }
        }
    }

    // First declaration of every event, in input order.
    let mut first_decl: HashMap<&str, (&SourceModel, Position, Option<bool>)> = HashMap::new();
    let mut distinct = 0usize;
    for source in sources {
        let mut in_file = HashSet::new();
        for decl in &source.events {
            let name = decl.name.value.as_str();
            if !in_file.insert(name) {
                continue;
            }
            match first_decl.get(name) {
                None => {
                    distinct += 1;
                    if distinct == MAX_EVENTS + 1 {
                        out.push(Diagnostic::new(
                            Code::V15,
                            &source.file,
                            decl.at,
                            format!(
                                "event `{name}` is event number {distinct} of the project; compiled supervisors address at most {}",
                                MAX_EVENTS
                            ),
                        ));
                    }
                    first_decl.insert(name, (source, decl.at, decl.controllable));
                }
                Some(&(first, at, con)) => {
                    let here = decl.controllable.unwrap_or(false);
                    let there = con.unwrap_or(false);
                    if here != there {
                        out.push(Diagnostic::new(
                            Code::V10,
                            &source.file,
                            decl.at,
                            format!(
                                "event `{name}` is {} here but {} in {}:{}",
                                describe(decl.controllable),
                                describe(con),
                                first.file,
                                at
                            ),
                        ));
                    }
                }
            }
        }
    }

    let plants: Vec<&SourceModel> = sources
        .iter()
        .filter(|s| declared_kind(s) == Some(ModelKind::Plant))
        .collect();
    let specs: Vec<&SourceModel> = sources
        .iter()
        .filter(|s| declared_kind(s) == Some(ModelKind::Spec))
        .collect();
    let plant_events: HashSet<&str> = plants
        .iter()
        .flat_map(|p| p.events.iter().map(|e| e.name.value.as_str()))
        .collect();
    let spec_events: HashSet<&str> = specs
        .iter()
        .flat_map(|s| s.events.iter().map(|e| e.name.value.as_str()))
        .collect();

    let mut warned = HashSet::new();
    for spec in &specs {
        for decl in &spec.events {
            let name = decl.name.value.as_str();
            if decl.controllable != Some(true)
                && name != "tick"
                && !plant_events.contains(name)
                && warned.insert(name)
            {
                out.push(Diagnostic::new(
                    Code::W5,
                    &spec.file,
                    decl.at,
                    format!(
                        "uncontrollable event `{name}` appears in no plant: it can never make a state bad, and it is applied only when every owning supervisor allows it"
                    ),
                ));
            }
        }
    }

    if !specs.is_empty() {
        for plant in &plants {
            if !plant
                .events
                .iter()
                .any(|e| spec_events.contains(e.name.value.as_str()))
            {
                out.push(Diagnostic::new(
                    Code::W6,
                    &plant.file,
                    plant.root,
                    format!(
                        "plant `{}` shares no event with any specification: its events belong to no local supervisor and are never enabled at runtime",
                        plant.name.value
                    ),
                ));
            }
        }
    }
}

/// "controllable", "uncontrollable" or "uncontrollable (con omitted)".
fn describe(con: Option<bool>) -> &'static str {
    match con {
        Some(true) => "controllable",
        Some(false) => "uncontrollable",
        None => "uncontrollable (con omitted)",
    }
}
