//! A wake-up that the real-time loop requests without a system call and
//! another thread delivers.
//!
//! Waking a thread is a futex syscall (plus an inter-processor interrupt
//! on a VM, several µs). The loop only presses a [`Doorbell`] (one atomic
//! store); a thread that runs after every tick anyway — the writer —
//! delivers the wake-ups pressed since its last round. The planner link
//! wakes the planner thread this way.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::Thread;

/// A wake-up the loop presses and another thread delivers (module docs).
#[derive(Debug, Default)]
pub struct Doorbell {
    pending: AtomicBool,
    thread: OnceLock<Thread>,
}

impl Doorbell {
    /// The thread a delivery wakes; only the first call counts.
    pub fn attach(&self, thread: Thread) {
        let _ = self.thread.set(thread);
    }

    /// Requests a wake-up (one atomic store).
    pub fn press(&self) {
        self.pending.store(true, Ordering::Release);
    }

    /// Whether a wake-up waits to be delivered.
    pub fn pressed(&self) -> bool {
        self.pending.load(Ordering::Acquire)
    }

    /// Wakes the thread if a wake-up was requested since the last call
    /// (called off the loop, e.g. by the writer thread every tick).
    pub fn deliver(&self) {
        if self.pending.swap(false, Ordering::AcqRel)
            && let Some(t) = self.thread.get()
        {
            t.unpark();
        }
    }
}
