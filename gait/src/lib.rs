//! # gait — the mathematics of gaitd
//!
//! Pure library (no I/O, no clock reads, no threads) implementing the model of
//! SPEC.md §1–§3 and the paper *Object Reorientation with Finger Gaiting*:
//! a sphere of radius R held by three hemispherical fingertips of radius r,
//! rolling contacts, and force-closure grasp analysis.
//!
//! Conventions (SPEC §1.1): hand frame H with the object centre O at the
//! origin, z up; quaternions are unit Hamilton quaternions mapping body to
//! hand frame; SI units; angles in radians in code (degrees only in the
//! configuration file, in keys ending in `_deg`).
//!
//! Modules: [`grasp`] (Facts 1–4, the exact force-closure margin and grasp
//! force optimisation of SPEC §3) and [`hand`] (the hand model and the
//! per-tick check of the invariants of SPEC §1.3).
//!
//! Allocation and clocks: everything a control tick calls is
//! allocation-free except a Clarabel re-solve, which makes exactly one
//! 404-byte allocation inside clarabel 0.11.1 (its solve timers; measured in
//! `tests/allocations.rs`, details in [`grasp`]). Clarabel reads the
//! monotonic clock for those timers; nothing in this crate does, and no
//! result depends on time. The invariant check reaches Clarabel only for a
//! three-finger state that is not force-closure, and never with
//! [`hand::InvariantChecker::set_conic_fallback`]`(false)`.

pub mod config;
pub mod contact;
pub mod executor;
pub mod grasp;
pub mod hand;
pub mod hand_state;
pub mod planner;
pub mod rolling;
pub mod sim;
pub mod sphere;
pub mod trace;

pub use config::{ConfigError, HandConfig};
pub use hand_state::{FINGERS, FingerMode, FingerState, HandState};
