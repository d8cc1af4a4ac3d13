//! Fixed-capacity queue of the events produced during one tick; published
//! and cleared by the loop's postprocess phase. Never allocates after
//! construction; overflow is counted, not hidden.

use shm_schema::{Event, EventKind, FaultCode, GoalState, ReasonCode};

/// Events per tick kept at most.
pub const EVENTS_PER_TICK: usize = 32;

/// The events of one tick.
#[derive(Debug, Clone)]
pub struct EventQueue {
    items: [Event; EVENTS_PER_TICK],
    len: usize,
    dropped: u64,
}

impl Default for EventQueue {
    fn default() -> Self {
        Self::new()
    }
}

impl EventQueue {
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

    /// A goal changed state.
    pub fn goal_transition(
        &mut self,
        client_id: u64,
        goal_id: u64,
        state: GoalState,
        reason: ReasonCode,
        remaining_angle: f64,
    ) {
        let mut e = Event::new(EventKind::GoalTransition);
        e.client_id = client_id;
        e.goal_id = goal_id;
        e.state = state.code();
        e.reason = reason.code();
        e.value = remaining_angle;
        self.push(e);
    }

    /// A gait event (place, lift, roll, substitution) of `finger`.
    pub fn gait(&mut self, kind: EventKind, finger: usize, goal_id: u64, client_id: u64) {
        self.push(goal_event(kind, finger as u32, 0, goal_id, client_id));
    }

    /// A finger rewind completed (paper §2.1): `relocated` as bits (bit k
    /// for finger k), `helper` free again.
    pub fn rewind(&mut self, helper: u8, relocated: u8, goal_id: u64, client_id: u64) {
        let e = goal_event(
            EventKind::Rewind,
            helper.into(),
            relocated.into(),
            goal_id,
            client_id,
        );
        self.push(e);
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
            finger.into(),
            replan.into(),
            goal_id,
            client_id,
        );
        e.fault = fault.code();
        self.push(e);
    }

    /// A contact drifted (SPEC §6.3): the goal is replanned.
    pub fn drift(&mut self, finger: u8, replan: u32, goal_id: u64, client_id: u64) {
        let e = goal_event(
            EventKind::Drift,
            finger.into(),
            replan.into(),
            goal_id,
            client_id,
        );
        self.push(e);
    }

    /// A fault was detected.
    pub fn fault(&mut self, fault: FaultCode) {
        let mut e = Event::new(EventKind::Fault);
        e.fault = fault.code();
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
fn goal_event(kind: EventKind, finger: u32, count: u64, goal_id: u64, client_id: u64) -> Event {
    let mut e = Event::new(kind);
    e.finger = finger;
    e.count = count;
    e.goal_id = goal_id;
    e.client_id = client_id;
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overflow_is_counted() {
        let mut q = EventQueue::new();
        for i in 0..EVENTS_PER_TICK + 3 {
            q.gait(EventKind::Place, i % 3, 1, 2);
        }
        assert_eq!(q.as_slice().len(), EVENTS_PER_TICK);
        assert_eq!(q.dropped(), 3);
        assert_eq!(q.as_slice()[1].finger, 1);
        q.clear();
        assert!(q.as_slice().is_empty());
    }
}
