//! The process around the loop (SPEC §7.1): the start-up that builds and
//! wires every other part of the daemon, `--check-config`, signals, logging
//! and housekeeping.
//!
//! - [`startup`]: the start-up steps in their order, and the shut-down.
//! - [`check`]: what `--check-config` prints: the configuration in effect.
//! - [`hand_setup`]: the configured hand (fingertips or chains), read
//!   and checked.
//! - [`load_check`]: whether the start grasp can hold the load.
//! - [`housekeeping`]: dead-node cleanup, client bookkeeping, `STATUS=`,
//!   rate-limited warnings for what the loop counted.
//! - [`signals`]: SIGTERM/SIGINT handling.
//! - [`logging`]: tracing set-up: human or JSON logs.

pub mod check;
pub mod hand_setup;
pub mod housekeeping;
pub mod load_check;
pub mod logging;
pub mod signals;
pub mod startup;
