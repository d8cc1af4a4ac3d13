//! The object as a tracking system reports it (SPEC §6.3): a camera or
//! motion-capture pipeline samples the object's pose at its own rate,
//! delivers each sample late and with noise, while the fingertips (from
//! the hand's own encoders) are fresh every tick.
//!
//! Two things follow. A sample is compared with the plan *at the tick it
//! was taken* (`Measurement::object_age` ticks before the rest of the
//! measurement), not with the plan now: compared with the plan now, a
//! turning object reads as lagging by its speed × the sample's age. And
//! the error of each new sample — a rotation vector, hand frame, measured
//! → planned, and the centre — is averaged over samples with gain α
//! (`feedback.tracker_gain`):
//!
//! $$ e_s = \log\big(q_{\text{plan}}(t_s)\, o\; q_{\text{measured}}^{-1}\big),
//!    \qquad \hat e \leftarrow \hat e + \alpha\,(e_s - \hat e), \qquad
//!    \hat c \leftarrow \hat c + \alpha\,(c_s - \hat c) $$
//!
//! (o the known offset of the true object from the plan). The estimate
//! the checks and the corrections see is the plan now carrying that error,
//! $\hat q = \exp(-\hat e)\, q_{\text{plan}}(t)\, o$, centre $\hat c$: a
//! slip or a lag that lasts shows in full after a few samples, the noise
//! of one sample in a share α/(2−α) of its variance. With α = 1 and
//! samples of age 0 the measurement is used exactly as it came.

use nalgebra::{UnitQuaternion, Vector3};

use crate::hand_state::HandState;
use crate::sim::Measurement;

/// The smoothed object error over the samples seen (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracking {
    gain: f64,
    /// Smoothed error e_hat and centre c_hat; `None` before the first sample
    /// (and after a re-base: a new plan's errors start afresh).
    estimate: Option<(Vector3<f64>, Option<Vector3<f64>>)>,
    /// The last sample's raw pose and centre, to tell a new sample from a
    /// held one.
    last: Option<(UnitQuaternion<f64>, Option<Vector3<f64>>)>,
    /// The offset `estimate` was taken against.
    offset: UnitQuaternion<f64>,
    /// The executor's epoch `estimate` belongs to.
    epoch: u32,
}

impl Tracking {
    /// No sample yet; `gain` = `feedback.tracker_gain`, in (0, 1].
    pub fn new(gain: f64) -> Self {
        Self {
            gain,
            estimate: None,
            last: None,
            offset: UnitQuaternion::identity(),
            epoch: 0,
        }
    }

    /// Forgets the samples (a reset).
    pub fn clear(&mut self) {
        self.estimate = None;
        self.last = None;
    }

    /// The measurement the checks see for `m`: its fingertips as measured,
    /// the object as the smoothed error puts it on the plan `now` (the
    /// plan the rest of `m` answers); `sampled` is the plan at the tick
    /// the object's pose was taken, `offset` the object's known offset
    /// from the plan, `epoch` the executor's (a new one forgets the
    /// samples). Allocation-free.
    pub fn estimate(
        &mut self,
        m: &Measurement,
        now: &HandState,
        sampled: &HandState,
        offset: &UnitQuaternion<f64>,
        epoch: u32,
    ) -> Measurement {
        if self.gain >= 1.0 && m.object_age == 0 {
            // Each sample as it is, at its own tick: nothing to do.
            self.clear();
            return *m;
        }
        if epoch != self.epoch || *offset != self.offset {
            self.clear();
            self.epoch = epoch;
            self.offset = *offset;
        }
        let raw = (m.object, m.center);
        if self.last != Some(raw) {
            self.last = Some(raw);
            let e = (sampled.object * offset * m.object.inverse()).scaled_axis();
            self.estimate = Some(match self.estimate {
                Some((e_hat, c_hat)) => (
                    e_hat + self.gain * (e - e_hat),
                    match (c_hat, m.center) {
                        (Some(c_hat), Some(c)) => Some(c_hat + self.gain * (c - c_hat)),
                        (_, c) => c,
                    },
                ),
                None => (e, m.center),
            });
        }
        let (e_hat, c_hat) = self.estimate.unwrap_or((Vector3::zeros(), m.center));
        Measurement {
            object: UnitQuaternion::from_scaled_axis(-e_hat) * (now.object * offset),
            center: c_hat,
            ..*m
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    fn at(
        state: &HandState,
        object: UnitQuaternion<f64>,
        c: Option<Vector3<f64>>,
        age: u32,
    ) -> Measurement {
        Measurement {
            object,
            center: c,
            object_age: age,
            ..Measurement::of(state)
        }
    }

    #[test]
    fn samples_are_averaged_held_ones_once_and_a_new_epoch_starts_afresh() {
        let plan = HandState::paper_start(&HandConfig::default());
        let mut t = Tracking::new(0.5);
        // The estimate for a sample `deg` off the plan about x (the plan
        // as sampled and now the same), in `epoch`.
        let mut see = |deg: f64, c: Option<Vector3<f64>>, age: u32, epoch: u32| {
            let off = UnitQuaternion::from_scaled_axis(Vector3::x() * deg.to_radians());
            let m = at(&plan, off * plan.object, c, age);
            let e = t.estimate(&m, &plan, &plan, &UnitQuaternion::identity(), epoch);
            (e.object.angle_to(&plan.object).to_degrees(), e.center)
        };
        // First sample: taken as it is (1° off about x, centre 1 mm up).
        let c1 = Some(Vector3::new(0.0, 0.0, 1e-3));
        let (deg, c) = see(-1.0, c1, 3, 0);
        assert!((deg - 1.0).abs() < 1e-9);
        assert_eq!(c, c1);
        // The same sample held: unchanged.
        let (deg, _) = see(-1.0, c1, 4, 0);
        assert!((deg - 1.0).abs() < 1e-9);
        // A new one on the plan: halfway there (gain 0.5).
        let (deg, c) = see(0.0, Some(Vector3::zeros()), 0, 0);
        assert!((deg - 0.5).abs() < 1e-9);
        assert!((c.unwrap().z - 0.5e-3).abs() < 1e-15);
        // That one held: counted once, still halfway.
        let (deg, _) = see(0.0, Some(Vector3::zeros()), 1, 0);
        assert!((deg - 0.5).abs() < 1e-9);
        // Another epoch (a re-base): the next sample as it is.
        let (deg, c) = see(-2.0, None, 0, 1);
        assert!((deg - 2.0).abs() < 1e-9);
        assert_eq!(c, None);
    }

    #[test]
    fn an_exact_plant_is_passed_through_bit_for_bit() {
        let plan = HandState::paper_start(&HandConfig::default());
        let mut t = Tracking::new(1.0);
        let m = Measurement {
            object: UnitQuaternion::from_scaled_axis(Vector3::new(0.1, 0.2, 0.3)),
            center: Some(Vector3::new(1e-4, 0.0, 0.0)),
            ..Measurement::of(&plan)
        };
        let id = UnitQuaternion::identity();
        assert_eq!(t.estimate(&m, &plan, &plan, &id, 0), m);
    }
}
