//! Writer for the thesis XML format (docs/ptsct.md section 10.4): children in DTD order (states, events, transitions),
//! canonical `1`/`0` flags, explicit `prob` and `time` on every controllable transition and neither on uncontrollable
//! ones. Probabilities are written with the shortest text that reads back to the same `f64`, so reading a written
//! file gives the same automaton.

use std::fmt::Write as _;

use quick_xml::escape::escape;

use crate::automaton::{Automaton, EventTable};

/// Renders `automaton` as a model file of its own kind (`type="supervisor"` for synthesis results).
pub fn to_xml(automaton: &Automaton, events: &EventTable) -> String {
    let mut out = String::new();
    let flag = |b: bool| if b { "1" } else { "0" };
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    out.push_str("<!DOCTYPE automata SYSTEM \"automata.dtd\">\n");
    // Writing into a String cannot fail.
    let _ = writeln!(
        out,
        "<automata name=\"{}\" type=\"{}\">",
        escape(automaton.name()),
        automaton.kind()
    );
    out.push_str("  <states>\n");
    for state in automaton.states() {
        let _ = writeln!(
            out,
            "    <state name=\"{}\" i=\"{}\" m=\"{}\"/>",
            escape(automaton.state_name(state)),
            flag(state == automaton.initial()),
            flag(automaton.is_marked(state))
        );
    }
    out.push_str("  </states>\n  <events>\n");
    for &event in automaton.alphabet() {
        let _ = writeln!(
            out,
            "    <event name=\"{}\" con=\"{}\"/>",
            escape(events.name(event)),
            flag(events.is_controllable(event))
        );
    }
    out.push_str("  </events>\n  <transitions>\n");
    for state in automaton.states() {
        for t in automaton.transitions(state) {
            let _ = write!(
                out,
                "    <transition src=\"{}\" dst=\"{}\" event=\"{}\"",
                escape(automaton.state_name(state)),
                escape(automaton.state_name(t.target)),
                escape(events.name(t.event))
            );
            if events.is_controllable(t.event) {
                let _ = write!(out, " prob=\"{}\" time=\"{}\"", t.prob, t.lower_bound);
            }
            out.push_str("/>\n");
        }
    }
    out.push_str("  </transitions>\n</automata>\n");
    out
}
