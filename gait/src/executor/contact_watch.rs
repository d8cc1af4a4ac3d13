//! Lost contacts (SPEC §6.2): a grasping finger the plant measures as not
//! touching — its contact flag off, or a measured normal force below
//! `feedback.min_contact_force` — for `feedback.contact_grace_ticks`
//! measurements in a row has lost its contact.

use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::sim::Measurement;

/// Per finger, how many measurements in a row missed its contact.
#[derive(Debug)]
pub(super) struct ContactWatch {
    missing: [u32; FINGERS],
    grace: u32,
    min_force: f64,
}

impl ContactWatch {
    /// Lost after `grace` measurements in a row below `min_force` (or not
    /// touching).
    pub(super) fn new(grace: u32, min_force: f64) -> Self {
        Self {
            missing: [0; FINGERS],
            grace,
            min_force,
        }
    }

    /// Counts measurement `m` against the setpoint `cmd` it reflects;
    /// returns the fingers whose contact is lost with it (each counted
    /// afresh after).
    pub(super) fn lost(&mut self, cmd: &HandState, m: &Measurement) -> [bool; FINGERS] {
        let mut lost = [false; FINGERS];
        for (k, f) in m.fingers.iter().enumerate() {
            let touching = f.contact && f.normal_force.is_none_or(|n| n >= self.min_force);
            if cmd.fingers[k].mode != FingerMode::Grasping || touching {
                self.missing[k] = 0;
                continue;
            }
            self.missing[k] += 1;
            if self.missing[k] >= self.grace {
                self.missing[k] = 0;
                lost[k] = true;
            }
        }
        lost
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    #[test]
    fn a_contact_is_lost_after_the_grace_in_a_row_and_counted_afresh() {
        let cmd = HandState::paper_start(&HandConfig::default());
        let mut touching = Measurement::of(&cmd);
        for f in &mut touching.fingers {
            f.normal_force = Some(1.0);
        }
        let mut light = touching;
        light.fingers[1].normal_force = Some(0.2);
        let mut w = ContactWatch::new(3, 0.5);
        assert_eq!(w.lost(&cmd, &light), [false; 3]);
        assert_eq!(w.lost(&cmd, &light), [false; 3]);
        // One touching measurement starts the count again.
        assert_eq!(w.lost(&cmd, &touching), [false; 3]);
        assert_eq!(w.lost(&cmd, &light), [false; 3]);
        assert_eq!(w.lost(&cmd, &light), [false; 3]);
        assert_eq!(w.lost(&cmd, &light), [false, true, false]);
        assert_eq!(w.lost(&cmd, &light), [false; 3]);
        // A finger not grasping in the setpoint is never lost.
        let mut lifted = cmd;
        lifted.fingers[1].mode = FingerMode::Free;
        for _ in 0..10 {
            assert_eq!(w.lost(&lifted, &light), [false; 3]);
        }
    }
}
