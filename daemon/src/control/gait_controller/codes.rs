//! The executor's enums → wire codes (`shm_schema`), in one place.
//!
//! A planning failure keeps the planner's own reason (SPEC §4.1): each
//! [`PlanError`] has its code.

use gait::executor::{self, FaultKind, Reason};
use gait::planner::PlanError;
use shm_schema::{FaultCode, GoalState, ReasonCode};

/// A goal state on the wire.
pub fn goal_state(s: executor::GoalStage) -> GoalState {
    match s {
        executor::GoalStage::Accepted => GoalState::Accepted,
        executor::GoalStage::Planning => GoalState::Planning,
        executor::GoalStage::Executing => GoalState::Executing,
        executor::GoalStage::Succeeded => GoalState::Succeeded,
        executor::GoalStage::Aborted => GoalState::Aborted,
        executor::GoalStage::Canceled => GoalState::Canceled,
        executor::GoalStage::Preempted => GoalState::Preempted,
        executor::GoalStage::Rejected => GoalState::Rejected,
    }
}

/// The wire reason of a goal in `state` that the executor gave `reason`
/// (a success is `Reached`).
pub fn goal_reason(state: Option<executor::GoalStage>, reason: Reason) -> ReasonCode {
    match state {
        Some(executor::GoalStage::Succeeded) => ReasonCode::Reached,
        _ => reason_code(reason),
    }
}

/// A reason on the wire.
pub fn reason_code(r: Reason) -> ReasonCode {
    match r {
        Reason::None => ReasonCode::None,
        Reason::InvalidTarget => ReasonCode::InvalidGoalTarget,
        Reason::InvalidLimits => ReasonCode::NonPositiveLimit,
        Reason::FaultActive => ReasonCode::Faulted,
        Reason::NoPlan(e) => plan_error_code(e),
        Reason::PlannerBusy => ReasonCode::PlannerUnavailable,
        Reason::Fault => ReasonCode::FaultDetected,
        Reason::CancelCommand => ReasonCode::CanceledByClient,
        Reason::HoldCommand => ReasonCode::HoldRequested,
        Reason::NewerGoal => ReasonCode::PreemptedByGoal,
        Reason::DuplicateId => ReasonCode::DuplicateGoalId,
        Reason::MeasuredStateInvalid => ReasonCode::MeasuredStateInvalid,
        Reason::NotAtRest => ReasonCode::NotAtRest,
        Reason::NoFreshMeasurement => ReasonCode::NoFreshMeasurement,
    }
}

/// The planner's reason on the wire.
pub fn plan_error_code(e: PlanError) -> ReasonCode {
    match e {
        PlanError::InvalidGoal => ReasonCode::InvalidGoalTarget,
        PlanError::InvalidLimits => ReasonCode::NonPositiveLimit,
        PlanError::NonFiniteState => ReasonCode::StartNotFinite,
        PlanError::NoGrasp => ReasonCode::StartNotForceClosure,
        PlanError::NoTwoFingerGrasp => ReasonCode::NoTwoFingerGrasp,
        PlanError::SearchExhausted => ReasonCode::NoPlan,
        PlanError::Blocked { .. } => ReasonCode::FingerBlocked,
        PlanError::LoadInfeasible { .. } => ReasonCode::LoadInfeasible,
        PlanError::Timeout => ReasonCode::PlanTimeout,
        // A request is canceled only when its goal is no longer waited for
        // (canceled or preempted): its goal has its answer already.
        PlanError::Canceled => ReasonCode::CanceledByClient,
    }
}

/// The finger a reason concerns, if any.
pub fn reason_finger(r: Reason) -> Option<u8> {
    match r {
        Reason::NoPlan(PlanError::Blocked { finger }) => u8::try_from(finger).ok(),
        _ => None,
    }
}

/// A fault on the wire.
pub fn fault_code(k: FaultKind) -> FaultCode {
    match k {
        FaultKind::MissingMeasurement => FaultCode::MeasurementMissing,
        FaultKind::BadMeasurement => FaultCode::NonFiniteState,
        FaultKind::ObjectTracking | FaultKind::ContactDrift => FaultCode::Slip,
        FaultKind::FingerTracking => FaultCode::StuckFinger,
        FaultKind::Trajectory | FaultKind::Contact => FaultCode::NonFiniteState,
        FaultKind::ForceClosure => FaultCode::ForceClosureLost,
        FaultKind::Workspace => FaultCode::WorkspaceViolation,
        FaultKind::Fingertip => FaultCode::FingertipViolation,
        FaultKind::Collision => FaultCode::FingertipCollision,
        FaultKind::PlantWaiting => FaultCode::PlantWaiting,
        FaultKind::PlantLost => FaultCode::PlantLost,
        FaultKind::PlantInvalid => FaultCode::PlantInvalid,
        FaultKind::PlantSequence => FaultCode::PlantSequence,
        FaultKind::PlantFault => FaultCode::PlantFault,
        FaultKind::ContactLost => FaultCode::ContactLost,
        FaultKind::PlantTiming => FaultCode::PlantTiming,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every planner reason reaches the wire as its own code, none as the
    /// generic "no plan" but the search running out.
    #[test]
    fn each_plan_error_has_its_own_code() {
        let all = [
            PlanError::InvalidGoal,
            PlanError::InvalidLimits,
            PlanError::NonFiniteState,
            PlanError::NoGrasp,
            PlanError::NoTwoFingerGrasp,
            PlanError::SearchExhausted,
            PlanError::Blocked { finger: 2 },
            PlanError::LoadInfeasible { start: false },
            PlanError::Timeout,
        ];
        let codes: Vec<_> = all.iter().map(|e| plan_error_code(*e)).collect();
        assert_eq!(
            codes,
            [
                ReasonCode::InvalidGoalTarget,
                ReasonCode::NonPositiveLimit,
                ReasonCode::StartNotFinite,
                ReasonCode::StartNotForceClosure,
                ReasonCode::NoTwoFingerGrasp,
                ReasonCode::NoPlan,
                ReasonCode::FingerBlocked,
                ReasonCode::LoadInfeasible,
                ReasonCode::PlanTimeout,
            ]
        );
        let blocked = Reason::NoPlan(PlanError::Blocked { finger: 2 });
        assert_eq!(reason_finger(blocked), Some(2));
        assert_eq!(reason_finger(Reason::NoPlan(PlanError::NoGrasp)), None);
        assert_eq!(
            goal_reason(Some(executor::GoalStage::Succeeded), Reason::None),
            ReasonCode::Reached
        );
    }
}
