//! A counting global allocator for the allocation tests. Counts are per
//! thread, so the test harness and tests running in parallel do not show
//! up in each other's numbers (a process-wide counter made these tests
//! flaky on a loaded machine).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Heap traffic of one thread.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Allocations and reallocations.
    pub allocs: usize,
    /// Frees.
    pub frees: usize,
    /// Bytes requested by allocations and reallocations.
    pub bytes: usize,
}

thread_local! {
    static COUNTS: Cell<Counts> = const { Cell::new(Counts { allocs: 0, frees: 0, bytes: 0 }) };
}

fn note(f: impl FnOnce(&mut Counts)) {
    // `try_with`: the thread-local may already be gone while a thread exits.
    let _ = COUNTS.try_with(|c| {
        let mut v = c.get();
        f(&mut v);
        c.set(v);
    });
}

/// Forwards to the system allocator and counts.
pub struct Counting;

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(|c| {
            c.allocs += 1;
            c.bytes += layout.size();
        });
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        note(|c| c.frees += 1);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(|c| {
            c.allocs += 1;
            c.bytes += new_size;
        });
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Runs `f` and returns its result with this thread's heap traffic during it.
pub fn count<T>(f: impl FnOnce() -> T) -> (T, Counts) {
    let before = COUNTS.with(Cell::get);
    let r = f();
    let after = COUNTS.with(Cell::get);
    (
        r,
        Counts {
            allocs: after.allocs - before.allocs,
            frees: after.frees - before.frees,
            bytes: after.bytes - before.bytes,
        },
    )
}
