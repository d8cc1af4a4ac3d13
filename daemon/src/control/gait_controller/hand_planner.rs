//! The planner of the configured hand: the free fingertips' or a chain
//! hand's, behind one [`GoalPlanner`].

use gait::config::{ConfigError, LimitsConfig};
use gait::planner::chains::planner::ChainPlanner;
use gait::planner::{Budget, GoalPlanner, Plan, PlanError, Planner, Target};
use gait::{HandConfig, HandState};

/// Either hand's planner.
#[derive(Debug, Clone)]
pub enum HandPlanner {
    /// The paper's free fingertips.
    Fingertips(Box<Planner>),
    /// A hand of finger joint chains (SPEC §14).
    Chains(Box<ChainPlanner>),
}

impl From<Planner> for HandPlanner {
    fn from(p: Planner) -> Self {
        Self::Fingertips(Box::new(p))
    }
}

impl From<ChainPlanner> for HandPlanner {
    fn from(p: ChainPlanner) -> Self {
        Self::Chains(Box::new(p))
    }
}

impl HandPlanner {
    /// Does ahead what planning from `start` begins with, where the
    /// planner has such work (the fingertips' start-grasp searches).
    pub fn prepare(&self, start: &HandState) {
        if let Self::Fingertips(p) = self {
            p.prepare(start);
        }
    }
}

impl GoalPlanner for HandPlanner {
    fn config(&self) -> &HandConfig {
        match self {
            Self::Fingertips(p) => GoalPlanner::config(&**p),
            Self::Chains(p) => GoalPlanner::config(&**p),
        }
    }

    fn with_limits(&self, limits: &LimitsConfig) -> Result<Self, ConfigError> {
        Ok(match self {
            Self::Fingertips(p) => {
                Self::Fingertips(Box::new(GoalPlanner::with_limits(&**p, limits)?))
            }
            Self::Chains(p) => Self::Chains(Box::new(p.with_limits(limits)?)),
        })
    }

    fn plan_target(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        match self {
            Self::Fingertips(p) => p.plan_target(start, target, budget),
            Self::Chains(p) => p.plan_target(start, target, budget),
        }
    }
}
