//! Linux futex wait/wake on a 32-bit word in shared memory.
//!
//! The lockstep protocol parks each agent on its chain's word and the world on one counter; the words live in a
//! `MAP_SHARED` mapping, so the shared (non-private) futex operations are used. This module must never spin:
//! callers decide how long to spin before they block here.
//!
//! The calls go through rustix's raw Linux backend rather than glibc's `syscall()`: the `syscall` instruction is
//! inlined into the caller, in the agents' hot section, so an agent returning from its wait does not first walk
//! the page tables for glibc's wrapper and its GOT entry (docs/transport.md, "Agent code locality").

use std::sync::atomic::AtomicU32;
use std::time::Duration;

use rustix::io::Errno;
use rustix::thread::futex::{self, Flags, Timespec};

/// Blocks while `word` still holds `expected`, for at most `timeout` (forever when `None`).
///
/// Returns on a wake-up, a value change, a signal or the timeout; callers re-check their condition in a loop,
/// so every return is a "maybe". The result tells whether the timeout expired, so that callers can act on a
/// long silence without reading the clock on every wake-up.
#[unsafe(link_section = "swarm_hot")]
pub fn wait(word: &AtomicU32, expected: u32, timeout: Option<Duration>) -> Waited {
    let spec = timeout.map(|t| Timespec {
        tv_sec: i64::try_from(t.as_secs()).unwrap_or(i64::MAX),
        tv_nsec: i64::from(t.subsec_nanos()),
    });
    match futex::wait(word, Flags::empty(), expected, spec.as_ref()) {
        Err(Errno::TIMEDOUT) => Waited::TimedOut,
        _ => Waited::Woken,
    }
}

/// One 32-bit futex word on its own cache line, so that processes polling it do not share a line with writers
/// of other words.
#[repr(C, align(64))]
pub struct LineWord(pub AtomicU32);

/// How a [`wait`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Waited {
    /// Woken, interrupted, or the word no longer held the expected value.
    Woken,
    /// The timeout expired.
    TimedOut,
}

/// Wakes at most `count` processes blocked in [`wait`] on `word` (`i32::MAX` wakes all).
#[unsafe(link_section = "swarm_hot")]
pub fn wake(word: &AtomicU32, count: i32) {
    // FUTEX_WAKE fails only for an unmapped or misaligned word, which a `&AtomicU32` cannot be.
    let _ = futex::wake(word, Flags::empty(), u32::try_from(count).unwrap_or(0));
}
