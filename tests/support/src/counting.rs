//! A counting global allocator that counts per thread, and only where asked.
//!
//! A test binary installs it and measures a closure with [`count`]:
//!
//! ```
//! #[global_allocator]
//! static GLOBAL: test_support::counting::Counting = test_support::counting::Counting;
//!
//! let (v, heap) = test_support::counting::count(|| vec![0u8; 16]);
//! assert_eq!((heap.allocs, heap.bytes, heap.frees), (1, 16, 0));
//! # drop(v);
//! ```
//!
//! Only the allocations, frees and
//! bytes of the calling thread while the closure runs are counted. Other
//! threads (the test harness, tests running in parallel, helper threads of
//! the code under test) never show up, and a test never resets another
//! test's numbers: both made process-wide counters report false passes and
//! false failures.
//!
//! The allocator itself never allocates: its state is two `const`-initialised
//! thread-locals of `Copy` types without `Drop`, which need neither a lazy
//! initialisation nor a TLS destructor (so they are usable while a thread
//! exits, when the allocator is still called).

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

impl Counts {
    /// No traffic.
    pub const ZERO: Counts = Counts {
        allocs: 0,
        frees: 0,
        bytes: 0,
    };

    /// Whether nothing was allocated or freed.
    pub fn is_zero(&self) -> bool {
        *self == Counts::ZERO
    }
}

impl std::ops::AddAssign for Counts {
    fn add_assign(&mut self, o: Counts) {
        self.allocs += o.allocs;
        self.frees += o.frees;
        self.bytes += o.bytes;
    }
}

impl std::fmt::Display for Counts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} allocations ({} bytes), {} frees",
            self.allocs, self.bytes, self.frees
        )
    }
}

thread_local! {
    /// Whether [`count`] is running on this thread.
    static ENABLED: Cell<bool> = const { Cell::new(false) };
    /// This thread's traffic while [`ENABLED`].
    static COUNTS: Cell<Counts> = const { Cell::new(Counts::ZERO) };
}

fn note(f: impl FnOnce(&mut Counts)) {
    // `try_with` never fails for these thread-locals (no destructor), but
    // the allocator must not panic whatever happens.
    let _ = ENABLED.try_with(|on| {
        if on.get() {
            let _ = COUNTS.try_with(|c| {
                let mut v = c.get();
                f(&mut v);
                c.set(v);
            });
        }
    });
}

/// Forwards to the system allocator; counts on threads inside [`count`].
#[derive(Debug)]
pub struct Counting;

// SAFETY: forwards every call to the system allocator unchanged; the
// counting touches only thread-locals that never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(|c| {
            c.allocs += 1;
            c.bytes += layout.size();
        });
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(|c| {
            c.allocs += 1;
            c.bytes += layout.size();
        });
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
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

/// Runs `f` and returns its result with the calling thread's heap traffic
/// during it. Nested calls count for each enclosing call too.
///
/// Counts are zero if [`Counting`] is not the binary's global allocator:
/// test that it is with [`is_installed`].
pub fn count<T>(f: impl FnOnce() -> T) -> (T, Counts) {
    let was = ENABLED.with(|on| on.replace(true));
    let before = COUNTS.with(Cell::get);
    let r = f();
    let after = COUNTS.with(Cell::get);
    ENABLED.with(|on| on.set(was));
    let d = Counts {
        allocs: after.allocs - before.allocs,
        frees: after.frees - before.frees,
        bytes: after.bytes - before.bytes,
    };
    (r, d)
}

/// The sum of this thread's counts over many counted sections (e.g. every
/// tick of a loop), measured with [`Tally::count`].
#[derive(Debug, Default)]
pub struct Tally(Cell<Counts>);

impl Tally {
    /// Runs `f` as [`count`] does and adds its traffic to the sum.
    pub fn count<T>(&self, f: impl FnOnce() -> T) -> T {
        let (r, c) = count(f);
        let mut sum = self.0.get();
        sum += c;
        self.0.set(sum);
        r
    }

    /// The sum so far.
    pub fn total(&self) -> Counts {
        self.0.get()
    }
}

/// Whether [`Counting`] is this binary's global allocator and sees this
/// thread's allocations (otherwise every count is zero and an allocation
/// test proves nothing).
pub fn is_installed() -> bool {
    let (b, c) = count(|| std::hint::black_box(Box::new(7u64)));
    drop(b);
    c.allocs == 1 && c.bytes == 8
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, Ordering};

    #[global_allocator]
    static GLOBAL: Counting = Counting;

    #[test]
    fn an_allocation_and_its_free_are_counted() {
        assert!(is_installed());
        let (_, c) = count(|| drop(std::hint::black_box(vec![1u8; 100])));
        assert_eq!(
            c,
            Counts {
                allocs: 1,
                frees: 1,
                bytes: 100
            }
        );
        let (_, none) = count(|| std::hint::black_box(1 + 1));
        assert!(none.is_zero(), "{none}");
    }

    #[test]
    fn nothing_is_counted_outside_count() {
        let (_, first) = count(|| ());
        let _outside = std::hint::black_box(vec![0u8; 64]);
        let (_, second) = count(|| ());
        assert!(first.is_zero() && second.is_zero());
    }

    /// Another thread allocating all the while never shows up in this
    /// thread's count (the false failure of a process-wide counter).
    #[test]
    fn other_threads_are_not_counted() {
        let stop = AtomicBool::new(false);
        let started = AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    drop(std::hint::black_box(vec![0u8; 32]));
                    started.store(true, Ordering::Relaxed);
                }
            });
            while !started.load(Ordering::Relaxed) {
                std::hint::spin_loop();
            }
            let (_, c) = count(|| {
                let mut x = 0u64;
                for i in 0..2_000_000u64 {
                    x = std::hint::black_box(x.wrapping_add(i));
                }
            });
            stop.store(true, Ordering::Relaxed);
            assert!(c.is_zero(), "another thread's traffic counted: {c}");
        });
    }

    #[test]
    fn a_tally_sums_its_sections_only() {
        let t = Tally::default();
        let a = t.count(|| std::hint::black_box(Box::new(1u8)));
        let _outside = std::hint::black_box(Box::new(2u8));
        t.count(|| drop(a));
        assert_eq!(
            t.total(),
            Counts {
                allocs: 1,
                frees: 1,
                bytes: 1
            }
        );
    }

    #[test]
    fn nested_counts_add_up() {
        let ((_, inner), outer) = count(|| {
            let a = std::hint::black_box(Box::new(1u32));
            let r = count(|| std::hint::black_box(Box::new(2u32)));
            drop(a);
            r
        });
        assert_eq!(inner.allocs, 1);
        assert_eq!((outer.allocs, outer.frees), (2, 1));
    }
}
