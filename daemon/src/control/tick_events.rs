//! Fixed-capacity queue of the events produced during one tick: the
//! controller pushes them through its
//! [`TickContext`](super::controller::TickContext), the loop's postprocess
//! phase publishes and clears them. Never allocates after construction;
//! overflow is counted, not hidden.

use shm_schema::{Event, EventKind, FaultCode, GoalState, NO_FINGER, ReasonCode};

/// Events per tick kept at most.
pub const EVENTS_PER_TICK: usize = 32;

/// The events of one tick.
#[derive(Debug, Clone)]
pub struct TickEvents {
    items: [Event; EVENTS_PER_TICK],
    len: usize,
    dropped: u64,
}

impl Default for TickEvents {
    fn default() -> Self {
        Self::new()
    }
}

impl TickEvents {
    /// An empty queue.
    pub fn new() -> Self {
        Self {
            items: [Event::default(); EVENTS_PER_TICK],
            len: 0,
            dropped: 0,
        }
    }

    /// Adds an event (the loop stamps seq, tick, time and instance).
    pub fn push(&mut self, e: Event) {
        if self.len < EVENTS_PER_TICK {
            self.items[self.len] = e;
            self.len += 1;
        } else {
            self.dropped += 1;
        }
    }

    /// A goal changed state; `finger` is the finger the reason concerns, if
    /// any (e.g. the blocked finger of a `FingerBlocked` plan failure).
    pub fn goal_transition(
        &mut self,
        client_id: u64,
        goal_id: u64,
        state: GoalState,
        reason: ReasonCode,
        remaining_angle: f64,
        finger: Option<u8>,
    ) {
        let mut e = Event::new(EventKind::GoalTransition);
        e.client_id = client_id;
        e.goal_id = goal_id;
        e.state = state.code();
        e.reason = reason.code();
        e.value = remaining_angle;
        e.finger = wire_finger(finger.unwrap_or(u8::MAX));
        self.push(e);
    }

    /// A gait event (place, lift, roll, substitution) of `finger`.
    pub fn gait(&mut self, kind: EventKind, finger: u8, goal_id: u64, client_id: u64) {
        self.push(goal_event(kind, finger, 0, goal_id, client_id));
    }

    /// A substitution completed (paper §2.1): `left` broke contact after
    /// `by` took over its place in the grasp (`count` = `by` as a bit).
    pub fn substitution(&mut self, left: u8, by: u8, goal_id: u64, client_id: u64) {
        let by_bit = if usize::from(by) < shm_schema::FINGERS {
            1 << by
        } else {
            0
        };
        self.push(goal_event(
            EventKind::Substitution,
            left,
            by_bit,
            goal_id,
            client_id,
        ));
    }

    /// A finger rewind completed (paper §2.1): `relocated` as bits (bit k
    /// for finger k), `helper` free again.
    pub fn rewind(&mut self, helper: u8, relocated: u8, goal_id: u64, client_id: u64) {
        self.push(goal_event(
            EventKind::Rewind,
            helper,
            relocated.into(),
            goal_id,
            client_id,
        ));
    }

    /// The measured state came near an invariant's limit (SPEC §6.3): the
    /// goal is replanned.
    pub fn near_limit(
        &mut self,
        fault: FaultCode,
        finger: u8,
        replan: u32,
        goal_id: u64,
        client_id: u64,
    ) {
        let mut e = goal_event(
            EventKind::NearLimit,
            finger,
            replan.into(),
            goal_id,
            client_id,
        );
        e.fault = fault.code();
        self.push(e);
    }

    /// A contact drifted (SPEC §6.3): the goal is replanned.
    pub fn drift(&mut self, finger: u8, replan: u32, goal_id: u64, client_id: u64) {
        self.push(goal_event(
            EventKind::Drift,
            finger,
            replan.into(),
            goal_id,
            client_id,
        ));
    }

    /// A fault was detected; `finger` is the one finger whose state caused
    /// it (a stuck fingertip, a lost contact), or 255 when the cause is not
    /// one finger's (the object, the grasp, the plant link), and `count` is
    /// kind-specific (`PlantFault`: the plant's own `PlantFault` code).
    pub fn fault(&mut self, fault: FaultCode, finger: u8, count: u64) {
        let mut e = Event::new(EventKind::Fault);
        e.fault = fault.code();
        e.finger = wire_finger(finger);
        e.count = count;
        self.push(e);
    }

    /// The queued events.
    pub fn as_slice(&self) -> &[Event] {
        &self.items[..self.len]
    }

    /// Empties the queue (keeps the overflow count).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Events lost to overflow since start.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
}

/// An event of `kind` about `finger` of goal (`client_id`, `goal_id`), with
/// its kind-specific `count`.
fn goal_event(kind: EventKind, finger: u8, count: u64, goal_id: u64, client_id: u64) -> Event {
    let mut e = Event::new(kind);
    e.finger = wire_finger(finger);
    e.count = count;
    e.goal_id = goal_id;
    e.client_id = client_id;
    e
}

/// A finger index on the wire: 0–2, or [`NO_FINGER`] for "no finger"
/// (the executor's `u8` 255, e.g. a force-closure limit, which concerns
/// the grasp, not one finger). Clients reject any other value.
fn wire_finger(finger: u8) -> u32 {
    if usize::from(finger) < shm_schema::FINGERS {
        finger.into()
    } else {
        NO_FINGER
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflow_is_counted() {
        let mut q = TickEvents::new();
        for i in 0..EVENTS_PER_TICK + 3 {
            q.gait(EventKind::Place, (i % 3) as u8, 1, 2);
        }
        assert_eq!(q.as_slice().len(), EVENTS_PER_TICK);
        assert_eq!(q.dropped(), 3);
        assert_eq!(q.as_slice()[1].finger, 1);
        q.clear();
        assert!(q.as_slice().is_empty());
    }

    /// Every event the queue builds passes the clients' check, including
    /// those about no finger in particular (the executor's 255).
    #[test]
    fn events_without_a_finger_pass_the_clients_check() {
        let mut q = TickEvents::new();
        q.near_limit(FaultCode::ForceClosureLost, 255, 1, 7, 9);
        q.drift(255, 1, 7, 9);
        q.near_limit(FaultCode::WorkspaceViolation, 2, 1, 7, 9);
        q.substitution(0, 2, 7, 9);
        for e in q.as_slice() {
            assert_eq!(e.check(), Ok(()), "{e:?}");
        }
        assert_eq!(q.as_slice()[0].finger, NO_FINGER);
        assert_eq!(q.as_slice()[1].finger, NO_FINGER);
        assert_eq!(q.as_slice()[2].finger, 2);
        assert_eq!((q.as_slice()[3].finger, q.as_slice()[3].count), (0, 0b100));
        q.clear();
        assert!(q.as_slice().is_empty());
    }

    /// A fault names its finger when it has one, none otherwise.
    #[test]
    fn a_fault_names_its_finger() {
        let mut q = TickEvents::new();
        q.fault(FaultCode::StuckFinger, 2, 0);
        q.fault(FaultCode::PlantFault, 255, 3);
        let [stuck, plant] = q.as_slice() else {
            panic!("{:?}", q.as_slice());
        };
        assert_eq!(
            (stuck.fault, stuck.finger),
            (FaultCode::StuckFinger.code(), 2)
        );
        assert_eq!((plant.finger, plant.count), (NO_FINGER, 3));
        assert!(q.as_slice().iter().all(|e| e.check().is_ok()));
    }
}
