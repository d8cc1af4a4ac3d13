//! Integer codes of every enumeration that crosses the process boundary.
//!
//! On the wire every enum is a `u32`. A reader never trusts another
//! process's bytes: it decodes with `TryFrom<u32>`, which fails with
//! [`UnknownCode`] for any value not listed here. Codes are stable within a
//! schema version; new codes need a new [`SCHEMA_VERSION`](crate::SCHEMA_VERSION).

use core::fmt;

/// A `u32` that is not a valid code of the enum it was read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownCode {
    /// Name of the enum (e.g. `"Phase"`).
    pub kind: &'static str,
    /// The value read.
    pub code: u32,
}

impl fmt::Display for UnknownCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown {} code {}", self.kind, self.code)
    }
}

impl core::error::Error for UnknownCode {}

/// One row of an enum's code table (for the layout document).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CodeInfo {
    /// The integer on the wire.
    pub code: u32,
    /// Variant name.
    pub name: &'static str,
    /// One-line meaning.
    pub doc: &'static str,
}

/// Defines a `#[repr(u32)]` enum with checked decoding, its code table and
/// `Display`. Every variant carries exactly one doc line.
macro_rules! code_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $(
                #[doc = $doc:literal]
                $var:ident = $val:literal
            ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u32)]
        pub enum $name {
            $(
                #[doc = $doc]
                $var = $val,
            )+
        }

        impl $name {
            /// Every variant, in code order.
            pub const ALL: &'static [$name] = &[$($name::$var),+];
            /// Code table (code, name, meaning) for documentation.
            pub const TABLE: &'static [$crate::codes::CodeInfo] = &[
                $($crate::codes::CodeInfo { code: $val, name: stringify!($var), doc: $doc.trim_ascii() }),+
            ];

            /// The integer written on the wire.
            pub const fn code(self) -> u32 {
                self as u32
            }

            /// The variant's name.
            pub const fn name(self) -> &'static str {
                match self {
                    $($name::$var => stringify!($var)),+
                }
            }
        }

        impl TryFrom<u32> for $name {
            type Error = $crate::codes::UnknownCode;
            fn try_from(code: u32) -> Result<Self, Self::Error> {
                match code {
                    $($val => Ok($name::$var),)+
                    _ => Err($crate::codes::UnknownCode { kind: stringify!($name), code }),
                }
            }
        }

        impl From<$name> for u32 {
            fn from(v: $name) -> u32 {
                v.code()
            }
        }

        impl core::fmt::Display for $name {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

code_enum! {
    /// What a [`Command`](crate::Command) asks for. Code 0 is never valid, so
    /// an all-zero request is rejected.
    pub enum CommandKind {
        /// Reorient the object (SPEC §6.4); preempts the active goal.
        Goal = 1,
        /// Stop the active goal smoothly, then hold.
        Cancel = 2,
        /// Keep the grasp, no motion.
        Hold = 3,
        /// Clear a fault and return to hold.
        Reset = 4,
    }
}

code_enum! {
    /// How a goal's target quaternion is meant.
    pub enum GoalFrame {
        /// Target is the object orientation q_o to reach (object → hand frame).
        Absolute = 1,
        /// Target is a rotation applied to the current orientation, hand frame: q_goal = q_rel · q_o.
        Relative = 2,
        /// Target is `[angle, x, y, z]`: turn the object by `angle` \[rad\] about the hand-frame axis (x, y, z) from its orientation at acceptance; any angle (2π is a full turn, not a no-op).
        AxisAngle = 3,
    }
}

code_enum! {
    /// The immediate answer to a command.
    pub enum AnswerCode {
        /// The command was accepted (for goals: it is now the active goal).
        Accepted = 1,
        /// The command was refused; the reason code says why.
        Rejected = 2,
    }
}

code_enum! {
    /// Goal lifecycle (SPEC §6.4).
    pub enum GoalState {
        /// No goal has been accepted yet.
        None = 0,
        /// Accepted, waiting for the planner.
        Accepted = 1,
        /// Being planned off the real-time thread.
        Planning = 2,
        /// Plan is being executed.
        Executing = 3,
        /// Reached the target (terminal).
        Succeeded = 4,
        /// Stopped by a fault or a failed plan (terminal; reason says why).
        Aborted = 5,
        /// Stopped by a cancel command (terminal).
        Canceled = 6,
        /// Replaced by a newer goal (terminal).
        Preempted = 7,
        /// Never started (terminal; reason says why).
        Rejected = 8,
    }
}

impl GoalState {
    /// Whether the goal is over (no further transitions).
    pub const fn is_terminal(self) -> bool {
        matches!(
            self,
            GoalState::Succeeded
                | GoalState::Aborted
                | GoalState::Canceled
                | GoalState::Preempted
                | GoalState::Rejected
        )
    }
}

code_enum! {
    /// Why a command was rejected or a goal ended. Every terminal state carries one.
    pub enum ReasonCode {
        /// No reason (success, or nothing to report).
        None = 0,
        /// `kind` is not a known [`CommandKind`].
        UnknownCommandKind = 1,
        /// `frame` is not a known [`GoalFrame`].
        UnknownGoalFrame = 2,
        /// A goal needs a non-zero `goal_id`.
        ZeroGoalId = 3,
        /// `client_id` must be non-zero.
        ZeroClientId = 4,
        /// The target quaternion has a NaN or infinite component.
        NonFiniteQuaternion = 5,
        /// The target quaternion is (nearly) zero.
        ZeroQuaternion = 6,
        /// The target quaternion's norm is not within tolerance of 1.
        NonUnitQuaternion = 7,
        /// `limit_mask` has bits beyond the nine defined overrides.
        BadLimitMask = 8,
        /// A limit override is NaN or infinite.
        NonFiniteLimit = 9,
        /// A limit override is zero or negative.
        NonPositiveLimit = 10,
        /// A field that must be zero is not (padding, unused field, unset limit).
        NonZeroReserved = 11,
        /// The client already used this goal id.
        DuplicateGoalId = 12,
        /// A limit override exceeds the configured limit.
        LimitAboveConfigured = 13,
        /// The planner could not take the goal (its request queue was full): the accepted goal is Aborted with this reason.
        PlannerUnavailable = 14,
        /// The controller is in a fault; send Reset first.
        Faulted = 15,
        /// Cancel named a goal that is not the active one.
        UnknownGoalId = 16,
        /// Nothing to cancel.
        NoActiveGoal = 17,
        /// The daemon is shutting down.
        ShuttingDown = 18,
        /// The planner's search ran out of nodes: no plan at its resolution (SPEC §4.1).
        NoPlan = 19,
        /// Reset while there is no fault.
        NotFaulted = 20,
        /// Replaced by a newer goal.
        PreemptedByGoal = 21,
        /// Stopped by a cancel command.
        CanceledByClient = 22,
        /// Stopped by a hold command.
        HoldRequested = 23,
        /// Stopped because a fault was detected (see the fault code).
        FaultDetected = 24,
        /// The target was reached within tolerance.
        Reached = 25,
        /// An axis-angle target has a non-finite or zero axis, or a non-finite or huge (> 64π) angle.
        BadAxisAngle = 26,
        /// A limit override is below the smallest allowed: 1 % of the configured limit (`MIN_LIMIT_OVERRIDE_FRACTION`).
        LimitBelowMinimum = 27,
        /// No plan: the state to plan from has fewer than two grasping fingers, or they are not force-closure.
        StartNotForceClosure = 28,
        /// No plan: the state to plan from holds a non-finite number.
        StartNotFinite = 29,
        /// No plan: three fingers grasp, no pair is force-closure, and no roll reaches a force-closure pair.
        NoTwoFingerGrasp = 30,
        /// No plan: a free finger cannot travel clear of the other fingertips (the event's `finger` names it).
        FingerBlocked = 31,
        /// The goal's target is not a finite orientation or turn the planner can use.
        InvalidGoalTarget = 32,
        /// Reset refused: the measured state breaks an invariant (SPEC §1.3); bring the hand back to a valid grasp first.
        MeasuredStateInvalid = 33,
        /// No plan keeps the load feasible (SPEC §1.3 I1'): no sequence of grasps found holds the weight, the acceleration torque and the configured disturbance with every normal force within `load.max_grip` (also when the start grasp itself cannot).
        LoadInfeasible = 34,
        /// Planning ran out of its budget (`[planner] budget_ms` of wall clock, or `max_expansions`) before it found a plan.
        PlanTimeout = 35,
        /// Reset refused: no fresh valid measurement from the plant (it is lost, stalled or not started); start the plant, then reset.
        NoFreshMeasurement = 36,
        /// Reset refused: the hand is still braking to rest after the fault; reset once it is still.
        NotAtRest = 37,
    }
}

code_enum! {
    /// What the controller is doing this tick.
    pub enum Phase {
        /// Holding the grasp still.
        Hold = 1,
        /// A fingertip rolls on the object (object still).
        Roll = 2,
        /// The object rotates with the grasping fingertips.
        Rotate = 3,
        /// A free finger moves through free space and makes contact.
        Place = 4,
        /// A finger breaks contact and leaves to its free space.
        Lift = 5,
        /// Motion being brought smoothly to rest (preemption, cancel, hold).
        Stopping = 6,
        /// Safe hold after a fault.
        SafeHold = 7,
    }
}

code_enum! {
    /// State of one finger.
    pub enum FingerPhase {
        /// In contact, part of the grasp.
        Grasping = 1,
        /// In contact, rolling on the object.
        Rolling = 2,
        /// Breaking contact, moving away along the normal.
        Lifting = 3,
        /// In its free-space shell (parked or transferring).
        Free = 4,
        /// Descending to make contact.
        Placing = 5,
    }
}

code_enum! {
    /// What a plant's fingertip is to do (`PlantFingerCommand::mode`).
    pub enum PlantFingerMode {
        /// In contact, part of the grasp: follow the pose and press with the grip force.
        Grasping = 1,
        /// Lifted, in its free space: follow the pose, touch nothing.
        Free = 2,
        /// Descending to make contact: follow the pose; the grip force ramps in.
        Placing = 3,
        /// Breaking contact and rising: the grip force ramps out, then follow the pose.
        Lifting = 4,
    }
}

code_enum! {
    /// A plant's own fault (`PlantMeasurement::fault`).
    pub enum PlantFault {
        /// No fault.
        None = 0,
        /// An emergency stop is pressed.
        EmergencyStop = 1,
        /// An actuator or sensor failed.
        Hardware = 2,
        /// A joint, torque or force limit was hit.
        Limit = 3,
        /// The simulation diverged (non-finite or exploding state).
        Diverged = 4,
        /// Another fault of the plant.
        Other = 5,
    }
}

code_enum! {
    /// Force-closure state of the grasp (SPEC §1.3 I1).
    pub enum GraspState {
        /// Not computed by this controller.
        Unknown = 0,
        /// The grasping fingers are force-closure with margin.
        ForceClosure = 1,
        /// The grasping fingers are not force-closure.
        NotForceClosure = 2,
    }
}

code_enum! {
    /// Fault of the controller or plant (SPEC §6.4, §12).
    pub enum FaultCode {
        /// No fault.
        None = 0,
        /// Force closure lost (invariant I1).
        ForceClosureLost = 1,
        /// A contact or free fingertip left its workspace (I2).
        WorkspaceViolation = 2,
        /// A fingertip contact left its hemisphere or the roll limit (I3).
        FingertipViolation = 3,
        /// Two fingertips too close (I4).
        FingertipCollision = 4,
        /// A grasping contact slipped (I5).
        Slip = 5,
        /// A plant measurement is missing.
        MeasurementMissing = 6,
        /// A finger does not follow its setpoint.
        StuckFinger = 7,
        /// A NaN or infinite value appeared in the state.
        NonFiniteState = 8,
        /// No fresh measurement from the plant for more than `plant.max_missed` ticks (real time: or none that arrived within `plant.stale_after_ms`; lockstep: none within `plant.lockstep_timeout_ms`), or one that echoes a command more than `plant.max_missed` behind: it stopped, stalled or vanished.
        PlantLost = 9,
        /// The plant sent an invalid measurement: a bad code, a missing required field, a non-finite number (in any field it flags valid, velocities included) or a non-unit quaternion.
        PlantInvalid = 10,
        /// The plant's measurements went backwards (`seq` 0 or below the last, `time_ns` not after the last), echoed another daemon session, or echoed a command never sent.
        PlantSequence = 11,
        /// The plant reports a fault of its own (the event's `count` holds its `PlantFault` code).
        PlantFault = 12,
        /// A grasping contact is not touching: the measured contact flag or normal force says so.
        ContactLost = 13,
        /// Waiting for the plant's first valid measurement: nothing moves until it arrives.
        PlantWaiting = 14,
        /// The plant exchange missed its timing contract `plant.max_misses_in_row` ticks in a row: commands late or repeated by the plant, measurements late or repeated (PLANT-GUIDE.md; the status's `timing` counts each).
        PlantTiming = 15,
    }
}

code_enum! {
    /// Kind of an [`Event`](crate::Event).
    pub enum EventKind {
        /// A goal changed state (`state`, `reason`, `goal_id`, `client_id`).
        GoalTransition = 1,
        /// A finger made contact (`finger`).
        Place = 2,
        /// A finger broke contact (`finger`).
        Lift = 3,
        /// A finger started rolling (`finger`).
        Roll = 4,
        /// A finger substitution gait completed (paper §2.1): a finger took over a grasping finger's place, then that one lifted (`finger` = the finger that left; `count` = the finger that took over as a bit, bit k for finger k).
        Substitution = 5,
        /// A finger rewind gait completed (paper §2.1): one or both fingers of the grasping pair were moved back into their workspace with the third finger's help (`finger` = that helper, free again; `count` = the relocated fingers as bits, bit k for finger k). Its substitutions were reported before it.
        Rewind = 6,
        /// A fault was detected (`fault`; `finger` = the finger whose state caused it, none when the cause is not one finger's: CLIENT-GUIDE.md lists which faults name one; with `PlantFault`, `count` = the plant's `PlantFault` code).
        Fault = 7,
        /// The fault was cleared by a reset.
        FaultCleared = 8,
        /// The loop missed periods (`count` = periods skipped).
        Overrun = 9,
        /// Dead client nodes were cleaned up (`count` = how many).
        ClientsCleaned = 10,
        /// The daemon started (first event of an instance).
        DaemonStarted = 11,
        /// The daemon is shutting down (last event of an instance).
        DaemonStopping = 12,
        /// The controller switched to hold on a command (`reason`).
        Hold = 13,
        /// A contact drifted beyond tolerance (`finger`, `goal_id`, `client_id`; `count` = replans of the goal so far, drifts and near-limits together): the motion stops and the goal is replanned from the measured state.
        Drift = 14,
        /// While moving, the measured state came near the limit of an invariant (SPEC §6.3; `fault` = the invariant as the fault it would become, `finger` = the finger concerned, or none (0xFFFFFFFF) for force closure, `goal_id`, `client_id`, `count` = replans of the goal so far, drifts and near-limits together): the motion stops and the goal is replanned from the measured state.
        NearLimit = 15,
    }
}

code_enum! {
    /// Lifecycle of the daemon, in [`Status`](crate::Status).
    pub enum DaemonState {
        /// The control loop is running.
        Running = 1,
        /// Final status: the daemon held the grasp and is exiting.
        Stopped = 2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip<T>(all: &[T], table: &[CodeInfo])
    where
        T: Copy + PartialEq + core::fmt::Debug + TryFrom<u32, Error = UnknownCode> + Into<u32>,
    {
        assert_eq!(all.len(), table.len());
        for (v, row) in all.iter().zip(table) {
            let c: u32 = (*v).into();
            assert_eq!(c, row.code);
            assert_eq!(T::try_from(c).unwrap(), *v);
            assert!(!row.doc.is_empty());
        }
        // Every other code in a wide range is refused.
        for c in (0..1000u32).chain([u32::MAX, u32::MAX - 1, 1 << 31]) {
            if table.iter().all(|r| r.code != c) {
                assert!(T::try_from(c).is_err(), "{c}");
            }
        }
    }

    #[test]
    fn every_enum_decodes_its_codes_and_refuses_the_rest() {
        roundtrip(CommandKind::ALL, CommandKind::TABLE);
        roundtrip(GoalFrame::ALL, GoalFrame::TABLE);
        roundtrip(AnswerCode::ALL, AnswerCode::TABLE);
        roundtrip(GoalState::ALL, GoalState::TABLE);
        roundtrip(ReasonCode::ALL, ReasonCode::TABLE);
        roundtrip(Phase::ALL, Phase::TABLE);
        roundtrip(FingerPhase::ALL, FingerPhase::TABLE);
        roundtrip(GraspState::ALL, GraspState::TABLE);
        roundtrip(FaultCode::ALL, FaultCode::TABLE);
        roundtrip(EventKind::ALL, EventKind::TABLE);
        roundtrip(DaemonState::ALL, DaemonState::TABLE);
    }

    #[test]
    fn unknown_code_names_the_enum() {
        let e = Phase::try_from(99).unwrap_err();
        assert_eq!(e.to_string(), "unknown Phase code 99");
    }
}
