//! A rolling path: a bounded sequence of segments with precomputed
//! boundary states, evaluated exactly and without allocation.

use super::segment::{PathSample, RollSegment, SegmentKind, Waypoint};
use crate::contact::{ContactGeometry, RelativeContact};
use crate::sphere::rotation::{angle_between, tangent_towards};
use core::f64::consts::{PI, TAU};
use nalgebra::{UnitQuaternion, Vector3};

/// Capacity of a [`RollingPath`] in segments.
pub const MAX_SEGMENTS: usize = 32;

/// Why a segment could not be appended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PathError {
    /// The path already holds [`MAX_SEGMENTS`] segments.
    #[error("rolling path is full")]
    Full,
    /// An input holds NaN or an infinity.
    #[error("rolling path input is not finite")]
    NonFinite,
    /// Negative length, zero axis, or an axis that does not fit the kind.
    #[error("invalid rolling segment")]
    InvalidSegment,
    /// A roll direction has no component tangent to the object at the contact.
    #[error("roll direction is not tangent to the object")]
    NotTangent,
    /// A Fig. 2 path must start with the fingertip contact at its pole.
    #[error("fingertip contact is not at its pole")]
    NotAtPole,
    /// The target is beyond what one Fig. 2 path can reach.
    #[error("target beyond the reach of one Fig. 2 path")]
    BeyondReach,
    /// The fingertip contact is (nearly) on the fingertip equator, where a
    /// spin cannot change the roll.
    #[error("spin cannot change the roll with the contact on the fingertip equator")]
    SpinCannotRoll,
}

/// Extremes of a path, computed exactly per segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathMargins {
    /// Smallest hemisphere margin π/2 − angle(m, e_z) along the path \[rad\]
    /// (≥ 0: the fingertip contact never leaves its closed hemisphere).
    pub min_hemisphere: f64,
    /// Largest |τ| along the path (τ is linear on each segment) \[rad\].
    pub max_abs_roll: f64,
    /// τ at the end \[rad\].
    pub final_roll: f64,
}

/// Fixed-capacity rolling path of one fingertip on the still object
/// (module docs of [`crate::rolling`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RollingPath {
    geom: ContactGeometry,
    len: usize,
    segments: [RollSegment; MAX_SEGMENTS],
    waypoints: [Waypoint; MAX_SEGMENTS + 1],
}

/// min over x ∈ [0, span] of a cos x + b sin x + c.
pub(crate) fn min_sinusoid(a: f64, b: f64, c: f64, span: f64) -> f64 {
    let amp = a.hypot(b);
    if span >= TAU {
        return c - amp;
    }
    let mut m = (a + c).min(a * span.cos() + b * span.sin() + c);
    if amp > 0.0 {
        let x_min = (b.atan2(a) + PI).rem_euclid(TAU);
        if x_min <= span {
            m = m.min(c - amp);
        }
    }
    m
}

impl RollingPath {
    /// An empty path starting at `start`.
    pub fn new(geom: ContactGeometry, start: RelativeContact) -> Self {
        let w = Waypoint {
            s: 0.0,
            arc: 0.0,
            contact: start,
            delta: UnitQuaternion::identity(),
        };
        let seg = RollSegment {
            kind: SegmentKind::Roll,
            axis: Vector3::x(),
            length: 0.0,
        };
        Self {
            geom,
            len: 0,
            segments: [seg; MAX_SEGMENTS],
            waypoints: [w; MAX_SEGMENTS + 1],
        }
    }

    /// The radii this path was built for.
    pub fn geometry(&self) -> &ContactGeometry {
        &self.geom
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the path has no segment.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The segments.
    pub fn segments(&self) -> &[RollSegment] {
        &self.segments[..self.len]
    }

    /// The boundary states: `len() + 1` waypoints, start first.
    pub fn waypoints(&self) -> &[Waypoint] {
        &self.waypoints[..=self.len]
    }

    /// The start contact.
    pub fn start(&self) -> &RelativeContact {
        &self.waypoints[0].contact
    }

    /// The end contact.
    pub fn end(&self) -> &RelativeContact {
        &self.waypoints[self.len].contact
    }

    /// Total length in s (fingertip rotation relative to the object) \[rad\].
    pub fn length(&self) -> f64 {
        self.waypoints[self.len].s
    }

    /// Total contact arc length (equal on both bodies) \[m\].
    pub fn arc_length(&self) -> f64 {
        self.waypoints[self.len].arc
    }

    /// The s-interval of segment `i`.
    pub fn segment_range(&self, i: usize) -> Option<(f64, f64)> {
        (i < self.len).then(|| (self.waypoints[i].s, self.waypoints[i + 1].s))
    }

    /// The state at `s` and its derivatives (s is clamped to
    /// [0, length]; NaN counts as 0). Exact, O(len), allocation-free.
    pub fn eval(&self, s: f64) -> PathSample {
        let total = self.length();
        let s = if s > 0.0 { s.min(total) } else { 0.0 };
        if self.len == 0 {
            let w = &self.waypoints[0];
            let m = w.contact.fingertip_contact();
            return PathSample {
                s: 0.0,
                segment: 0,
                kind: SegmentKind::Roll,
                contact: w.contact.contact,
                d_contact: Vector3::zeros(),
                fingertip_contact: m,
                d_fingertip_contact: Vector3::zeros(),
                fingertip: w.contact.fingertip,
                delta: w.delta,
                omega: Vector3::zeros(),
                roll: w.contact.roll,
                d_roll: 0.0,
                arc: 0.0,
                d_arc: 0.0,
            };
        }
        let mut i = 0;
        while i + 1 < self.len && s > self.waypoints[i + 1].s {
            i += 1;
        }
        let seg = &self.segments[i];
        let sigma = (s - self.waypoints[i].s).clamp(0.0, seg.length);
        let mut out = seg.eval(&self.geom, &self.waypoints[i], sigma);
        out.segment = i;
        out
    }

    /// Drops the segments after the first `len` (no-op if `len` ≥ len()).
    pub fn truncate(&mut self, len: usize) {
        self.len = self.len.min(len);
    }

    /// Appends `seg` (its axis is normalised; a Spin axis is snapped onto
    /// ±n). A zero-length segment is accepted and dropped.
    pub fn push(&mut self, seg: RollSegment) -> Result<(), PathError> {
        if !(seg.axis.iter().all(|x| x.is_finite()) && seg.length.is_finite()) {
            return Err(PathError::NonFinite);
        }
        let norm = seg.axis.norm();
        if seg.length < 0.0 || norm < 1e-12 {
            return Err(PathError::InvalidSegment);
        }
        if seg.length == 0.0 {
            return Ok(());
        }
        if self.len == MAX_SEGMENTS {
            return Err(PathError::Full);
        }
        let n = self.end().contact;
        let mut k = seg.axis / norm;
        match seg.kind {
            SegmentKind::Roll if k.dot(&n).abs() > 1e-9 => return Err(PathError::InvalidSegment),
            SegmentKind::Spin if k.cross(&n).norm() > 1e-9 => {
                return Err(PathError::InvalidSegment);
            }
            SegmentKind::Spin => k = n * k.dot(&n).signum(),
            SegmentKind::Roll => {}
        }
        let seg = RollSegment { axis: k, ..seg };
        let w = &self.waypoints[self.len];
        let e = seg.eval(&self.geom, w, seg.length);
        self.segments[self.len] = seg;
        self.waypoints[self.len + 1] = Waypoint {
            s: e.s,
            arc: e.arc,
            contact: RelativeContact {
                contact: e.contact.normalize(),
                fingertip: UnitQuaternion::new_normalize(e.fingertip.into_inner()),
                roll: e.roll,
            },
            delta: UnitQuaternion::new_normalize(e.delta.into_inner()),
        };
        self.len += 1;
        Ok(())
    }

    /// Appends a great-circle roll moving the object contact by
    /// `object_angle` ≥ 0 \[rad\] in the tangent `direction` (projected onto
    /// the tangent plane). The fingertip contact moves (R/r)·object_angle
    /// (Theory 2); s advances by object_angle·(R + r)/r.
    pub fn push_roll(
        &mut self,
        direction: &Vector3<f64>,
        object_angle: f64,
    ) -> Result<(), PathError> {
        if !(direction.iter().all(|x| x.is_finite()) && object_angle.is_finite()) {
            return Err(PathError::NonFinite);
        }
        let n = self.end().contact;
        let h = direction - n * n.dot(direction);
        if h.norm() < 1e-12 {
            return Err(PathError::NotTangent);
        }
        self.push(RollSegment {
            kind: SegmentKind::Roll,
            axis: n.cross(&h).normalize(),
            length: object_angle / self.geom.object_ratio(),
        })
    }

    /// Appends the great-circle roll from the current object contact to
    /// `target` (unit, object frame); any great circle if they are opposite.
    pub fn push_roll_to(&mut self, target: &Vector3<f64>) -> Result<(), PathError> {
        if !target.iter().all(|x| x.is_finite()) {
            return Err(PathError::NonFinite);
        }
        let n = self.end().contact;
        let angle = angle_between(&n, target);
        self.push_roll(&tangent_towards(&n, target), angle)
    }

    /// Appends a spin by `angle` \[rad\] about the outward contact normal +n
    /// (negative: about −n). The roll changes by −angle·m_z.
    pub fn push_spin(&mut self, angle: f64) -> Result<(), PathError> {
        if !angle.is_finite() {
            return Err(PathError::NonFinite);
        }
        let n = self.end().contact;
        self.push(RollSegment {
            kind: SegmentKind::Spin,
            axis: if angle >= 0.0 { n } else { -n },
            length: angle.abs(),
        })
    }

    /// Appends the spin that changes the roll by `roll_change` \[rad\]
    /// (SPEC §2.4: unwinding; at the pole the spin angle is −roll_change).
    pub fn push_spin_roll(&mut self, roll_change: f64) -> Result<(), PathError> {
        if !roll_change.is_finite() {
            return Err(PathError::NonFinite);
        }
        let e = self.end();
        // Roll rate per radian of spin about +n: n·a_f = −m_z.
        let rate = e.contact.dot(&e.pole_axis());
        if rate.abs() < 1e-6 {
            return Err(PathError::SpinCannotRoll);
        }
        self.push_spin(roll_change / rate)
    }

    /// Hemisphere and roll extremes, exact per segment.
    pub fn margins(&self) -> PathMargins {
        let fr = self.geom.fingertip_ratio();
        let mut min_mz = self.waypoints[0].contact.fingertip_contact().z;
        let mut max_roll = self.waypoints[0].contact.roll.abs();
        for (seg, w) in self.segments().iter().zip(self.waypoints.iter()) {
            // m_z(φ) = A cos φ + B sin φ + C, φ = σ R/(R + r) (fingertip
            // contact angle travelled), from m_z = −a(σ)·n(σ).
            let (k, a0, n0) = (&seg.axis, w.contact.pole_axis(), w.contact.contact);
            let (ak, kn) = (a0.dot(k), k.dot(&n0));
            let a = -a0.dot(&n0) + ak * kn;
            let b = a0.dot(&k.cross(&n0));
            min_mz = min_mz.min(min_sinusoid(a, b, -ak * kn, seg.length * fr));
        }
        for w in self.waypoints() {
            max_roll = max_roll.max(w.contact.roll.abs());
        }
        PathMargins {
            min_hemisphere: min_mz.clamp(-1.0, 1.0).asin(),
            max_abs_roll: max_roll,
            final_roll: self.end().roll,
        }
    }

    /// Largest angle between the object contact and the unit object-frame
    /// `axis` along the path \[rad\] — e.g. against a workspace cone W_k
    /// (SPEC §1.1) by the caller, who knows Q_o and d_k.
    pub fn max_angle_from(&self, axis: &Vector3<f64>) -> f64 {
        let c = self.geom.object_ratio();
        let mut min_cos = axis.dot(&self.waypoints[0].contact.contact);
        for (seg, w) in self.segments().iter().zip(self.waypoints.iter()) {
            let (k, n0) = (&seg.axis, &w.contact.contact);
            let (wk, kn) = (axis.dot(k), k.dot(n0));
            let a = axis.dot(n0) - wk * kn;
            let b = axis.dot(&k.cross(n0));
            min_cos = min_cos.min(min_sinusoid(a, b, wk * kn, seg.length * c));
        }
        min_cos.clamp(-1.0, 1.0).acos()
    }
}
