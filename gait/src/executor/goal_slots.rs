//! The goals the executor knows (SPEC §6.4): the active one, a newer one
//! waiting for the motion to stop, the last one that ended (the status
//! reports it until another starts), the request left for the planner,
//! and the ids taken lately. Every change of a goal's stage is an event.

use super::command::{GoalTarget, PlanRequest};
use super::lifecycle::{ExecutorEvent, ExecutorEvents, GoalStage, Reason};
use crate::config::LimitsConfig;
use nalgebra::UnitQuaternion;

/// A goal taken and not yet ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct ActiveGoal {
    pub(super) id: u64,
    pub(super) target: GoalTarget,
    /// The orientation the goal ends at (resolved when planning starts).
    pub(super) end: UnitQuaternion<f64>,
    pub(super) limits: LimitsConfig,
    pub(super) state: GoalStage,
}

/// The ids of the last [`RecentIds::KEPT`] goals taken: a goal id seen
/// again is refused as a duplicate.
#[derive(Debug, Default)]
pub(super) struct RecentIds {
    ids: [u64; RecentIds::KEPT],
    len: usize,
}

impl RecentIds {
    /// How many ids are kept.
    const KEPT: usize = 16;

    /// Whether `id` is new; if so, it is kept (the oldest dropped).
    pub(super) fn remember(&mut self, id: u64) -> bool {
        if self.ids[..self.len].contains(&id) {
            return false;
        }
        if self.len < Self::KEPT {
            self.len += 1;
        } else {
            self.ids.rotate_left(1);
        }
        self.ids[self.len - 1] = id;
        true
    }
}

/// The executor's goals (module docs).
#[derive(Debug, Default)]
pub(super) struct GoalSlots {
    active: Option<ActiveGoal>,
    pending: Option<ActiveGoal>,
    last: Option<(u64, GoalStage, Reason)>,
    request: Option<PlanRequest>,
    recent: RecentIds,
}

impl GoalSlots {
    /// The active goal.
    pub(super) fn active(&self) -> Option<ActiveGoal> {
        self.active
    }

    /// The active goal, to resolve or re-aim.
    pub(super) fn active_mut(&mut self) -> Option<&mut ActiveGoal> {
        self.active.as_mut()
    }

    /// Whether goal `id` is the active one.
    pub(super) fn is_active(&self, id: u64) -> bool {
        self.active.is_some_and(|g| g.id == id)
    }

    /// The goal waiting for the motion to stop.
    pub(super) fn pending(&self) -> Option<ActiveGoal> {
        self.pending
    }

    /// The active goal with no reason yet, else the last one ended, as the
    /// status reports it.
    pub(super) fn reported(&self) -> Option<(u64, GoalStage, Reason)> {
        match self.active {
            Some(g) => Some((g.id, g.state, Reason::None)),
            None => self.last,
        }
    }

    /// Whether `id` was not taken lately; if so, it is now.
    pub(super) fn remember(&mut self, id: u64) -> bool {
        self.recent.remember(id)
    }

    /// Goal `id` reaches `state` for `reason`: an event; a terminal stage
    /// is what the status reports once no goal is active.
    pub(super) fn event(
        &mut self,
        events: &mut ExecutorEvents,
        id: u64,
        state: GoalStage,
        reason: Reason,
    ) {
        events.push(ExecutorEvent::Goal { id, state, reason });
        if state.is_terminal() {
            self.last = Some((id, state, reason));
        }
    }

    /// The active goal moves on to `state`.
    pub(super) fn set_state(&mut self, events: &mut ExecutorEvents, state: GoalStage) {
        if let Some(g) = self.active.as_mut() {
            g.state = state;
            let id = g.id;
            self.event(events, id, state, Reason::None);
        }
    }

    /// The active goal ends in `state` for `reason`.
    pub(super) fn end(&mut self, events: &mut ExecutorEvents, state: GoalStage, reason: Reason) {
        if let Some(g) = self.active.take() {
            self.event(events, g.id, state, reason);
        }
    }

    /// The waiting goal ends in `state` for `reason` without starting.
    pub(super) fn end_pending(
        &mut self,
        events: &mut ExecutorEvents,
        state: GoalStage,
        reason: Reason,
    ) {
        if let Some(p) = self.pending.take() {
            self.event(events, p.id, state, reason);
        }
    }

    /// `goal` becomes the active goal.
    pub(super) fn activate(&mut self, goal: ActiveGoal) {
        self.active = Some(goal);
    }

    /// `goal` waits for the motion to stop.
    pub(super) fn defer(&mut self, goal: ActiveGoal) {
        self.pending = Some(goal);
    }

    /// The waiting goal becomes the active one; false if none waited.
    pub(super) fn promote(&mut self) -> bool {
        match self.pending.take() {
            Some(g) => {
                self.active = Some(g);
                true
            }
            None => false,
        }
    }

    /// Leaves `request` for the planner (replacing one not taken).
    pub(super) fn ask(&mut self, request: PlanRequest) {
        self.request = Some(request);
    }

    /// The request left for the planner, if any.
    pub(super) fn take_request(&mut self) -> Option<PlanRequest> {
        self.request.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    fn goal(id: u64) -> ActiveGoal {
        ActiveGoal {
            id,
            target: GoalTarget::Orientation(UnitQuaternion::identity()),
            end: UnitQuaternion::identity(),
            limits: HandConfig::default().limits,
            state: GoalStage::Accepted,
        }
    }

    #[test]
    fn an_id_is_a_duplicate_while_among_the_last_sixteen() {
        let mut r = RecentIds::default();
        assert!(r.remember(1));
        assert!(!r.remember(1));
        for id in 2..=16 {
            assert!(r.remember(id));
        }
        assert!(!r.remember(1), "16 kept: the first is still there");
        assert!(r.remember(17));
        assert!(r.remember(1), "the first was dropped for the 17th");
        assert!(!r.remember(17));
    }

    #[test]
    fn the_status_reports_the_active_goal_else_the_last_ended() {
        let mut events = ExecutorEvents::default();
        let mut g = GoalSlots::default();
        assert_eq!(g.reported(), None);
        g.activate(goal(1));
        g.set_state(&mut events, GoalStage::Executing);
        assert_eq!(g.reported(), Some((1, GoalStage::Executing, Reason::None)));
        g.defer(goal(2));
        g.end(&mut events, GoalStage::Preempted, Reason::NewerGoal);
        assert_eq!(
            g.reported(),
            Some((1, GoalStage::Preempted, Reason::NewerGoal))
        );
        // A stage that is not terminal is not the last goal's.
        g.event(&mut events, 2, GoalStage::Planning, Reason::None);
        assert_eq!(g.reported().map(|r| r.0), Some(1));
        assert!(g.promote());
        assert!(g.is_active(2) && g.pending().is_none());
        assert!(!g.promote());
        g.end_pending(&mut events, GoalStage::Canceled, Reason::None);
        assert_eq!(g.reported().map(|r| r.0), Some(2), "no goal waited");
        let stages: Vec<_> = std::iter::from_fn(|| events.pop())
            .map(|e| match e {
                ExecutorEvent::Goal { id, state, .. } => (id, state),
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(
            stages,
            [
                (1, GoalStage::Executing),
                (1, GoalStage::Preempted),
                (2, GoalStage::Planning)
            ]
        );
    }
}
