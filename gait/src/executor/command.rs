//! What the executor is told and what it asks for (SPEC §6.4, §7.3): goal
//! targets, commands and their answers, and the plan request it leaves for
//! whoever owns the planner.

use nalgebra::{UnitQuaternion, Vector3};

use super::Reason;
use crate::config::LimitsConfig;
use crate::hand_state::HandState;
use crate::planner::timing::step_profiles;
use crate::planner::{Budget, GoalPlanner, Plan, PlanError, Target, Unbounded};

/// Where a goal wants the object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GoalTarget {
    /// An absolute orientation (object → hand).
    Orientation(UnitQuaternion<f64>),
    /// A rotation about a hand-frame axis by an angle of any size (a full
    /// turn is a full turn), from the orientation the object has when
    /// planning starts.
    Rotation {
        /// Axis (hand frame, any length > 0).
        axis: Vector3<f64>,
        /// Angle \[rad\].
        angle: f64,
    },
}

impl GoalTarget {
    /// The orientation reached from `from`.
    pub fn resolve(&self, from: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        match *self {
            Self::Orientation(q) => q,
            Self::Rotation { axis, angle } => {
                UnitQuaternion::from_scaled_axis(axis.normalize() * angle) * from
            }
        }
    }

    pub(super) fn is_valid(&self) -> bool {
        match self {
            Self::Orientation(q) => {
                let q = q.quaternion();
                q.coords.iter().all(|x| x.is_finite()) && (q.norm() - 1.0).abs() < 1e-6
            }
            Self::Rotation { axis, angle } => {
                axis.iter().all(|x| x.is_finite()) && axis.norm() > 1e-9 && angle.is_finite()
            }
        }
    }

    /// Plans it from `start` within the planner's expansion budget.
    pub fn plan(&self, planner: &impl GoalPlanner, start: &HandState) -> Result<Plan, PlanError> {
        let mut never = Unbounded;
        let mut budget = Budget::new(planner.config().planner.max_expansions, &mut never);
        self.plan_within(planner, start, &mut budget)
    }

    /// Plans it from `start` within `budget`.
    pub fn plan_within(
        &self,
        planner: &impl GoalPlanner,
        start: &HandState,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        let target = match *self {
            Self::Orientation(q) => Target::Orientation(q),
            Self::Rotation { axis, angle } => Target::Turn { axis, angle },
        };
        planner.plan_target(start, &target, budget)
    }
}

/// A command to the executor (SPEC §6.4, §7.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ExecutorCommand {
    /// Reorient the object.
    Goal {
        /// Goal id, unique.
        id: u64,
        /// Where to.
        target: GoalTarget,
        /// Motion limits for this goal (`None`: the configured ones). Each
        /// must be positive; the caller keeps them within the configured
        /// limits.
        limits: Option<LimitsConfig>,
    },
    /// Stop the active goal smoothly, then hold.
    Cancel,
    /// Stop any motion smoothly and hold the grasp.
    Hold,
    /// Clear a fault (only if the measured state is valid).
    Reset,
}

/// The answer to a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExecutorAnswer {
    /// Taken.
    Accepted,
    /// Refused, with the reason.
    Rejected(Reason),
}

/// What the executor asks the planner for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanRequest {
    /// Goal the plan is for.
    pub goal: u64,
    /// State to plan from (at rest).
    pub start: HandState,
    /// Where to.
    pub target: GoalTarget,
    /// The motion limits the plan will be executed with (the goal's
    /// overrides applied): it is timed and costed with them.
    pub limits: LimitsConfig,
    /// The executor's control period \[s\]: the steps' trajectories are
    /// calculated with the plan for it.
    pub dt: f64,
}

impl PlanRequest {
    /// Plans it with `planner`, re-timed for the request's limits when they
    /// differ from the planner's (SPEC §4.3: a plan's cost is its execution
    /// time under the limits it runs with).
    pub fn plan(&self, planner: &impl GoalPlanner) -> Result<Plan, PlanError> {
        let mut never = Unbounded;
        let mut budget = Budget::new(planner.config().planner.max_expansions, &mut never);
        self.plan_within(planner, &mut budget)
    }

    /// [`PlanRequest::plan`] within `budget` (the caller's clock and
    /// cancel flag, and the expansion count).
    pub fn plan_within(
        &self,
        planner: &impl GoalPlanner,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        let mut plan = if self.limits == planner.config().limits {
            self.target.plan_within(planner, &self.start, budget)?
        } else {
            let timed = planner
                .with_limits(&self.limits)
                .map_err(|_| PlanError::InvalidLimits)?;
            self.target.plan_within(&timed, &self.start, budget)?
        };
        // Off the loop: the executor adopts these at each step's start.
        plan.profiles = step_profiles(&plan.steps, &self.limits, self.dt);
        Ok(plan)
    }
}
