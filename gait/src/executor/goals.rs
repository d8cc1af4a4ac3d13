//! The goal lifecycle of the executor (SPEC §6.4): commands (goal, cancel,
//! hold, reset), preemption, stops and plan hand-over. The per-tick motion
//! is in the parent module.

use super::goal_slots::ActiveGoal;
use super::*;

impl Executor {
    pub(super) fn set_goal_state(&mut self, state: GoalStage) {
        self.goals.set_state(&mut self.events, state);
    }

    /// Ends the active goal.
    pub(super) fn end_goal(&mut self, state: GoalStage, reason: Reason) {
        self.goals.end(&mut self.events, state, reason);
        self.replans = 0;
    }

    /// Ends the goal waiting for the motion to stop, never started.
    pub(super) fn end_pending(&mut self, state: GoalStage, reason: Reason) {
        self.goals.end_pending(&mut self.events, state, reason);
    }

    /// Takes a command (SPEC §6.4). Never blocks, never allocates.
    pub fn command(&mut self, cmd: ExecutorCommand) -> ExecutorAnswer {
        match cmd {
            ExecutorCommand::Goal { id, target, limits } => self.new_goal(id, target, limits),
            ExecutorCommand::Cancel => {
                if self.goals.active().is_none() && self.goals.pending().is_none() {
                    return ExecutorAnswer::Rejected(Reason::None);
                }
                self.request_stop(AfterStop::Hold(Reason::CancelCommand));
                ExecutorAnswer::Accepted
            }
            ExecutorCommand::Hold => {
                if self.phase != Mode::SafeHold {
                    self.request_stop(AfterStop::Hold(Reason::HoldCommand));
                }
                ExecutorAnswer::Accepted
            }
            ExecutorCommand::Reset => self.reset(),
        }
    }

    pub(super) fn new_goal(
        &mut self,
        id: u64,
        target: GoalTarget,
        limits: Option<LimitsConfig>,
    ) -> ExecutorAnswer {
        let limits = limits.unwrap_or(self.limits);
        let positive = [limits.object, limits.fingertip, limits.rolling]
            .iter()
            .all(|l| {
                [l.velocity, l.acceleration, l.jerk]
                    .iter()
                    .all(|x| x.is_finite() && *x > 0.0)
            });
        if !target.is_valid() {
            return ExecutorAnswer::Rejected(Reason::InvalidTarget);
        }
        if !positive {
            return ExecutorAnswer::Rejected(Reason::InvalidLimits);
        }
        if self.phase == Mode::SafeHold {
            return ExecutorAnswer::Rejected(Reason::FaultActive);
        }
        if !self.goals.remember(id) {
            return ExecutorAnswer::Rejected(Reason::DuplicateId);
        }
        let goal = ActiveGoal {
            id,
            target,
            end: target.resolve(&self.setpoint.state.object),
            limits,
            state: GoalStage::Accepted,
        };
        self.goals
            .event(&mut self.events, id, GoalStage::Accepted, Reason::None);
        self.replans = 0;
        self.end_pending(GoalStage::Preempted, Reason::NewerGoal);
        match self.phase {
            Mode::Holding | Mode::Planning => {
                if self.phase == Mode::Planning {
                    // The plan in the making is for the old goal: it is
                    // dropped as stale when it arrives.
                    self.end_goal(GoalStage::Preempted, Reason::NewerGoal);
                }
                self.goals.activate(goal);
                self.begin_planning();
            }
            Mode::Moving | Mode::Stopping => {
                self.end_goal(GoalStage::Preempted, Reason::NewerGoal);
                self.goals.defer(goal);
                self.request_stop(AfterStop::Replan);
            }
            Mode::SafeHold => {}
        }
        ExecutorAnswer::Accepted
    }

    pub(super) fn begin_planning(&mut self) {
        self.phase = Mode::Planning;
        self.set_goal_state(GoalStage::Planning);
        let from = self.setpoint.state.object;
        if let Some(g) = self.goals.active_mut() {
            g.end = g.target.resolve(&from);
        }
        if let Some(g) = self.goals.active() {
            self.goals.ask(PlanRequest {
                goal: g.id,
                start: self.setpoint.state,
                target: g.target,
                limits: g.limits,
                dt: self.dt,
            });
        }
    }

    /// Brings the motion to rest, then does `then`.
    pub(super) fn request_stop(&mut self, then: AfterStop) {
        match self.phase {
            Mode::Holding => self.finish_stop(then),
            Mode::Planning => {
                // At rest already; a plan in the making becomes stale.
                self.finish_stop(then)
            }
            Mode::Moving | Mode::Stopping => {
                self.after_stop = then;
                self.phase = Mode::Stopping;
                // A gait, or a handover under way, finishes first.
                let finishing = self.carrying.handover().is_some()
                    || self
                        .current_step()
                        .is_some_and(|s| matches!(s.kind, StepKind::Place | StepKind::Lift));
                if finishing {
                    self.stop_after_step = true;
                } else if !self.runner.stopping() {
                    // Braking past the path end is not possible: then the
                    // step simply runs to its (resting) end.
                    if self.runner.stop().is_err() {
                        let cause = Cause::new(FaultKind::Trajectory, Source::Trajectory);
                        self.handle(cause, NOT_A_FINGER, None);
                    }
                }
            }
            Mode::SafeHold => {}
        }
    }

    pub(super) fn finish_stop(&mut self, then: AfterStop) {
        self.stop_after_step = false;
        // Rotation the interrupted plan still had to make.
        let left = self.planned_rotation_left();
        if self.drift.is_some() && !self.rebase() {
            self.progress.rewind();
            return;
        }
        match then {
            AfterStop::Replan => {
                if self.goals.promote() {
                    self.begin_planning();
                } else {
                    self.phase = Mode::Holding;
                }
            }
            AfterStop::Hold(reason) => {
                self.end_goal(GoalStage::Canceled, reason);
                self.end_pending(GoalStage::Canceled, reason);
                self.phase = Mode::Holding;
            }
            AfterStop::Fault => self.phase = Mode::SafeHold,
            AfterStop::Recover => self.replan_after_drift(Some(left)),
        }
        self.progress.rewind();
    }

    pub(super) fn reset(&mut self) -> ExecutorAnswer {
        if self.phase != Mode::SafeHold {
            return ExecutorAnswer::Accepted;
        }
        // Only at rest, and from a measurement of the last tick (not one
        // from before measurements stopped).
        if self.braking {
            return ExecutorAnswer::Rejected(Reason::NotAtRest);
        }
        if self.measured_at != self.tick {
            return ExecutorAnswer::Rejected(Reason::NoFreshMeasurement);
        }
        let Some(state) = self.measured_state() else {
            return ExecutorAnswer::Rejected(Reason::NoFreshMeasurement);
        };
        // Resume from the measured state if it is valid.
        match self.checker.check(&state) {
            Ok(r) if r.ok() => {
                self.resume_from(state);
                ExecutorAnswer::Accepted
            }
            _ => ExecutorAnswer::Rejected(Reason::MeasuredStateInvalid),
        }
    }

    /// Leaves safe hold holding `state` (valid, measured): a new estimate,
    /// no fault (`FaultCleared`).
    pub(super) fn resume_from(&mut self, state: HandState) {
        // Measured: the fingertips are where the object is; no offset.
        self.placement.clear();
        self.adopt(state);
        self.fault = None;
        self.phase = Mode::Holding;
        self.events.push(ExecutorEvent::FaultCleared);
    }

    /// Accepts the planner's answer for goal `id`. Returns the plan the
    /// executor no longer needs (the replaced one, or the delivered one if
    /// it is stale) so the caller can free it off the control thread.
    pub fn deliver_plan(
        &mut self,
        id: u64,
        result: Result<Box<Plan>, PlanError>,
    ) -> Option<Box<Plan>> {
        let current = self.phase == Mode::Planning && self.goals.is_active(id);
        if current && self.drift.is_some() {
            // Drifted while planning: the plan starts from the old estimate.
            if self.rebase() {
                self.replan_after_drift(None);
            }
            return result.ok();
        }
        match result {
            Err(e) => {
                if current {
                    self.end_goal(GoalStage::Aborted, Reason::NoPlan(e));
                    self.phase = Mode::Holding;
                }
                None
            }
            Ok(plan) if !current => Some(plan),
            Ok(plan) => {
                let old = self.progress.replace(plan);
                self.start_plan();
                old
            }
        }
    }

    /// The planner could not take the request for goal `id` (its queue is
    /// full): the goal is aborted rather than left waiting.
    pub fn plan_unavailable(&mut self, id: u64) {
        let current = self.phase == Mode::Planning && self.goals.is_active(id);
        if current {
            self.end_goal(GoalStage::Aborted, Reason::PlannerBusy);
            self.phase = Mode::Holding;
        }
    }

    pub(super) fn start_plan(&mut self) {
        if self.progress.plan().is_none() {
            return;
        }
        if !self.progress.start(self.dt) {
            self.end_goal(GoalStage::Succeeded, Reason::None);
            self.phase = Mode::Holding;
            return;
        }
        self.phase = Mode::Moving;
        self.set_goal_state(GoalStage::Executing);
        self.begin_step();
    }
}
