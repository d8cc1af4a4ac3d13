//! The real-time loop thread (SPEC §6.1, §7.2): injected time, absolute
//! deadlines, the tick's phases, command intake, events and timing
//! statistics. Nothing here allocates, blocks or logs once running.
//!
//! - [`ticker`]: absolute-deadline wake-ups; missed periods counted, never burst.
//! - [`runtime`]: the loop and its phases, shutdown.
//! - [`lockstep`]: lockstep pacing: a plant's measurements pace the loop.
//! - [`intake`]: commands in: validation, duplicate ids, answers.
//! - [`events`]: events out: the per-tick queue of wire events.
//! - [`stats`]: loop timing: compute time, jitter, overruns.
//! - [`histogram`]: fixed-size latency histograms.

pub mod events;
pub mod histogram;
pub mod intake;
pub mod lockstep;
pub mod runtime;
pub mod stats;
pub mod ticker;
