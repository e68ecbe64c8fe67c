//! The compiled supervisor-set file: the byte layout of section 9 behind a small versioned header.
//!
//! File layout (all multi-byte integers big-endian):
//!
//! ```text
//! header   "PTSC"  version:u16  e:u16  N:u16
//!          e × [name_len:u16][name:utf8]                     event names, id = position
//!          N × [name_len:u16][name:utf8][states:u16]          supervisor names and state counts
//! payload  N × ( δ array, P array, T array )                  section 9, per supervisor
//!          controllable[e]:u8   member[e][N]:u8   current[N]:u16
//! ```
//!
//! The payload is exactly the thesis layout, so its length is MemCons (section 9). A supervisor's alphabet is the
//! column of the membership matrix; state 0 is the initial state, so every `current` entry is 0 in a file.
//!
//! Reading must treat the bytes as hostile: every malformed file gives a [`CompiledFormatError`] naming the byte
//! offset and the problem, never a panic and never an allocation larger than the input justifies.
//!
//! This module holds the types and the writer; `reader.rs` reads a file back, `errors.rs` says what can go wrong.

mod errors;
mod reader;

use std::io;
use std::path::Path;

use crate::automaton::{Automaton, EventTable, StateId};
pub use errors::{CodegenError, CompiledFormatError, FormatProblem};
use reader::Reader;

/// The four magic bytes that open every compiled supervisor-set file.
pub const MAGIC: [u8; 4] = *b"PTSC";
/// The format version written by [`SupervisorSet::to_bytes`] and the only one accepted by the reader.
pub const FORMAT_VERSION: u16 = 1;
/// At most this many events (1-byte event ids, section 9).
pub const MAX_EVENTS: usize = 256;
/// At most this many states per supervisor (2-byte state ids, section 9).
pub const MAX_STATES: usize = 65_535;
/// At most this many outgoing transitions per state (1-byte count, section 9).
pub const MAX_TRANSITIONS_PER_STATE: usize = 255;

/// A set of supervisors executed together by one robot's player.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SupervisorSet {
    /// The global event table; an event's id is its index.
    pub events: Vec<CompiledEvent>,
    /// The supervisors, in player order.
    pub supervisors: Vec<CompiledSupervisor>,
}

/// One entry of the global event table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledEvent {
    /// The event name, used by agents to bind callbacks.
    pub name: String,
    /// Whether the event is controllable.
    pub controllable: bool,
}

/// One compiled supervisor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledSupervisor {
    /// The supervisor name.
    pub name: String,
    /// Sorted global ids of the events this supervisor owns.
    pub alphabet: Vec<u8>,
    /// The states; state 0 is the initial state.
    pub states: Vec<CompiledState>,
}

/// The outgoing transitions of one state.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct CompiledState {
    /// Controllable transitions first, then uncontrollable ones, each group by ascending event id.
    pub transitions: Vec<CompiledTransition>,
}

/// One transition in compiled form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompiledTransition {
    /// Global event id.
    pub event: u8,
    /// Target state id.
    pub target: u16,
    /// Probability in unsigned Q0.16 (`round(p × 65535)`, A9); 0xFFFF for uncontrollable transitions.
    pub prob_q16: u16,
    /// Lower time bound in ticks; 0 for uncontrollable transitions.
    pub lower_bound: u16,
}

impl CompiledTransition {
    /// The probability as a real number in [0, 1].
    pub fn probability(&self) -> f64 {
        f64::from(self.prob_q16) / 65535.0
    }
}

impl CompiledSupervisor {
    /// Whether the supervisor owns `event` (it is in its alphabet).
    pub fn owns(&self, event: u8) -> bool {
        self.alphabet.binary_search(&event).is_ok()
    }

    /// Total number of transitions.
    pub fn transition_count(&self) -> usize {
        self.states.iter().map(|s| s.transitions.len()).sum()
    }
}

/// Encodes a probability in unsigned Q0.16 (A9). `p` must be in [0, 1].
pub fn prob_to_q16(p: f64) -> u16 {
    (p.clamp(0.0, 1.0) * 65535.0).round() as u16
}

impl SupervisorSet {
    /// Compiles synthesised supervisors over a project's event table, enforcing the limits of V15.
    ///
    /// The initial state of each automaton becomes state 0; the other states keep their relative order.
    pub fn from_supervisors<'a>(
        events: &EventTable,
        sups: impl IntoIterator<Item = &'a Automaton>,
    ) -> Result<Self, CodegenError> {
        let sups: Vec<&Automaton> = sups.into_iter().collect();
        if events.len() > MAX_EVENTS {
            return Err(CodegenError::TooManyEvents {
                count: events.len(),
            });
        }
        if sups.len() > usize::from(u16::MAX) {
            return Err(CodegenError::TooManySupervisors { count: sups.len() });
        }
        let compiled_events = events
            .ids()
            .map(|id| {
                check_name(events.name(id))?;
                Ok(CompiledEvent {
                    name: events.name(id).to_owned(),
                    controllable: events.is_controllable(id),
                })
            })
            .collect::<Result<Vec<_>, CodegenError>>()?;
        let supervisors = sups
            .iter()
            .map(|&a| compile_supervisor(events, a))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            events: compiled_events,
            supervisors,
        })
    }

    /// MemCons of section 9: `(s + 3t) + 2(s + 2·t_c) + e + (e + 2)·N` bytes, which is the payload length.
    pub fn mem_cons(&self) -> usize {
        let e = self.events.len();
        let n = self.supervisors.len();
        let (mut s, mut t, mut tc) = (0, 0, 0);
        for sup in &self.supervisors {
            s += sup.states.len();
            for st in &sup.states {
                t += st.transitions.len();
                tc += st
                    .transitions
                    .iter()
                    .filter(|tr| self.is_controllable(tr.event))
                    .count();
            }
        }
        (s + 3 * t) + 2 * (s + 2 * tc) + e + (e + 2) * n
    }

    fn is_controllable(&self, event: u8) -> bool {
        self.events
            .get(usize::from(event))
            .is_some_and(|e| e.controllable)
    }

    /// Serialises the set: header, then the section 9 payload.
    ///
    /// The set must respect the layout limits (as every set from [`Self::from_supervisors`] or
    /// [`Self::from_bytes`] does); counts and lengths beyond them are truncated to their field widths.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.header_len() + self.mem_cons());
        out.extend_from_slice(&MAGIC);
        put_u16(&mut out, FORMAT_VERSION);
        put_u16(&mut out, self.events.len() as u16);
        put_u16(&mut out, self.supervisors.len() as u16);
        for ev in &self.events {
            put_name(&mut out, &ev.name);
        }
        for sup in &self.supervisors {
            put_name(&mut out, &sup.name);
            put_u16(&mut out, sup.states.len() as u16);
        }
        for sup in &self.supervisors {
            for st in &sup.states {
                out.push(st.transitions.len() as u8);
                for tr in &st.transitions {
                    out.push(tr.event);
                    put_u16(&mut out, tr.target);
                }
            }
            self.put_controllable_block(&mut out, sup, |tr| tr.prob_q16);
            self.put_controllable_block(&mut out, sup, |tr| tr.lower_bound);
        }
        out.extend(self.events.iter().map(|e| u8::from(e.controllable)));
        for ev in 0..self.events.len() {
            out.extend(self.supervisors.iter().map(|s| u8::from(s.owns(ev as u8))));
        }
        for _ in &self.supervisors {
            put_u16(&mut out, 0);
        }
        out
    }

    fn put_controllable_block(
        &self,
        out: &mut Vec<u8>,
        sup: &CompiledSupervisor,
        value: impl Fn(&CompiledTransition) -> u16,
    ) {
        for st in &sup.states {
            let ctrl = st
                .transitions
                .iter()
                .filter(|t| self.is_controllable(t.event));
            out.push(ctrl.clone().count() as u8);
            for tr in ctrl {
                put_u16(out, value(tr));
            }
        }
    }

    fn header_len(&self) -> usize {
        10 + self.events.iter().map(|e| 2 + e.name.len()).sum::<usize>()
            + self
                .supervisors
                .iter()
                .map(|s| 4 + s.name.len())
                .sum::<usize>()
    }

    /// Parses and validates a compiled set. Any malformed input gives a typed error, never a panic.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, CompiledFormatError> {
        Reader::new(bytes)
            .parse()
            .map_err(|(offset, problem)| CompiledFormatError::Malformed {
                path: None,
                offset,
                problem,
            })
    }

    /// Reads and validates a compiled set from a file; errors name the file.
    pub fn read(path: &Path) -> Result<Self, CompiledFormatError> {
        let bytes = crate::load::read_limited(path).map_err(|source| CompiledFormatError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_bytes(&bytes).map_err(|e| match e {
            CompiledFormatError::Malformed {
                offset, problem, ..
            } => CompiledFormatError::Malformed {
                path: Some(path.to_owned()),
                offset,
                problem,
            },
            other => other,
        })
    }

    /// Writes [`Self::to_bytes`] to a file.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        std::fs::write(path, self.to_bytes())
    }
}

/// MemCons (section 9) of automata that would be compiled over `events`, without compiling them.
pub fn mem_cons_of(events: &EventTable, sups: &[&Automaton]) -> usize {
    let (e, n) = (events.len(), sups.len());
    let (mut s, mut t, mut tc) = (0, 0, 0);
    for a in sups {
        s += a.state_count();
        for x in a.states() {
            let trs = a.transitions(x);
            t += trs.len();
            tc += trs
                .iter()
                .filter(|tr| events.is_controllable(tr.event))
                .count();
        }
    }
    (s + 3 * t) + 2 * (s + 2 * tc) + e + (e + 2) * n
}

fn check_name(name: &str) -> Result<(), CodegenError> {
    if name.len() > usize::from(u16::MAX) {
        return Err(CodegenError::NameTooLong {
            prefix: name.chars().take(32).collect(),
            len: name.len(),
        });
    }
    Ok(())
}

fn compile_supervisor(
    events: &EventTable,
    a: &Automaton,
) -> Result<CompiledSupervisor, CodegenError> {
    check_name(a.name())?;
    let n = a.state_count();
    if n == 0 {
        return Err(CodegenError::NoStates {
            supervisor: a.name().to_owned(),
        });
    }
    if n > MAX_STATES {
        return Err(CodegenError::TooManyStates {
            supervisor: a.name().to_owned(),
            count: n,
        });
    }
    // New numbering: the initial state first, the others in their original order.
    let init = a.initial().index();
    let order: Vec<usize> = std::iter::once(init)
        .chain((0..n).filter(|&i| i != init))
        .collect();
    let mut new_id = vec![0u16; n];
    for (new, &old) in order.iter().enumerate() {
        new_id[old] = new as u16;
    }
    let alphabet = a
        .alphabet()
        .iter()
        .map(|e| {
            u8::try_from(e.0)
                .ok()
                .filter(|_| e.index() < events.len())
                .ok_or_else(|| CodegenError::UnknownEvent {
                    supervisor: a.name().to_owned(),
                    event: e.0,
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut states = Vec::with_capacity(n);
    for &old in &order {
        let sid = StateId(old as u32);
        let trs = a.transitions(sid);
        if trs.len() > MAX_TRANSITIONS_PER_STATE {
            return Err(CodegenError::TooManyTransitions {
                supervisor: a.name().to_owned(),
                state: a.state_name(sid).to_owned(),
                count: trs.len(),
            });
        }
        let mut transitions = Vec::with_capacity(trs.len());
        for tr in trs {
            let event = u8::try_from(tr.event.0)
                .ok()
                .filter(|_| tr.event.index() < events.len())
                .ok_or_else(|| CodegenError::UnknownEvent {
                    supervisor: a.name().to_owned(),
                    event: tr.event.0,
                })?;
            let ctrl = events.is_controllable(tr.event);
            let located = || {
                (
                    a.name().to_owned(),
                    a.state_name(sid).to_owned(),
                    events.name(tr.event).to_owned(),
                )
            };
            let (prob_q16, lower_bound) = if ctrl {
                if !(0.0..=1.0).contains(&tr.prob) {
                    let (supervisor, state, event) = located();
                    return Err(CodegenError::ProbabilityOutOfRange {
                        supervisor,
                        state,
                        event,
                        prob: tr.prob,
                    });
                }
                let lb = u16::try_from(tr.lower_bound).map_err(|_| {
                    let (supervisor, state, event) = located();
                    CodegenError::LowerBoundTooLarge {
                        supervisor,
                        state,
                        event,
                        bound: tr.lower_bound,
                    }
                })?;
                (prob_to_q16(tr.prob), lb)
            } else {
                (u16::MAX, 0)
            };
            // Automaton builders only accept existing targets, so the lookup always succeeds.
            let target = new_id.get(tr.target.index()).copied().unwrap_or(0);
            transitions.push((
                !ctrl,
                CompiledTransition {
                    event,
                    target,
                    prob_q16,
                    lower_bound,
                },
            ));
        }
        transitions.sort_by_key(|(unctrl, t)| (*unctrl, t.event));
        states.push(CompiledState {
            transitions: transitions.into_iter().map(|(_, t)| t).collect(),
        });
    }
    Ok(CompiledSupervisor {
        name: a.name().to_owned(),
        alphabet,
        states,
    })
}

fn put_u16(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_be_bytes());
}

fn put_name(out: &mut Vec<u8>, name: &str) {
    let len = name.len().min(usize::from(u16::MAX));
    put_u16(out, len as u16);
    out.extend_from_slice(&name.as_bytes()[..len]);
}

#[cfg(test)]
mod tests;
