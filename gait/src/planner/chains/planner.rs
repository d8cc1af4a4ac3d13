//! Planning on finger chains: the one search ([`crate::planner::search`])
//! with the chain hand behind its boundary ([`ChainModel`]), the plan
//! certified by the chain check ([`super::certify`]) before it is returned.
//!
//! As for the free fingertips: the request is checked (a finite goal; a
//! start whose grasp is force-closure, on the object, within every limit
//! of §14.1 and holding the load), the search runs within the caller's
//! budget as the passes of
//! [`crate::planner::alternatives::STILL_PAIR_PASSES`] say (a greedy pass
//! that finds a plan, then one that looks for a quicker one within a
//! multiple of that effort), and the plan records its route and effort.
//! (Detours and escapes are a pair's turns: on chains, where pairs do not
//! turn, the search makes none.)

use nalgebra::UnitQuaternion;

use super::certify::{ChainViolation, check};
use super::model::ChainModel;
use crate::hand_state::HandState;
use crate::planner::alternatives::STILL_PAIR_PASSES;
use crate::planner::budget::{Budget, Effort, Halt, Unbounded};
use crate::planner::goal::Remaining;
use crate::planner::hand_model::HandModel;
use crate::planner::route::Route;
use crate::planner::search::{self, Mode, NotFound, Params};
use crate::planner::{Plan, PlanError, assemble, fibonacci_sphere};

/// How far a grasping tip's centre may be from the object's surface
/// shell R + r \[m\] (a start's rounding, not a gap: the plan's first carry
/// puts the tip on the shell).
const CONTACT_TOLERANCE: f64 = 1e-6;

/// The planner of a chain hand. Cheap to clone (the model's grids are
/// shared).
#[derive(Debug, Clone)]
pub struct ChainPlanner {
    model: ChainModel,
    params: Params,
}

impl ChainPlanner {
    /// The planner of `model`, with the search's settings from the
    /// model's configuration (`planner.branching`; the detour and escape
    /// axes as configured, which a chain search does not turn about).
    pub fn new(model: ChainModel) -> Self {
        let p = &model.config().planner;
        let params = Params {
            branching: p.branching as usize,
            detour_axes: fibonacci_sphere(p.detour_axes as usize),
            escape_axes: fibonacci_sphere(p.escape_axes as usize),
        };
        Self { model, params }
    }

    /// The hand model.
    pub fn model(&self) -> &ChainModel {
        &self.model
    }

    /// Plans from `start` to the object orientation `goal` within the
    /// configured expansion budget (deterministic).
    pub fn plan(&self, start: &HandState, goal: &UnitQuaternion<f64>) -> Result<Plan, PlanError> {
        let mut never = Unbounded;
        let max = self.model.config().planner.max_expansions;
        self.plan_within(start, goal, &mut Budget::new(max, &mut never))
    }

    /// Plans from `start` to `goal` within `budget` (module docs).
    pub fn plan_within(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        let gq = goal.quaternion();
        if !gq.coords.iter().all(|x| x.is_finite()) || gq.norm() < 1e-9 {
            return Err(PlanError::InvalidGoal);
        }
        let goal = UnitQuaternion::new_normalize(*gq);
        let finite = start.object.coords.iter().all(|x| x.is_finite())
            && start
                .fingers
                .iter()
                .all(|f| f.center.iter().all(|x| x.is_finite()));
        if !finite {
            return Err(PlanError::NonFiniteState);
        }
        self.check_start(start)?;
        let rem = Remaining::orientation(&start.object, &goal);
        let angle = start.object.angle_to(&goal);
        let mut effort = Effort::default();
        if rem.reached() {
            return Ok(assemble(
                start,
                goal,
                angle,
                Vec::new(),
                Route::default(),
                effort,
            ));
        }
        let m = &self.model;
        let mut best: Option<(search::Found<ChainModel>, usize)> = None;
        let mut last = NotFound::Capped;
        for (i, pass) in STILL_PAIR_PASSES.iter().enumerate() {
            let found = best.as_ref().map(|(f, _)| f.duration);
            let Some(mode) = Mode::for_pass(pass, found, budget.used(), true, false) else {
                continue;
            };
            effort.passes += 1;
            match search::run(m, &self.params, mode, start, rem, budget, &mut effort) {
                Ok(found) => best = Some((found, i)),
                Err(NotFound::Halted(Halt::Canceled)) => return Err(PlanError::Canceled),
                Err(e) if best.is_none() => last = e,
                Err(_) => {}
            }
        }
        if let Some((found, pass)) = best {
            let route = Route::new(&STILL_PAIR_PASSES, pass, start, m, &found.actions);
            return Ok(assemble(start, goal, angle, found.steps, route, effort));
        }
        Err(match last {
            NotFound::Halted(Halt::Canceled) => PlanError::Canceled,
            NotFound::Halted(Halt::OutOfBudget) | NotFound::Capped => PlanError::Timeout,
            NotFound::Exhausted {
                blocked: Some(finger),
                ..
            } => PlanError::Blocked { finger },
            NotFound::Exhausted { .. } if m.load_active() => {
                PlanError::LoadInfeasible { start: false }
            }
            NotFound::Exhausted { .. } => PlanError::SearchExhausted,
        })
    }

    /// The start must be a force-closure grasp of two or three fingers
    /// touching the object, keep every limit of §14.1 (a finger that does
    /// not: [`PlanError::Blocked`]), and hold the load.
    fn check_start(&self, start: &HandState) -> Result<(), PlanError> {
        let m = &self.model;
        let (idx, n) = start.grasping();
        let o = m.hand().object();
        let touching = idx[..n].iter().all(|&k| {
            let r = o.radius + m.hand().chain(k).tip_radius;
            (start.fingers[k].center.norm() - r).abs() <= CONTACT_TOLERANCE
        });
        if !touching {
            return Err(PlanError::NoGrasp);
        }
        let normal = |k: usize| start.fingers[k].center.normalize();
        let closed = match n {
            2 => m.good_pair(&normal(idx[0]), &normal(idx[1])),
            3 => m.fc_triple(&[normal(0), normal(1), normal(2)]),
            _ => false,
        };
        if !closed {
            return Err(PlanError::NoGrasp);
        }
        match check(m.hand(), start, &[], m.check_params()) {
            Err(ChainViolation {
                finger: Some(finger),
                ..
            }) => Err(PlanError::Blocked { finger }),
            Err(_) => Err(PlanError::LoadInfeasible { start: true }),
            Ok(_) if !m.holds_at_rest(start) => Err(PlanError::LoadInfeasible { start: true }),
            Ok(_) => Ok(()),
        }
    }
}
