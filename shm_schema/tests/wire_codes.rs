//! Every number that crosses the process boundary, pinned to a literal.
//!
//! The code tables and LAYOUT.md are generated from the same tokens as the
//! enums, so they follow a renumbering (and a bless makes it pass). These
//! numbers are written out by hand instead: changing a wire code fails here
//! until this file is changed too, which must come with a new
//! `SCHEMA_VERSION` (C and Python clients read the same numbers).

use core::fmt::Debug;
use shm_schema::codes::UnknownCode;
use shm_schema::{
    AnswerCode, CommandKind, DaemonState, EventKind, FaultCode, FingerPhase, GoalFrame, GoalState,
    GraspState, LimitKind, LimitOrder, Phase, ReasonCode, limit_bit,
};

/// Each `(variant, code)` encodes to `code` and `code` decodes to the
/// variant, and the pins name every variant once (a new variant needs one).
fn pin<T>(all: &[T], pins: &[(T, u32)])
where
    T: Copy + Eq + Debug + TryFrom<u32, Error = UnknownCode> + Into<u32>,
{
    for &(v, code) in pins {
        assert_eq!(v.into(), code, "{v:?} encodes to another number");
        assert_eq!(
            T::try_from(code),
            Ok(v),
            "{code} decodes to another variant"
        );
    }
    for v in all {
        let n = pins.iter().filter(|(p, _)| p == v).count();
        assert_eq!(n, 1, "{v:?} is pinned {n} times");
    }
    assert_eq!(all.len(), pins.len());
}

#[test]
fn schema_version_is_pinned() {
    assert_eq!(shm_schema::SCHEMA_VERSION, 8);
}

#[test]
fn command_kind_codes() {
    use CommandKind::*;
    pin(
        CommandKind::ALL,
        &[(Goal, 1), (Cancel, 2), (Hold, 3), (Reset, 4)],
    );
    assert!(
        CommandKind::try_from(0).is_err(),
        "an all-zero command is refused"
    );
}

#[test]
fn goal_frame_codes() {
    use GoalFrame::*;
    pin(
        GoalFrame::ALL,
        &[(Absolute, 1), (Relative, 2), (AxisAngle, 3)],
    );
}

#[test]
fn answer_codes() {
    use AnswerCode::*;
    pin(AnswerCode::ALL, &[(Accepted, 1), (Rejected, 2)]);
}

#[test]
fn goal_state_codes() {
    use GoalState::*;
    pin(
        GoalState::ALL,
        &[
            (None, 0),
            (Accepted, 1),
            (Planning, 2),
            (Executing, 3),
            (Succeeded, 4),
            (Aborted, 5),
            (Canceled, 6),
            (Preempted, 7),
            (Rejected, 8),
        ],
    );
}

#[test]
fn reason_codes() {
    use ReasonCode::*;
    pin(
        ReasonCode::ALL,
        &[
            (None, 0),
            (UnknownCommandKind, 1),
            (UnknownGoalFrame, 2),
            (ZeroGoalId, 3),
            (ZeroClientId, 4),
            (NonFiniteQuaternion, 5),
            (ZeroQuaternion, 6),
            (NonUnitQuaternion, 7),
            (BadLimitMask, 8),
            (NonFiniteLimit, 9),
            (NonPositiveLimit, 10),
            (NonZeroReserved, 11),
            (DuplicateGoalId, 12),
            (LimitAboveConfigured, 13),
            (PlannerUnavailable, 14),
            (Faulted, 15),
            (UnknownGoalId, 16),
            (NoActiveGoal, 17),
            (ShuttingDown, 18),
            (NoPlan, 19),
            (NotFaulted, 20),
            (PreemptedByGoal, 21),
            (CanceledByClient, 22),
            (HoldRequested, 23),
            (FaultDetected, 24),
            (Reached, 25),
            (BadAxisAngle, 26),
            (LimitBelowMinimum, 27),
            (StartNotForceClosure, 28),
            (StartNotFinite, 29),
            (NoTwoFingerGrasp, 30),
            (FingerBlocked, 31),
            (InvalidGoalTarget, 32),
            (MeasuredStateInvalid, 33),
            (LoadInfeasible, 34),
            (PlanTimeout, 35),
            (NoFreshMeasurement, 36),
            (NotAtRest, 37),
        ],
    );
}

#[test]
fn phase_codes() {
    use Phase::*;
    pin(
        Phase::ALL,
        &[
            (Hold, 1),
            (Roll, 2),
            (Rotate, 3),
            (Place, 4),
            (Lift, 5),
            (Stopping, 6),
            (SafeHold, 7),
        ],
    );
}

#[test]
fn finger_phase_codes() {
    use FingerPhase::*;
    pin(
        FingerPhase::ALL,
        &[
            (Grasping, 1),
            (Rolling, 2),
            (Lifting, 3),
            (Free, 4),
            (Placing, 5),
        ],
    );
}

#[test]
fn grasp_state_codes() {
    use GraspState::*;
    pin(
        GraspState::ALL,
        &[(Unknown, 0), (ForceClosure, 1), (NotForceClosure, 2)],
    );
}

#[test]
fn fault_codes() {
    use FaultCode::*;
    pin(
        FaultCode::ALL,
        &[
            (None, 0),
            (ForceClosureLost, 1),
            (WorkspaceViolation, 2),
            (FingertipViolation, 3),
            (FingertipCollision, 4),
            (Slip, 5),
            (MeasurementMissing, 6),
            (StuckFinger, 7),
            (NonFiniteState, 8),
            (PlantLost, 9),
            (PlantInvalid, 10),
            (PlantSequence, 11),
            (PlantFault, 12),
            (ContactLost, 13),
            (PlantWaiting, 14),
            (PlantTiming, 15),
        ],
    );
}

#[test]
fn plant_codes_and_bits() {
    use shm_schema::{PlantFault, PlantFingerMode, command_flags, measurement_valid, plant_state};
    pin(
        PlantFingerMode::ALL,
        &[
            (PlantFingerMode::Grasping, 1),
            (PlantFingerMode::Free, 2),
            (PlantFingerMode::Placing, 3),
            (PlantFingerMode::Lifting, 4),
        ],
    );
    pin(
        PlantFault::ALL,
        &[
            (PlantFault::None, 0),
            (PlantFault::EmergencyStop, 1),
            (PlantFault::Hardware, 2),
            (PlantFault::Limit, 3),
            (PlantFault::Diverged, 4),
            (PlantFault::Other, 5),
        ],
    );
    use command_flags as c;
    assert_eq!(
        (c::ENABLE, c::HOLD, c::LOCKSTEP, c::JOINTS, c::ALL),
        (1, 2, 4, 8, 15)
    );
    use measurement_valid as v;
    assert_eq!(
        [
            v::OBJECT_ORIENTATION,
            v::OBJECT_VELOCITY,
            v::OBJECT_CENTER,
            v::TIP_POSE,
            v::TIP_VELOCITY,
            v::CONTACT,
            v::FORCE,
            v::ROLL,
            v::JOINT_POSITION,
            v::JOINT_VELOCITY,
            v::JOINT_TORQUE,
            v::REQUIRED,
            v::REQUIRED_JOINTS,
            v::ALL
        ],
        [1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 169, 289, 2047]
    );
    assert_eq!(shm_schema::MAX_JOINTS, 4);
    use plant_state as p;
    assert_eq!((p::SIMULATED, p::PAUSED, p::FAULT, p::ALL), (1, 2, 4, 7));
}

#[test]
fn event_kind_codes() {
    use EventKind::*;
    pin(
        EventKind::ALL,
        &[
            (GoalTransition, 1),
            (Place, 2),
            (Lift, 3),
            (Roll, 4),
            (Substitution, 5),
            (Rewind, 6),
            (Fault, 7),
            (FaultCleared, 8),
            (Overrun, 9),
            (ClientsCleaned, 10),
            (DaemonStarted, 11),
            (DaemonStopping, 12),
            (Hold, 13),
            (Drift, 14),
            (NearLimit, 15),
        ],
    );
}

#[test]
fn daemon_state_codes() {
    use DaemonState::*;
    pin(DaemonState::ALL, &[(Running, 1), (Stopped, 2)]);
}

/// The nine `limit_mask` bits of `Command`.
#[test]
fn limit_mask_bits() {
    use LimitKind::*;
    use LimitOrder::*;
    let bits = [
        (Object, Velocity, 0x001),
        (Object, Acceleration, 0x002),
        (Object, Jerk, 0x004),
        (Fingertip, Velocity, 0x008),
        (Fingertip, Acceleration, 0x010),
        (Fingertip, Jerk, 0x020),
        (Rolling, Velocity, 0x040),
        (Rolling, Acceleration, 0x080),
        (Rolling, Jerk, 0x100),
    ];
    for (kind, order, bit) in bits {
        assert_eq!(limit_bit(kind, order), bit, "{kind:?} {order:?}");
    }
}

/// Notification ids on the notify service, and the "no finger" value.
#[test]
fn notification_ids_and_sentinels() {
    assert_eq!(shm_schema::EVENT_ID_STATUS, 1);
    assert_eq!(shm_schema::EVENT_ID_EVENT, 2);
    assert_eq!(shm_schema::EVENT_ID_ANSWER, 3);
    assert_eq!(shm_schema::EVENT_ID_DAEMON_DEAD, 4);
    assert_eq!(shm_schema::NO_FINGER, 0xFFFF_FFFF);
}

#[test]
fn measured_mask_bits() {
    use shm_schema::measured::*;
    assert_eq!(
        (OBJECT, TIPS, CONTACTS, FORCES, JOINTS, ALL),
        (1, 2, 4, 8, 16, 31)
    );
}
