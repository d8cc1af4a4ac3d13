//! iceoryx2 and the threads that publish off the loop (SPEC §7.2, §7.3):
//! services and ports, the writer that publishes what the loop produced,
//! goal traces.
//!
//! - [`ipc`]: iceoryx2 services and ports.
//! - [`outbox`]: the writer thread: publishes status, answers and events.
//! - [`plan_paths`]: each plan's path, published by the planner thread.
//! - [`tracer`]: goal traces (`gait-trajectory/1`) written off the loop.

pub mod ipc;
pub mod outbox;
pub mod plan_paths;
pub mod tracer;
