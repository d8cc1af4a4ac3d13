//! What the planner thread says about the plans it made — their route,
//! effort and planning time — for the trace headers. The planner thread
//! adds a note per plan and the trace thread takes it when the goal's
//! trace is written; the loop never touches it (it only carries the
//! executor goal id in `TraceMsg::Begin`).

use gait::planner::Effort;
use std::collections::VecDeque;
use std::sync::Mutex;

/// Notes kept (the oldest go first).
const KEPT: usize = 64;

/// One plan's note.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanNote {
    /// The executor goal it was made for.
    pub goal: u64,
    /// Its route, as `gaitctl plan` prints it.
    pub route: String,
    /// What finding it cost.
    pub effort: Effort,
    /// Planning wall time \[ms\].
    pub planning_ms: f64,
}

/// The notes (module docs).
#[derive(Debug, Default)]
pub struct PlanNotes {
    notes: Mutex<VecDeque<PlanNote>>,
}

impl PlanNotes {
    /// Adds a note (the planner thread).
    pub fn add(&self, note: PlanNote) {
        let mut n = self.notes.lock().unwrap_or_else(|e| e.into_inner());
        if n.len() >= KEPT {
            n.pop_front();
        }
        n.push_back(note);
    }

    /// The newest note for executor goal `goal` (a replanned goal's last
    /// plan), removing every note for it.
    pub fn take(&self, goal: u64) -> Option<PlanNote> {
        let mut n = self.notes.lock().unwrap_or_else(|e| e.into_inner());
        let newest = n.iter().rev().find(|x| x.goal == goal).cloned();
        n.retain(|x| x.goal != goal);
        newest
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_newest_note_of_a_goal_is_taken_once() {
        let notes = PlanNotes::default();
        let note = |goal, ms| PlanNote {
            goal,
            route: format!("r{goal}"),
            effort: Effort::default(),
            planning_ms: ms,
        };
        notes.add(note(1, 1.0));
        notes.add(note(2, 2.0));
        notes.add(note(1, 3.0));
        assert_eq!(notes.take(1).map(|n| n.planning_ms), Some(3.0));
        assert_eq!(notes.take(1), None);
        for g in 0..100 {
            notes.add(note(10 + g, 0.0));
        }
        assert_eq!(notes.take(2), None, "pushed out by newer notes");
        assert!(notes.take(109).is_some());
    }
}
