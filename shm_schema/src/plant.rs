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
//! Fingertips or joints: a hand of free fingertips is commanded and
//! measured by its tips' poses. A hand of finger joint chains
//! ([`command_flags::JOINTS`]) is commanded per joint, in the shape of a
//! TriFinger action — position and velocity setpoints, a feed-forward
//! torque, PD gains; the motor law `τ = τ_ff + kp·(q* − q) + kd·(q̇* − q̇)`
//! — beside the tips those joints put where the fingertip fields say; it
//! measures its joints ([`measurement_valid::JOINT_POSITION`]) and the
//! daemon's forward kinematics makes the tips from them.
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
    /// The hand is a chain hand: each finger's joint fields hold its
    /// setpoint (`joint_count` joints), and a joint-level plant follows
    /// them (module docs).
    pub const JOINTS: u32 = 1 << 3;
    /// Every bit defined.
    pub const ALL: u32 = ENABLE | HOLD | LOCKSTEP | JOINTS;
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
    /// Every finger's `joint_position` (`joint_count` joints).
    pub const JOINT_POSITION: u32 = 1 << 8;
    /// Every finger's `joint_velocity`.
    pub const JOINT_VELOCITY: u32 = 1 << 9;
    /// Every finger's `joint_torque` (the torque applied).
    pub const JOINT_TORQUE: u32 = 1 << 10;
    /// What the daemon needs to control a hand of free fingertips.
    pub const REQUIRED: u32 = OBJECT_ORIENTATION | TIP_POSE | CONTACT | ROLL;
    /// What the daemon needs to control a hand of finger chains (the tips
    /// it makes from the joints; tip poses, if sent too, are not read).
    pub const REQUIRED_JOINTS: u32 = OBJECT_ORIENTATION | JOINT_POSITION | CONTACT;
    /// Every bit defined.
    pub const ALL: u32 = OBJECT_ORIENTATION
        | OBJECT_VELOCITY
        | OBJECT_CENTER
        | TIP_POSE
        | TIP_VELOCITY
        | CONTACT
        | FORCE
        | ROLL
        | JOINT_POSITION
        | JOINT_VELOCITY
        | JOINT_TORQUE;
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

/// Most joints a finger's command and measurement carry.
pub const MAX_JOINTS: usize = 4;

/// One finger's setpoint: its tip, and on a chain hand its joints.
///
/// Type name `gaitd::PlantFingerCommand.v8`, 312 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantFingerCommand.v8")]
pub struct PlantFingerCommand {
    /// [`PlantFingerMode`] code.
    pub mode: u32,
    /// Joints the joint fields hold, base to tip (0 on free fingertips;
    /// at most [`MAX_JOINTS`]); the rest of each array is 0.
    pub joint_count: u32,
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
    /// Joint position setpoints \[rad\].
    pub joint_position: [f64; MAX_JOINTS],
    /// Joint velocity setpoints \[rad/s\].
    pub joint_velocity: [f64; MAX_JOINTS],
    /// Feed-forward joint torques \[N·m\]: the grip through the tip's
    /// Jacobian, Jᵀ·f, plus the links' weight where the daemon compensates
    /// it.
    pub joint_torque: [f64; MAX_JOINTS],
    /// Position gains \[N·m/rad\].
    pub kp: [f64; MAX_JOINTS],
    /// Velocity gains \[N·m·s/rad\].
    pub kd: [f64; MAX_JOINTS],
}

/// The daemon's setpoint for the plant, one per tick.
///
/// Type name `gaitd::PlantCommand.v8`, 1040 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantCommand.v8")]
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

/// One finger as measured: its tip, and on a chain hand its joints.
///
/// Type name `gaitd::PlantFingerMeasurement.v8`, 224 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantFingerMeasurement.v8")]
pub struct PlantFingerMeasurement {
    /// 1: the fingertip touches the object; 0: it does not.
    pub contact: u32,
    /// Joints the joint fields hold, base to tip (at most
    /// [`MAX_JOINTS`]; 0 on free fingertips).
    pub joint_count: u32,
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
    /// Joint positions \[rad\].
    pub joint_position: [f64; MAX_JOINTS],
    /// Joint velocities \[rad/s\].
    pub joint_velocity: [f64; MAX_JOINTS],
    /// Joint torques applied \[N·m\] (after the hand's own limits).
    pub joint_torque: [f64; MAX_JOINTS],
}

/// What the plant measured, one per plant step (lockstep) or sample.
///
/// Type name `gaitd::PlantMeasurement.v8`, 800 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::PlantMeasurement.v8")]
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
    /// How long before `time_ns` the object's pose (`object_q`,
    /// `object_omega`, `object_center`) was sampled \[µs\]: a tracking
    /// system's latency and the age of its last sample (0: sampled with
    /// the rest of the measurement).
    pub object_age_us: u32,
    /// Object orientation [w, x, y, z] (object → hand frame).
    pub object_q: [f64; 4],
    /// Object angular velocity, hand frame \[rad/s\].
    pub object_omega: [f64; 3],
    /// Object centre, hand frame \[m\] (the model keeps it at the origin).
    pub object_center: [f64; 3],
    /// Fingers f1, f2, f3.
    pub fingers: [PlantFingerMeasurement; FINGERS],
}

const _: () = assert!(core::mem::size_of::<PlantFingerCommand>() == 312);
const _: () = assert!(core::mem::size_of::<PlantCommand>() == 1040);
const _: () = assert!(core::mem::size_of::<PlantFingerMeasurement>() == 224);
const _: () = assert!(core::mem::size_of::<PlantMeasurement>() == 800);
const _: () = assert!(core::mem::align_of::<PlantMeasurement>() == 8);

fn bits(kind: &'static str, value: u32, all: u32) -> Result<(), UnknownCode> {
    if value & !all != 0 {
        return Err(UnknownCode { kind, code: value });
    }
    Ok(())
}

fn joint_count(n: u32) -> Result<(), UnknownCode> {
    if n as usize > MAX_JOINTS {
        return Err(UnknownCode {
            kind: "joint count",
            code: n,
        });
    }
    Ok(())
}

impl PlantCommand {
    /// Checks every code (a plant never trusts the daemon's bytes either).
    pub fn check(&self) -> Result<(), UnknownCode> {
        bits("command flags", self.flags, command_flags::ALL)?;
        for f in &self.fingers {
            PlantFingerMode::try_from(f.mode)?;
            joint_count(f.joint_count)?;
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
            joint_count(f.joint_count)?;
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
        m.fingers[1].contact = 1;
        m.fingers[2].joint_count = MAX_JOINTS as u32;
        m.check().unwrap();
        m.fingers[2].joint_count = MAX_JOINTS as u32 + 1;
        assert!(m.check().is_err(), "more joints than the arrays hold");
        let mut c = PlantCommand::default();
        assert!(c.check().is_err(), "mode 0 is no mode");
        for f in &mut c.fingers {
            f.mode = PlantFingerMode::Grasping.code();
        }
        c.check().unwrap();
        c.flags = command_flags::JOINTS;
        c.fingers[0].joint_count = 3;
        c.check().unwrap();
        c.fingers[0].joint_count = 5;
        assert!(c.check().is_err(), "more joints than the arrays hold");
        c.fingers[0].joint_count = 3;
        c.flags = 1 << 9;
        assert!(c.check().is_err());
    }
}
