//! The executor numbers goals itself (one counter, never reused); clients
//! name them by (client id, goal id). [`GoalIds`] maps one to the other
//! for the goals still in flight, in a fixed table (no allocation).

use gait::executor;

/// Goals whose ids are remembered at once: far more than can be in flight
/// (one active, one pending, the last one reported).
pub const GOAL_SLOTS: usize = 32;

#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    /// Executor goal id (0: empty).
    exec: u64,
    client: u64,
    goal: u64,
    /// The goal's target, for trace headers.
    target: Option<executor::GoalTarget>,
}

/// Executor goal id ↔ (client id, goal id) for the last [`GOAL_SLOTS`]
/// goals (module docs).
#[derive(Debug, Clone)]
pub struct GoalIds {
    slots: [Slot; GOAL_SLOTS],
    next: u64,
}

impl Default for GoalIds {
    fn default() -> Self {
        Self::new()
    }
}

impl GoalIds {
    /// An empty table; the first goal gets executor id 1.
    pub fn new() -> Self {
        Self {
            slots: [Slot::default(); GOAL_SLOTS],
            next: 1,
        }
    }

    fn slot(id: u64) -> usize {
        (id as usize) % GOAL_SLOTS
    }

    /// A new executor id for the client's goal (forgets the goal
    /// [`GOAL_SLOTS`] before it).
    pub fn assign(&mut self, client: u64, goal: u64, target: executor::GoalTarget) -> u64 {
        let id = self.next;
        self.next += 1;
        self.slots[Self::slot(id)] = Slot {
            exec: id,
            client,
            goal,
            target: Some(target),
        };
        id
    }

    /// (client id, goal id) of executor goal `id`; `(0, id)` when it is no
    /// longer remembered, and `(0, 0)` for no goal.
    pub fn wire(&self, id: u64) -> (u64, u64) {
        if id == 0 {
            return (0, 0);
        }
        let s = &self.slots[Self::slot(id)];
        if s.exec == id {
            (s.client, s.goal)
        } else {
            (0, id)
        }
    }

    /// The target executor goal `id` was given, if remembered.
    pub fn target(&self, id: u64) -> Option<executor::GoalTarget> {
        let s = &self.slots[Self::slot(id)];
        if s.exec == id { s.target } else { None }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    #[test]
    fn ids_map_both_ways_until_forgotten() {
        let mut ids = GoalIds::new();
        let t = executor::GoalTarget::Orientation(UnitQuaternion::identity());
        let first = ids.assign(7, 100, t);
        assert_eq!(first, 1);
        assert_eq!(ids.wire(first), (7, 100));
        assert_eq!(ids.target(first), Some(t));
        assert_eq!(ids.wire(0), (0, 0));
        for g in 0..GOAL_SLOTS as u64 {
            ids.assign(8, 200 + g, t);
        }
        // The slot was reused: the first goal is forgotten, not misnamed.
        assert_eq!(ids.wire(first), (0, first));
        assert_eq!(ids.target(first), None);
        let last = GOAL_SLOTS as u64 + 1;
        assert_eq!(ids.wire(last), (8, 200 + GOAL_SLOTS as u64 - 1));
    }
}
