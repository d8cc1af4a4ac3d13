//! Feedback that corrects (SPEC §6.3): the error between the measured and
//! the planned object orientation feeds the fingertip setpoints.
//!
//! A plant that follows fingertip poses ignores a commanded object angular
//! velocity, so correcting only that (as the embedded kinematic hand
//! allows) would not move a real object. Instead the whole commanded hand
//! — object and fingertips — is turned about the object centre by a small
//! correction C, which integrates the object's error from the plan:
//!
//! $$ C_{k+1} = \exp\big(g\,\Delta t\; e_k\big)\, C_k, \qquad
//!    e_k = \log\big(q_{\text{plan}}\, q_{\text{measured}}^{-1}\big) $$
//!
//! (hand frame, g = `feedback.orientation_gain`), |C| at most
//! `feedback.max_correction_deg`. A hand that lags behind the grasp's
//! motion, or whose soft contacts creep under load, thus still brings the
//! object to the plan. Turning a valid state rigidly about O keeps every
//! contact where it is on the object and on the fingertip; it only uses up
//! a little workspace margin, hence the bound. Errors below a numerical
//! noise floor are ignored, so an exact plant (the kinematic hand) is
//! commanded exactly the plan, bit for bit.

use nalgebra::{UnitQuaternion, Vector3};

use crate::planner::Setpoint;

/// Object errors below this are rounding, not motion \[rad\].
const NOISE_FLOOR: f64 = 1e-9;

/// The correction of the commanded grasp (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correction {
    rotation: UnitQuaternion<f64>,
    rate: Vector3<f64>,
    gain: f64,
    max_angle: f64,
}

impl Correction {
    /// No correction yet; `gain` \[1/s\], at most `max_angle` \[rad\].
    pub fn new(gain: f64, max_angle: f64) -> Self {
        Self {
            rotation: UnitQuaternion::identity(),
            rate: Vector3::zeros(),
            gain,
            max_angle,
        }
    }

    /// The correction now: the commanded hand is the plan turned by it.
    pub fn rotation(&self) -> UnitQuaternion<f64> {
        self.rotation
    }

    /// Forgets the correction (a re-based estimate, a reset).
    pub fn clear(&mut self) {
        self.rotation = UnitQuaternion::identity();
        self.rate = Vector3::zeros();
    }

    /// Holds it still (no measurement this tick, or a fault).
    pub fn freeze(&mut self) {
        self.rate = Vector3::zeros();
    }

    /// Integrates the object error `err` (rotation vector, measured →
    /// planned, hand frame) over `dt` seconds.
    pub fn update(&mut self, err: &Vector3<f64>, dt: f64) {
        if err.norm() < NOISE_FLOOR || self.gain == 0.0 {
            self.rate = Vector3::zeros();
            return;
        }
        self.rate = err * self.gain;
        let next = UnitQuaternion::from_scaled_axis(self.rate * dt) * self.rotation;
        let angle = next.angle();
        self.rotation = if angle > self.max_angle {
            // Saturated: as far as allowed, about the same axis.
            let axis = next.scaled_axis() / angle;
            UnitQuaternion::from_scaled_axis(axis * self.max_angle)
        } else {
            next
        };
    }

    /// The setpoint as commanded: `plan` turned by the correction about the
    /// object centre (poses and velocities), exactly `plan` when there is
    /// none.
    pub fn apply(&self, plan: &Setpoint) -> Setpoint {
        if self.rotation == UnitQuaternion::identity() && self.rate == Vector3::zeros() {
            return *plan;
        }
        let c = self.rotation;
        let w = self.rate;
        let mut sp = *plan;
        sp.state.object = c * plan.state.object;
        sp.object_rate = c * plan.object_rate + w;
        for k in 0..sp.state.fingers.len() {
            let f = &mut sp.state.fingers[k];
            f.center = c * plan.state.fingers[k].center;
            f.orientation = c * plan.state.fingers[k].orientation;
            sp.finger_velocity[k] = c * plan.finger_velocity[k] + w.cross(&f.center);
            sp.finger_rate[k] = c * plan.finger_rate[k] + w;
        }
        sp
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor::rest;
    use crate::{HandConfig, HandState};

    #[test]
    fn a_constant_lag_is_integrated_away_and_bounded() {
        let plan = rest(HandState::paper_start(&HandConfig::default()));
        let mut c = Correction::new(10.0, 0.01);
        // An exact plant: nothing changes, bit for bit.
        c.update(&Vector3::new(1e-12, 0.0, 0.0), 1e-3);
        assert_eq!(c.apply(&plan), plan);
        // A plant whose object lags the command by a fixed 2 mrad about z:
        // measured = lag⁻¹ · commanded. The correction converges to it.
        let lag = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.002);
        for _ in 0..2000 {
            let commanded = c.apply(&plan).state.object;
            let measured = lag.inverse() * commanded;
            let err = (plan.state.object * measured.inverse()).scaled_axis();
            c.update(&err, 1e-3);
        }
        let measured = lag.inverse() * c.apply(&plan).state.object;
        assert!(measured.angle_to(&plan.state.object) < 1e-6);
        // Rigid: every contact stays where it was on the object.
        let out = c.apply(&plan).state;
        for k in 0..3 {
            let before = plan.state.object_contact(k);
            let after = out.object_contact(k);
            assert!((before - after).norm() < 1e-12);
        }
        // Bounded.
        let lag = UnitQuaternion::from_scaled_axis(Vector3::x() * 0.1);
        for _ in 0..5000 {
            let measured = lag.inverse() * c.apply(&plan).state.object;
            let err = (plan.state.object * measured.inverse()).scaled_axis();
            c.update(&err, 1e-3);
        }
        assert!(c.rotation().angle() <= 0.01 + 1e-12);
    }
}
