//! # gaitd — the daemon's library part
//!
//! Everything of the `gaitd` binary except argument parsing lives here so
//! that tests drive the same code (SPEC.md §7). One module per concept:
//!
//! - [`config`]: the TOML file, every key validated by name;
//! - [`clock`], [`ticker`]: injected time and absolute-deadline wake-ups;
//! - [`runtime`]: the real-time loop and its phases, shutdown;
//! - [`controller`]: the seam where the controller plugs in;
//!   [`gait_controller`] is the real one (planner, executor, kinematic
//!   hand), [`hold`] a still stand-in the tests use;
//! - [`intake`], [`convert`], [`events`]: commands in, status and events out;
//! - [`ipc`]: iceoryx2 services and ports; [`outbox`]: the writer thread
//!   that publishes what the loop produced (the loop never publishes);
//! - [`planner`], [`handoff`]: the planner thread and its lock-free link;
//! - [`tracer`]: goal traces (`gait-trajectory/1`) written off the loop;
//! - [`housekeeping`]: dead-node cleanup, client bookkeeping, rate-limited
//!   warnings, `STATUS=`;
//! - [`stats`], [`histogram`]: loop timing;
//! - [`rt`], [`sd_notify`], [`signals`], [`logging`]: the process around it.

pub mod clock;
pub mod config;
pub mod controller;
pub mod convert;
pub mod events;
pub mod gait_controller;
pub mod handoff;
pub mod histogram;
pub mod hold;
pub mod housekeeping;
pub mod intake;
pub mod ipc;
pub mod logging;
pub mod outbox;
pub mod planner;
pub mod rt;
pub mod runtime;
pub mod sd_notify;
pub mod signals;
pub mod stats;
pub mod ticker;
pub mod tracer;
pub mod worker;

/// A random id for this daemon run (clients see a restart as a new id).
pub fn new_instance_id() -> u64 {
    let mut v = 0u64;
    // SAFETY: writes at most 8 bytes into v.
    let n = unsafe { libc::getrandom((&raw mut v).cast(), 8, 0) };
    if n != 8 || v == 0 {
        // No entropy source: fall back to time and pid (unique enough per host).
        v = clock::monotonic_now() ^ (u64::from(std::process::id()) << 32) | 1;
    }
    v
}
