//! From a goal to a plan (SPEC §4): an orientation goal, or a turn of a
//! given size about an axis; under load the fallbacks — a long turn in
//! pieces, the exact load test, a turn about gravity split off, an
//! intermediate orientation (gait/LOAD-FIGURES.md §10, §14), and last
//! spins (§0) — each only when the ways before it plan nothing.

use nalgebra::{UnitQuaternion, Vector3};

use super::geometry::rotation;
use super::{Plan, PlanError, PlanSummary, Planner, count_finger_gaits, rotation_to, state_finite};
use crate::state::HandState;

/// Longest piece of a turn planned on its own when the whole turn is too
/// long for one search \[rad\] (short enough that an escape inside a piece
/// cannot reverse its direction).
const TURN_CHUNK: f64 = 2.0 * std::f64::consts::FRAC_PI_3;

/// How far the start is turned for an intermediate goal of
/// [`Planner::plan_via_waypoints`] \[rad\] (90°).
const WAYPOINT_ANGLE: f64 = std::f64::consts::FRAC_PI_2;

/// Shortest piece of a turn [`Planner::plan_in_chunks`] halves a piece
/// down to when it finds no plan for it \[rad\] (15°).
const MIN_TURN_CHUNK: f64 = std::f64::consts::PI / 12.0;

impl Planner {
    /// Plans from `start` to the object orientation `goal`.
    pub fn plan(&self, start: &HandState, goal: &UnitQuaternion<f64>) -> Result<Plan, PlanError> {
        let gq = goal.quaternion();
        if !gq.coords.iter().all(|x| x.is_finite()) || gq.norm() < 1e-9 {
            return Err(PlanError::InvalidGoal);
        }
        let goal = UnitQuaternion::new_normalize(*gq);
        if !state_finite(start) {
            return Err(PlanError::NonFiniteState);
        }
        // After a three-finger turn towards the goal, the cheap tiers only:
        // the fallbacks are for when nothing else plans.
        self.with_triple_turn_first(
            start,
            &goal,
            |s| self.plan_from(s, &goal),
            |short, s| short.in_tiers(|p: &Planner, spins| p.plan_orientation(s, &goal, spins)),
        )
    }

    /// [`Planner::plan`] from `start` as it is: the tiers, then under load
    /// the fallbacks.
    pub(super) fn plan_from(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
    ) -> Result<Plan, PlanError> {
        // Spins come after the waypoints: a plan that spins a contact
        // under load is the last resort (its contact force flickers in
        // MuJoCo, and from some reached grasps the spinning plan was 100
        // gaits long where a waypoint plan has 22: LOAD-FIGURES §12).
        let orientation = |p: &Planner, spins| p.plan_orientation(start, goal, spins);
        self.detour_before_spins(orientation, || self.plan_via_waypoints(start, goal))
    }

    /// [`Planner::in_tiers`]; under load, when they find nothing,
    /// `detour`, and last [`Planner::spinning_tier`]. The first error is
    /// kept.
    fn detour_before_spins(
        &self,
        plan: impl Fn(&Planner, bool) -> Result<Plan, PlanError>,
        detour: impl FnOnce() -> Option<Plan>,
    ) -> Result<Plan, PlanError> {
        match self.in_tiers(&plan) {
            Err(e) if self.load.active() && found_nothing(&e) => {
                detour().map_or_else(|| self.spinning_tier(plan).map_err(|_| e), Ok)
            }
            r => r,
        }
    }

    /// `plan` in tiers under load, without spins, the second tried only
    /// when the first finds nothing: the search's sufficient load test;
    /// the exact closed form behind it (slower per pair, more pairs). The
    /// first error is kept. Spins are [`Planner::spinning_tier`], after the
    /// detours (in MuJoCo a spinning fingertip's contact force flickers:
    /// gait/LOAD-FIGURES.md §0).
    fn in_tiers(
        &self,
        plan: impl Fn(&Planner, bool) -> Result<Plan, PlanError>,
    ) -> Result<Plan, PlanError> {
        let e = match plan(self, false) {
            Err(e) if self.load.active() && found_nothing(&e) => e,
            r => return r,
        };
        plan(&self.exact(), false).map_err(|_| e)
    }

    /// The last tier: the exact load test, contacts spinning allowed.
    fn spinning_tier(
        &self,
        plan: impl Fn(&Planner, bool) -> Result<Plan, PlanError>,
    ) -> Result<Plan, PlanError> {
        plan(&self.exact(), true)
    }

    /// This planner with the exact load test behind the sufficient one.
    fn exact(&self) -> Planner {
        Planner {
            load: self.load.with_exact(&self.config),
            ..self.clone()
        }
    }

    /// [`Planner::plan`] with or without spins under load (`spins`).
    fn plan_orientation(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        spins: bool,
    ) -> Result<Plan, PlanError> {
        let (axis, total) = rotation_to(&start.object, goal);
        match self.plan_about(start, goal, axis, total, false, spins) {
            Err(e) if self.load.active() && found_nothing(&e) => {
                self.plan_via_twist(start, goal, spins).ok_or(e)
            }
            r => r,
        }
    }

    /// Under load, the goal rotation split into a turn about gravity (which
    /// leaves every grasp's load unchanged) and the rest, in either order,
    /// each planned on its own: the fallback when one search about the
    /// goal's axis finds nothing.
    fn plan_via_twist(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        spins: bool,
    ) -> Option<Plan> {
        let up = -self.grip.hold().weight();
        let up = if up.norm() > 0.0 {
            up.normalize()
        } else {
            Vector3::z()
        };
        let rel = goal * start.object.inverse();
        let q = rel.quaternion();
        // Twist about `up`: the projection of the rotation onto it.
        let v = Vector3::new(q.i, q.j, q.k);
        let t = nalgebra::Quaternion::from_parts(q.w, up * up.dot(&v));
        if t.norm() < 1e-9 {
            return None;
        }
        let twist = UnitQuaternion::new_normalize(t);
        for first in [twist, twist.inverse() * rel] {
            let mid = first * start.object;
            let Ok(a) = self.plan_leg(start, &mid, spins) else {
                continue;
            };
            let at = a.end_state();
            let Ok(b) = self.plan_leg(&at, goal, spins) else {
                continue;
            };
            return Some(a.then(b));
        }
        None
    }

    /// Under load, the goal by way of an intermediate orientation: the
    /// start turned by [`WAYPOINT_ANGLE`] about each of
    /// `planner.waypoint_axes` directions in turn, both legs planned
    /// without spins by the sufficient load test (the cheap tier). The
    /// last fallback of [`Planner::plan`]: from some reached grasps the
    /// search about the goal's axis runs out of nodes while most other
    /// goals still plan (gait/LOAD-FIGURES.md §10).
    fn plan_via_waypoints(&self, start: &HandState, goal: &UnitQuaternion<f64>) -> Option<Plan> {
        let n = self.config.planner.waypoint_axes as usize;
        super::fibonacci_sphere(n).iter().find_map(|axis| {
            let mid = rotation(axis, WAYPOINT_ANGLE) * start.object;
            let a = self.plan_orientation(start, &mid, false).ok()?;
            let b = self.plan_orientation(&a.end_state(), goal, false).ok()?;
            Some(a.then(b))
        })
    }

    /// One leg of [`Planner::plan_via_twist`].
    fn plan_leg(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        spins: bool,
    ) -> Result<Plan, PlanError> {
        let (axis, total) = rotation_to(&start.object, goal);
        self.plan_about(start, goal, axis, total, false, spins)
    }

    /// Plans a rotation of the object by `angle` (any size, e.g. a full
    /// turn) about the hand-frame `axis`: the object turns that far, not
    /// just to the orientation it ends at. (If gaits are impossible from the
    /// start, an escape rotation about another axis comes first; the rest
    /// then reaches the same end orientation with the requested number of
    /// full turns, about an axis near `axis`. Under load, a turn or a
    /// piece of one no longer than 120° that the search about
    /// `axis` cannot plan is reached as an orientation, as
    /// [`Planner::plan`] reaches it.)
    pub fn plan_rotation(
        &self,
        start: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
    ) -> Result<Plan, PlanError> {
        let n = axis.norm();
        if !(n.is_finite() && n > 1e-9 && angle.is_finite()) {
            return Err(PlanError::InvalidGoal);
        }
        if !state_finite(start) {
            return Err(PlanError::NonFiniteState);
        }
        let (axis, angle) = if angle < 0.0 {
            (-axis / n, -angle)
        } else {
            (axis / n, angle)
        };
        let goal = rotation(&axis, angle) * start.object;
        let turn =
            |p: &Planner, spins: bool| match p.plan_about(start, &goal, axis, angle, true, spins) {
                Err(
                    PlanError::SearchExhausted
                    | PlanError::Blocked { .. }
                    | PlanError::LoadInfeasible { start: false },
                ) if angle > TURN_CHUNK => p.plan_in_chunks(start, &axis, angle, spins),
                r => r,
            };
        // As for orientation goals, a detour comes before spinning a
        // contact: from where a canceled goal stopped, one turn in five
        // found nothing in the tiers about its own axis, while the goal
        // orientation planned (LOAD-FIGURES §14).
        self.detour_before_spins(turn, || self.short_turn_by_way_of(start, &axis, angle))
    }

    /// Under load, a turn of at most [`TURN_CHUNK`] that the search about
    /// its axis cannot plan, reached as an orientation: split into a turn
    /// about gravity and the rest, or by way of a waypoint (the fallbacks of
    /// [`Planner::plan`]). The object may leave the axis on the way; the
    /// turn is shorter than half a turn, so its end orientation says all
    /// there is to say about it (no full turn to count).
    fn short_turn_by_way_of(
        &self,
        start: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
    ) -> Option<Plan> {
        if angle > TURN_CHUNK {
            return None;
        }
        let goal = rotation(axis, angle) * start.object;
        let mut plan = self
            .plan_via_twist(start, &goal, false)
            .or_else(|| self.plan_via_waypoints(start, &goal))?;
        plan.summary.goal_angle = angle;
        Some(plan)
    }

    /// A long turn as consecutive turns of at most [`TURN_CHUNK`], each
    /// planned from where the previous one ends: the fallback when one
    /// search over the whole turn runs out of budget (many full turns, or
    /// an escape first). A piece with no plan (under load, SPEC §1.3 I1',
    /// a pair may hold for less of a turn than its cones allow) is halved,
    /// down to [`MIN_TURN_CHUNK`], and the next piece is full size again.
    fn plan_in_chunks(
        &self,
        start: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
        spins: bool,
    ) -> Result<Plan, PlanError> {
        let mut steps = Vec::new();
        let mut summary = PlanSummary {
            goal_angle: angle,
            ..PlanSummary::default()
        };
        let mut at = *start;
        let mut left = angle;
        let mut piece = TURN_CHUNK;
        while left > 1e-12 {
            // Even pieces of at most `piece` for what is left.
            let this = left / (left / piece).ceil().max(1.0);
            let goal = rotation(axis, this) * at.object;
            let plan = match self.plan_about(&at, &goal, *axis, this, true, spins) {
                Ok(p) => p,
                Err(e) if this * 0.5 < MIN_TURN_CHUNK => {
                    match (self.load.active() && !spins && found_nothing(&e))
                        .then(|| self.short_turn_by_way_of(&at, axis, this))
                        .flatten()
                    {
                        Some(p) => p,
                        None => return Err(e),
                    }
                }
                Err(_) => {
                    piece = this * 0.5;
                    continue;
                }
            };
            at = plan.end_state();
            left -= this;
            piece = TURN_CHUNK;
            summary.add(&plan.summary);
            steps.extend(plan.steps);
        }
        (summary.substitutions, summary.rewinds) = count_finger_gaits(&steps);
        Ok(Plan {
            start: *start,
            goal: rotation(axis, angle) * start.object,
            steps,
            summary,
        })
    }
}

/// Whether `e` says only that no plan was found (another way may find
/// one), not that the start or goal is wrong.
fn found_nothing(e: &PlanError) -> bool {
    matches!(
        e,
        PlanError::LoadInfeasible { start: false } | PlanError::SearchExhausted
    )
}
