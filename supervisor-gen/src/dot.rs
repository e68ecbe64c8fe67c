//! Graphviz drawings of models, products and supervisors with the conventions of docs/ptsct.md section 1: controllable
//! arcs single black lines, uncontrollable arcs red double lines, marked states double circles, an entry arrow on the
//! initial state, bad states filled red and otherwise removed states outlined in dashed red. Controllable labels show
//! P (when not 1) and T (when not 0) on the same line as their event, `a [P=0.8 T=2]`, so that when Graphviz stacks
//! the labels of several self-loops every probability stays next to the event it belongs to. Every drawing carries
//! a small legend of these conventions.
//!
//! DOT text is always produced. SVG and PNG are rendered only when the `dot` program is on PATH; its absence is
//! logged once and is not an error.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use crate::automaton::{Automaton, EventTable, StateId, Transition};

/// Why a state is drawn in red.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateMark {
    /// Removed by SupC as bad (section 6.3): filled red.
    Bad,
    /// Removed as inaccessible or non-coaccessible: dashed red outline.
    Removed,
}

/// How the probabilities on controllable arcs are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbLabels {
    /// As stored (supervisors: already normalised as the runtime uses them).
    Stored,
    /// Normalised per state over its controllable transitions (input models, whose weights are raw).
    PerState,
}

/// Renders `automaton` as a DOT digraph. `marks` colours removed states; `probs` picks the P shown.
pub fn to_dot(
    automaton: &Automaton,
    events: &EventTable,
    marks: &HashMap<StateId, StateMark>,
    probs: ProbLabels,
) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = writeln!(out, "digraph \"{}\" {{", quote(automaton.name()));
    out.push_str("  rankdir=LR;\n  fontname=\"Helvetica\";\n  node [shape=circle, fontname=\"Helvetica\"];\n");
    out.push_str("  edge [fontname=\"Helvetica\", fontsize=10];\n");
    let _ = writeln!(
        out,
        "  label=\"{} ({})\"; labelloc=t;",
        quote(automaton.name()),
        automaton.kind()
    );
    if automaton.state_count() > 0 {
        out.push_str("  __start [shape=point, width=0.08, label=\"\"];\n");
    }
    for state in automaton.states() {
        let mut attrs = vec![format!("label=\"{}\"", quote(automaton.state_name(state)))];
        if automaton.is_marked(state) {
            attrs.push("shape=doublecircle".into());
        }
        match marks.get(&state) {
            Some(StateMark::Bad) => attrs.push(
                "style=filled, fillcolor=\"#ff9999\", color=red, fontcolor=\"#990000\"".into(),
            ),
            Some(StateMark::Removed) => attrs.push("style=dashed, color=red, fontcolor=red".into()),
            None => {}
        }
        let _ = writeln!(out, "  s{} [{}];", state.0, attrs.join(", "));
    }
    if automaton.state_count() > 0 {
        let _ = writeln!(out, "  __start -> s{};", automaton.initial().0);
    }
    for state in automaton.states() {
        let transitions = automaton.transitions(state);
        let weight_sum: f64 = transitions
            .iter()
            .filter(|t| events.is_controllable(t.event))
            .map(|t| t.prob)
            .sum();
        for t in transitions {
            let _ = writeln!(
                out,
                "  s{} -> s{} [{}];",
                state.0,
                t.target.0,
                edge_attrs(t, events, probs, weight_sum)
            );
        }
    }
    out.push_str(LEGEND);
    out.push_str("}\n");
    out
}

/// The legend drawn in a corner of every drawing: what colours, lines, shapes, P and T mean.
const LEGEND: &str = concat!(
    "  subgraph cluster_legend {\n",
    "    label=\"legend\"; fontsize=10; style=dashed; color=gray;\n",
    "    node [shape=plaintext, fontsize=9, width=0, height=0, margin=0.02];\n",
    "    __legend [label=<<table border=\"0\" cellspacing=\"1\">",
    "<tr><td align=\"left\">black arc: controllable event</td></tr>",
    "<tr><td align=\"left\"><font color=\"red\">red double arc: uncontrollable event</font></td></tr>",
    "<tr><td align=\"left\">double circle: marked state</td></tr>",
    "<tr><td align=\"left\">e [P=p]: probability of e among the state's enabled controllable events</td></tr>",
    "<tr><td align=\"left\">e [T=n]: lower time bound: e only after n ticks (docs/ptsct.md)</td></tr>",
    "<tr><td align=\"left\"><font color=\"red\">red fill: bad state; dashed red: removed state</font></td></tr>",
    "</table>>];\n",
    "  }\n",
);

/// Label and style of one arc.
fn edge_attrs(t: &Transition, events: &EventTable, probs: ProbLabels, weight_sum: f64) -> String {
    let name = quote(events.name(t.event));
    if !events.is_controllable(t.event) {
        return format!("label=\"{name}\", color=\"red:invis:red\", fontcolor=red");
    }
    let p = match probs {
        ProbLabels::Stored => t.prob,
        ProbLabels::PerState if weight_sum > 0.0 => t.prob / weight_sum,
        ProbLabels::PerState => 0.0,
    };
    let mut label = name;
    let mut extras = Vec::new();
    if (p - 1.0).abs() > 1e-12 {
        extras.push(format!("P={}", round4(p)));
    }
    if t.lower_bound > 0 {
        extras.push(format!("T={}", t.lower_bound));
    }
    if !extras.is_empty() {
        let _ = write!(label, " [{}]", extras.join(" "));
    }
    format!("label=\"{label}\"")
}

/// A probability rounded to 4 decimals for display.
fn round4(p: f64) -> f64 {
    (p * 10_000.0).round() / 10_000.0
}

/// Escapes a string for a double-quoted DOT id or label.
fn quote(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

/// A file-system friendly form of a model name (anything but letters, digits, `-`, `_`, `.` becomes `_`).
pub fn file_stem(name: &str) -> String {
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if stem.is_empty() { "_".into() } else { stem }
}

/// Whether the Graphviz `dot` program can be run; checked once per process, with one warning if it cannot.
pub fn graphviz_available() -> bool {
    static AVAILABLE: OnceLock<bool> = OnceLock::new();
    *AVAILABLE.get_or_init(|| {
        let found = Command::new("dot")
            .arg("-V")
            .output()
            .is_ok_and(|o| o.status.success());
        if !found {
            tracing::warn!("Graphviz `dot` is not on PATH: writing DOT files only (no SVG or PNG)");
        }
        found
    })
}

/// An image format Graphviz renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Scalable vector graphics.
    Svg,
    /// Portable network graphics (resolution set by [`Images::dpi`]).
    Png,
    /// Portable document format.
    Pdf,
}

impl ImageFormat {
    /// The Graphviz `-T` name, also used as the file extension.
    pub fn as_str(self) -> &'static str {
        match self {
            ImageFormat::Svg => "svg",
            ImageFormat::Png => "png",
            ImageFormat::Pdf => "pdf",
        }
    }
}

/// Which images to render next to each DOT file (when Graphviz is available).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Images {
    /// Formats to render; empty for DOT only.
    pub formats: Vec<ImageFormat>,
    /// Resolution of raster images in dots per inch; Graphviz' default (96) when `None`.
    pub dpi: Option<u32>,
}

impl Default for Images {
    /// SVG and PNG at Graphviz' default resolution.
    fn default() -> Self {
        Images {
            formats: vec![ImageFormat::Svg, ImageFormat::Png],
            dpi: None,
        }
    }
}

/// Largest automaton drawn at all (in states): a DOT file of more states is too large to read or lay out.
pub const MAX_DOT_STATES: usize = 50_000;
/// Largest automaton Graphviz is asked to render (in states): its layout of a few thousand states already takes
/// minutes, of a million hours; above this only the DOT file is written.
pub const MAX_IMAGE_STATES: usize = 2_000;

/// Writes `dot` to `dir/<stem>.dot` and, when Graphviz is available, renders the requested images next to it.
/// Returns every file written.
pub fn write_drawing(
    dir: &Path,
    stem: &str,
    dot: &str,
    images: &Images,
) -> io::Result<Vec<PathBuf>> {
    let dot_path = dir.join(format!("{stem}.dot"));
    if let Some(parent) = dot_path.parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(&dot_path, dot)?;
    let mut written = vec![dot_path.clone()];
    if images.formats.is_empty() || !graphviz_available() {
        return Ok(written);
    }
    for format in &images.formats {
        let image = dir.join(format!("{stem}.{}", format.as_str()));
        let mut command = Command::new("dot");
        command.arg(format!("-T{}", format.as_str()));
        if let Some(dpi) = images.dpi {
            command.arg(format!("-Gdpi={dpi}"));
        }
        let output = command.arg("-o").arg(&image).arg(&dot_path).output()?;
        if !output.status.success() {
            return Err(io::Error::other(format!(
                "dot failed on {}: {}",
                dot_path.display(),
                String::from_utf8_lossy(&output.stderr).trim()
            )));
        }
        written.push(image);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automaton::ModelKind;

    /// The generator of section 9: q0 (initial, marked) -a(0.8, T 2)-> q1, q0 -b(0.2)-> q2, q1 -a-> q1,
    /// q1 -u-> q0, q2 -b(1)-> q0, q2 -c(3)-> q1.
    fn example() -> (Automaton, EventTable) {
        let mut events = EventTable::new();
        let [a, b, c] = ["a", "b", "c"].map(|n| events.intern(n, true).unwrap());
        let u = events.intern("u", false).unwrap();
        let mut g = Automaton::new("example", ModelKind::Spec);
        let q0 = g.add_state("q0", true).unwrap();
        let q1 = g.add_state("q1", false).unwrap();
        let q2 = g.add_state("q2", false).unwrap();
        for (from, e, to, p, t) in [
            (q0, a, q1, 0.8, 2),
            (q0, b, q2, 0.2, 0),
            (q1, a, q1, 1.0, 0),
            (q1, u, q0, 1.0, 0),
            (q2, b, q0, 1.0, 0),
            (q2, c, q1, 3.0, 0),
        ] {
            g.add_transition(from, e, to, p, t).unwrap();
        }
        (g, events)
    }

    #[test]
    fn drawing_follows_the_section_1_conventions() {
        let (g, events) = example();
        let marks = HashMap::from([
            (StateId(2), StateMark::Bad),
            (StateId(1), StateMark::Removed),
        ]);
        let dot = to_dot(&g, &events, &marks, ProbLabels::Stored);
        assert!(
            dot.contains("s0 [label=\"q0\", shape=doublecircle];"),
            "marked state is a double circle"
        );
        assert!(
            dot.contains("__start -> s0;"),
            "initial state has an entry arrow"
        );
        assert!(
            dot.contains("s1 -> s0 [label=\"u\", color=\"red:invis:red\", fontcolor=red];"),
            "uncontrollable arcs are red double lines"
        );
        assert!(
            dot.contains("s0 -> s1 [label=\"a [P=0.8 T=2]\"];"),
            "controllable labels show P and T"
        );
        assert!(
            dot.contains("s1 -> s1 [label=\"a\"];"),
            "P = 1 and T = 0 are not shown"
        );
        assert!(
            dot.contains("s2 [label=\"q2\", style=filled, fillcolor=\"#ff9999\""),
            "bad states are red"
        );
        assert!(
            dot.contains("s1 [label=\"q1\", style=dashed, color=red"),
            "removed states are red"
        );
    }

    #[test]
    fn input_weights_are_shown_normalised_per_state() {
        let (g, events) = example();
        let dot = to_dot(&g, &events, &HashMap::new(), ProbLabels::PerState);
        assert!(dot.contains("s2 -> s0 [label=\"b [P=0.25]\"];"));
        assert!(dot.contains("s2 -> s1 [label=\"c [P=0.75]\"];"));
        assert!(dot.contains("cluster_legend"), "every drawing has a legend");
    }

    #[test]
    fn names_are_quoted_for_dot_and_files() {
        assert_eq!(quote(r#"a"b\c"#), r#"a\"b\\c"#);
        assert_eq!(file_stem("S_((a,b))/x"), "S___a_b___x");
    }
}
