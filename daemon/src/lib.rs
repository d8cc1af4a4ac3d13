//! # gaitd — the daemon's library part
//!
//! Configuration loading and validation (SPEC.md §7.1). The binary in
//! `main.rs` is a thin shell around this library so that tests can drive the
//! same code.

pub mod config;
