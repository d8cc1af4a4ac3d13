//! The paper's longitude–equator–longitude path (Fig. 2) and its reach
//! (SPEC §2.4).
//!
//! With the fingertip contact at its pole: roll A→B along a fingertip
//! longitude (fingertip arc rπ/2, no roll change: the rotation axis is ⊥ the
//! pole axis), B→C along the fingertip equator (rotation about the pole
//! axis itself: the roll changes by the full relative rotation, and the
//! fingertip turns (1 + r/R) times the angle its contact moves on its
//! equator), C→D back along a longitude to the pole. On the object the
//! contact runs along three great-circle arcs of the same lengths, legs
//! a = (π/2)(r/R) and base b = |Δτ|·r/(R + r) (SPEC §2.4: not the paper's
//! flat-object γr), with two 90° turns to the same side: a Saccheri
//! quadrilateral ABCD with right angles at B and C. Its summit AD = δ and
//! summit angle ε (at A, between AB and AD) are
//!   sin(δ/2) = cos a · sin(b/2),   cos ε = −tan a · tan(δ/2).
//! Turning left (towards n × heading, seen from outside the object) changes
//! the roll by +|Δτ|, turning right by −|Δτ|; both reach the same D with
//! mirrored headings, so the turn side is free to unwind the roll.

use super::path::{PathError, RollingPath};
use super::segment::{RollSegment, SegmentKind};
use crate::contact::ContactGeometry;
use crate::sphere::rotation::{angle_between, rotate, tangent_towards};
use core::f64::consts::{FRAC_PI_2, PI};
use nalgebra::Vector3;

/// Side of the two 90° turns of a Fig. 2 path, seen from outside the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Turn {
    /// Towards n × heading; the roll increases.
    Left,
    /// Towards heading × n; the roll decreases.
    Right,
}

impl Turn {
    /// +1 for Left, −1 for Right: the sign of the roll change.
    pub fn sign(self) -> f64 {
        match self {
            Turn::Left => 1.0,
            Turn::Right => -1.0,
        }
    }
}

/// Object angle of one Fig. 2 longitude leg, a = (π/2)(r/R) \[rad\].
pub fn fig2_leg_angle(geom: &ContactGeometry) -> f64 {
    FRAC_PI_2 * geom.fingertip_radius / geom.object_radius
}

/// Object-contact displacement δ of one Fig. 2 path whose equator leg
/// changes the roll by `roll_budget` (its magnitude) \[rad\]; the base is
/// capped at π.
pub fn fig2_reach(geom: &ContactGeometry, roll_budget: f64) -> f64 {
    let b = (roll_budget.abs() * geom.object_ratio()).min(PI);
    let a = fig2_leg_angle(geom);
    2.0 * (a.cos() * (0.5 * b).sin()).clamp(-1.0, 1.0).asin()
}

/// |Δτ| a Fig. 2 path needs to displace the object contact by `distance`
/// \[rad\], or None if one path cannot reach that far.
pub fn fig2_roll_for(geom: &ContactGeometry, distance: f64) -> Option<f64> {
    let sb = (0.5 * distance).sin() / fig2_leg_angle(geom).cos();
    (distance.is_finite() && (0.0..=PI).contains(&distance) && sb <= 1.0)
        .then(|| 2.0 * sb.asin() / geom.object_ratio())
}

impl RollingPath {
    /// Appends a Fig. 2 path: from the pole, first leg along the object
    /// tangent `heading`, turns to `turn`, equator leg changing the roll by
    /// `roll_change` ≥ 0 in magnitude (sign given by `turn`). Returns the
    /// signed roll change. All three segments or none are appended.
    pub fn push_fig2(
        &mut self,
        heading: &Vector3<f64>,
        turn: Turn,
        roll_change: f64,
    ) -> Result<f64, PathError> {
        if !(heading.iter().all(|x| x.is_finite()) && roll_change.is_finite()) {
            return Err(PathError::NonFinite);
        }
        if roll_change < 0.0 {
            return Err(PathError::InvalidSegment);
        }
        let start = *self.end();
        if start.fingertip_contact().z < 1.0 - 1e-9 {
            return Err(PathError::NotAtPole);
        }
        let na = start.contact;
        let h1 = heading - na * na.dot(heading);
        if h1.norm() < 1e-12 {
            return Err(PathError::NotTangent);
        }
        if self.len() + 3 > super::MAX_SEGMENTS {
            return Err(PathError::Full);
        }
        let before = self.len();
        let s = turn.sign();
        let leg = FRAC_PI_2 / self.geometry().fingertip_ratio();
        let roll = |axis: Vector3<f64>, length: f64| RollSegment {
            kind: SegmentKind::Roll,
            axis,
            length,
        };
        let k1 = na.cross(&h1).normalize();
        let result = (|| {
            self.push(roll(k1, leg))?;
            // Tangent of leg 1 at B is k1 × n_B; turning by s·90° gives the
            // axis k2 = n_B × (s n_B × h) = −s h.
            let k2 = -k1.cross(&self.end().contact).normalize() * s;
            self.push(roll(k2, roll_change))?;
            let k3 = -k2.cross(&self.end().contact).normalize() * s;
            self.push(roll(k3, leg))
        })();
        match result {
            Ok(()) => Ok(self.end().roll - start.roll),
            Err(e) => {
                self.truncate(before);
                Err(e)
            }
        }
    }

    /// Appends the Fig. 2 path with turns to `turn` that brings the object
    /// contact exactly to `target` (unit, object frame), choosing the
    /// heading and the equator leg from the Saccheri relations (module
    /// docs). Returns the signed roll change.
    pub fn push_fig2_to(&mut self, target: &Vector3<f64>, turn: Turn) -> Result<f64, PathError> {
        if !target.iter().all(|x| x.is_finite()) {
            return Err(PathError::NonFinite);
        }
        let g = *self.geometry();
        let na = self.end().contact;
        let delta = angle_between(&na, target);
        let roll = fig2_roll_for(&g, delta).ok_or(PathError::BeyondReach)?;
        let a = fig2_leg_angle(&g);
        let eps = (-a.tan() * (0.5 * delta).tan()).clamp(-1.0, 1.0).acos();
        let toward = tangent_towards(&na, target);
        // D lies at ε from the first leg, on the turning side.
        let heading = rotate(&na, -turn.sign() * eps, &toward);
        self.push_fig2(&heading, turn, roll)
    }
}
