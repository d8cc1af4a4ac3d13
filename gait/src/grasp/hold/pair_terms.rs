//! The exact pair test's terms (see [`HoldModel::pair_holds`]): each
//! contact of a soft pair in its own tangent frame, and the load part of
//! one load term there. The load part is linear in the load, so the parts
//! of the weight, a force vertex and a torque vertex add up to a
//! scenario's. The methods are `#[inline]`: the pair test calls them per
//! scenario from its own module (without it they were not inlined there,
//! and planning took ~15 % longer).

use nalgebra::Vector3;

#[cfg(doc)]
use super::HoldModel;
use crate::sphere::rotation::any_perpendicular;

/// One contact of a soft pair in its own frame (normal `nn`, tangents
/// `t1`, `t2`), with the squeeze's share: direction `dir` along the chord,
/// whose normal part is `a` and tangential part `aa` (see
/// [`HoldModel::pair_holds`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct PairContact {
    nn: Vector3<f64>,
    t1: Vector3<f64>,
    t2: Vector3<f64>,
    pub(super) a: f64,
    /// The tangential part of the squeeze direction in (t1, t2).
    aa: [f64; 2],
    /// μ², the friction the contact was made with.
    mu2: f64,
    /// |aa|² − μ² a², the quadratic's leading coefficient.
    pub(super) qa: f64,
}

impl PairContact {
    #[inline]
    pub(super) fn new(dir: &Vector3<f64>, nn: &Vector3<f64>, mu: f64) -> Self {
        let t1 = any_perpendicular(nn);
        let t2 = nn.cross(&t1);
        let a = dir.dot(&-nn);
        let aa = dir + nn * a;
        let aa = [aa.dot(&t1), aa.dot(&t2)];
        Self {
            nn: *nn,
            t1,
            t2,
            a,
            aa,
            mu2: mu * mu,
            qa: aa[0] * aa[0] + aa[1] * aa[1] - mu * mu * a * a,
        }
    }

    /// The larger of `f` and [`PairContact::least`], without the root
    /// where the load part is already inside the cone at squeeze `f` with
    /// a normal of at least `floor`: the squeezes that put it inside form
    /// an interval unbounded above (the squeeze direction lies inside the
    /// cone), so its least squeeze is below `f`. The relative margin keeps
    /// a "below" far from rounding, so the result is the same number the
    /// root would give.
    #[inline]
    pub(super) fn least_beyond(&self, f: f64, b: f64, x: f64, y: f64, s: f64, floor: f64) -> f64 {
        let normal = self.a * f + b;
        if normal > 0.0 && normal >= floor {
            let (tx, ty) = (self.aa[0] * f + x, self.aa[1] * f + y);
            let cone = self.mu2 * normal * normal;
            if tx * tx + ty * ty + s * s <= (1.0 - INSIDE_MARGIN) * cone {
                return f;
            }
        }
        f.max(self.least(b, x, y, s, floor))
    }

    /// `HoldModel::least` for this contact with the load part's normal
    /// `b`, tangential (x, y) and torsion term `s`. Only for a contact
    /// whose squeeze direction lies inside its cone (`a` > 0, `qa` < 0),
    /// as [`HoldModel::pair_holds`] checks first.
    #[inline]
    pub(super) fn least(&self, b: f64, x: f64, y: f64, s: f64, floor: f64) -> f64 {
        let (mu2, qa) = (self.mu2, self.qa);
        let qb = 2.0 * (self.aa[0] * x + self.aa[1] * y - mu2 * self.a * b);
        let qc = x * x + y * y + s * s - mu2 * b * b;
        let mut f = ((floor - b) / self.a).max(0.0);
        let disc = qb * qb - 4.0 * qa * qc;
        if disc > 0.0 {
            f = f.max((-qb - disc.sqrt()) / (2.0 * qa));
        }
        f
    }
}

/// Relative margin of [`PairContact::least_beyond`]'s "inside".
const INSIDE_MARGIN: f64 = 1e-9;

/// The load part of one load term at a soft pair: per contact its normal
/// component b = g·(−n) and tangential components (x, y), and the scaled
/// torsion. Linear in the load, so terms add.
#[derive(Debug, Clone, Copy)]
pub(super) struct LoadPart {
    pub(super) contact: [[f64; 3]; 2],
    pub(super) torsion: f64,
}

impl LoadPart {
    pub(super) const ZERO: Self = Self {
        contact: [[0.0; 3]; 2],
        torsion: 0.0,
    };

    #[inline]
    pub(super) fn new(frames: &[PairContact; 2], g: &[Vector3<f64>; 2], torsion: f64) -> Self {
        Self {
            contact: core::array::from_fn(|c| {
                let f = &frames[c];
                [g[c].dot(&-f.nn), g[c].dot(&f.t1), g[c].dot(&f.t2)]
            }),
            torsion,
        }
    }

    #[inline]
    pub(super) fn plus(&self, o: &Self) -> Self {
        Self {
            contact: core::array::from_fn(|c| {
                core::array::from_fn(|k| self.contact[c][k] + o.contact[c][k])
            }),
            torsion: self.torsion + o.torsion,
        }
    }
}
