//! Detours: a first rotation about another axis when the straight plan is
//! long (PLANNER-NOTES: trying the first segment about other axes lowers
//! the mean and the worst case). Only plans longer than
//! `planner.detour_above_s` pay for it, within a budget of search
//! expansions, so typical planning stays fast.

use nalgebra::{UnitQuaternion, Vector3};

use super::search::{Root, rotate_hand, split};
use super::start::Start;
use super::{Escape, Plan, PlanSummary, Planner, fibonacci_sphere, rotation_to};
use crate::state::HandState;

/// Detour rotations shorter than this are not worth a segment \[rad\].
const MIN_DETOUR: f64 = 0.17;

/// A first rotation to try: start index, hand after it, axis, angle, and a
/// lower bound on the plan's duration through it.
struct Candidate {
    start: usize,
    hand: HandState,
    axis: Vector3<f64>,
    angle: f64,
    bound: f64,
}

impl Planner {
    /// The cheapest of `best` and the plans that first rotate the object
    /// about one of `planner.detour_axes` axes (as far as the pair allows,
    /// or half as far) and then search about the remaining axis. Detours
    /// are searched in order of their lower bound, within a total of
    /// `planner.max_expansions` expansions.
    pub(super) fn detour(
        &self,
        start: &HandState,
        goal: &UnitQuaternion<f64>,
        starts: &[Start],
        mut best: Plan,
        summary: &mut PlanSummary,
    ) -> Plan {
        let p = &self.config.planner;
        if best.summary.duration <= p.detour_above_s || p.detour_axes == 0 {
            return best;
        }
        let mut cands = Vec::new();
        for (i, s) in starts.iter().enumerate() {
            let Some((pair, free)) = split(&s.hand) else {
                continue;
            };
            for e in fibonacci_sphere(p.detour_axes as usize) {
                let about = self.problem(e, 0.0);
                let range = about.pair_range(&s.hand, pair).min(std::f64::consts::PI);
                for t in [range, 0.5 * range] {
                    if t < MIN_DETOUR {
                        continue;
                    }
                    let mut h = s.hand;
                    rotate_hand(&mut h, &e, t);
                    if !about.theory1(&h, pair, free) {
                        continue;
                    }
                    let (_, rest) = rotation_to(&h.object, goal);
                    let bound = s.cost + self.timing.rotate(t) + self.timing.rotate(rest);
                    if bound < best.summary.duration {
                        cands.push(Candidate {
                            start: i,
                            hand: h,
                            axis: e,
                            angle: t,
                            bound,
                        });
                    }
                }
            }
        }
        cands.sort_by(|a, b| a.bound.total_cmp(&b.bound));
        let mut budget = p.max_expansions as usize;
        for c in &cands {
            if budget == 0 || c.bound >= best.summary.duration {
                break;
            }
            let s = &starts[c.start];
            let (axis2, total2) = rotation_to(&c.hand.object, goal);
            let mut problem = self.problem(axis2, total2);
            problem.max_expansions = (problem.max_expansions / 4).clamp(1, budget);
            let root = Root {
                hand: c.hand,
                cost: 0.0,
                tag: 0,
            };
            let found = problem.solve(&[root]);
            let used = found
                .as_ref()
                .map_or(problem.max_expansions, |f| f.expansions);
            budget = budget.saturating_sub(used);
            summary.expansions += used as u32;
            let Some(found) = found else {
                continue;
            };
            if s.cost + self.timing.rotate(c.angle) + found.cost >= best.summary.duration {
                continue;
            }
            let esc = Escape::Rotate((c.axis, c.angle));
            if let Ok(plan) = self.build(
                start,
                goal,
                s,
                Some(&esc),
                &axis2,
                &found.segments,
                *summary,
            ) && plan.summary.duration < best.summary.duration
            {
                best = plan;
            }
        }
        best.summary.expansions = summary.expansions;
        best
    }
}
