//! The real-time loop thread (SPEC §6.1, §7.2): absolute deadlines, the
//! tick's phases, lockstep pacing, command intake and timing statistics.
//! The loop drives a [`Controller`](crate::control::controller::Controller),
//! reads an external plant's input and hands its output to the writer
//! thread. Nothing here allocates, blocks or logs once running.
//!
//! - [`ticker`]: absolute-deadline wake-ups; missed periods counted, never burst.
//! - [`runtime`]: the loop and its phases, shutdown.
//! - [`lockstep`]: lockstep pacing: a plant's measurements pace the loop.
//! - [`intake`]: commands in: validation, duplicate ids, answers.
//! - [`stats`]: loop timing: compute time, jitter, overruns.
//! - [`histogram`]: fixed-size latency histograms.

pub mod histogram;
pub mod intake;
pub mod lockstep;
pub mod runtime;
pub mod stats;
pub mod ticker;
