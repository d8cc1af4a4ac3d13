//! # gaitd — the daemon's library part
//!
//! Everything of the `gaitd` binary except argument parsing lives here so
//! that tests drive the same code (SPEC.md §7). The folders are the
//! daemon's design, each using only those below it:
//!
//! ```text
//!  process/   the process around it: start-up (which builds and wires every
//!             part below), --check-config, signals, logs, housekeeping
//!  realtime/  the loop thread: deadlines, the tick's phases, lockstep
//!             pacing, command intake, timing statistics   (never allocates)
//!  control/   what a tick runs: the controller seam and the tick's events,
//!             the gait controller (planner link + executor + plant), the
//!             planner thread, status conversion
//!  plant/     the hand: the embedded kinematic hand or an external plant's
//!             link (checks, held measurements, faults, timing contract)
//!  io/        off the loop: iceoryx2 services and ports, the writer thread
//!             (outbox), goal traces
//!  config/    the configuration file, every key validated
//!  sys/       time, real-time set-up, systemd, and what threads share:
//!             rings, doorbells, counters, stoppable threads
//! ```
//!
//! `config/` and `sys/` use none of the others.
//!
//! Data flows one way per tick: commands → [`realtime::intake`] →
//! [`control::controller::Controller`] → [`control::tick_events`] and
//! [`control::convert`] → [`io::outbox`] (published by the writer thread).

// Lets the test-support files shared with the integration tests name
// this crate `gaitd` in the crate's own unit tests.
#[cfg(test)]
extern crate self as gaitd;

pub mod config;
pub mod control;
pub mod io;
pub mod plant;
pub mod process;
pub mod realtime;
pub mod sys;

// The still test controller, shared with the integration tests.
#[cfg(test)]
#[path = "../tests/support/hold.rs"]
mod hold;

/// A random id for this daemon run (clients see a restart as a new id).
pub fn new_instance_id() -> u64 {
    let mut v = 0u64;
    // SAFETY: writes at most 8 bytes into v.
    let n = unsafe { libc::getrandom((&raw mut v).cast(), 8, 0) };
    if n != 8 || v == 0 {
        // No entropy source: fall back to time and pid (unique enough per host).
        v = sys::clock::monotonic_now() ^ (u64::from(std::process::id()) << 32) | 1;
    }
    v
}
