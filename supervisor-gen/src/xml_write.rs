//! Writer for the thesis XML format (docs/ptsct.md section 10.4): children in DTD order (states, events, transitions),
//! canonical `1`/`0` flags, explicit `prob` and `time` on every controllable transition and neither on uncontrollable
//! ones. Probabilities are written with the shortest text that reads back to the same `f64`, so reading a written
//! file gives the same automaton.

use std::io::{self, Write};

use quick_xml::escape::escape;

use crate::automaton::{Automaton, EventTable};

/// Renders `automaton` as a model file of its own kind (`type="supervisor"` for synthesis results).
pub fn to_xml(automaton: &Automaton, events: &EventTable) -> String {
    let mut out = Vec::new();
    write_xml(automaton, events, &mut out).expect("writing into memory cannot fail");
    String::from_utf8(out).expect("names and the markup are UTF-8")
}

/// Writes `automaton` as a model file to `out` as it goes, so a supervisor of millions of transitions never has
/// its whole text in memory. `out` should be buffered.
pub fn write_xml(
    automaton: &Automaton,
    events: &EventTable,
    out: &mut impl Write,
) -> io::Result<()> {
    let flag = |b: bool| if b { "1" } else { "0" };
    out.write_all(b"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n")?;
    out.write_all(b"<!DOCTYPE automata SYSTEM \"automata.dtd\">\n")?;
    writeln!(
        out,
        "<automata name=\"{}\" type=\"{}\">",
        escape(automaton.name()),
        automaton.kind()
    )?;
    out.write_all(b"  <states>\n")?;
    for state in automaton.states() {
        writeln!(
            out,
            "    <state name=\"{}\" i=\"{}\" m=\"{}\"/>",
            escape(automaton.state_name(state)),
            flag(state == automaton.initial()),
            flag(automaton.is_marked(state))
        )?;
    }
    out.write_all(b"  </states>\n  <events>\n")?;
    for &event in automaton.alphabet() {
        writeln!(
            out,
            "    <event name=\"{}\" con=\"{}\"/>",
            escape(events.name(event)),
            flag(events.is_controllable(event))
        )?;
    }
    out.write_all(b"  </events>\n  <transitions>\n")?;
    for state in automaton.states() {
        let src = escape(automaton.state_name(state));
        for t in automaton.transitions(state) {
            write!(
                out,
                "    <transition src=\"{src}\" dst=\"{}\" event=\"{}\"",
                escape(automaton.state_name(t.target)),
                escape(events.name(t.event))
            )?;
            if events.is_controllable(t.event) {
                write!(out, " prob=\"{}\" time=\"{}\"", t.prob, t.lower_bound)?;
            }
            out.write_all(b"/>\n")?;
        }
    }
    out.write_all(b"  </transitions>\n</automata>\n")
}
