//! Writer for the thesis XML format (docs/ptsct.md section 10.4): children in DTD order (states, events, transitions),
//! canonical `1`/`0` flags, explicit `prob` and `time` on every controllable transition and neither on uncontrollable
//! ones, except that a plant's `prob` is left out when it is 1, the default (a plant's weight is read only under
//! the thesis-literal rule, and is warned about otherwise). Probabilities are written with the shortest text that
//! reads back to the same `f64`, so reading a written file gives the same automaton.
//!
//! A synthesised supervisor can have millions of transitions (a gigabyte of XML), so the text is never held whole:
//! two threads format alternate blocks of states into buffers while the caller's thread writes them out in order.
//! At most a few buffers are alive at a time.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::{self, Write};
use std::ops::Range;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use quick_xml::escape::escape;

use crate::automaton::{Automaton, EventTable, ModelKind, StateId};

/// States formatted into one buffer.
const STATES_PER_BLOCK: usize = 4_096;

/// Threads formatting blocks.
const FORMATTERS: usize = 2;

/// Distinct probabilities whose text is remembered by each formatter.
const PROB_CACHE: usize = 4_096;

/// Renders `automaton` as a model file of its own kind (`type="supervisor"` for synthesis results).
pub fn to_xml(automaton: &Automaton, events: &EventTable) -> String {
    let mut out = Vec::new();
    write_xml(automaton, events, &mut out).expect("writing into memory cannot fail");
    String::from_utf8(out).expect("names and the markup are UTF-8")
}

/// Writes `automaton` as a model file to `out` as it goes. `out` should be buffered.
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
    write_blocks(automaton, out, |line, _, state| {
        line.bytes(b"    <state name=\"");
        line.name(automaton, state);
        line.bytes(if state == automaton.initial() {
            b"\" i=\"1\""
        } else {
            b"\" i=\"0\""
        });
        line.bytes(if automaton.is_marked(state) {
            b" m=\"1\"/>\n"
        } else {
            b" m=\"0\"/>\n"
        });
    })?;
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
    let plant = automaton.kind() == ModelKind::Plant;
    let event_attrs: Vec<String> = events
        .ids()
        .map(|e| format!("\" event=\"{}\"", escape(events.name(e))))
        .collect();
    write_blocks(automaton, out, |line, probs, state| {
        for t in automaton.transitions(state) {
            line.bytes(b"    <transition src=\"");
            line.name(automaton, state);
            line.bytes(b"\" dst=\"");
            line.name(automaton, t.target);
            line.bytes(event_attrs[t.event.index()].as_bytes());
            if events.is_controllable(t.event) {
                if !(plant && t.prob == 1.0) {
                    line.bytes(b" prob=\"");
                    line.bytes(probs.text(t.prob));
                    line.bytes(b"\"");
                }
                line.bytes(b" time=\"");
                line.number(t.lower_bound);
                line.bytes(b"\"");
            }
            line.bytes(b"/>\n");
        }
    })?;
    out.write_all(b"  </transitions>\n</automata>\n")
}

/// One formatter's output buffer.
struct Line(Vec<u8>);

impl Line {
    fn bytes(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
    }

    fn name(&mut self, automaton: &Automaton, state: StateId) {
        match escape(automaton.state_name(state)) {
            Cow::Borrowed(plain) => self.bytes(plain.as_bytes()),
            Cow::Owned(escaped) => self.bytes(escaped.as_bytes()),
        }
    }

    fn number(&mut self, n: u32) {
        let mut digits = [0u8; 10];
        let mut at = digits.len();
        let mut n = n;
        loop {
            at -= 1;
            digits[at] = b'0' + (n % 10) as u8;
            n /= 10;
            if n == 0 {
                break;
            }
        }
        self.bytes(&digits[at..]);
    }
}

/// The shortest text of each probability seen, remembered for the few distinct values a model has.
#[derive(Default)]
struct ProbTexts(HashMap<u64, Box<[u8]>>, String);

impl ProbTexts {
    fn text(&mut self, p: f64) -> &[u8] {
        if self.0.len() < PROB_CACHE {
            return self
                .0
                .entry(p.to_bits())
                .or_insert_with(|| p.to_string().into_bytes().into_boxed_slice());
        }
        if let Some(text) = self.0.get(&p.to_bits()) {
            return text;
        }
        self.1 = p.to_string();
        self.1.as_bytes()
    }
}

/// The writer's ends of one formatter's channels: blocks it filled, and buffers handed back for reuse.
struct Formatter {
    filled: Receiver<Vec<u8>>,
    spare: SyncSender<Vec<u8>>,
}

/// Formats every state of `automaton` with `line` into blocks on [`FORMATTERS`] threads and writes the blocks to
/// `out` in state order.
fn write_blocks<F>(automaton: &Automaton, out: &mut impl Write, line: F) -> io::Result<()>
where
    F: Fn(&mut Line, &mut ProbTexts, StateId) + Sync,
{
    let n = automaton.state_count();
    let blocks = n.div_ceil(STATES_PER_BLOCK);
    let block =
        |b: usize| -> Range<usize> { b * STATES_PER_BLOCK..((b + 1) * STATES_PER_BLOCK).min(n) };
    std::thread::scope(|scope| {
        let mut formatters = Vec::with_capacity(FORMATTERS);
        for worker in 0..FORMATTERS {
            let (full_tx, full_rx) = sync_channel::<Vec<u8>>(2);
            let (empty_tx, empty_rx) = sync_channel::<Vec<u8>>(4);
            let line = &line;
            scope.spawn(move || {
                let mut probs = ProbTexts::default();
                for b in (worker..blocks).step_by(FORMATTERS) {
                    let mut buf = Line(empty_rx.try_recv().unwrap_or_default());
                    buf.0.clear();
                    for x in block(b) {
                        line(&mut buf, &mut probs, StateId(x as u32));
                    }
                    if full_tx.send(buf.0).is_err() {
                        // The writer stopped on an error; it reports it.
                        return;
                    }
                }
            });
            formatters.push(Formatter {
                filled: full_rx,
                spare: empty_tx,
            });
        }
        for b in 0..blocks {
            let formatter = &formatters[b % FORMATTERS];
            let buf = formatter
                .filled
                .recv()
                .expect("a formatter sends each of its blocks");
            out.write_all(&buf)?;
            // A formatter that has finished no longer takes buffers back.
            let _ = formatter.spare.try_send(buf);
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plant_leaves_out_only_the_default_weight() {
        let mut events = EventTable::new();
        let a = events.intern("a", true).unwrap();
        let b = events.intern("b", true).unwrap();
        let mut plant = Automaton::new("g", ModelKind::Plant);
        let s = plant.add_state("s", true).unwrap();
        plant.add_transition(s, a, s, 1.0, 2).unwrap();
        plant.add_transition(s, b, s, 0.5, 0).unwrap();
        let text = to_xml(&plant, &events);
        assert!(text.contains(r#"event="a" time="2"/>"#), "{text}");
        assert!(
            text.contains(r#"event="b" prob="0.5" time="0"/>"#),
            "{text}"
        );
        plant.set_kind(ModelKind::Supervisor);
        let text = to_xml(&plant, &events);
        assert!(text.contains(r#"event="a" prob="1" time="2"/>"#), "{text}");
    }

    /// Several blocks per formatter: states and transitions come out in state order, each once.
    #[test]
    fn blocks_formatted_on_several_threads_are_written_in_state_order() {
        let mut events = EventTable::new();
        let next = events.intern("next", true).unwrap();
        let n = STATES_PER_BLOCK * (2 * FORMATTERS + 1) + 7;
        let mut chain = Automaton::new("chain", ModelKind::Supervisor);
        let states: Vec<StateId> = (0..n)
            .map(|i| chain.add_state(format!("q{i}"), i == 0).unwrap())
            .collect();
        for w in states.windows(2) {
            chain.add_transition(w[0], next, w[1], 1.0, 0).unwrap();
        }
        let text = to_xml(&chain, &events);
        let names: Vec<&str> = text
            .lines()
            .filter_map(|l| l.trim().strip_prefix("<state name=\"q"))
            .map(|l| &l[..l.find('"').unwrap()])
            .collect();
        let expected: Vec<String> = (0..n).map(|i| i.to_string()).collect();
        assert_eq!(names, expected);
        let sources: Vec<&str> = text
            .lines()
            .filter_map(|l| l.trim().strip_prefix("<transition src=\"q"))
            .map(|l| &l[..l.find('"').unwrap()])
            .collect();
        assert_eq!(sources, expected[..n - 1]);
        assert!(text.ends_with("  </transitions>\n</automata>\n"));
    }
}
