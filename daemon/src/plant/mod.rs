//! The hand the controller drives (SPEC §6.2): the embedded kinematic hand
//! in process, or a hand or simulator in another process over the plant
//! services (shm_schema `PLANT-GUIDE.md`).
//!
//! - [`external`]: the external plant's link on the loop side: checks every
//!   measurement (session, sequence, age, codes, numbers), holds the last
//!   one for a few ticks, detects a plant that is lost, lies or stalls, and
//!   numbers the commands;
//! - [`contract`]: the timing contract: commands and measurements late or
//!   repeated, counted, and a run of misses faulted;
//! - [`wire`]: measurements and commands ↔ the maths types;
//! - [`joints`]: a chain hand's joints on the link (measured joints → tips,
//!   the command's joint setpoints, feed-forward torques and gains);
//! - [`ports`]: the loop thread's receiving end (iceoryx2 subscriber and
//!   listener), which also paces the loop in lockstep.

pub mod contract;
pub mod external;
pub mod joints;
pub mod ports;
pub mod wire;

use crate::sys::clock::Nanos;
use gait::sim::KinematicHand;
use shm_schema::PlantMeasurement;

/// What the loop received from an external plant for this tick.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlantSample {
    /// The newest measurement received since the last tick, if any.
    pub newest: Option<PlantMeasurement>,
    /// How many measurements arrived since the last tick.
    pub received: u32,
    /// Wall-clock (CLOCK_MONOTONIC) time the newest one was taken from the
    /// service \\[ns\\].
    pub received_at: Nanos,
    /// Lockstep: no measurement came within `plant.lockstep_timeout_ms`.
    pub timed_out: bool,
    /// The plant missed its timing contract `plant.max_misses_in_row`
    /// ticks in a row ([`contract`]): a fault.
    pub contract_broken: bool,
}

/// The hand behind the gait controller.
#[derive(Debug)]
pub enum Hand {
    /// The embedded kinematic hand (executes every setpoint exactly).
    Embedded(KinematicHand),
    /// A plant in another process.
    External(external::ExternalPlant),
}
