//! Importer for Nadzoru2 FSA files (docs/ptsct.md section 13): `<model type="FSA"><data>` with states, events and
//! transitions referring to each other by numeric id.
//!
//! Ids are resolved to names here; `x`, `y`, `observable` and any other layout attributes are ignored. The format has
//! no model type, no probabilities and no times: the type is the role the file was passed with, and every transition
//! gets the defaults (P = 1, T = 0). The model name is the file stem.

use std::collections::HashMap;
use std::path::Path;

use crate::automaton::ModelKind;
use crate::diagnostics::{Code, Diagnostic, Position};
use crate::source::{EventDecl, Located, SourceFormat, SourceModel, StateDecl, TransitionDecl};
use crate::xml_read::Shape;
use crate::xml_tree::Element;

/// Interprets a `<model>` root as a Nadzoru2 FSA.
pub(crate) fn import(
    file: &str,
    root: &Element,
    role: Option<ModelKind>,
) -> Result<SourceModel, Vec<Diagnostic>> {
    let mut shape = Shape::new(file);
    match root.attr("type") {
        Some(t) if t.value == "FSA" => {}
        Some(t) => shape.x2(
            t.at,
            format!(
                "Nadzoru2 model type is `{}`; only `FSA` can be imported",
                t.value
            ),
        ),
        None => shape.x2(
            root.at,
            "`<model>` lacks the required attribute `type` (Nadzoru2 files say type=\"FSA\")"
                .into(),
        ),
    }
    let stem = Path::new(file)
        .file_stem()
        .map_or_else(|| file.to_owned(), |s| s.to_string_lossy().into_owned());
    let mut model = SourceModel {
        file: file.to_owned(),
        format: SourceFormat::Nadzoru,
        root: root.at,
        name: Located {
            value: stem,
            at: root.at,
        },
        kind: role.map(|r| Located {
            value: r.as_str().to_owned(),
            at: root.at,
        }),
        role,
        states: Vec::new(),
        events: Vec::new(),
        transitions: Vec::new(),
    };
    let mut states: HashMap<String, (String, Position)> = HashMap::new();
    let mut events: HashMap<String, (String, Position)> = HashMap::new();
    let mut transitions = Vec::new();
    let mut found_data = false;
    for data in &root.children {
        if data.name != "data" {
            shape.x2(
                data.at,
                format!(
                    "unexpected `<{}>` in a Nadzoru2 `<model>` (expected `<data>`)",
                    data.name
                ),
            );
            continue;
        }
        found_data = true;
        for item in &data.children {
            match item.name.as_str() {
                "state" => {
                    let initial = shape.flag(item, "initial").unwrap_or(false);
                    let marked = shape.flag(item, "marked").unwrap_or(false);
                    let (Some(id), Some(name)) =
                        (shape.required(item, "id"), shape.required(item, "name"))
                    else {
                        continue;
                    };
                    if declare(&mut shape, &mut states, &id, &name.value, "state") {
                        model.states.push(StateDecl {
                            at: item.at,
                            name,
                            initial,
                            marked,
                        });
                    }
                }
                "event" => {
                    let controllable = shape.flag(item, "controllable");
                    let (Some(id), Some(name)) =
                        (shape.required(item, "id"), shape.required(item, "name"))
                    else {
                        continue;
                    };
                    if declare(&mut shape, &mut events, &id, &name.value, "event") {
                        model.events.push(EventDecl {
                            at: item.at,
                            name,
                            controllable,
                        });
                    }
                }
                "transition" => transitions.push(item),
                other => shape.x2(
                    item.at,
                    format!(
                        "unexpected `<{other}>` in `<data>` (expected `<state>`, `<event>` or `<transition>`)"
                    ),
                ),
            }
        }
    }
    if !found_data {
        shape.x2(root.at, "Nadzoru2 `<model>` has no `<data>` element".into());
    }
    // Transitions are resolved after all declarations, so declarations may come in any order.
    for item in transitions {
        let src = resolve(&mut shape, &states, item, "source", Code::V5, "state");
        let dst = resolve(&mut shape, &states, item, "target", Code::V5, "state");
        let event = resolve(&mut shape, &events, item, "event", Code::V4, "event");
        if let (Some(src), Some(dst), Some(event)) = (src, dst, event) {
            model.transitions.push(TransitionDecl {
                at: item.at,
                src,
                dst,
                event,
                prob: None,
                time: None,
            });
        }
    }
    shape.finish(model)
}

/// Registers `id -> name`; reports a duplicate id (V9) and returns whether it was new.
fn declare(
    shape: &mut Shape<'_>,
    table: &mut HashMap<String, (String, Position)>,
    id: &Located<String>,
    name: &str,
    what: &str,
) -> bool {
    if let Some((_, first)) = table.get(&id.value) {
        let message = format!(
            "duplicate {what} id `{}` (first at line {})",
            id.value, first.line
        );
        shape.report(Code::V9, id.at, message);
        return false;
    }
    table.insert(id.value.clone(), (name.to_owned(), id.at));
    true
}

/// Resolves the id in attribute `key` of a transition to a name, reporting a missing attribute (X2) or an unknown id.
fn resolve(
    shape: &mut Shape<'_>,
    table: &HashMap<String, (String, Position)>,
    item: &Element,
    key: &str,
    unknown: Code,
    what: &str,
) -> Option<Located<String>> {
    let id = shape.required(item, key)?;
    match table.get(&id.value) {
        Some((name, _)) => Some(Located {
            value: name.clone(),
            at: id.at,
        }),
        None => {
            shape.report(
                unknown,
                id.at,
                format!(
                    "transition {key} refers to {what} id `{}`, which no {what} declares",
                    id.value
                ),
            );
            None
        }
    }
}
