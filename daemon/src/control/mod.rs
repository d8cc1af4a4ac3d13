//! What a tick runs (SPEC §6): the controller seam and the events a tick
//! produces, the gait controller (planner link, executor, plant), the
//! planner thread, and the conversion of the controller's output to the
//! wire format.
//!
//! - [`controller`]: the seam: the `Controller` trait the loop drives.
//! - [`tick_events`]: the events of one tick: the queue a controller fills and
//!   the loop publishes.
//! - [`gait_controller`]: the real controller: planner + executor + plant.
//! - [`convert`]: maths types to wire types (status), in one place.
//! - [`plan_thread`]: the planner thread and its lock-free link to the loop.

pub mod controller;
pub mod convert;
pub mod gait_controller;
pub mod plan_thread;
pub mod tick_events;
