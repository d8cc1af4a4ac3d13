//! Rolling-path segments: constant relative angular velocity about an
//! object-fixed axis, evaluated in closed form (SPEC §2.3 with ω_o = 0).

use crate::contact::{ContactGeometry, RelativeContact};
use crate::hand_state::{FingerMode, FingerState};
use crate::sphere::rotation::{axis_angle, rotate};
use nalgebra::{UnitQuaternion, Vector3};

/// What a segment does to the contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SegmentKind {
    /// Pure rolling (axis ⊥ contact normal): both contact points move along
    /// great circles by equal arc lengths; no spin.
    Roll,
    /// Spin about the contact normal: contact points stay, the roll changes
    /// by (axis·a_f) per radian. Only for three-finger hard-contact grasps.
    Spin,
}

/// One segment: the fingertip turns, relative to the object, about the
/// unit object-frame `axis` by `length` radians (ω_rel = ṡ · axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollSegment {
    /// Roll or spin.
    pub kind: SegmentKind,
    /// Unit axis k, object frame (⊥ n for Roll, ±n for Spin).
    pub axis: Vector3<f64>,
    /// Fingertip rotation angle relative to the object, ≥ 0 \[rad\].
    pub length: f64,
}

/// The state at a segment boundary (precomputed, so evaluation is O(1)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    /// Path parameter s at this point \[rad\].
    pub s: f64,
    /// Contact arc length travelled so far (equal on both bodies) \[m\].
    pub arc: f64,
    /// The contact here (object frame).
    pub contact: RelativeContact,
    /// Fingertip rotation since the path start, object frame:
    /// `contact.fingertip = delta * start.fingertip`.
    pub delta: UnitQuaternion<f64>,
}

/// The state of a path at parameter s and its derivatives d/ds (object
/// frame; hand frame = Q_o times these while the object is still).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Path parameter s (clamped to the path) \[rad\].
    pub s: f64,
    /// Index of the segment s lies in (at a boundary: the earlier one;
    /// 0 for an empty path).
    pub segment: usize,
    /// Kind of that segment (Roll for an empty path).
    pub kind: SegmentKind,
    /// Contact point on the object n_o (unit); fingertip centre is
    /// (R + r) n_o.
    pub contact: Vector3<f64>,
    /// d n_o / ds.
    pub d_contact: Vector3<f64>,
    /// Contact point on the fingertip m (unit, fingertip frame).
    pub fingertip_contact: Vector3<f64>,
    /// d m / ds.
    pub d_fingertip_contact: Vector3<f64>,
    /// Fingertip orientation relative to the object (fingertip → object).
    pub fingertip: UnitQuaternion<f64>,
    /// Fingertip rotation since the path start (object frame).
    pub delta: UnitQuaternion<f64>,
    /// Relative angular velocity per unit s (unit vector, object frame):
    /// ω_f = Q_o · omega · ṡ while the object is still.
    pub omega: Vector3<f64>,
    /// Roll τ \[rad\].
    pub roll: f64,
    /// dτ/ds.
    pub d_roll: f64,
    /// Contact arc length travelled (equal on both bodies) \[m\].
    pub arc: f64,
    /// d arc / ds \[m/rad\].
    pub d_arc: f64,
}

impl PathSample {
    /// The finger in the hand frame with the object at `object`.
    pub fn finger_state(
        &self,
        object: &UnitQuaternion<f64>,
        geom: &ContactGeometry,
    ) -> FingerState {
        FingerState {
            mode: FingerMode::Grasping,
            center: object * self.contact * geom.center_distance(),
            orientation: object * self.fingertip,
            roll: self.roll,
        }
    }
}

impl RollSegment {
    /// Contact arc length per unit s on this segment \[m/rad\].
    pub fn arc_rate(&self, geom: &ContactGeometry) -> f64 {
        match self.kind {
            SegmentKind::Roll => geom.arc_ratio(),
            SegmentKind::Spin => 0.0,
        }
    }

    /// Evaluates the segment starting at `w` at local parameter
    /// `sigma` ∈ [0, length] (not clamped).
    pub fn eval(&self, geom: &ContactGeometry, w: &Waypoint, sigma: f64) -> PathSample {
        let k = &self.axis;
        let c = geom.object_ratio();
        let rot = axis_angle(k, sigma);
        let fingertip = rot * w.contact.fingertip;
        let contact = rotate(k, c * sigma, &w.contact.contact);
        let kxn = k.cross(&contact);
        let inv = fingertip.inverse();
        let d_roll = k.dot(&w.contact.pole_axis());
        let d_arc = self.arc_rate(geom);
        PathSample {
            s: w.s + sigma,
            segment: 0,
            kind: self.kind,
            contact,
            d_contact: kxn * c,
            fingertip_contact: inv * (-contact),
            d_fingertip_contact: inv * (kxn * geom.fingertip_ratio()),
            fingertip,
            delta: rot * w.delta,
            omega: *k,
            roll: w.contact.roll + d_roll * sigma,
            d_roll,
            arc: w.arc + d_arc * sigma,
            d_arc,
        }
    }
}
