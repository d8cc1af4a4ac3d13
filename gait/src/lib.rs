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

pub mod config;
pub mod contact;
pub mod executor;
pub mod grasp;
pub mod hand;
pub mod planner;
pub mod rolling;
pub mod sim;
pub mod sphere;
pub mod state;
pub mod trace;

pub use config::{ConfigError, HandConfig};
pub use state::{FINGERS, FingerMode, FingerState, HandState};
