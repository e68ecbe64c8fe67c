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

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

use crate::automaton::{Automaton, EventTable, StateId};

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

/// Errors while turning synthesised supervisors into a [`SupervisorSet`] (validation V15 and encodability).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CodegenError {
    /// More than 256 events in the project (V15).
    #[error(
        "the project has {count} events; the compiled format supports at most {MAX_EVENTS} (1-byte event ids)"
    )]
    TooManyEvents {
        /// Number of events.
        count: usize,
    },
    /// More than 65 535 supervisors (the header counts them in 2 bytes).
    #[error("{count} supervisors; the compiled format supports at most 65535")]
    TooManySupervisors {
        /// Number of supervisors.
        count: usize,
    },
    /// A supervisor with more than 65 535 states (V15).
    #[error(
        "supervisor `{supervisor}` has {count} states; the compiled format supports at most {MAX_STATES}"
    )]
    TooManyStates {
        /// Supervisor name.
        supervisor: String,
        /// Number of states.
        count: usize,
    },
    /// A supervisor without states (an empty SupC result cannot be compiled).
    #[error("supervisor `{supervisor}` has no states")]
    NoStates {
        /// Supervisor name.
        supervisor: String,
    },
    /// A state with more than 255 outgoing transitions (V15).
    #[error(
        "supervisor `{supervisor}`, state `{state}`: {count} outgoing transitions; at most {MAX_TRANSITIONS_PER_STATE} are supported"
    )]
    TooManyTransitions {
        /// Supervisor name.
        supervisor: String,
        /// State name.
        state: String,
        /// Number of transitions.
        count: usize,
    },
    /// A lower bound above 65 535 ticks (V15, A9).
    #[error(
        "supervisor `{supervisor}`, state `{state}`, event `{event}`: lower bound {bound} ticks exceeds 65535"
    )]
    LowerBoundTooLarge {
        /// Supervisor name.
        supervisor: String,
        /// State name.
        state: String,
        /// Event name.
        event: String,
        /// The bound.
        bound: u32,
    },
    /// A probability that Q0.16 cannot encode (negative, above 1, or not finite; e.g. raw weights above 1).
    #[error(
        "supervisor `{supervisor}`, state `{state}`, event `{event}`: probability {prob} is outside [0, 1] and cannot be stored in Q0.16 (with raw weights, use weights of at most 1)"
    )]
    ProbabilityOutOfRange {
        /// Supervisor name.
        supervisor: String,
        /// State name.
        state: String,
        /// Event name.
        event: String,
        /// The value.
        prob: f64,
    },
    /// A supervisor uses an event id that is not in the event table.
    #[error(
        "supervisor `{supervisor}` uses event id {event}, which is not in the project's event table"
    )]
    UnknownEvent {
        /// Supervisor name.
        supervisor: String,
        /// The id.
        event: u16,
    },
    /// A name longer than the 2-byte length field allows.
    #[error("name `{prefix}...` is {len} bytes long; at most 65535 bytes are supported")]
    NameTooLong {
        /// The first characters of the name.
        prefix: String,
        /// Its length in bytes.
        len: usize,
    },
}

/// What is wrong with a compiled file's bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FormatProblem {
    /// The file does not start with [`MAGIC`].
    BadMagic,
    /// A format version this reader does not understand.
    UnsupportedVersion(u16),
    /// The file ends inside the named field.
    Truncated(&'static str),
    /// A name is not valid UTF-8.
    InvalidUtf8(&'static str),
    /// The event count exceeds [`MAX_EVENTS`].
    TooManyEvents(u16),
    /// A supervisor declares zero states.
    NoStates {
        /// Supervisor index.
        supervisor: usize,
    },
    /// A transition's event id is not below the event count.
    EventOutOfRange {
        /// Supervisor index.
        supervisor: usize,
        /// State id.
        state: usize,
        /// The event id.
        event: u8,
    },
    /// A transition's target is not a state of its supervisor.
    TargetOutOfRange {
        /// Supervisor index.
        supervisor: usize,
        /// State id.
        state: usize,
        /// The target id.
        target: u16,
    },
    /// Transitions not ordered controllable-first, then by strictly ascending event id.
    BadTransitionOrder {
        /// Supervisor index.
        supervisor: usize,
        /// State id.
        state: usize,
    },
    /// A transition on an event the supervisor does not own per the membership matrix.
    EventNotInAlphabet {
        /// Supervisor index.
        supervisor: usize,
        /// State id.
        state: usize,
        /// The event id.
        event: u8,
    },
    /// A probability or time block whose count differs from the state's controllable transitions.
    CountMismatch {
        /// Supervisor index.
        supervisor: usize,
        /// State id.
        state: usize,
        /// Which array (`"probability"` or `"time"`).
        array: &'static str,
        /// Controllable transitions in the δ block.
        expected: u8,
        /// Count found.
        found: u8,
    },
    /// A flag byte that is neither 0 nor 1.
    BadFlag(&'static str, u8),
    /// A current-state entry other than 0 (files start every supervisor in its initial state).
    NonInitialCurrentState {
        /// Supervisor index.
        supervisor: usize,
        /// The value found.
        state: u16,
    },
    /// Bytes after the end of the layout.
    TrailingBytes(usize),
}

impl fmt::Display for FormatProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadMagic => write!(
                f,
                "not a compiled supervisor set (magic bytes are not \"PTSC\")"
            ),
            Self::UnsupportedVersion(v) => {
                write!(
                    f,
                    "format version {v} is not supported (this build reads version {FORMAT_VERSION})"
                )
            }
            Self::Truncated(what) => write!(f, "file ends inside the {what}"),
            Self::InvalidUtf8(what) => write!(f, "the {what} is not valid UTF-8"),
            Self::TooManyEvents(n) => {
                write!(f, "{n} events declared; at most {MAX_EVENTS} are supported")
            }
            Self::NoStates { supervisor } => {
                write!(f, "supervisor {supervisor} declares no states")
            }
            Self::EventOutOfRange {
                supervisor,
                state,
                event,
            } => write!(
                f,
                "supervisor {supervisor}, state {state}: event id {event} is not in the event table"
            ),
            Self::TargetOutOfRange {
                supervisor,
                state,
                target,
            } => write!(
                f,
                "supervisor {supervisor}, state {state}: target state {target} does not exist"
            ),
            Self::BadTransitionOrder { supervisor, state } => write!(
                f,
                "supervisor {supervisor}, state {state}: transitions are not controllable-first in strictly ascending event order"
            ),
            Self::EventNotInAlphabet {
                supervisor,
                state,
                event,
            } => write!(
                f,
                "supervisor {supervisor}, state {state}: event {event} is not in the supervisor's alphabet"
            ),
            Self::CountMismatch {
                supervisor,
                state,
                array,
                expected,
                found,
            } => write!(
                f,
                "supervisor {supervisor}, state {state}: {array} block has {found} entries but the state has {expected} controllable transitions"
            ),
            Self::BadFlag(what, v) => write!(f, "{what} byte is {v}, expected 0 or 1"),
            Self::NonInitialCurrentState { supervisor, state } => write!(
                f,
                "current state of supervisor {supervisor} is {state}; compiled files start in state 0"
            ),
            Self::TrailingBytes(n) => write!(f, "{n} unexpected bytes after the end of the layout"),
        }
    }
}

/// Errors while reading a compiled supervisor-set file.
#[derive(Debug, thiserror::Error)]
pub enum CompiledFormatError {
    /// The file could not be read.
    #[error("cannot read compiled supervisor set {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
    /// The bytes do not follow the layout.
    #[error("{}byte {offset}: {problem}", path.as_ref().map(|p| format!("{}: ", p.display())).unwrap_or_default())]
    Malformed {
        /// The file, when reading from one.
        path: Option<PathBuf>,
        /// Byte offset of the problem.
        offset: usize,
        /// What is wrong.
        problem: FormatProblem,
    },
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
        Reader { bytes, pos: 0 }
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

type ParseResult<T> = Result<T, (usize, FormatProblem)>;

/// A bounds-checked cursor over untrusted bytes.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize, what: &'static str) -> ParseResult<&[u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&end| end <= self.bytes.len())
            .ok_or((self.pos, FormatProblem::Truncated(what)))?;
        let slice = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(slice)
    }

    fn u8(&mut self, what: &'static str) -> ParseResult<u8> {
        Ok(self.take(1, what)?[0])
    }

    fn u16(&mut self, what: &'static str) -> ParseResult<u16> {
        let b = self.take(2, what)?;
        Ok(u16::from_be_bytes([b[0], b[1]]))
    }

    fn flag(&mut self, what: &'static str) -> ParseResult<bool> {
        let at = self.pos;
        match self.u8(what)? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err((at, FormatProblem::BadFlag(what, v))),
        }
    }

    fn name(&mut self, what: &'static str) -> ParseResult<String> {
        let len = usize::from(self.u16(what)?);
        let at = self.pos;
        let raw = self.take(len, what)?;
        std::str::from_utf8(raw)
            .map(str::to_owned)
            .map_err(|_| (at, FormatProblem::InvalidUtf8(what)))
    }

    fn parse(mut self) -> ParseResult<SupervisorSet> {
        if self.take(4, "magic bytes")? != MAGIC {
            return Err((0, FormatProblem::BadMagic));
        }
        let version = self.u16("format version")?;
        if version != FORMAT_VERSION {
            return Err((4, FormatProblem::UnsupportedVersion(version)));
        }
        let e_at = self.pos;
        let e = self.u16("event count")?;
        if usize::from(e) > MAX_EVENTS {
            return Err((e_at, FormatProblem::TooManyEvents(e)));
        }
        let n = usize::from(self.u16("supervisor count")?);
        let mut names = Vec::with_capacity(usize::from(e));
        for _ in 0..e {
            names.push(self.name("event name")?);
        }
        // Each supervisor entry takes at least 4 bytes, which bounds the allocation by the input size.
        let mut sups = Vec::with_capacity(n.min(self.bytes.len() / 4));
        for i in 0..n {
            let name = self.name("supervisor name")?;
            let at = self.pos;
            let count = usize::from(self.u16("state count")?);
            if count == 0 {
                return Err((at, FormatProblem::NoStates { supervisor: i }));
            }
            sups.push((name, count));
        }
        // δ blocks are checked against the membership matrix, which comes after them: parse raw first.
        let mut raw = Vec::with_capacity(sups.len());
        for (i, &(_, count)) in sups.iter().enumerate() {
            raw.push(self.supervisor_arrays(i, count, usize::from(e))?);
        }
        let mut controllable = Vec::with_capacity(usize::from(e));
        for _ in 0..e {
            controllable.push(self.flag("controllability table")?);
        }
        let mut member = vec![false; usize::from(e) * n];
        for m in member.iter_mut() {
            *m = self.flag("membership matrix")?;
        }
        for i in 0..n {
            let at = self.pos;
            let cur = self.u16("current-state table")?;
            if cur != 0 {
                return Err((
                    at,
                    FormatProblem::NonInitialCurrentState {
                        supervisor: i,
                        state: cur,
                    },
                ));
            }
        }
        if self.pos != self.bytes.len() {
            return Err((
                self.pos,
                FormatProblem::TrailingBytes(self.bytes.len() - self.pos),
            ));
        }
        let events: Vec<CompiledEvent> = names
            .into_iter()
            .zip(&controllable)
            .map(|(name, &controllable)| CompiledEvent { name, controllable })
            .collect();
        let mut supervisors = Vec::with_capacity(n);
        for (i, ((name, _), arrays)) in sups.into_iter().zip(raw).enumerate() {
            let alphabet: Vec<u8> = (0..usize::from(e))
                .filter(|&ev| member[ev * n + i])
                .map(|ev| ev as u8)
                .collect();
            let states = arrays.assemble(i, &alphabet, &controllable)?;
            supervisors.push(CompiledSupervisor {
                name,
                alphabet,
                states,
            });
        }
        Ok(SupervisorSet {
            events,
            supervisors,
        })
    }

    fn supervisor_arrays(&mut self, sup: usize, count: usize, e: usize) -> ParseResult<RawArrays> {
        let mut delta = Vec::with_capacity(count);
        for state in 0..count {
            let at = self.pos;
            let k = self.u8("transition array")?;
            let mut trs = Vec::with_capacity(usize::from(k));
            for _ in 0..k {
                let event = self.u8("transition array")?;
                let target = self.u16("transition array")?;
                if usize::from(event) >= e {
                    return Err((
                        at,
                        FormatProblem::EventOutOfRange {
                            supervisor: sup,
                            state,
                            event,
                        },
                    ));
                }
                if usize::from(target) >= count {
                    return Err((
                        at,
                        FormatProblem::TargetOutOfRange {
                            supervisor: sup,
                            state,
                            target,
                        },
                    ));
                }
                trs.push((event, target));
            }
            delta.push((at, trs));
        }
        let probs = self.value_blocks(count, "probability array")?;
        let times = self.value_blocks(count, "time array")?;
        Ok(RawArrays {
            delta,
            probs,
            times,
        })
    }

    fn value_blocks(
        &mut self,
        count: usize,
        what: &'static str,
    ) -> ParseResult<Vec<(usize, Vec<u16>)>> {
        let mut blocks = Vec::with_capacity(count);
        for _ in 0..count {
            let at = self.pos;
            let k = self.u8(what)?;
            let mut vals = Vec::with_capacity(usize::from(k));
            for _ in 0..k {
                vals.push(self.u16(what)?);
            }
            blocks.push((at, vals));
        }
        Ok(blocks)
    }
}

/// One supervisor's δ, P and T arrays as read, with the offset of each state's block.
struct RawArrays {
    delta: Vec<(usize, Vec<(u8, u16)>)>,
    probs: Vec<(usize, Vec<u16>)>,
    times: Vec<(usize, Vec<u16>)>,
}

impl RawArrays {
    fn assemble(
        self,
        sup: usize,
        alphabet: &[u8],
        controllable: &[bool],
    ) -> ParseResult<Vec<CompiledState>> {
        let mut states = Vec::with_capacity(self.delta.len());
        for (state, (((at, trs), (p_at, probs)), (t_at, times))) in self
            .delta
            .into_iter()
            .zip(self.probs)
            .zip(self.times)
            .enumerate()
        {
            let ctrl = |ev: u8| controllable.get(usize::from(ev)).copied().unwrap_or(false);
            let key = |ev: u8| (!ctrl(ev), ev);
            if trs.windows(2).any(|w| key(w[0].0) >= key(w[1].0)) {
                return Err((
                    at,
                    FormatProblem::BadTransitionOrder {
                        supervisor: sup,
                        state,
                    },
                ));
            }
            if let Some(&(event, _)) = trs
                .iter()
                .find(|(ev, _)| alphabet.binary_search(ev).is_err())
            {
                return Err((
                    at,
                    FormatProblem::EventNotInAlphabet {
                        supervisor: sup,
                        state,
                        event,
                    },
                ));
            }
            let n_c = trs.iter().filter(|(ev, _)| ctrl(*ev)).count() as u8;
            for (block_at, array, found) in [
                (p_at, "probability", probs.len()),
                (t_at, "time", times.len()),
            ] {
                if found != usize::from(n_c) {
                    return Err((
                        block_at,
                        FormatProblem::CountMismatch {
                            supervisor: sup,
                            state,
                            array,
                            expected: n_c,
                            found: found as u8,
                        },
                    ));
                }
            }
            let transitions = trs
                .iter()
                .enumerate()
                .map(|(j, &(event, target))| {
                    let (prob_q16, lower_bound) = if ctrl(event) {
                        (probs[j], times[j])
                    } else {
                        (u16::MAX, 0)
                    };
                    CompiledTransition {
                        event,
                        target,
                        prob_q16,
                        lower_bound,
                    }
                })
                .collect();
            states.push(CompiledState { transitions });
        }
        Ok(states)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automaton::ModelKind;

    /// The generator of the worked example in section 9, with normalised probabilities.
    fn worked_example() -> (EventTable, Automaton) {
        let mut ev = EventTable::new();
        let a = ev.intern("a", true).unwrap();
        let b = ev.intern("b", true).unwrap();
        let c = ev.intern("c", true).unwrap();
        let u = ev.intern("u", false).unwrap();
        let mut g = Automaton::new("example", ModelKind::Supervisor);
        let q0 = g.add_state("q0", true).unwrap();
        let q1 = g.add_state("q1", false).unwrap();
        let q2 = g.add_state("q2", false).unwrap();
        g.add_transition(q0, a, q1, 0.8, 2).unwrap();
        g.add_transition(q0, b, q2, 0.2, 0).unwrap();
        g.add_transition(q1, a, q1, 1.0, 0).unwrap();
        g.add_transition(q1, u, q0, 1.0, 0).unwrap();
        g.add_transition(q2, b, q0, 0.25, 0).unwrap();
        g.add_transition(q2, c, q1, 0.75, 0).unwrap();
        (ev, g)
    }

    /// The arrays of the worked example, as printed in section 9.
    const WORKED_DELTA: [u8; 21] = [
        0x02, 0x00, 0x00, 0x01, 0x01, 0x00, 0x02, //
        0x02, 0x00, 0x00, 0x01, 0x03, 0x00, 0x00, //
        0x02, 0x01, 0x00, 0x00, 0x02, 0x00, 0x01,
    ];
    const WORKED_P: [u8; 13] = [
        0x02, 0xCC, 0xCC, 0x33, 0x33, 0x01, 0xFF, 0xFF, 0x02, 0x40, 0x00, 0xBF, 0xFF,
    ];
    const WORKED_T: [u8; 13] = [
        0x02, 0x00, 0x02, 0x00, 0x00, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00,
    ];
    const WORKED_CTRL: [u8; 4] = [0x01, 0x01, 0x01, 0x00];
    const WORKED_MEMBER: [u8; 4] = [0x01, 0x01, 0x01, 0x01];
    const WORKED_CURRENT: [u8; 2] = [0x00, 0x00];

    fn worked_payload() -> Vec<u8> {
        [
            &WORKED_DELTA[..],
            &WORKED_P,
            &WORKED_T,
            &WORKED_CTRL,
            &WORKED_MEMBER,
            &WORKED_CURRENT,
        ]
        .concat()
    }

    #[test]
    fn worked_example_of_section_9_gives_the_thesis_bytes_and_memcons_57() {
        let (ev, g) = worked_example();
        let set = SupervisorSet::from_supervisors(&ev, std::slice::from_ref(&g)).unwrap();
        let bytes = set.to_bytes();
        let payload = worked_payload();
        assert_eq!(payload.len(), 21 + 13 + 13 + 4 + 4 + 2);
        assert!(bytes.ends_with(&payload), "payload differs: {bytes:02X?}");
        assert_eq!(set.mem_cons(), 57);
        assert_eq!(mem_cons_of(&ev, &[&g]), 57);
        // Header: magic, version, counts, 4 one-letter event names, one supervisor entry.
        assert_eq!(bytes.len() - 57, 10 + 4 * 3 + (2 + 7 + 2));
        assert_eq!(&bytes[..4], b"PTSC");
        assert_eq!(SupervisorSet::from_bytes(&bytes).unwrap(), set);
    }

    #[test]
    fn initial_state_is_renumbered_to_zero() {
        let (ev, mut g) = worked_example();
        g.set_initial(StateId(2)).unwrap();
        let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
        let s = &set.supervisors[0];
        // Old q2 (b -> q0, c -> q1) is now state 0; old q0 is 1, old q1 is 2.
        let t: Vec<_> = s.states[0]
            .transitions
            .iter()
            .map(|t| (t.event, t.target))
            .collect();
        assert_eq!(t, vec![(1, 1), (2, 2)]);
    }

    #[test]
    fn uncontrollable_transitions_are_stored_after_controllable_ones() {
        let mut ev = EventTable::new();
        let u = ev.intern("u", false).unwrap();
        let a = ev.intern("a", true).unwrap();
        let mut g = Automaton::new("s", ModelKind::Supervisor);
        let q = g.add_state("q", true).unwrap();
        g.add_transition(q, u, q, 1.0, 0).unwrap();
        g.add_transition(q, a, q, 1.0, 3).unwrap();
        let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
        let events: Vec<_> = set.supervisors[0].states[0]
            .transitions
            .iter()
            .map(|t| t.event)
            .collect();
        assert_eq!(events, vec![a.0 as u8, u.0 as u8]);
        assert_eq!(SupervisorSet::from_bytes(&set.to_bytes()).unwrap(), set);
    }

    #[test]
    fn v15_lower_bound_over_65535_is_a_codegen_error() {
        let (ev, mut g) = worked_example();
        g.transitions_mut(StateId(0))[0].lower_bound = 70_000;
        assert!(matches!(
            SupervisorSet::from_supervisors(&ev, &[g]),
            Err(CodegenError::LowerBoundTooLarge { bound: 70_000, .. })
        ));
    }

    #[test]
    fn v15_more_than_256_events_is_a_codegen_error() {
        let mut ev = EventTable::new();
        for i in 0..257 {
            ev.intern(&format!("e{i}"), true).unwrap();
        }
        let g = Automaton::identity("s", ModelKind::Supervisor);
        assert!(matches!(
            SupervisorSet::from_supervisors(&ev, &[g]),
            Err(CodegenError::TooManyEvents { count: 257 })
        ));
    }

    #[test]
    fn v15_more_than_255_transitions_in_a_state_is_a_codegen_error() {
        let mut ev = EventTable::new();
        let mut g = Automaton::new("s", ModelKind::Supervisor);
        let q = g.add_state("q", true).unwrap();
        for i in 0..256 {
            let e = ev.intern(&format!("e{i}"), true).unwrap();
            g.add_transition(q, e, q, 1.0, 0).unwrap();
        }
        assert!(matches!(
            SupervisorSet::from_supervisors(&ev, &[g]),
            Err(CodegenError::TooManyTransitions { count: 256, .. })
        ));
    }

    #[test]
    fn raw_weight_above_one_cannot_be_encoded() {
        let (ev, mut g) = worked_example();
        g.transitions_mut(StateId(2))[1].prob = 3.0;
        assert!(matches!(
            SupervisorSet::from_supervisors(&ev, &[g]),
            Err(CodegenError::ProbabilityOutOfRange { .. })
        ));
    }

    fn worked_bytes() -> Vec<u8> {
        let (ev, g) = worked_example();
        SupervisorSet::from_supervisors(&ev, &[g])
            .unwrap()
            .to_bytes()
    }

    fn problem(bytes: &[u8]) -> (usize, FormatProblem) {
        match SupervisorSet::from_bytes(bytes) {
            Err(CompiledFormatError::Malformed {
                offset, problem, ..
            }) => (offset, problem),
            other => panic!("expected a format error, got {other:?}"),
        }
    }

    #[test]
    fn every_truncation_is_reported_as_truncated() {
        let bytes = worked_bytes();
        for len in 0..bytes.len() {
            let (offset, p) = problem(&bytes[..len]);
            assert!(matches!(p, FormatProblem::Truncated(_)), "len {len}: {p:?}");
            assert!(offset <= len);
        }
    }

    #[test]
    fn corrupt_fields_are_named() {
        let good = worked_bytes();
        let payload = good.len() - 57;
        let mut b = good.clone();
        b[0] = b'X';
        assert_eq!(problem(&b), (0, FormatProblem::BadMagic));
        let mut b = good.clone();
        b[5] = 2;
        assert_eq!(problem(&b).1, FormatProblem::UnsupportedVersion(2));
        let mut b = good.clone();
        b[payload + 1] = 9; // first event id of q0
        assert!(matches!(
            problem(&b).1,
            FormatProblem::EventOutOfRange { event: 9, .. }
        ));
        let mut b = good.clone();
        b[payload + 3] = 7; // first target of q0
        assert!(matches!(
            problem(&b).1,
            FormatProblem::TargetOutOfRange { target: 7, .. }
        ));
        let mut b = good.clone();
        b[payload + 1] = 1; // q0: b, b -> not strictly ascending
        assert!(matches!(
            problem(&b).1,
            FormatProblem::BadTransitionOrder { .. }
        ));
        let mut b = good.clone();
        b[payload + 47 + 3] = 2; // controllability flag of u
        assert_eq!(
            problem(&b),
            (
                payload + 50,
                FormatProblem::BadFlag("controllability table", 2)
            )
        );
        let mut b = good.clone();
        b[payload + 51] = 0; // a is no longer in the alphabet
        assert!(matches!(
            problem(&b).1,
            FormatProblem::EventNotInAlphabet { event: 0, .. }
        ));
        let mut b = good.clone();
        b[payload + 56] = 1;
        assert!(matches!(
            problem(&b).1,
            FormatProblem::NonInitialCurrentState { .. }
        ));
        let mut b = good.clone();
        b.push(0);
        assert_eq!(problem(&b).1, FormatProblem::TrailingBytes(1));
    }

    #[test]
    fn read_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.ptsc");
        std::fs::write(&path, b"PTSC\x00").unwrap();
        let msg = SupervisorSet::read(&path).unwrap_err().to_string();
        assert!(msg.contains("bad.ptsc") && msg.contains("byte 4"), "{msg}");
        let ok = dir.path().join("ok.ptsc");
        let (ev, g) = worked_example();
        let set = SupervisorSet::from_supervisors(&ev, &[g]).unwrap();
        set.write(&ok).unwrap();
        assert_eq!(SupervisorSet::read(&ok).unwrap(), set);
    }
}
