//! Which fingers carry the load (SPEC §1.3 I1', §3.3), and the handover
//! that passes it from one set to another at rest. Bits as in
//! [`crate::grasp::grip`]: carrying fingers, and spin marks three bits up.

use crate::grasp::grip;
use crate::planner::Handover;

/// The grip passing from one carrying set to another, object still.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct HandoverPhase {
    /// Time since the motion ended \[s\].
    pub(super) elapsed: f64,
    /// Its length \[s\].
    pub(super) duration: f64,
    /// Carrying set after.
    pub(super) to: u8,
}

/// The carrying set, kept in step with the setpoint's grasp.
#[derive(Debug)]
pub(super) struct Carrying {
    set: u8,
    /// Grasping fingers of the last setpoint (bit mask).
    grasp_prev: u8,
    handover: Option<HandoverPhase>,
}

impl Carrying {
    /// Every finger of `grasp` (a bit mask) carries.
    pub(super) fn new(grasp: u8) -> Self {
        Self {
            set: grasp,
            grasp_prev: grasp,
            handover: None,
        }
    }

    /// The carrying set.
    pub(super) fn set(&self) -> u8 {
        self.set
    }

    /// The handover under way, if any.
    pub(super) fn handover(&self) -> Option<HandoverPhase> {
        self.handover
    }

    /// The set a handover goes to and the fraction of it done.
    pub(super) fn blend(&self) -> Option<(u8, f64)> {
        self.handover.map(|h| (h.to, h.elapsed / h.duration))
    }

    /// Keeps the set in step with the setpoint's `grasp`: a finger that
    /// leaves carries nothing; a finger that touches carries at once
    /// unless it is in `pending` (the running step hands the grip over to
    /// it); at rest (`moving` false), or with fewer than two carrying,
    /// every touching finger carries — unless a handover is under way.
    pub(super) fn update(&mut self, grasp: u8, moving: bool, pending: u8) {
        let joined = grasp & !self.grasp_prev;
        // (A spin mark lasts while its finger touches.)
        self.set = (self.set | (joined & !pending)) & (grasp | grasp << 3);
        if self.handover.is_none() && (!moving || (self.set & grip::CARRY_BITS).count_ones() < 2) {
            self.set = grasp;
        }
        self.grasp_prev = grasp;
    }

    /// The motion has ended: `h` passes the grip over its duration.
    pub(super) fn begin_handover(&mut self, h: &Handover) {
        self.handover = Some(HandoverPhase {
            elapsed: 0.0,
            duration: h.duration,
            to: h.target(self.set),
        });
    }

    /// A period `dt` of the handover under way: None without one, else
    /// whether it is over (then the new set carries).
    pub(super) fn advance_handover(&mut self, dt: f64) -> Option<bool> {
        let h = self.handover.as_mut()?;
        h.elapsed += dt;
        if h.elapsed < h.duration - 1e-12 {
            return Some(false);
        }
        self.set = h.to;
        self.handover = None;
        Some(true)
    }

    /// The handover stops where it is (a fault): every touching finger
    /// carries from the next update on.
    pub(super) fn abandon_handover(&mut self) {
        self.handover = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn handover(take: Option<usize>, release: Option<usize>) -> Handover {
        Handover {
            take,
            release,
            spin: None,
            duration: 0.0105,
        }
    }

    #[test]
    fn a_placed_finger_carries_once_its_handover_is_over() {
        let dt = 1e-3;
        let mut c = Carrying::new(0b011);
        // Finger 2 touches while moving; the step hands the grip to it.
        c.update(0b111, true, 0b100);
        assert_eq!(c.set(), 0b011, "pending: not carrying yet");
        c.begin_handover(&handover(Some(2), Some(0)));
        let mut ticks = 0;
        while c.advance_handover(dt) == Some(false) {
            ticks += 1;
            let (to, done) = c.blend().expect("under way");
            assert_eq!(to, 0b110);
            assert!(done > 0.0 && done < 1.0);
            c.update(0b111, true, 0b100);
            assert_eq!(c.set(), 0b011, "the old set carries during the handover");
        }
        assert_eq!(ticks, 10, "10.5 ms on 1 ms ticks: over on the 11th");
        assert_eq!(c.set(), 0b110);
        assert!(c.handover().is_none());
        assert_eq!(c.advance_handover(dt), None);
    }

    #[test]
    fn a_finger_that_leaves_carries_nothing_and_at_rest_every_toucher_carries() {
        let mut c = Carrying::new(0b111);
        c.update(0b011, true, 0);
        assert_eq!(c.set(), 0b011);
        // Touches again, not pending, moving with two carrying: joins.
        c.update(0b111, true, 0);
        assert_eq!(c.set(), 0b111);
        // Pending while moving: does not join.
        let mut c = Carrying::new(0b011);
        c.update(0b111, true, 0b100);
        assert_eq!(c.set(), 0b011);
        // At rest with no handover: every touching finger carries.
        c.update(0b111, false, 0b100);
        assert_eq!(c.set(), 0b111);
    }

    #[test]
    fn an_abandoned_handover_leaves_the_set_to_the_grasp() {
        let mut c = Carrying::new(0b011);
        c.update(0b111, true, 0b100);
        c.begin_handover(&handover(Some(2), Some(0)));
        c.abandon_handover();
        assert!(c.blend().is_none());
        c.update(0b111, false, 0);
        assert_eq!(c.set(), 0b111);
    }
}
