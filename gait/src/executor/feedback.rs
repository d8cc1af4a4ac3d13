//! Measured against commanded state (SPEC §6.3): fault detection and the
//! orientation correction fed into the commanded rotation.
//!
//! The measurement read at a tick reflects the setpoint written at the
//! previous tick, so it is compared with that setpoint.

use nalgebra::{UnitQuaternion, Vector3};

use super::lifecycle::FaultKind;
use crate::config::FeedbackConfig;
use crate::hand_state::{FingerMode, HandState};
use crate::sim::Measurement;

/// The executor's finger field for "no finger in particular" (the wire's
/// is `shm_schema::NO_FINGER`, a `u32`; the daemon maps one to the other).
pub const NOT_A_FINGER: u8 = 255;

/// How a setpoint was commanded beyond its plan: turned by the orientation
/// correction about the object centre ([`super::correction`]), then each
/// fingertip moved by its placement offset ([`super::placement`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adjustment {
    /// The correction's rotation.
    pub rotation: UnitQuaternion<f64>,
    /// Each fingertip's placement offset, hand frame \[m\].
    pub offsets: [Vector3<f64>; 3],
}

impl Adjustment {
    /// None: the plan as it is.
    pub const NONE: Self = Self {
        rotation: UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(1.0, 0.0, 0.0, 0.0)),
        offsets: [Vector3::new(0.0, 0.0, 0.0); 3],
    };

    /// Where fingertip `k`, planned at `p`, was commanded.
    pub fn tip(&self, k: usize, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.offsets[k]
    }
}

/// Derived thresholds.
#[derive(Debug, Clone, Copy)]
pub struct Feedback {
    object_tol: f64,
    finger_tol: f64,
    contact_tol: f64,
    stall_ratio: f64,
    object_radius: f64,
}

/// Motion below which a fingertip is not checked for stalling [m/tick].
const STALL_MIN_MOTION: f64 = 1e-6;

impl Feedback {
    /// From the configuration.
    pub fn new(c: &FeedbackConfig, object_radius: f64) -> Self {
        Self {
            object_tol: c.object_tolerance_deg.to_radians(),
            finger_tol: c.finger_tolerance,
            contact_tol: c.contact_tolerance,
            stall_ratio: c.stall_ratio,
            object_radius,
        }
    }

    /// Checks `m` against the planned state `cmd` it reflects (and the one
    /// the previous measurement `prev_m` reflected, `prev_cmd`, for the
    /// stall check). The fingertips were commanded as `adjusted.0`
    /// ([`Adjustment`]; `prev_cmd`'s as `adjusted.1`): they are expected
    /// there, and expected to have moved as commanded (a correction that
    /// turns the grasp against a slow start of the plan's motion is no
    /// stall); the object is expected at the plan. `offset` is a known
    /// object-frame offset of the true object from the planned one (true ≈
    /// `cmd.object · offset`; identity unless a drift is being recovered
    /// from). Returns the object's error from the plan as a rotation vector
    /// (hand frame, measured → planned), or the fault.
    pub fn check(
        &self,
        m: Option<&Measurement>,
        cmd: &HandState,
        prev_cmd: &HandState,
        prev_m: Option<&Measurement>,
        offset: &UnitQuaternion<f64>,
        adjusted: (&Adjustment, &Adjustment),
    ) -> Result<Vector3<f64>, (FaultKind, u8)> {
        let (adjusted, prev_adjusted) = adjusted;
        let Some(m) = m else {
            return Err((FaultKind::MissingMeasurement, NOT_A_FINGER));
        };
        if !m.is_finite() {
            return Err((FaultKind::BadMeasurement, NOT_A_FINGER));
        }
        let expected = cmd.object * offset;
        // Where the object centre is, if measured: contacts are located on
        // the object relative to it.
        let centre = m.center.unwrap_or_else(Vector3::zeros);
        // Slip: a grasping contact moved over the object surface.
        for (k, f) in cmd.fingers.iter().enumerate() {
            if f.mode != FingerMode::Grasping {
                continue;
            }
            let planned = expected.inverse() * f.center.normalize();
            let measured = m.object.inverse() * (m.fingers[k].center - centre).normalize();
            if (planned - measured).norm() * self.object_radius > self.contact_tol {
                return Err((FaultKind::ContactDrift, k as u8));
            }
        }
        for (k, f) in cmd.fingers.iter().enumerate() {
            let mf = &m.fingers[k];
            if (mf.center - adjusted.tip(k, &f.center)).norm() > self.finger_tol {
                return Err((FaultKind::FingerTracking, k as u8));
            }
            if self.stall_ratio > 0.0
                && let Some(pm) = prev_m
            {
                let commanded = (adjusted.tip(k, &f.center)
                    - prev_adjusted.tip(k, &prev_cmd.fingers[k].center))
                .norm();
                let moved = (mf.center - pm.fingers[k].center).norm();
                if commanded > STALL_MIN_MOTION && moved < self.stall_ratio * commanded {
                    return Err((FaultKind::FingerTracking, k as u8));
                }
            }
        }
        let err = (expected * m.object.inverse()).scaled_axis();
        if err.norm() > self.object_tol {
            return Err((FaultKind::ObjectTracking, NOT_A_FINGER));
        }
        Ok(err)
    }
}
