//! Counters shared between the daemon's threads: the loop, the writer and
//! housekeeping each write some and read others (atomics only, no lock).
//! The loop counts what it must not log; housekeeping reports it.

use std::sync::atomic::{AtomicU32, AtomicU64};

/// The counters (module docs); each names the thread that writes it.
#[derive(Debug, Default)]
pub struct Shared {
    /// Ticks run (loop writes).
    pub ticks: AtomicU64,
    /// Missed periods (loop writes).
    pub overruns: AtomicU64,
    /// Failed iceoryx2 sends/receives/notifications (loop and writer).
    pub ipc_errors: AtomicU64,
    /// Messages the loop dropped because the writer's ring was full.
    pub outbox_dropped: AtomicU64,
    /// Events lost because more than `EVENTS_PER_TICK` happened in a tick.
    pub events_dropped: AtomicU64,
    /// Client nodes alive (housekeeping writes).
    pub clients: AtomicU32,
    /// The loop's next deadline \[ns\] (loop writes; the writer thread sleeps
    /// until it). 0 before the first tick.
    pub next_deadline: AtomicU64,
    /// Deadline of the last tick whose output is queued (loop writes).
    pub done_deadline: AtomicU64,
    /// Messages the loop queued for the writer so far (loop writes, once
    /// per tick).
    pub queued: AtomicU64,
    /// Messages the writer took from the ring so far (writer writes).
    pub published: AtomicU64,
    /// Dead nodes cleaned up since start (housekeeping writes).
    pub cleaned: AtomicU64,
}
