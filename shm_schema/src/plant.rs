//! daemon ↔ plant: [`PlantCommand`] (daemon → plant, every tick) and
//! [`PlantMeasurement`] (plant → daemon), the interface of a hand or a
//! simulator outside the daemon (SPEC §6.2, issue "Hands outside the
//! daemon").
//!
//! Every command carries the daemon's session id (random per daemon start),
//! its own sequence number and the sequence number of the measurement it
//! answers; every measurement echoes the session and the command it applied
//! and carries its own sequence number and the plant's clock (libfranka's
//! message ids, Drake's iiwa status/command pair, PX4 SITL's sim-time
//! stamps). A reader never trusts the other side: codes are checked with
//! [`PlantCommand::check`] / [`PlantMeasurement::check`] and numbers for
//! finiteness by the daemon.
//!
//! Timing ([`command_flags::LOCKSTEP`]): in lockstep the plant publishes
//! measurement k at its time t_k and waits; the daemon runs tick k with
//! now = t_k and publishes the command answering k; the plant then steps
//! to t_k + period and measures k + 1. In real time both run on their own
//! clocks and the daemon takes the newest measurement each tick.

use crate::FINGERS;
use crate::codes::{PlantFault, PlantFingerMode, UnknownCode};
use iceoryx2::prelude::ZeroCopySend;

/// Bits of [`PlantCommand::flags`].
pub mod command_flags {
    /// The daemon controls the hand: follow the setpoints. Without it (no
    /// valid state yet) the plant keeps what it has and moves nothing.
    pub const ENABLE: u32 = 1 << 0;
    /// Safe hold: the setpoint is still (zero velocity) and keeps the grasp;
    /// dropping the object is the unsafe action.
    pub const HOLD: u32 = 1 << 1;
    /// The daemon runs in lockstep with the plant (module docs).
    pub const LOCKSTEP: u32 = 1 << 2;
    /// Every bit defined.
    pub const ALL: u32 = ENABLE | HOLD | LOCKSTEP;
}

/// Bits of [`PlantMeasurement::valid`]: which fields hold a measurement.
pub mod measurement_valid {
    /// `object_q`.
    pub const OBJECT_ORIENTATION: u32 = 1 << 0;
    /// `object_omega`.
    pub const OBJECT_VELOCITY: u32 = 1 << 1;
    /// `object_center`.
    pub const OBJECT_CENTER: u32 = 1 << 2;
    /// Every finger's `position` and `orientation`.
    pub const TIP_POSE: u32 = 1 << 3;
    /// Every finger's `velocity` and `angular_velocity`.
    pub const TIP_VELOCITY: u32 = 1 << 4;
    /// Every finger's `contact`.
    pub const CONTACT: u32 = 1 << 5;
    /// Every finger's `normal_force`.
    pub const FORCE: u32 = 1 << 6;
    /// Every finger's `roll`.
    pub const ROLL: u32 = 1 << 7;
    /// What the daemon needs to control the hand.
    pub const REQUIRED: u32 = OBJECT_ORIENTATION | TIP_POSE | CONTACT | ROLL;
    /// Every bit defined.
    pub const ALL: u32 = OBJECT_ORIENTATION
        | OBJECT_VELOCITY
        | OBJECT_CENTER
        | TIP_POSE
        | TIP_VELOCITY
        | CONTACT
        | FORCE
        | ROLL;
}

/// Bits of [`PlantMeasurement::state`].
pub mod plant_state {
    /// The plant is a simulator.
    pub const SIMULATED: u32 = 1 << 0;
    /// The plant is paused (its clock stands still).
    pub const PAUSED: u32 = 1 << 1;
    /// The plant reports a fault of its own (`fault` says which).
    pub const FAULT: u32 = 1 << 2;
    /// Every bit defined.
    pub const ALL: u32 = SIMULATED | PAUSED | FAULT;
}

/// One fingertip's setpoint.
///
/// Type name `gaitd::PlantFingerCommand.v5`, 152 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantFingerCommand.v6")]
pub struct PlantFingerCommand {
    /// [`PlantFingerMode`] code.
    pub mode: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Fingertip centre, hand frame \[m\].
    pub position: [f64; 3],
    /// Fingertip orientation [w, x, y, z] (fingertip → hand frame).
    pub orientation: [f64; 4],
    /// Fingertip linear velocity, hand frame \[m/s\].
    pub velocity: [f64; 3],
    /// Fingertip angular velocity, hand frame \[rad/s\].
    pub angular_velocity: [f64; 3],
    /// Linear acceleration feed-forward, hand frame \[m/s²\].
    pub acceleration: [f64; 3],
    /// Commanded roll τ about the fingertip pole axis \[rad\] (SPEC §1.1).
    pub roll: f64,
    /// Intended normal (grip) force at the contact \[N\]; 0 when not grasping.
    pub grip_force: f64,
}

/// The daemon's setpoint for the plant, one per tick.
///
/// Type name `gaitd::PlantCommand.v5`, 560 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantCommand.v6")]
pub struct PlantCommand {
    /// The daemon's session id (random per daemon start).
    pub session: u64,
    /// Command sequence number, from 1, one more per command.
    pub seq: u64,
    /// Sequence number of the measurement this command answers (0: none).
    pub answers: u64,
    /// Plant time at which the setpoint is to hold \[ns\] (the answered
    /// measurement's time plus one period; 0 before any measurement).
    pub target_time_ns: u64,
    /// Control period \[ns\].
    pub period_ns: u64,
    /// [`command_flags`] bits.
    pub flags: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Object orientation setpoint [w, x, y, z] (object → hand frame).
    pub object_q: [f64; 4],
    /// Object angular velocity setpoint, hand frame \[rad/s\].
    pub object_omega: [f64; 3],
    /// Fingers f1, f2, f3.
    pub fingers: [PlantFingerCommand; FINGERS],
}

/// One fingertip as measured.
///
/// Type name `gaitd::PlantFingerMeasurement.v5`, 128 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantFingerMeasurement.v6")]
pub struct PlantFingerMeasurement {
    /// 1: the fingertip touches the object; 0: it does not.
    pub contact: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Fingertip centre, hand frame \[m\].
    pub position: [f64; 3],
    /// Fingertip orientation [w, x, y, z] (fingertip → hand frame).
    pub orientation: [f64; 4],
    /// Fingertip linear velocity, hand frame \[m/s\].
    pub velocity: [f64; 3],
    /// Fingertip angular velocity, hand frame \[rad/s\].
    pub angular_velocity: [f64; 3],
    /// Roll τ about the fingertip pole axis \[rad\] (a hand's twist joint).
    pub roll: f64,
    /// Normal force at the contact \[N\].
    pub normal_force: f64,
}

/// What the plant measured, one per plant step (lockstep) or sample.
///
/// Type name `gaitd::PlantMeasurement.v5`, 512 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantMeasurement.v6")]
pub struct PlantMeasurement {
    /// Session id of the last command applied (0 before the first one).
    pub session: u64,
    /// Measurement sequence number, from 1, one more per measurement.
    pub seq: u64,
    /// Sequence number of the last command applied (0: none yet).
    pub applied: u64,
    /// Sample time on the plant's clock \[ns\] (simulated time for a
    /// simulator).
    pub time_ns: u64,
    /// [`measurement_valid`] bits.
    pub valid: u32,
    /// [`plant_state`] bits.
    pub state: u32,
    /// [`PlantFault`] code (with `plant_state::FAULT`; else 0).
    pub fault: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Object orientation [w, x, y, z] (object → hand frame).
    pub object_q: [f64; 4],
    /// Object angular velocity, hand frame \[rad/s\].
    pub object_omega: [f64; 3],
    /// Object centre, hand frame \[m\] (the model keeps it at the origin).
    pub object_center: [f64; 3],
    /// Fingers f1, f2, f3.
    pub fingers: [PlantFingerMeasurement; FINGERS],
}

const _: () = assert!(core::mem::size_of::<PlantFingerCommand>() == 152);
const _: () = assert!(core::mem::size_of::<PlantCommand>() == 560);
const _: () = assert!(core::mem::size_of::<PlantFingerMeasurement>() == 128);
const _: () = assert!(core::mem::size_of::<PlantMeasurement>() == 512);
const _: () = assert!(core::mem::align_of::<PlantMeasurement>() == 8);

fn bits(kind: &'static str, value: u32, all: u32) -> Result<(), UnknownCode> {
    if value & !all != 0 {
        return Err(UnknownCode { kind, code: value });
    }
    Ok(())
}

impl PlantCommand {
    /// Checks every code (a plant never trusts the daemon's bytes either).
    pub fn check(&self) -> Result<(), UnknownCode> {
        bits("command flags", self.flags, command_flags::ALL)?;
        for f in &self.fingers {
            PlantFingerMode::try_from(f.mode)?;
        }
        Ok(())
    }
}

impl PlantMeasurement {
    /// Checks every code and bit field (the daemon never trusts a plant's
    /// bytes; numbers are checked where they are used).
    pub fn check(&self) -> Result<(), UnknownCode> {
        bits("measurement valid bits", self.valid, measurement_valid::ALL)?;
        bits("plant state bits", self.state, plant_state::ALL)?;
        let fault = PlantFault::try_from(self.fault)?;
        if (fault != PlantFault::None) != (self.state & plant_state::FAULT != 0) {
            return Err(UnknownCode {
                kind: "plant fault without the FAULT bit (or the reverse)",
                code: self.fault,
            });
        }
        for f in &self.fingers {
            if f.contact > 1 {
                return Err(UnknownCode {
                    kind: "contact flag",
                    code: f.contact,
                });
            }
        }
        Ok(())
    }

    /// Decoded fault.
    pub fn fault(&self) -> Result<PlantFault, UnknownCode> {
        PlantFault::try_from(self.fault)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_bits_are_checked() {
        let mut m = PlantMeasurement {
            valid: measurement_valid::REQUIRED,
            ..PlantMeasurement::default()
        };
        m.check().unwrap();
        m.valid |= 1 << 20;
        assert!(m.check().is_err());
        m.valid = measurement_valid::REQUIRED;
        m.fault = PlantFault::EmergencyStop.code();
        assert!(m.check().is_err(), "a fault code needs the FAULT bit");
        m.state = plant_state::FAULT;
        m.check().unwrap();
        m.fingers[1].contact = 2;
        assert!(m.check().is_err());
        let mut c = PlantCommand::default();
        assert!(c.check().is_err(), "mode 0 is no mode");
        for f in &mut c.fingers {
            f.mode = PlantFingerMode::Grasping.code();
        }
        c.check().unwrap();
        c.flags = 1 << 9;
        assert!(c.check().is_err());
    }
}
