//! Progress of long syntheses. The library says what it is doing (which product it builds and how many states
//! it has explored, each round of SupC) to a sink that a program installs once; the `supervisor-gen` binary
//! installs a terminal progress bar when stderr is a terminal. Without a sink (tests, other programs, output to
//! a file or pipe) a report costs one atomic load.

use std::sync::OnceLock;

/// Where progress goes.
pub trait Sink: Send + Sync {
    /// A new stage began, e.g. "product G_mon".
    fn stage(&self, what: &str);
    /// The current product has explored `states` states so far.
    fn states(&self, states: usize);
    /// SupC finished round `round` with `removed` states removed in all so far.
    fn round(&self, round: u32, removed: usize);
}

static SINK: OnceLock<Box<dyn Sink>> = OnceLock::new();

/// States explored between two reports of a product.
pub const STATES_PER_REPORT: usize = 1 << 14;

/// Sends the process's progress to `sink` from now on; a second call is ignored.
pub fn install(sink: Box<dyn Sink>) {
    let _ = SINK.set(sink);
}

pub(crate) fn stage(what: impl FnOnce() -> String) {
    if let Some(sink) = SINK.get() {
        sink.stage(&what());
    }
}

pub(crate) fn states(states: usize) {
    if let Some(sink) = SINK.get() {
        sink.states(states);
    }
}

pub(crate) fn round(round: u32, removed: usize) {
    if let Some(sink) = SINK.get() {
        sink.round(round, removed);
    }
}
