//! A plan's path in time, for whoever shows it (SPEC §4.2, §5): where the
//! object and the fingertips are at evenly spaced instants of the plan's
//! execution, each step timed as the executor runs it — its trajectory
//! from rest to rest, then its handover at rest. Made with the plan, off
//! the control loop.

use super::Plan;
use super::plan::{MAX_DOFS, Step};
use super::timing::on_ticks;
use crate::hand_state::{FINGERS, FingerMode};
use nalgebra::{UnitQuaternion, Vector3};

/// The hand at one instant of a plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Time since the plan's start \[s\].
    pub t: f64,
    /// Object orientation (object frame → hand frame).
    pub object: UnitQuaternion<f64>,
    /// Fingertip sphere centres, hand frame \[m\].
    pub tips: [Vector3<f64>; FINGERS],
    /// Bit k set: finger k grasps.
    pub touching: u8,
}

/// How long step `i` of `plan` moves and then holds for its handover
/// \[s\]: its trajectory's duration (else, no profile having come with the
/// plan, its planned motion), and the handover's.
fn step_times(plan: &Plan, i: usize) -> (f64, f64) {
    let step = &plan.steps[i];
    let hold = step.handover.map_or(0.0, |h| h.duration);
    let motion = plan
        .profiles
        .get(i)
        .and_then(Option::as_ref)
        .map_or(step.duration - hold, |p| p.trajectory.duration);
    (motion.max(0.0), hold.max(0.0))
}

/// The grasping fingers of a state, as bits.
fn touching(state: &crate::HandState) -> u8 {
    let mut bits = 0;
    for (k, f) in state.fingers.iter().enumerate() {
        if f.mode == FingerMode::Grasping {
            bits |= 1 << k;
        }
    }
    bits
}

/// The point of `state` at time `t`.
fn point(t: f64, state: &crate::HandState) -> PathPoint {
    PathPoint {
        t,
        object: state.object,
        tips: state.fingers.map(|f| f.center),
        touching: touching(state),
    }
}

/// How long `plan` runs on a loop of period `dt` \[s\]: every step's
/// motion and handover, each to whole periods (as the executor's ETA
/// counts them).
pub fn duration(plan: &Plan, dt: f64) -> f64 {
    (0..plan.steps.len())
        .map(|i| {
            let (m, h) = step_times(plan, i);
            on_ticks(m, dt) + on_ticks(h, dt)
        })
        .sum()
}

/// Where `plan` has the hand `t` seconds after it started on a loop of
/// period `dt`: the setpoint the executor commands at that time when it
/// runs the plan undisturbed (a step begins on the tick the one before it
/// ends; its trajectory is sampled at whole periods of its own time).
pub fn point_at(plan: &Plan, dt: f64, t: f64) -> PathPoint {
    let mut begun = 0.0;
    for (i, step) in plan.steps.iter().enumerate() {
        let (motion, hold) = step_times(plan, i);
        let length = on_ticks(motion, dt) + on_ticks(hold, dt);
        let last = i + 1 == plan.steps.len();
        // (A hair's tolerance: t is a whole number of periods.)
        if t - begun < length - 1e-9 * dt || last {
            let tau = t - begun;
            let end = step.dofs().length;
            let (position, velocity) = if tau >= motion {
                (end, [0.0; MAX_DOFS])
            } else if let Some(p) = plan.profiles.get(i).and_then(Option::as_ref) {
                let s = p.trajectory.at_time(tau);
                (s.position, s.velocity)
            } else {
                // No profile: the path parameters in proportion to time
                // (a view's approximation; the executor times the step
                // itself).
                let f = if motion > 0.0 { tau / motion } else { 1.0 };
                (end.map(|l| l * f), [0.0; MAX_DOFS])
            };
            let step: &Step = step;
            return point(t, &step.eval(&position, &velocity).state);
        }
        begun += length;
    }
    point(t, &plan.start)
}

/// `count` points (at least 2) at equal intervals from the plan's start
/// (t = 0) to its [`duration`] on a loop of period `dt`. A plan without
/// steps gives its start state at t = 0 only.
pub fn path_points(plan: &Plan, dt: f64, count: usize) -> Vec<PathPoint> {
    if plan.steps.is_empty() {
        return vec![point(0.0, &plan.start)];
    }
    let total = duration(plan, dt);
    let count = count.max(2);
    (0..count)
        .map(|j| point_at(plan, dt, total * j as f64 / (count - 1) as f64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor::GoalTarget;
    use crate::executor::PlanRequest;
    use crate::planner::{Planner, Unbounded};
    use crate::{HandConfig, HandState};

    fn plan() -> Plan {
        let config = HandConfig::default();
        let start = HandState::paper_start(&config);
        let goal = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2.0);
        let request = PlanRequest {
            goal: 1,
            start,
            target: GoalTarget::Orientation(goal),
            limits: config.limits,
            dt: 1e-3,
        };
        let planner = Planner::new(&config).unwrap();
        request
            .plan_within(
                &planner,
                &mut crate::planner::Budget::new(100_000, &mut Unbounded),
            )
            .unwrap()
    }

    #[test]
    fn the_path_runs_from_the_start_to_the_end_through_every_step_in_time() {
        let plan = plan();
        assert!(plan.profiles.iter().all(Option::is_some));
        let points = path_points(&plan, 1e-3, 400);
        assert_eq!(points.len(), 400);
        let first = points[0];
        let last = points[points.len() - 1];
        assert_eq!(first.t, 0.0);
        assert!(first.object.angle_to(&plan.start.object) < 1e-12);
        for (k, f) in plan.start.fingers.iter().enumerate() {
            assert!((first.tips[k] - f.center).norm() < 1e-12);
        }
        let end = plan.end_state();
        assert!(last.object.angle_to(&end.object) < 1e-12);
        assert!(last.object.angle_to(&plan.goal) < 1e-6);
        assert!((last.t - duration(&plan, 1e-3)).abs() < 1e-12);
        // Within a step's motion the object moves at most at the
        // object's velocity limit (the path is timed, not just traced).
        let w = HandConfig::default().limits.object.velocity;
        for pair in points.windows(2) {
            let dt = pair[1].t - pair[0].t;
            let turned = pair[0].object.angle_to(&pair[1].object);
            assert!(turned <= w * dt * 1.0001 + 1e-12, "{turned} in {dt} s");
        }
        // Gaits change which fingers touch along the way.
        let changes = points
            .windows(2)
            .filter(|p| p[0].touching != p[1].touching)
            .count();
        assert!(changes >= 2, "{changes} changes of grasp");
    }

    #[test]
    fn a_plan_without_steps_is_its_start() {
        let mut plan = plan();
        plan.steps.clear();
        plan.profiles.clear();
        let points = path_points(&plan, 1e-3, 10);
        assert_eq!(points.len(), 1);
        assert_eq!(points[0].object, plan.start.object);
    }
}
