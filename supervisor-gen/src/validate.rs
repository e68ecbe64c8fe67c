//! Structural validation of ptsct.md section 11: the per-file rules V1-V9, V11, V12, V14, V15 and W1-W4, and the
//! project rules V10, V13, V15 (event count), W5 and W6. Supervisor files (tool output read back) are exempt from
//! V6 and V7.
//!
//! Every problem of every file is reported in one pass; nothing here stops early. A project with any error yields no
//! models, so it can never reach synthesis. This module never reads files and never prints.

use std::collections::{HashMap, HashSet, VecDeque};

use crate::automaton::ModelKind;
use crate::diagnostics::{Code, Diagnostic, Position, has_errors};
use crate::source::{Located, SourceFormat, SourceModel, parse_kind};

/// Limits of the compiled byte layout (section 9) that input models are checked against (V15).
pub mod limits {
    /// Most outgoing transitions of one state (1-byte count).
    pub const MAX_TRANSITIONS_PER_STATE: usize = 255;
    /// Most states of one model (2-byte state ids).
    pub const MAX_STATES: usize = 65_535;
    /// Most events in a project (1-byte event ids).
    pub const MAX_EVENTS: usize = 256;
    /// Largest lower bound, in ticks (2-byte values).
    pub const MAX_TIME: u64 = 65_535;
}

/// Choices that change which rules apply.
#[derive(Debug, Clone, Copy, Default)]
pub struct ValidateOptions {
    /// Keep plant probabilities (`--thesis-literal-probabilities`): no W4, and V12 applies to plants too.
    pub thesis_literal_probabilities: bool,
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
    let file = source.file.as_str();
    let mut report = |code: Code, at: Position, message: String| {
        out.push(Diagnostic::new(code, file, at, message))
    };

    // V13: type.
    let kind = match &source.kind {
        None => {
            let message = match source.format {
                SourceFormat::Thesis => {
                    format!(
                        "model `{}` has no `type` (expected plant or spec)",
                        source.name.value
                    )
                }
                SourceFormat::Nadzoru => format!(
                    "Nadzoru2 model `{}` carries no type: pass it with --plant or --spec",
                    source.name.value
                ),
            };
            report(Code::V13, source.root, message);
            None
        }
        Some(k) => match parse_kind(&k.value) {
            None => {
                report(
                    Code::V13,
                    k.at,
                    format!(
                        "unknown model type `{}` (expected plant, spec, free-behaviour, specification or supervisor)",
                        k.value
                    ),
                );
                None
            }
            Some(kind) => {
                if let Some(role) = source.role.filter(|&r| r != kind) {
                    report(
                        Code::V13,
                        k.at,
                        format!(
                            "model `{}` declares type `{kind}` but was passed as --{role}",
                            source.name.value
                        ),
                    );
                }
                Some(kind)
            }
        },
    };
    let weights_count = match kind {
        Some(ModelKind::Plant) => options.thesis_literal_probabilities,
        _ => true,
    };

    // States: V9, V2, V1, V3, V15.
    let mut state_index: HashMap<&str, usize> = HashMap::new();
    let mut state_at: Vec<Position> = Vec::new();
    let mut states = Vec::new();
    let mut first_initial: Option<Position> = None;
    let mut any_marked = false;
    for decl in &source.states {
        if let Some(&first) = state_index.get(decl.name.value.as_str()) {
            report(
                Code::V9,
                decl.name.at,
                format!(
                    "duplicate state name `{}` (first at line {})",
                    decl.name.value, state_at[first].line
                ),
            );
            continue;
        }
        if decl.initial {
            match first_initial {
                Some(first) => report(
                    Code::V2,
                    decl.at,
                    format!(
                        "state `{}` is a second initial state (first at line {})",
                        decl.name.value, first.line
                    ),
                ),
                None => first_initial = Some(decl.at),
            }
        }
        any_marked |= decl.marked;
        state_index.insert(&decl.name.value, states.len());
        state_at.push(decl.at);
        states.push(CheckedState {
            name: decl.name.value.clone(),
            initial: decl.initial && first_initial == Some(decl.at),
            marked: decl.marked,
        });
    }
    if first_initial.is_none() {
        report(
            Code::V1,
            source.root,
            format!("model `{}` has no initial state", source.name.value),
        );
    }
    if !any_marked {
        report(
            Code::V3,
            source.root,
            format!("model `{}` has no marked state", source.name.value),
        );
    }
    if states.len() > limits::MAX_STATES {
        report(
            Code::V15,
            source.root,
            format!(
                "model `{}` has {} states; a compiled supervisor holds at most {}",
                source.name.value,
                states.len(),
                limits::MAX_STATES
            ),
        );
    }

    // Events: V9, V14, W1.
    let mut event_index: HashMap<&str, usize> = HashMap::new();
    let mut event_at: Vec<Position> = Vec::new();
    let mut events = Vec::new();
    for decl in &source.events {
        if let Some(&first) = event_index.get(decl.name.value.as_str()) {
            report(
                Code::V9,
                decl.name.at,
                format!(
                    "duplicate event name `{}` (first at line {})",
                    decl.name.value, event_at[first].line
                ),
            );
            continue;
        }
        if decl.name.value == "tick" {
            report(
                Code::V14,
                decl.name.at,
                "event name `tick` is reserved for the global clock and must not be declared"
                    .into(),
            );
        }
        if decl.controllable.is_none() {
            report(
                Code::W1,
                decl.at,
                format!(
                    "event `{}` has no `con` attribute; it is treated as uncontrollable",
                    decl.name.value
                ),
            );
        }
        event_index.insert(&decl.name.value, events.len());
        event_at.push(decl.at);
        events.push(CheckedEvent {
            name: decl.name.value.clone(),
            controllable: decl.controllable.unwrap_or(false),
        });
    }

    // Transitions: V4, V5, V8, V11, V15, W3, W4.
    let mut transitions = Vec::new();
    let mut first_on: HashMap<(usize, usize), Position> = HashMap::new();
    let mut used_states = vec![false; states.len()];
    let mut used_events = vec![false; events.len()];
    let mut complete = true;
    for decl in &source.transitions {
        let event = event_index.get(decl.event.value.as_str()).copied();
        if event.is_none() {
            report(
                Code::V4,
                decl.event.at,
                format!(
                    "transition uses event `{}`, which is not declared in `<events>`",
                    decl.event.value
                ),
            );
        }
        let state =
            |name: &Located<String>, role: &str, report: &mut dyn FnMut(Code, Position, String)| {
                let found = state_index.get(name.value.as_str()).copied();
                if found.is_none() {
                    report(
                        Code::V5,
                        name.at,
                        format!(
                            "transition {role} `{}` is not declared in `<states>`",
                            name.value
                        ),
                    );
                }
                found
            };
        let src = state(&decl.src, "source", &mut report);
        let dst = state(&decl.dst, "target", &mut report);
        let controllable = event.map(|e| events[e].controllable);
        let weight = decl
            .prob
            .as_ref()
            .and_then(|p| match p.value.parse::<f64>() {
                Ok(w) if w.is_finite() && w >= 0.0 => Some(w),
                _ => {
                    report(
                        Code::V11,
                        p.at,
                        format!(
                            "`prob` is `{}`; expected a finite real number >= 0",
                            p.value
                        ),
                    );
                    None
                }
            });
        let time = decl
            .time
            .as_ref()
            .and_then(|t| match t.value.parse::<u64>() {
                Ok(n) if n > limits::MAX_TIME => {
                    report(
                        Code::V15,
                        t.at,
                        format!(
                            "`time` is {n} ticks; a compiled supervisor stores at most {}",
                            limits::MAX_TIME
                        ),
                    );
                    None
                }
                Ok(n) => u16::try_from(n).ok(),
                Err(_) => {
                    report(
                        Code::V11,
                        t.at,
                        format!(
                            "`time` is `{}`; expected an integer number of ticks >= 0",
                            t.value
                        ),
                    );
                    None
                }
            });
        if controllable == Some(false) {
            for (key, attr) in [("prob", &decl.prob), ("time", &decl.time)] {
                let Some(attr) = attr else { continue };
                report(
                    Code::W3,
                    attr.at,
                    format!(
                        "`{key}` on a transition of uncontrollable event `{}` is ignored",
                        decl.event.value
                    ),
                );
            }
        } else if controllable == Some(true)
            && kind == Some(ModelKind::Plant)
            && !weights_count
            && let Some(p) = &decl.prob
        {
            report(
                Code::W4,
                p.at,
                "`prob` in a plant model is ignored (probabilities belong in specifications)"
                    .into(),
            );
        }
        if let Some(s) = src {
            used_states[s] = true;
        }
        if let Some(d) = dst {
            used_states[d] = true;
        }
        if let Some(e) = event {
            used_events[e] = true;
        }
        let (Some(src), Some(dst), Some(event)) = (src, dst, event) else {
            complete = false;
            continue;
        };
        if let Some(first) = first_on.get(&(src, event)) {
            report(
                Code::V8,
                decl.at,
                format!(
                    "state `{}` has two transitions on event `{}` (first at line {})",
                    states[src].name, events[event].name, first.line
                ),
            );
            continue;
        }
        first_on.insert((src, event), decl.at);
        let is_controllable = events[event].controllable;
        transitions.push(CheckedTransition {
            src,
            dst,
            event,
            weight: weight.filter(|_| is_controllable && weights_count),
            time: if is_controllable {
                time.unwrap_or(0)
            } else {
                0
            },
        });
    }

    // V6, V7. A supervisor's alphabet is meaningful even for events it never enables (they stay disabled at
    // runtime), so tool output is exempt.
    let is_supervisor = kind == Some(ModelKind::Supervisor);
    for (s, used) in used_states.iter().enumerate() {
        if !used && !is_supervisor {
            report(
                Code::V6,
                state_at[s],
                format!("state `{}` is used by no transition", states[s].name),
            );
        }
    }
    for (e, used) in used_events.iter().enumerate() {
        if !used && !is_supervisor {
            report(
                Code::V7,
                event_at[e],
                format!("event `{}` is used by no transition", events[e].name),
            );
        }
    }

    // V12 and V15 per state.
    let mut outgoing = vec![0usize; states.len()];
    let mut controllable_out = vec![(0usize, false); states.len()];
    for t in &transitions {
        outgoing[t.src] += 1;
        if events[t.event].controllable {
            let entry = &mut controllable_out[t.src];
            entry.0 += 1;
            entry.1 |= t.weight.unwrap_or(1.0) > 0.0;
        }
    }
    for (s, &(count, positive)) in controllable_out.iter().enumerate() {
        if weights_count && count > 0 && !positive {
            report(
                Code::V12,
                state_at[s],
                format!(
                    "all {count} outgoing controllable transitions of state `{}` have weight 0",
                    states[s].name
                ),
            );
        }
        if outgoing[s] > limits::MAX_TRANSITIONS_PER_STATE {
            report(
                Code::V15,
                state_at[s],
                format!(
                    "state `{}` has {} outgoing transitions; a compiled supervisor allows at most {}",
                    states[s].name,
                    outgoing[s],
                    limits::MAX_TRANSITIONS_PER_STATE
                ),
            );
        }
    }

    // W2: reachability from the single initial state; unused states already have V6.
    if let Some(initial) = states.iter().position(|s| s.initial) {
        let reached = reachable(initial, states.len(), &transitions);
        for (s, reached) in reached.iter().enumerate() {
            if !reached && used_states[s] {
                report(
                    Code::W2,
                    state_at[s],
                    format!(
                        "state `{}` is unreachable from the initial state `{}`",
                        states[s].name, states[initial].name
                    ),
                );
            }
        }
    }

    let kind = kind?;
    complete.then(|| CheckedModel {
        file: source.file.clone(),
        name: source.name.value.clone(),
        kind,
        states,
        events,
        transitions,
    })
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
                    if distinct == limits::MAX_EVENTS + 1 {
                        out.push(Diagnostic::new(
                            Code::V15,
                            &source.file,
                            decl.at,
                            format!(
                                "event `{name}` is event number {distinct} of the project; compiled supervisors address at most {}",
                                limits::MAX_EVENTS
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
