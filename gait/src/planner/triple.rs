//! A turn with all three fingers first (SPEC §4.2: Rotate by a grasping
//! triple). From a three-finger grasp — the paper's start, or where a
//! cancel or a plan left the hand — the object can turn towards the goal
//! with every fingertip carried, before the two-finger planning: no pair
//! has to hold the load yet (three hard contacts carry it), and the turn
//! made there is turn the pairs need not make. How far each finger's cone
//! and roll limit allow bounds it; a few fractions of that are planned on,
//! and the quickest plan wins (gait/LOAD-FIGURES.md §15).
//!
//! Under a weight the three may also tilt the object first, about the
//! chord of one of their pairs. A pair resists the weight's moment about
//! its chord by torsion only, F* ≈ (R/2μ_t)·cot(θ/2)·|w⊥| with w⊥ the
//! weight's part normal to the plane of the chord and the centre
//! (`../shared/GRAVITY-NOTES.md`). At the paper's start that plane is the
//! horizontal one, all of the weight is normal to it, and the pair must
//! roll apart beyond one great circle's reach (three zigzag legs) before it
//! holds. Turning about the chord tilts the plane towards the vertical, so
//! w⊥ and the opening needed shrink (gait/LOAD-FIGURES.md §17).

use nalgebra::{UnitQuaternion, Vector3};

use super::geometry::rotation;
use super::plan::{Motion, Step, StepKind};
use super::search::grasp_range;
use super::{Plan, PlanError, PlanSummary, Planner, load, rotation_to};
use crate::state::HandState;

/// Fractions of the longest three-finger turn towards the goal that are
/// planned on. Quarters: with the tilts ([`TILT_FRACTIONS`]) beside them,
/// eighths made 200 plans from the paper start under load no quicker at
/// the median (7.90 s either way; mean 7.84 against 7.87 s) for 40 % more
/// planning time (LOAD-FIGURES §17). Without the tilts they had paid
/// (8.60 s against 8.83 s on average, §16).
const FRACTIONS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// Fractions of the longest tilt about a pair's chord that are planned on
/// (both ways, each pair). 200 goals from the paper start under load
/// (median / mean time to goal): no tilt 8.02 / 8.14 s, halves
/// 7.97 / 7.90 s, quarters 7.90 / 7.84 s, thirds 7.94 / 7.86 s
/// (LOAD-FIGURES §17).
const TILT_FRACTIONS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// Longest tilt tried \[rad\] (90°): beyond it the pair's plane tilts past
/// the vertical again.
const MAX_TILT: f64 = std::f64::consts::FRAC_PI_2;

/// Shortest three-finger turn worth a step of its own \[rad\] (2°).
const MIN_TURN: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Search budget of the planning after a three-finger turn, as a fraction
/// of `planner.max_expansions`: an alternative to a plan already found, so
/// a search that runs long is cut short rather than paid for in full.
const BUDGET_FRACTION: u32 = 6;

impl Planner {
    /// The quickest of `plan(start)` and, when three fingers grasp,
    /// `rest(turned)` after a three-finger turn towards `goal` by each of
    /// [`FRACTIONS`] of the longest one the fingers allow, and under a
    /// weight after a tilt about each pair's chord by [`TILT_FRACTIONS`] of
    /// the longest one (each turn held at every sample under load), `rest`
    /// planning with a smaller search budget ([`BUDGET_FRACTION`]) and no
    /// escapes. The first error is kept when nothing plans.
    pub(super) fn with_triple_turn_first(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        plan: impl Fn(&HandState) -> Result<Plan, PlanError>,
        rest: impl Fn(&Planner, &HandState) -> Result<Plan, PlanError>,
    ) -> Result<Plan, PlanError> {
        let mut best = plan(start);
        if start.grasping().1 != 3 {
            return best;
        }
        let (axis, total) = rotation_to(&start.object, goal);
        let range = self.triple_range(start, &axis, total);
        let mut short = self.clone();
        short.config.planner.max_expansions =
            (self.config.planner.max_expansions / BUDGET_FRACTION).max(1);
        // An alternative to a plan in hand: a search that fails is not
        // followed by the escapes (they cost ~30 % of this planning; left
        // out, the mean time of 60 plans went 8.835 → 8.828 s and the
        // slowest planning 3.1 → 1.0 s, LOAD-FIGURES §16).
        short.escapes = false;
        let weighed = self.grip.hold().weight().norm() > 0.0;
        if !weighed {
            // Without a weight one great-circle roll opens a pair far
            // enough (LOAD-FIGURES §12), and the zigzag search costs ~5 ms
            // a finger (§15).
            short.zigzags = None;
        }
        let towards = FRACTIONS.map(|f| (axis, range * f));
        // (Without a weight no pair's plane needs tilting.)
        let tilts = if weighed {
            self.tilts(start)
        } else {
            Vec::new()
        };
        for (axis, angle) in towards.into_iter().chain(tilts) {
            // No quicker than the turn, a lift with its handover (the rest
            // needs a pair) and the rest of the way in one move: skip it if
            // the plan found already is as quick.
            let left = (rotation(&axis, angle) * start.object).angle_to(goal);
            let mut bound = self.timing.rotate(angle);
            if left > 1e-9 {
                bound += self.timing.vertical + self.timing.handover + self.timing.rotate(left);
            }
            if best.as_ref().is_ok_and(|b| b.summary.duration <= bound) {
                continue;
            }
            let Some(first) = self.triple_turn(start, goal, &axis, angle) else {
                continue;
            };
            let Ok(then) = rest(&short, &first.end_state()) else {
                continue;
            };
            let whole = first.then(then);
            if best
                .as_ref()
                .is_ok_and(|b| b.summary.duration <= whole.summary.duration)
            {
                continue;
            }
            best = Ok(whole);
        }
        best
    }

    /// The tilts tried: about each grasping pair's chord, both ways, by
    /// [`TILT_FRACTIONS`] of the longest turn the three allow (at most
    /// [`MAX_TILT`]).
    fn tilts(&self, hand: &HandState) -> Vec<(Vector3<f64>, f64)> {
        let c = hand.fingers.map(|f| f.contact_normal());
        let mut out = Vec::with_capacity(6 * TILT_FRACTIONS.len());
        for (i, j) in [(0, 1), (1, 2), (0, 2)] {
            let Some(chord) = (c[j] - c[i]).try_normalize(1e-9) else {
                continue;
            };
            for axis in [chord, -chord] {
                let range = grasp_range(&self.geom, hand, &[0, 1, 2], &axis).min(MAX_TILT);
                out.extend(TILT_FRACTIONS.map(|f| (axis, range * f)));
            }
        }
        out
    }

    /// How far the three grasping fingers of `hand` can carry the object
    /// about `axis` (at most `total`): each contact in its cone, each roll
    /// within its limit.
    fn triple_range(&self, hand: &HandState, axis: &Vector3<f64>, total: f64) -> f64 {
        grasp_range(&self.geom, hand, &[0, 1, 2], axis).min(total)
    }

    /// The one-step plan turning `start` by `angle` about `axis` with all
    /// three fingers, if it is worth a step and holds the load at every
    /// sample (`load::check_steps`, the check every plan passes).
    fn triple_turn(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        axis: &Vector3<f64>,
        angle: f64,
    ) -> Option<Plan> {
        if angle < MIN_TURN {
            return None;
        }
        let mut step = Step {
            kind: StepKind::Rotate,
            start: *start,
            motion: Motion::Rotate {
                axis: *axis,
                angle,
                free: None,
            },
            duration: 0.0,
            handover: None,
        };
        step.duration = step.planned_duration(&self.config.limits);
        let steps = vec![step];
        if self.load.active() {
            let a = self.config.limits.object.acceleration;
            load::check_steps(&self.grip, a, start, &steps).ok()?;
        }
        Some(Plan {
            start: *start,
            goal: *goal,
            steps,
            summary: PlanSummary {
                rotations: 1,
                duration: step.duration,
                goal_angle: angle,
                ..PlanSummary::default()
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A Haar-random orientation (a normalised 4-D Gaussian, Box–Muller).
    fn haar(rng: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
        let mut g = || {
            let (u1, u2): (f64, f64) = (rng.random_range(1e-300..1.0), rng.random());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        UnitQuaternion::new_normalize(nalgebra::Quaternion::new(g(), g(), g(), g()))
    }

    #[test]
    fn a_three_finger_turn_first_makes_plans_from_the_paper_start_quicker() {
        // Under the default load the paper start's pair must open ~24° per
        // finger (three zigzag legs) before it can carry the object alone;
        // the three fingers can turn it towards the goal before that, or
        // tilt it about a pair's chord so that the pair needs less. Never
        // slower than planning without the turn (the quicker plan wins);
        // measured on 100 goals: median 9.63 → 8.25 s (LOAD-FIGURES §15);
        // the tilts: 200 goals, median 8.02 → 7.90 s (§17).
        let cfg = HandConfig::default();
        let p = Planner::new(&cfg).unwrap();
        let start = HandState::paper_start(&cfg);
        let mut rng = ChaCha8Rng::seed_from_u64(15);
        let (mut with, mut without, mut turned, mut tilted) = (0.0, 0.0, 0, 0);
        for i in 0..16 {
            let goal = haar(&mut rng);
            let a = p.plan(&start, &goal).expect("planned");
            let b = p.plan_from(&start, &goal).expect("planned without");
            assert!(
                a.summary.duration <= b.summary.duration + 1e-12,
                "goal {i}: {:.2} s with the turn, {:.2} s without",
                a.summary.duration,
                b.summary.duration
            );
            assert!(a.end_state().object.angle_to(&goal) < 1e-9, "goal {i}");
            let first = &a.steps[0];
            if first.kind == StepKind::Rotate
                && first.start.grasping().1 == 3
                && let Motion::Rotate { axis, .. } = first.motion
            {
                turned += 1;
                // Not towards the goal: about the chord of a pair.
                let (towards, _) = rotation_to(&start.object, &goal);
                if axis.dot(&towards) < 1.0 - 1e-9 {
                    let c = start.fingers.map(|f| f.contact_normal());
                    let about_a_chord = [(0, 1), (1, 2), (0, 2)]
                        .iter()
                        .any(|&(i, j)| axis.cross(&(c[j] - c[i])).norm() < 1e-9);
                    assert!(about_a_chord, "goal {i}: a first turn about {axis:?}");
                    tilted += 1;
                }
            }
            with += a.summary.duration;
            without += b.summary.duration;
        }
        println!(
            "16 goals: {turned} turn with three fingers first ({tilted} tilt about a chord); {with:.1} s against {without:.1} s"
        );
        assert!(tilted >= 1, "no plan tilts about a pair's chord first");
        assert!(
            turned >= 4,
            "only {turned} of 16 plans turn with three fingers first"
        );
        assert!(with < 0.96 * without, "{with:.1} s against {without:.1} s");
    }
}
