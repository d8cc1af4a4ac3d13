//! The layouts of the plant's payloads (SPEC §6.2): what the daemon
//! commands a hand outside it, and what that hand measures.

use super::{TypeLayout, field, layout};
use crate::*;
use core::mem::offset_of;

/// The plant's payload types, nested types after the types that use them.
pub(super) fn layouts() -> Vec<TypeLayout> {
    vec![
        layout::<PlantCommand>(
            "PlantCommand",
            vec![
                f!(
                    PlantCommand,
                    session,
                    "",
                    "daemon session id, random per start"
                ),
                f!(
                    PlantCommand,
                    seq,
                    "",
                    "command sequence number, from 1, +1 each"
                ),
                f!(
                    PlantCommand,
                    answers,
                    "",
                    "seq of the measurement it answers, 0 = none"
                ),
                f!(
                    PlantCommand,
                    target_time_ns,
                    "ns",
                    "plant time the setpoint holds at: answered time + period"
                ),
                f!(PlantCommand, period_ns, "ns", "control period"),
                f!(
                    PlantCommand,
                    flags,
                    "bits",
                    "1 ENABLE (without it: move nothing, still echo the command), 2 HOLD (safe hold: still, grasp kept), 4 LOCKSTEP, 8 JOINTS (a chain hand: follow the joint fields)"
                ),
                f!(PlantCommand, reserved, "", "padding, 0"),
                f!(
                    PlantCommand,
                    object_q,
                    "[w,x,y,z]",
                    "object orientation setpoint, object → hand: what the controller wants, never to be copied into a measurement"
                ),
                f!(
                    PlantCommand,
                    object_omega,
                    "rad/s",
                    "object angular velocity setpoint, hand frame"
                ),
                f!(
                    PlantCommand,
                    fingers,
                    "PlantFingerCommand",
                    "fingers f1, f2, f3"
                ),
            ],
        ),
        layout::<PlantFingerCommand>(
            "PlantFingerCommand",
            vec![
                f!(
                    PlantFingerCommand,
                    mode,
                    "PlantFingerMode",
                    "what the fingertip does"
                ),
                f!(
                    PlantFingerCommand,
                    joint_count,
                    "",
                    "joints the joint fields hold, base to tip (0 on free fingertips, at most 4)"
                ),
                f!(
                    PlantFingerCommand,
                    position,
                    "m",
                    "fingertip centre, hand frame (chains: relative to the object's centre O)"
                ),
                f!(
                    PlantFingerCommand,
                    orientation,
                    "[w,x,y,z]",
                    "fingertip orientation Q_f, fingertip → hand; pole axis Q_f e_z"
                ),
                f!(
                    PlantFingerCommand,
                    velocity,
                    "m/s",
                    "linear velocity, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    angular_velocity,
                    "rad/s",
                    "angular velocity, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    acceleration,
                    "m/s²",
                    "linear acceleration feed-forward, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    roll,
                    "rad",
                    "commanded roll τ about the pole axis (τ̇ = ω_f · Q_f e_z, 0 in the start grasp)"
                ),
                f!(
                    PlantFingerCommand,
                    grip_force,
                    "N",
                    "intended normal force, 0 when not grasping"
                ),
                f!(
                    PlantFingerCommand,
                    joint_position,
                    "rad",
                    "joint position setpoints q*"
                ),
                f!(
                    PlantFingerCommand,
                    joint_velocity,
                    "rad/s",
                    "joint velocity setpoints q̇*"
                ),
                f!(
                    PlantFingerCommand,
                    joint_torque,
                    "N·m",
                    "feed-forward torque τ_ff: the grip through the tip Jacobian, Jᵀf, plus the links' weight where compensated"
                ),
                f!(
                    PlantFingerCommand,
                    kp,
                    "N·m/rad",
                    "position gain: motor torque τ_ff + kp (q* − q) + kd (q̇* − q̇)"
                ),
                f!(PlantFingerCommand, kd, "N·m·s/rad", "velocity gain"),
            ],
        ),
        layout::<PlantMeasurement>(
            "PlantMeasurement",
            vec![
                f!(
                    PlantMeasurement,
                    session,
                    "",
                    "session of the last command applied, 0 = none yet"
                ),
                f!(
                    PlantMeasurement,
                    seq,
                    "",
                    "measurement sequence number, from 1, +1 each (the daemon takes any increase)"
                ),
                f!(
                    PlantMeasurement,
                    applied,
                    "",
                    "seq of the last command applied, 0 = none"
                ),
                f!(
                    PlantMeasurement,
                    time_ns,
                    "ns",
                    "sample time, plant clock: later than the last within a plant run"
                ),
                f!(
                    PlantMeasurement,
                    valid,
                    "bits",
                    "valid fields: 1 object_q, 2 object_omega, 4 object_center, 8 tip pose, \
                     16 tip velocity, 32 contact, 64 normal_force, 128 roll, 256 joint positions, \
                     512 joint velocities, 1024 joint torques (required: 1, 8, 32, 128; chains: 1, 32, 256)"
                ),
                f!(
                    PlantMeasurement,
                    state,
                    "bits",
                    "1 SIMULATED, 2 PAUSED, 4 FAULT"
                ),
                f!(
                    PlantMeasurement,
                    fault,
                    "PlantFault",
                    "with FAULT: the plant's fault"
                ),
                f!(
                    PlantMeasurement,
                    object_age_us,
                    "µs",
                    "how long before time_ns the object's pose was sampled (a tracker's latency; 0: with the rest)"
                ),
                f!(
                    PlantMeasurement,
                    object_q,
                    "[w,x,y,z]",
                    "object orientation, object → hand"
                ),
                f!(
                    PlantMeasurement,
                    object_omega,
                    "rad/s",
                    "object angular velocity, hand frame"
                ),
                f!(
                    PlantMeasurement,
                    object_center,
                    "m",
                    "object centre, hand frame"
                ),
                f!(
                    PlantMeasurement,
                    fingers,
                    "PlantFingerMeasurement",
                    "fingers f1, f2, f3"
                ),
            ],
        ),
        layout::<PlantFingerMeasurement>(
            "PlantFingerMeasurement",
            vec![
                f!(
                    PlantFingerMeasurement,
                    contact,
                    "0/1",
                    "1 = touching the object"
                ),
                f!(
                    PlantFingerMeasurement,
                    joint_count,
                    "",
                    "joints the joint fields hold, base to tip (chains: the hand's, 0 on free fingertips)"
                ),
                f!(
                    PlantFingerMeasurement,
                    position,
                    "m",
                    "fingertip centre, hand frame (not read on chains: the joints give it)"
                ),
                f!(
                    PlantFingerMeasurement,
                    orientation,
                    "[w,x,y,z]",
                    "fingertip orientation, fingertip → hand"
                ),
                f!(
                    PlantFingerMeasurement,
                    velocity,
                    "m/s",
                    "linear velocity, hand frame"
                ),
                f!(
                    PlantFingerMeasurement,
                    angular_velocity,
                    "rad/s",
                    "angular velocity, hand frame"
                ),
                f!(
                    PlantFingerMeasurement,
                    roll,
                    "rad",
                    "roll τ about the pole axis, as the command's"
                ),
                f!(
                    PlantFingerMeasurement,
                    normal_force,
                    "N",
                    "normal force at the contact"
                ),
                f!(
                    PlantFingerMeasurement,
                    joint_position,
                    "rad",
                    "joint positions"
                ),
                f!(
                    PlantFingerMeasurement,
                    joint_velocity,
                    "rad/s",
                    "joint velocities"
                ),
                f!(
                    PlantFingerMeasurement,
                    joint_torque,
                    "N·m",
                    "joint torques applied, after the hand's own limits"
                ),
            ],
        ),
    ]
}
