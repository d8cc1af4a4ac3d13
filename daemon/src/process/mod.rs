//! The process around the loop (SPEC §7.1): configuration, real-time
//! set-up, systemd notification, signals and logging.
//!
//! - [`check`]: what `--check-config` prints: the configuration in effect.
//! - [`load_check`]: whether the start grasp can hold the load.
//! - [`signals`]: SIGTERM/SIGINT handling.
//! - [`logging`]: tracing set-up: human or JSON logs.
//! - [`startup`]: the start-up steps in their order, and the shut-down.

pub mod check;
pub mod load_check;
pub mod logging;
pub mod signals;
pub mod startup;
