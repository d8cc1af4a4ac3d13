//! What a tick runs (SPEC §6): the controller seam, the gait controller
//! (planner link, executor, plant) and the conversion of its output to the
//! wire format.
//!
//! - [`controller`]: the seam: the `Controller` trait the loop drives.
//! - [`gait_controller`]: the real controller: planner + executor + plant.
//! - [`convert`]: maths types to wire types (status), in one place.
//! - [`planner`]: the planner thread and its lock-free link to the loop.

pub mod controller;
pub mod convert;
pub mod gait_controller;
pub mod planner;
