//! Linux futex wait/wake on a 32-bit word in shared memory.
//!
//! The lockstep protocol parks each agent on its own word and the world on one counter; the words live in a
//! `MAP_SHARED` mapping, so the shared (non-private) futex operations are used. This module must never spin:
//! callers decide how long to spin before they block here.

use std::sync::atomic::AtomicU32;
use std::time::Duration;

/// Blocks while `word` still holds `expected`, for at most `timeout` (forever when `None`).
///
/// Returns on a wake-up, a value change, a signal or the timeout; callers re-check their condition in a loop,
/// so every return is a "maybe". The result tells whether the timeout expired, so that callers can act on a
/// long silence without reading the clock on every wake-up.
#[unsafe(link_section = "swarm_hot")]
pub fn wait(word: &AtomicU32, expected: u32, timeout: Option<Duration>) -> Waited {
    let spec = timeout.map(|t| libc::timespec {
        tv_sec: libc::time_t::try_from(t.as_secs()).unwrap_or(libc::time_t::MAX),
        tv_nsec: libc::c_long::from(t.subsec_nanos()),
    });
    let spec_ptr = spec
        .as_ref()
        .map_or(std::ptr::null(), |s| s as *const libc::timespec);
    // SAFETY: `word` is a live, aligned 32-bit atomic; the kernel only reads it. The timespec outlives the call.
    let result = unsafe {
        libc::syscall(
            libc::SYS_futex,
            word.as_ptr(),
            libc::FUTEX_WAIT,
            expected,
            spec_ptr,
            std::ptr::null::<u32>(),
            0u32,
        )
    };
    if result == -1 && std::io::Error::last_os_error().raw_os_error() == Some(libc::ETIMEDOUT) {
        Waited::TimedOut
    } else {
        Waited::Woken
    }
}

/// One 32-bit futex word on its own cache line, so that processes polling it do not share a line with writers
/// of other words.
#[repr(C, align(64))]
pub(crate) struct LineWord(pub(crate) AtomicU32);

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
    // SAFETY: `word` is a live, aligned 32-bit atomic; FUTEX_WAKE does not touch memory.
    unsafe {
        libc::syscall(
            libc::SYS_futex,
            word.as_ptr(),
            libc::FUTEX_WAKE,
            count,
            std::ptr::null::<libc::timespec>(),
            std::ptr::null::<u32>(),
            0u32,
        );
    }
}
