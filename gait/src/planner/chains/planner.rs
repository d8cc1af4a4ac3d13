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
use crate::HandConfig;
use crate::config::{ConfigError, LimitsConfig};
use crate::hand::PAIRS;
use crate::hand_state::HandState;
use crate::planner::alternatives::{CHAIN_TURN_RECUTS, STILL_PAIR_PASSES, TURN_PIECE};
use crate::planner::budget::{Budget, Effort, Halt, Unbounded};
use crate::planner::goal::{Course, Remaining};
use crate::planner::hand_model::HandModel;
use crate::planner::route::Route;
use crate::planner::search::{self, Mode, NotFound, Params};
use crate::planner::{GoalPlanner, Plan, PlanError, Target, assemble, fibonacci_sphere};

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

    /// The same planner timing and costing plans under `limits` (a goal's
    /// motion-limit overrides; SPEC §4.3), validated as a configuration.
    pub fn with_limits(&self, limits: &LimitsConfig) -> Result<Self, ConfigError> {
        let config = HandConfig {
            limits: *limits,
            ..*self.model.config()
        };
        config.validate()?;
        Ok(Self {
            model: self.model.with_limits(limits),
            params: self.params.clone(),
        })
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
        self.plan_target(start, &Target::Orientation(*goal), budget)
    }

    /// Plans `target` from `start` within `budget`: an orientation, or a
    /// turn of any size about an axis, planned as consecutive pieces as on
    /// the free fingertips ([`crate::planner::goal::Course`]; the ball
    /// comes to rest where two pieces meet).
    pub fn plan_target(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        let finite = start.object.coords.iter().all(|x| x.is_finite())
            && start
                .fingers
                .iter()
                .all(|f| f.center.iter().all(|x| x.is_finite()));
        if !finite {
            return Err(PlanError::NonFiniteState);
        }
        let course = Course::new(&start.object, target)?;
        self.check_start(start)?;
        let mut effort = Effort::default();
        let mut at = *start;
        let (mut steps, mut route, mut pass) = (Vec::new(), Vec::new(), 0);
        // The turn done so far, the pieces left for the rest, the recuts
        // made ([`CHAIN_TURN_RECUTS`]), where each planned piece began.
        let (mut turned, mut left, mut recuts) = (0.0, course.pieces, 0);
        let mut began: Vec<(HandState, f64, usize, usize, usize)> = Vec::new();
        while left > 0 {
            let next = turned + (course.angle - turned) / left as f64;
            let rem = Remaining::orientation(&at.object, &course.along(next));
            if rem.reached() {
                (turned, left) = (next, left - 1);
                continue;
            }
            let (found, p) = match self.search(&at, rem, budget, &mut effort) {
                Ok(f) => f,
                // The grasp the last piece ended in may be one no gait
                // leaves: that piece is planned again, and the rest of the
                // turn through other orientations.
                Err(PlanError::LoadInfeasible { .. } | PlanError::SearchExhausted)
                    if course.is_turn() && recuts < CHAIN_TURN_RECUTS =>
                {
                    recuts += 1;
                    if let Some((state, t, n_steps, n_route, p)) = began.pop() {
                        (at, turned, pass) = (state, t, p);
                        steps.truncate(n_steps);
                        route.truncate(n_route);
                    }
                    let rest = course.angle - turned;
                    left = (rest / TURN_PIECE).ceil() as usize + recuts;
                    continue;
                }
                Err(e) => return Err(e),
            };
            began.push((at, turned, steps.len(), route.len(), pass));
            let r = Route::new(&STILL_PAIR_PASSES, p, &at, &self.model, &found.actions);
            at = found
                .steps
                .last()
                .map_or(at, |st| st.eval(&st.dofs().length, &[0.0; 3]).state);
            steps.extend(found.steps);
            route.extend(r.steps);
            pass = pass.max(p);
            (turned, left) = (next, left - 1);
        }
        let route = Route {
            passes: &STILL_PAIR_PASSES,
            pass,
            steps: route,
        };
        Ok(assemble(
            start,
            course.goal,
            course.angle,
            steps,
            route,
            effort,
        ))
    }

    /// The passes of [`STILL_PAIR_PASSES`] for `rem` from `start`: what
    /// the best found, and the pass that found it.
    fn search(
        &self,
        start: &HandState,
        rem: Remaining,
        budget: &mut Budget<'_>,
        effort: &mut Effort,
    ) -> Result<(search::Found<ChainModel>, usize), PlanError> {
        let m = &self.model;
        let mut best: Option<(search::Found<ChainModel>, usize)> = None;
        let mut last = NotFound::Capped;
        // An improving pass's effort is a multiple of this search's, not
        // of the whole goal's (earlier pieces of a turn).
        let before = budget.used();
        for (i, pass) in STILL_PAIR_PASSES.iter().enumerate() {
            let found = best.as_ref().map(|(f, _)| f.duration);
            let used = budget.used() - before;
            let Some(mode) = Mode::for_pass(pass, found, used, true, false) else {
                continue;
            };
            effort.passes += 1;
            match search::run(m, &self.params, mode, start, rem, budget, effort) {
                Ok(found) => best = Some((found, i)),
                Err(NotFound::Halted(Halt::Canceled)) => return Err(PlanError::Canceled),
                Err(e) if best.is_none() => last = e,
                Err(_) => {}
            }
        }
        if let Some(best) = best {
            return Ok(best);
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

    /// The start must be a force-closure grasp (with margin) of two or three fingers
    /// touching the object, keep every limit of §14.1 (a finger that does
    /// not: [`PlanError::Blocked`]), and hold the load.
    pub fn check_start(&self, start: &HandState) -> Result<(), PlanError> {
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
        // Three fingers: force closure as a placement needs it (Fact 4)
        // or through one pair of them (Fact 3), as the executor's check
        // accepts it; a turn may end where only a pair closes the grasp.
        let closed = match n {
            2 => m.good_pair(&normal(idx[0]), &normal(idx[1])),
            3 => {
                let c = [normal(0), normal(1), normal(2)];
                m.fc_triple(&c) || PAIRS.iter().any(|&(a, b)| m.good_pair(&c[a], &c[b]))
            }
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

impl GoalPlanner for ChainPlanner {
    fn config(&self) -> &HandConfig {
        self.model.config()
    }

    fn with_limits(&self, limits: &LimitsConfig) -> Result<Self, ConfigError> {
        ChainPlanner::with_limits(self, limits)
    }

    fn plan_target(
        &self,
        start: &HandState,
        target: &Target,
        budget: &mut Budget<'_>,
    ) -> Result<Plan, PlanError> {
        ChainPlanner::plan_target(self, start, target, budget)
    }
}
