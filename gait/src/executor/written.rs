//! The setpoints written to the plant, remembered: a measurement reflects
//! the setpoint written `age` ticks before ([`Measurement::age`]), and is
//! compared with that one, as it was commanded (SPEC §6.2, §6.3).

use super::*;

/// Setpoints remembered for comparing late measurements: 256 ticks, beyond
/// the delay a plant link tolerates (`plant.max_missed` is at most 200).
pub const WRITTEN: usize = 256;

impl Executor {
    /// The setpoint state written `age` ticks before the last one (0: the
    /// last).
    pub(super) fn written(&self, age: usize) -> HandState {
        self.written[self.written_index(age)]
    }

    /// How the setpoint written `age` ticks before the last was commanded.
    pub(super) fn written_adjustment(&self, age: usize) -> feedback::Adjustment {
        self.written_adjustment[self.written_index(age)]
    }

    /// Where in the ring the setpoint written `age` ticks before the last
    /// is (the oldest kept, beyond).
    fn written_index(&self, age: usize) -> usize {
        (self.written_next + 2 * WRITTEN - 1 - age.min(WRITTEN - 1)) % WRITTEN
    }

    /// Records the setpoint about to be written (and its correction).
    pub(super) fn remember_written(&mut self) {
        self.written[self.written_next] = self.setpoint.state;
        self.written_adjustment[self.written_next] = feedback::Adjustment {
            rotation: self.correction.rotation(),
            offsets: self.placement.shifts(&self.setpoint.state),
        };
        self.written_next = (self.written_next + 1) % WRITTEN;
    }

    /// Forgets the setpoints written before `state` (a re-based estimate:
    /// the older ones belong to the old estimate).
    pub(super) fn reset_written(&mut self, state: HandState) {
        let adjustment = feedback::Adjustment {
            rotation: UnitQuaternion::identity(),
            offsets: self.placement.shifts(&state),
        };
        self.written = [state; WRITTEN];
        self.written_adjustment = [adjustment; WRITTEN];
        self.written_next = 0;
        self.prev_reflected = state;
        self.prev_reflected_adjustment = adjustment;
        self.correction.clear();
    }
}
