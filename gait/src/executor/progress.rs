//! How far the executor is along its plan (SPEC §6.1, §7.3): the plan
//! kept, the running step, the goal that step was begun for, and what the
//! status counts down — the time and object rotation after the running
//! step, gaits done and planned. Each step begun subtracts its own share,
//! so the tick never sums over the plan.

use super::tick_report::step_on_ticks;
use crate::planner::timing::StepProfile;
use crate::planner::{Motion, Plan, Step, StepKind};

/// The object rotation a step makes \[rad\].
pub(super) fn step_rotation(step: &Step) -> f64 {
    match step.motion {
        Motion::Rotate { angle, .. } | Motion::Carry { angle, .. } => angle,
        _ => 0.0,
    }
}

/// The plan in hand and the executor's place in it.
#[derive(Debug, Default)]
pub(super) struct Progress {
    plan: Option<Box<Plan>>,
    /// Index of the running (or next) step.
    index: usize,
    /// The goal the running step was begun for (it still finishes for it
    /// when a newer goal preempts it mid-gait).
    step_goal: u64,
    /// Duration of the steps after the running one, on ticks \[s\].
    time_after: f64,
    /// Object rotation of the steps after the running one \[rad\].
    rotation_after: f64,
    gaits_done: u32,
    gaits_planned: u32,
}

impl Progress {
    /// The plan kept, if any.
    pub(super) fn plan(&self) -> Option<&Plan> {
        self.plan.as_deref()
    }

    /// Index of the running step.
    pub(super) fn index(&self) -> usize {
        self.index
    }

    /// The running step, if there is one.
    pub(super) fn current(&self) -> Option<&Step> {
        self.plan().and_then(|p| p.steps.get(self.index))
    }

    /// The goal the running step was begun for.
    pub(super) fn step_goal(&self) -> u64 {
        self.step_goal
    }

    /// Gaits (Place and Lift steps) done and planned.
    pub(super) fn gaits(&self) -> (u32, u32) {
        (self.gaits_done, self.gaits_planned)
    }

    /// Duration of the steps after the running one, on ticks \[s\].
    pub(super) fn time_after_step(&self) -> f64 {
        self.time_after
    }

    /// Object rotation left: the running step's beyond `position` (its
    /// first path parameter now), and every later step's \[rad\].
    pub(super) fn rotation_left(&self, position: f64) -> f64 {
        let in_step = self
            .current()
            .map_or(0.0, |s| (step_rotation(s) - position).max(0.0));
        self.rotation_after + in_step
    }

    /// Keeps `plan` and returns the plan it replaces (freed by the caller,
    /// off the control thread).
    pub(super) fn replace(&mut self, plan: Box<Plan>) -> Option<Box<Plan>> {
        self.plan.replace(plan)
    }

    /// Starts the plan kept from its first step, with the countdowns of
    /// the whole plan for control period `dt`. False when it has no step.
    /// (Bounded: one pass over the steps, once per plan.)
    pub(super) fn start(&mut self, dt: f64) -> bool {
        let Some(plan) = self.plan.as_deref() else {
            return false;
        };
        self.index = 0;
        self.gaits_done = 0;
        self.gaits_planned = plan.summary.gaits;
        self.time_after = plan.steps.iter().map(|s| step_on_ticks(s, dt)).sum();
        self.rotation_after = plan.steps.iter().map(step_rotation).sum();
        !plan.steps.is_empty()
    }

    /// Begins the running step for goal `goal`: its share leaves the
    /// countdowns. The step and the profile the planner brought for it.
    pub(super) fn begin(&mut self, dt: f64, goal: u64) -> Option<(&Step, Option<&StepProfile>)> {
        let plan = self.plan.as_deref()?;
        let step = plan.steps.get(self.index)?;
        self.time_after = (self.time_after - step_on_ticks(step, dt)).max(0.0);
        self.rotation_after = (self.rotation_after - step_rotation(step)).max(0.0);
        self.step_goal = goal;
        let profile = plan.profiles.get(self.index).and_then(Option::as_ref);
        Some((step, profile))
    }

    /// The running step of kind `kind` ran to its end: a gait is counted.
    pub(super) fn finished(&mut self, kind: StepKind) {
        if matches!(kind, StepKind::Place | StepKind::Lift) {
            self.gaits_done += 1;
        }
    }

    /// Moves on to the next step; false (and back at the first) when the
    /// plan has no more.
    pub(super) fn next(&mut self) -> bool {
        self.index += 1;
        let more = self.plan().is_some_and(|p| self.index < p.steps.len());
        if !more {
            self.index = 0;
        }
        more
    }

    /// Back at the first step (the plan is over or interrupted).
    pub(super) fn rewind(&mut self) {
        self.index = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planner::Planner;
    use crate::{HandConfig, HandState};
    use nalgebra::{UnitQuaternion, Vector3};

    /// A plan from the paper's start to a turn that needs gaits.
    fn plan() -> Box<Plan> {
        let config = HandConfig::default();
        let start = HandState::paper_start(&config);
        let goal = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 2.0);
        Box::new(Planner::new(&config).unwrap().plan(&start, &goal).unwrap())
    }

    #[test]
    fn the_countdowns_reach_zero_exactly_at_the_last_step() {
        let dt = 1e-3;
        let plan = plan();
        let steps = plan.steps.clone();
        let mut p = Progress::default();
        assert!(p.replace(plan).is_none());
        assert!(p.start(dt));
        let total: f64 = steps.iter().map(|s| step_on_ticks(s, dt)).sum();
        assert_eq!(p.time_after_step(), total);
        let mut gaits = 0;
        for (i, step) in steps.iter().enumerate() {
            assert_eq!(p.index(), i);
            let (begun, _) = p.begin(dt, 7).expect("a step");
            assert_eq!(begun.kind, step.kind);
            assert_eq!(p.step_goal(), 7);
            let after: f64 = steps[i + 1..].iter().map(|s| step_on_ticks(s, dt)).sum();
            assert!((p.time_after_step() - after).abs() < 1e-9);
            let left: f64 = steps[i..].iter().map(step_rotation).sum();
            assert!((p.rotation_left(0.0) - left).abs() < 1e-12);
            p.finished(step.kind);
            gaits += u32::from(matches!(step.kind, StepKind::Place | StepKind::Lift));
            assert_eq!(p.gaits().0, gaits);
            assert_eq!(p.next(), i + 1 < steps.len());
        }
        assert!(gaits > 0, "the plan has gaits");
        assert_eq!(p.gaits(), (gaits, gaits));
        assert_eq!(p.index(), 0, "back at the first step");
        assert_eq!(p.time_after_step(), 0.0);
    }

    #[test]
    fn a_plan_without_steps_does_not_start() {
        let mut plan = plan();
        plan.steps.clear();
        let mut p = Progress::default();
        p.replace(plan);
        assert!(!p.start(1e-3));
        assert!(p.current().is_none());
        assert!(p.begin(1e-3, 1).is_none());
    }
}
