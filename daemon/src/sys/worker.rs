//! The handle of a helper thread that runs until a stop flag is set
//! (writer, housekeeping, trace writer, planner): stopping sets the flag, unparks
//! the thread so it sees the flag at once, and joins it — on `join` or
//! when the handle is dropped.

use std::os::unix::thread::JoinHandleExt;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

/// A running helper thread and its stop flag.
#[derive(Debug)]
pub struct StoppableThread {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

impl StoppableThread {
    /// Wraps a spawned thread that returns once `stop` is set.
    pub fn new(stop: Arc<AtomicBool>, handle: JoinHandle<()>) -> Self {
        Self {
            stop,
            handle: Some(handle),
        }
    }

    /// Runs the thread with SCHED_FIFO at `priority` (1–99).
    pub fn set_fifo_priority(&self, priority: u32) -> std::io::Result<()> {
        match &self.handle {
            // SAFETY: the handle is live (not joined, not detached).
            Some(h) => unsafe {
                crate::sys::rt::set_thread_fifo_priority(h.as_pthread_t(), priority)
            },
            None => Err(std::io::Error::other("thread already stopped")),
        }
    }

    /// Stops the thread (it finishes what it does on stop) and waits for it.
    pub fn join(mut self) {
        self.stop_now();
    }

    fn stop_now(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(h) = self.handle.take() {
            h.thread().unpark();
            let _ = h.join();
        }
    }
}

impl Drop for StoppableThread {
    fn drop(&mut self) {
        self.stop_now();
    }
}
