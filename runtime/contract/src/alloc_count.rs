//! Counting one thread's heap allocations, for the tests that hold the per-tick hot path to "allocates nothing"
//! (style.md). A test binary installs the counter with
//! `#[global_allocator] static GLOBAL: CountingAllocator = CountingAllocator;` and compares
//! [`thread_allocations`] before and after the code under test. The count is per thread, so tests running in
//! parallel in the same binary do not disturb each other.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

/// A global allocator that forwards to the system allocator and counts allocations and reallocations.
pub struct CountingAllocator;

fn count() {
    // `try_with`: the thread local may already be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to the system allocator; the counter is a const-initialised thread
// local, which never allocates.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations and reallocations the current thread has made so far (0 unless [`CountingAllocator`] is the
/// global allocator).
pub fn thread_allocations() -> u64 {
    ALLOCATIONS.with(Cell::get)
}
