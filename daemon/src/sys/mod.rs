//! What every other part of the daemon stands on: time, the operating
//! system's real-time and systemd facilities, and the means by which the
//! daemon's threads share data. Nothing here uses another part of the
//! daemon.
//!
//! - [`clock`]: injected time: the monotonic clock and a mock clock tests step.
//! - [`rt`]: real-time set-up: SCHED_FIFO, affinity, memory locking.
//! - [`sd_notify`]: systemd notification (`READY=1`, `WATCHDOG=1`, `STATUS=`).
//! - [`handoff`]: pre-allocated lock-free rings between the loop and other threads.
//! - [`doorbell`]: wake-ups the loop requests and another thread delivers.
//! - [`shared`]: counters shared between the loop, the writer and housekeeping.
//! - [`worker`]: a helper thread that stops when asked.

pub mod clock;
pub mod doorbell;
pub mod handoff;
pub mod rt;
pub mod sd_notify;
pub mod shared;
pub mod worker;
