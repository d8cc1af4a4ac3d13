//! Threads off the loop (SPEC §7.2, §7.3): iceoryx2 services and ports, the
//! writer that publishes what the loop produced, goal traces and
//! housekeeping.
//!
//! - [`ipc`]: iceoryx2 services and ports.
//! - [`outbox`]: the writer thread: publishes status, answers and events.
//! - [`tracer`]: goal traces (`gait-trajectory/1`) written off the loop.
//! - [`housekeeping`]: dead-node cleanup, client bookkeeping, `STATUS=`.

pub mod housekeeping;
pub mod ipc;
pub mod outbox;
pub mod tracer;
