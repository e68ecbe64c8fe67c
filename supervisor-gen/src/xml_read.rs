//! Reader for model files: the thesis XML format (docs/ptsct.md section 10) and, by its root element, Nadzoru2
//! FSA files (section 13, see `nadzoru`).
//!
//! The reader only checks the document shape (codes `X1`, `X2`): known elements and attributes, required
//! attributes, flag values. Children may come in any order. Every rule about the model itself is left to `validate`.

use crate::automaton::ModelKind;
use crate::diagnostics::{Code, Diagnostic, Position};
use crate::nadzoru;
use crate::source::{EventDecl, Located, SourceFormat, SourceModel, StateDecl, TransitionDecl};
use crate::xml_tree::{self, Element};

/// Reads one model file. `file` is the name used in diagnostics; `role` is how the user passed it (`--plant`,
/// `--spec`), if at all. Returns every shape problem of the file at once, or the first well-formedness error.
pub fn read_model(
    file: &str,
    text: &str,
    role: Option<ModelKind>,
) -> Result<SourceModel, Vec<Diagnostic>> {
    let root = xml_tree::parse(file, text).map_err(|d| vec![d])?;
    match root.name.as_str() {
        "automata" => read_thesis(file, &root, role),
        "model" => nadzoru::import(file, &root, role),
        other => Err(vec![Diagnostic::new(
            Code::X2,
            file,
            root.at,
            format!(
                "root element is `<{other}>`; expected `<automata>` (ptSCT model) or `<model type=\"FSA\">` (Nadzoru2)"
            ),
        )]),
    }
}

/// Collects shape problems of one file.
pub(crate) struct Shape<'a> {
    pub file: &'a str,
    pub problems: Vec<Diagnostic>,
}

impl<'a> Shape<'a> {
    /// A collector for `file`.
    pub fn new(file: &'a str) -> Self {
        Shape {
            file,
            problems: Vec::new(),
        }
    }

    /// Records a problem with code `code`.
    pub fn report(&mut self, code: Code, at: Position, message: String) {
        self.problems
            .push(Diagnostic::new(code, self.file, at, message));
    }

    /// Records an `X2` problem.
    pub fn x2(&mut self, at: Position, message: String) {
        self.report(Code::X2, at, message);
    }

    /// Reports every attribute of `element` not in `allowed`.
    pub fn only_attributes(&mut self, element: &Element, allowed: &[&str]) {
        for attr in &element.attrs {
            if !allowed.contains(&attr.key.as_str()) {
                let expected = allowed
                    .iter()
                    .map(|a| format!("`{a}`"))
                    .collect::<Vec<_>>()
                    .join(", ");
                self.x2(
                    attr.value.at,
                    format!(
                        "unknown attribute `{}` on `<{}>` (expected {expected})",
                        attr.key, element.name
                    ),
                );
            }
        }
    }

    /// The value of a required attribute, or a reported problem.
    pub fn required(&mut self, element: &Element, key: &str) -> Option<Located<String>> {
        let found = element.attr(key).cloned();
        if found.is_none() {
            self.x2(
                element.at,
                format!("`<{}>` lacks the required attribute `{key}`", element.name),
            );
        }
        found
    }

    /// A flag attribute (`1`, `0`, `true`, `false`, any case); `None` when absent or invalid (reported).
    pub fn flag(&mut self, element: &Element, key: &str) -> Option<bool> {
        let value = element.attr(key)?;
        match value.value.to_ascii_lowercase().as_str() {
            "1" | "true" => Some(true),
            "0" | "false" => Some(false),
            _ => {
                self.x2(
                    value.at,
                    format!(
                        "attribute `{key}` is `{}`; expected 1, 0, true or false",
                        value.value
                    ),
                );
                None
            }
        }
    }

    /// Reports non-whitespace text inside `element`.
    pub fn no_text(&mut self, element: &Element) {
        if let Some(text) = &element.text {
            self.x2(
                text.at,
                format!(
                    "unexpected text `{}` inside `<{}>`",
                    text.value.trim(),
                    element.name
                ),
            );
        }
    }

    /// The collected problems as the error of a read, or `ok` if there are none.
    pub fn finish<T>(self, ok: T) -> Result<T, Vec<Diagnostic>> {
        if self.problems.is_empty() {
            Ok(ok)
        } else {
            Err(self.problems)
        }
    }
}

/// Interprets an `<automata>` root.
fn read_thesis(
    file: &str,
    root: &Element,
    role: Option<ModelKind>,
) -> Result<SourceModel, Vec<Diagnostic>> {
    let mut shape = Shape::new(file);
    shape.only_attributes(root, &["name", "type"]);
    shape.no_text(root);
    let name = shape.required(root, "name");
    let mut model = SourceModel {
        file: file.to_owned(),
        format: SourceFormat::Thesis,
        root: root.at,
        name: name.unwrap_or(Located {
            value: String::new(),
            at: root.at,
        }),
        kind: root.attr("type").cloned(),
        role,
        states: Vec::new(),
        events: Vec::new(),
        transitions: Vec::new(),
    };
    let mut seen: Vec<(&str, Position)> = Vec::new();
    for section in &root.children {
        if let Some((_, first)) = seen.iter().find(|(n, _)| *n == section.name) {
            shape.x2(
                section.at,
                format!(
                    "second `<{}>` section (first at line {})",
                    section.name, first.line
                ),
            );
            continue;
        }
        seen.push((section.name.as_str(), section.at));
        shape.only_attributes(section, &[]);
        shape.no_text(section);
        let item = match section.name.as_str() {
            "states" => "state",
            "events" => "event",
            "transitions" => "transition",
            other => {
                shape.x2(
                    section.at,
                    format!(
                        "unknown element `<{other}>` in `<automata>` (expected `<states>`, `<events>` or `<transitions>`)"
                    ),
                );
                continue;
            }
        };
        for child in &section.children {
            if child.name != item {
                shape.x2(
                    child.at,
                    format!(
                        "unexpected `<{}>` in `<{}>` (expected `<{item}>`)",
                        child.name, section.name
                    ),
                );
                continue;
            }
            shape.no_text(child);
            match item {
                "state" => read_state(&mut shape, child, &mut model.states),
                "event" => read_event(&mut shape, child, &mut model.events),
                _ => read_transition(&mut shape, child, &mut model.transitions),
            }
            for grandchild in &child.children {
                shape.x2(
                    grandchild.at,
                    format!(
                        "`<{}>` must be empty, found `<{}>`",
                        child.name, grandchild.name
                    ),
                );
            }
        }
    }
    shape.finish(model)
}

fn read_state(shape: &mut Shape<'_>, element: &Element, out: &mut Vec<StateDecl>) {
    shape.only_attributes(element, &["name", "i", "m"]);
    let initial = shape.flag(element, "i").unwrap_or(false);
    let marked = shape.flag(element, "m").unwrap_or(false);
    if let Some(name) = shape.required(element, "name") {
        out.push(StateDecl {
            at: element.at,
            name,
            initial,
            marked,
        });
    }
}

fn read_event(shape: &mut Shape<'_>, element: &Element, out: &mut Vec<EventDecl>) {
    shape.only_attributes(element, &["name", "con"]);
    let controllable = shape.flag(element, "con");
    if let Some(name) = shape.required(element, "name") {
        out.push(EventDecl {
            at: element.at,
            name,
            controllable,
        });
    }
}

fn read_transition(shape: &mut Shape<'_>, element: &Element, out: &mut Vec<TransitionDecl>) {
    shape.only_attributes(element, &["src", "dst", "event", "prob", "time"]);
    let src = shape.required(element, "src");
    let dst = shape.required(element, "dst");
    let event = shape.required(element, "event");
    if let (Some(src), Some(dst), Some(event)) = (src, dst, event) {
        out.push(TransitionDecl {
            at: element.at,
            src,
            dst,
            event,
            prob: element.attr("prob").cloned(),
            time: element.attr("time").cloned(),
        });
    }
}
