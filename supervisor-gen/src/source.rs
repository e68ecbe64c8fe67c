//! Located, not yet validated model declarations: what a model file says, with the position of every element and
//! attribute, before any rule of docs/ptsct.md section 11 is applied.
//!
//! Both readers (the thesis format in `xml_read` and the Nadzoru2 importer in `nadzoru`) produce a [`SourceModel`];
//! `validate` checks it and turns it into typed models. Nothing here interprets weights, times or reachability.

use crate::automaton::ModelKind;
use crate::diagnostics::Position;

/// A value together with where it was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Located<T> {
    /// The value as read.
    pub value: T,
    /// Where it starts (the attribute name for attributes, the `<` for elements).
    pub at: Position,
}

/// Parses the `automata/@type` value: `plant`, `spec`, `supervisor` and the long forms `free-behaviour` and
/// `specification`.
pub fn parse_kind(value: &str) -> Option<ModelKind> {
    match value {
        "plant" | "free-behaviour" => Some(ModelKind::Plant),
        "spec" | "specification" => Some(ModelKind::Spec),
        "supervisor" => Some(ModelKind::Supervisor),
        _ => None,
    }
}

/// Which file format a model was read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceFormat {
    /// The thesis format of docs/ptsct.md section 10 (`<automata>`).
    Thesis,
    /// A Nadzoru2 FSA file (docs/ptsct.md section 13), whose type comes from how it was passed.
    Nadzoru,
}

/// One declared state.
#[derive(Debug, Clone, PartialEq)]
pub struct StateDecl {
    /// The `<state>` element.
    pub at: Position,
    /// `state/@name`.
    pub name: Located<String>,
    /// `state/@i` (default false).
    pub initial: bool,
    /// `state/@m` (default false).
    pub marked: bool,
}

/// One declared event.
#[derive(Debug, Clone, PartialEq)]
pub struct EventDecl {
    /// The `<event>` element.
    pub at: Position,
    /// `event/@name`.
    pub name: Located<String>,
    /// `event/@con`; `None` when omitted (uncontrollable, warning W1).
    pub controllable: Option<bool>,
}

/// One declared transition, with `prob` and `time` still as written (validated later, V11).
#[derive(Debug, Clone, PartialEq)]
pub struct TransitionDecl {
    /// The `<transition>` element.
    pub at: Position,
    /// `transition/@src`.
    pub src: Located<String>,
    /// `transition/@dst`.
    pub dst: Located<String>,
    /// `transition/@event`.
    pub event: Located<String>,
    /// `transition/@prob`, if present.
    pub prob: Option<Located<String>>,
    /// `transition/@time`, if present.
    pub time: Option<Located<String>>,
}

/// Everything one model file declares, with positions.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceModel {
    /// The file as the user named it (used in every diagnostic).
    pub file: String,
    /// The format it was read from.
    pub format: SourceFormat,
    /// The root element.
    pub root: Position,
    /// The model name (`automata/@name`; the file stem for Nadzoru2 files).
    pub name: Located<String>,
    /// The raw `automata/@type`; for Nadzoru2 files the role it was passed with, if any.
    pub kind: Option<Located<String>>,
    /// The role the user gave the file on the command line (`--plant`, `--spec`), if any.
    pub role: Option<ModelKind>,
    /// Declared states, in file order.
    pub states: Vec<StateDecl>,
    /// Declared events, in file order.
    pub events: Vec<EventDecl>,
    /// Declared transitions, in file order.
    pub transitions: Vec<TransitionDecl>,
}
