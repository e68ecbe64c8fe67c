//! What can go wrong turning supervisors into a compiled set, and reading one back.

use std::fmt;
use std::io;
use std::path::PathBuf;

use super::{FORMAT_VERSION, MAX_EVENTS, MAX_STATES, MAX_TRANSITIONS_PER_STATE};

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
