//! The setpoints written to the plant, remembered: a measurement reflects
//! the setpoint written `age` ticks before ([`Measurement::age`]), and is
//! compared with that one, as it was commanded (SPEC §6.2, §6.3).

use super::*;
use feedback::Adjustment;

/// Setpoints remembered for comparing late measurements: 256 ticks, beyond
/// the delay a plant link tolerates (`plant.max_missed` is at most 200).
pub const WRITTEN: usize = 256;

/// The last [`WRITTEN`] setpoint states written, a ring, each with how it
/// was commanded beyond its plan; and the one the previous measurement
/// reflected (a measurement held or repeated reflects the same one: no
/// motion expected).
#[derive(Debug)]
pub(super) struct Written {
    states: [HandState; WRITTEN],
    adjustments: [Adjustment; WRITTEN],
    /// Where the next one goes.
    next: usize,
    reflected: (HandState, Adjustment),
}

impl Written {
    /// Nothing written but `start`.
    pub(super) fn new(start: HandState) -> Self {
        Self {
            states: [start; WRITTEN],
            adjustments: [Adjustment::NONE; WRITTEN],
            next: 0,
            reflected: (start, Adjustment::NONE),
        }
    }

    /// The setpoint written `age` ticks before the last one (0: the last;
    /// the oldest kept, beyond), and how it was commanded.
    pub(super) fn at(&self, age: usize) -> (HandState, Adjustment) {
        let i = (self.next + 2 * WRITTEN - 1 - age.min(WRITTEN - 1)) % WRITTEN;
        (self.states[i], self.adjustments[i])
    }

    /// Records a setpoint about to be written.
    pub(super) fn remember(&mut self, state: HandState, adjustment: Adjustment) {
        self.states[self.next] = state;
        self.adjustments[self.next] = adjustment;
        self.next = (self.next + 1) % WRITTEN;
    }

    /// The setpoint the previous measurement reflected.
    pub(super) fn reflected(&self) -> &(HandState, Adjustment) {
        &self.reflected
    }

    /// A measurement reflected this setpoint.
    pub(super) fn set_reflected(&mut self, reflected: (HandState, Adjustment)) {
        self.reflected = reflected;
    }

    /// Forgets every setpoint before `state` (a re-based estimate: the
    /// older ones belong to the old estimate).
    pub(super) fn reset(&mut self, state: HandState, adjustment: Adjustment) {
        self.states = [state; WRITTEN];
        self.adjustments = [adjustment; WRITTEN];
        self.next = 0;
        self.reflected = (state, adjustment);
    }
}

impl Executor {
    /// Records the setpoint about to be written (and its correction).
    pub(super) fn remember_written(&mut self) {
        let adjustment = Adjustment {
            rotation: self.correction.rotation(),
            offsets: self.placement.shifts(&self.setpoint.state),
        };
        self.written.remember(self.setpoint.state, adjustment);
    }

    /// Forgets the setpoints written before `state` (a re-based estimate)
    /// and the correction built on them.
    pub(super) fn reset_written(&mut self, state: HandState) {
        let adjustment = Adjustment {
            rotation: UnitQuaternion::identity(),
            offsets: self.placement.shifts(&state),
        };
        self.written.reset(state, adjustment);
        self.correction.clear();
        self.tracking.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    /// A state told apart by its object's angle about z.
    fn state(i: usize) -> HandState {
        let mut s = HandState::paper_start(&HandConfig::default());
        s.object = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), i as f64 * 1e-3);
        s
    }

    fn index_of(s: &HandState) -> usize {
        (s.object.angle() * 1e3).round() as usize
    }

    #[test]
    fn a_setpoint_is_found_by_its_age_and_the_oldest_kept_beyond() {
        let mut w = Written::new(state(0));
        for i in 1..=300 {
            w.remember(state(i), Adjustment::NONE);
        }
        assert_eq!(index_of(&w.at(0).0), 300);
        assert_eq!(index_of(&w.at(7).0), 293);
        assert_eq!(index_of(&w.at(WRITTEN - 1).0), 300 - (WRITTEN - 1));
        assert_eq!(index_of(&w.at(10 * WRITTEN).0), 300 - (WRITTEN - 1));
        w.reset(state(5), Adjustment::NONE);
        assert_eq!(index_of(&w.at(0).0), 5);
        assert_eq!(index_of(&w.at(100).0), 5);
        assert_eq!(index_of(&w.reflected().0), 5);
    }
}
