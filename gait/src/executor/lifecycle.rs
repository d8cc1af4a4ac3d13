//! Goal lifecycle (SPEC §6.4), reason codes and the event queue.
//!
//! ```text
//!            ┌────────── Rejected(reason)
//!  command ──┤
//!            └─ Accepted ─> Planning ─> Executing ─> Succeeded
//!                              │  ^         │
//!                              │  └─────────┤ contact drift: stop, re-base,
//!                              │            │ plan again (SPEC §6.3)
//!                              │            ├──────> Aborted(reason)
//!                              │            ├──────> Canceled   (cancel / hold)
//!                              └────────────┴──────> Preempted  (a newer goal)
//! ```
//! Every terminal state carries a reason ([`Reason`]); the daemon turns it
//! into a stable wire code.

use crate::planner::PlanError;

/// Where a goal is in its life.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum GoalStage {
    /// Received and valid; waiting for the motion to come to rest.
    Accepted = 1,
    /// A plan is being computed off the control thread.
    Planning = 2,
    /// The plan is being executed.
    Executing = 3,
    /// Reached: the object is at the goal orientation.
    Succeeded = 4,
    /// Given up (see the reason).
    Aborted = 5,
    /// Stopped by a cancel or hold command.
    Canceled = 6,
    /// Replaced by a newer goal.
    Preempted = 7,
    /// Refused on arrival (see the reason).
    Rejected = 8,
}

impl GoalStage {
    /// Whether the goal is over.
    pub fn is_terminal(self) -> bool {
        matches!(
            self,
            Self::Succeeded | Self::Aborted | Self::Canceled | Self::Preempted | Self::Rejected
        )
    }
}

/// Why a goal ended as it did, or why a command was refused. The daemon
/// maps each to a wire `ReasonCode` (one place: its controller's codes
/// module); a planning failure keeps the planner's own reason (SPEC §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reason {
    /// Nothing to report (Succeeded, or still running).
    None,
    /// The target orientation is not a finite, non-zero quaternion (or the
    /// axis of a turn is not a finite non-zero vector).
    InvalidTarget,
    /// A motion limit of the goal is not finite and positive.
    InvalidLimits,
    /// The hand is in safe hold: reset first.
    FaultActive,
    /// The planner returned no plan, for this reason.
    NoPlan(PlanError),
    /// The planner could not take the request (its queue is full).
    PlannerBusy,
    /// A fault stopped the motion (see the fault code).
    Fault,
    /// A cancel command.
    CancelCommand,
    /// A hold command.
    HoldCommand,
    /// A newer goal.
    NewerGoal,
    /// The goal id was used before.
    DuplicateId,
    /// A reset found the measured state breaking an invariant: the hand
    /// must be brought back to a valid grasp first.
    MeasuredStateInvalid,
    /// A reset while the hand still brakes to rest after the fault.
    NotAtRest,
    /// A reset without a measurement in the last tick (the plant is lost,
    /// stalled or not started).
    NoFreshMeasurement,
}

/// What the plant or the checks reported (SPEC §6.3, §6.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u16)]
pub enum FaultKind {
    /// The plant sent no measurement this tick.
    MissingMeasurement = 1,
    /// A measurement holds a non-finite number.
    BadMeasurement = 2,
    /// The measured object orientation left the planned one.
    ObjectTracking = 3,
    /// A measured fingertip left its commanded pose.
    FingerTracking = 4,
    /// A contact point drifted on the object (slip).
    ContactDrift = 5,
    /// The trajectory generator refused an input.
    Trajectory = 7,
    /// I1: the commanded grasp is not force-closure.
    ForceClosure = 8,
    /// I2: a contact or free fingertip outside its workspace or shell.
    Workspace = 9,
    /// I3: a fingertip contact outside its hemisphere, or the roll limit.
    Fingertip = 10,
    /// I4: two fingertips too close.
    Collision = 11,
    /// I5: a grasping fingertip off the contact sphere, or the state is not
    /// finite.
    Contact = 12,
    /// No plant has sent a valid measurement yet: nothing moves.
    PlantWaiting = 13,
    /// The plant stopped sending fresh measurements.
    PlantLost = 14,
    /// The plant sent an invalid measurement (codes, required fields,
    /// non-finite numbers, non-unit quaternions).
    PlantInvalid = 15,
    /// The plant's measurements went backwards, or echoed another session.
    PlantSequence = 16,
    /// The plant reports a fault of its own.
    PlantFault = 17,
    /// A grasping contact is measured as not touching.
    ContactLost = 18,
    /// The plant exchange missed its timing contract too many ticks in a
    /// row (commands or measurements late or repeated).
    PlantTiming = 19,
}

/// What happened, for clients (SPEC §7.3 events).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ExecutorEvent {
    /// A goal changed state.
    Goal {
        /// Goal id.
        id: u64,
        /// New state.
        state: GoalStage,
        /// Reason (for terminal states).
        reason: Reason,
    },
    /// A plan step started.
    Step {
        /// Goal id.
        id: u64,
        /// Index in the plan.
        index: u32,
        /// Its kind.
        kind: crate::planner::StepKind,
        /// The finger it concerns (Place/Lift/Transfer/Roll), or 255.
        finger: u8,
    },
    /// A plan step ended where it was planned to (not cut short by a stop).
    StepDone {
        /// Id of the goal the step was begun for (a placement or lift in
        /// flight finishes after a newer goal preempted that one).
        id: u64,
        /// Index in the plan.
        index: u32,
        /// Its kind.
        kind: crate::planner::StepKind,
        /// The finger it concerns, or 255.
        finger: u8,
    },
    /// A fault was detected; the hand is in safe hold.
    Fault {
        /// What.
        kind: FaultKind,
        /// Finger concerned, or 255.
        finger: u8,
    },
    /// The fault was cleared by a reset.
    FaultCleared,
    /// A grasping contact drifted beyond tolerance (SPEC §6.3): the motion
    /// stops smoothly, the controller re-bases its estimate on the measured
    /// state and the goal (if any) is planned again from there.
    Drift {
        /// Goal concerned, 0 if none.
        id: u64,
        /// The finger whose contact drifted.
        finger: u8,
        /// Drifts recovered since the goal started (or, with no goal,
        /// since the last one ended), this one included.
        replan: u32,
    },
    /// While moving, the measured state came near the limit of an
    /// invariant (SPEC §6.3, [`super::guard`]): the motion stops smoothly
    /// and the goal is planned again from the measured state, as after a
    /// drift (the same replan budget).
    NearLimit {
        /// Goal concerned, 0 if none.
        id: u64,
        /// Which invariant, as the fault it would become.
        kind: FaultKind,
        /// The finger concerned (for a collision, the first of the pair),
        /// or 255.
        finger: u8,
        /// Replans since the goal started, this one included.
        replan: u32,
    },
}

/// Capacity of the event queue between two drains.
pub const EVENT_CAPACITY: usize = 32;

/// Fixed-capacity FIFO of events (no allocation). When full, the oldest
/// event is dropped and counted.
#[derive(Debug, Clone)]
pub struct ExecutorEvents {
    buf: [Option<ExecutorEvent>; EVENT_CAPACITY],
    head: usize,
    len: usize,
    /// Events dropped because the queue was full.
    pub dropped: u64,
}

impl Default for ExecutorEvents {
    fn default() -> Self {
        Self {
            buf: [None; EVENT_CAPACITY],
            head: 0,
            len: 0,
            dropped: 0,
        }
    }
}

impl ExecutorEvents {
    /// Appends an event.
    pub fn push(&mut self, e: ExecutorEvent) {
        if self.len == EVENT_CAPACITY {
            self.head = (self.head + 1) % EVENT_CAPACITY;
            self.len -= 1;
            self.dropped += 1;
        }
        self.buf[(self.head + self.len) % EVENT_CAPACITY] = Some(e);
        self.len += 1;
    }

    /// Removes the oldest event.
    pub fn pop(&mut self) -> Option<ExecutorEvent> {
        if self.len == 0 {
            return None;
        }
        let e = self.buf[self.head].take();
        self.head = (self.head + 1) % EVENT_CAPACITY;
        self.len -= 1;
        e
    }

    /// Number of queued events.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no event is queued.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queue_is_fifo_and_drops_oldest() {
        let mut q = ExecutorEvents::default();
        for i in 0..(EVENT_CAPACITY as u64 + 3) {
            q.push(ExecutorEvent::Goal {
                id: i,
                state: GoalStage::Accepted,
                reason: Reason::None,
            });
        }
        assert_eq!(q.dropped, 3);
        assert_eq!(q.len(), EVENT_CAPACITY);
        match q.pop() {
            Some(ExecutorEvent::Goal { id, .. }) => assert_eq!(id, 3),
            e => panic!("{e:?}"),
        }
    }
}
