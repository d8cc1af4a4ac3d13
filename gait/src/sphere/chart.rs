//! The spherical chart of SPEC §2.1 (paper eq. (1)) and its surface forms.
//!
//! Primary chart, on the unit sphere:
//!   f(u, v) = (cos u cos v, −cos u sin v, sin u),  −π/2 < u < π/2, −π < v ≤ π,
//! Gauss frame x = f_u/|f_u| = (−sin u cos v, sin u sin v, cos u),
//! y = f_v/|f_v| = (−sin v, −cos v, 0), z = x × y.
//! Checked: x × y = (cos u cos v, −cos u sin v, sin u) = f, so z is the
//! outward normal and SPEC's formulas are consistent (the frame is
//! right-handed with the normal pointing out of the sphere).
//!
//! Secondary chart: f̄ = Q f with Q = [−e_x | e_z | e_y] (columns), a proper
//! rotation. The primary chart is singular at the poles ±e_z and has its
//! seam (v = π) on the half great circle {y = 0, x ≤ 0}; the secondary one
//! has its poles at ±e_y and its seam on {z = 0, x ≥ 0}. The two singular
//! sets are disjoint.

use nalgebra::{Matrix2, Matrix3, RowVector2, Vector3};

/// One of the two charts of the atlas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChartId {
    /// f(u, v) of SPEC §2.1; poles at ±e_z.
    Primary,
    /// f̄ = Q f with Q = [−e_x | e_z | e_y]; poles at ±e_y.
    Secondary,
}

impl ChartId {
    /// The fixed rotation Q with f̄ = Q f (identity for the primary chart).
    pub fn rotation(self) -> Matrix3<f64> {
        match self {
            ChartId::Primary => Matrix3::identity(),
            ChartId::Secondary => Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0),
        }
    }

    /// The other chart.
    pub fn other(self) -> Self {
        match self {
            ChartId::Primary => ChartId::Secondary,
            ChartId::Secondary => ChartId::Primary,
        }
    }

    /// Maps a body-frame vector into this chart's local frame (Qᵀ p).
    fn to_local(self, p: &Vector3<f64>) -> Vector3<f64> {
        match self {
            ChartId::Primary => *p,
            // Qᵀ = [[-1,0,0],[0,0,1],[0,1,0]] (Q is symmetric here).
            ChartId::Secondary => Vector3::new(-p.x, p.z, p.y),
        }
    }

    /// Maps a chart-local vector into the body frame (Q p).
    fn to_body(self, p: &Vector3<f64>) -> Vector3<f64> {
        match self {
            ChartId::Primary => *p,
            ChartId::Secondary => Vector3::new(-p.x, p.z, p.y),
        }
    }
}

/// Chart coordinates of a point: latitude u ∈ [−π/2, π/2], longitude
/// v ∈ (−π, π] \[rad\] (SPEC §2.1, paper eq. (1)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartPoint {
    /// Which chart the coordinates refer to.
    pub chart: ChartId,
    /// Latitude u.
    pub u: f64,
    /// Longitude v.
    pub v: f64,
}

/// Wraps an angle into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    use core::f64::consts::{PI, TAU};
    let w = a - TAU * ((a + PI) / TAU).floor();
    // `w` is in [−π, π); move −π to π so the range is (−π, π].
    if w <= -PI { w + TAU } else { w }
}

impl ChartPoint {
    /// A point from its coordinates; v is wrapped into (−π, π].
    pub fn new(chart: ChartId, u: f64, v: f64) -> Self {
        Self {
            chart,
            u,
            v: wrap_angle(v),
        }
    }

    /// Coordinates of the direction `n` (any non-zero vector, body frame)
    /// in `chart`. At a pole of the chart v is 0.
    pub fn from_unit(chart: ChartId, n: &Vector3<f64>) -> Self {
        let l = chart.to_local(n);
        let h = l.x.hypot(l.y);
        // atan2 forms stay accurate near the poles, unlike asin.
        let u = l.z.atan2(h);
        let v = if h == 0.0 { 0.0 } else { (-l.y).atan2(l.x) };
        Self::new(chart, u, v)
    }

    /// The point on the unit sphere, body frame: Q f(u, v).
    pub fn unit(&self) -> Vector3<f64> {
        let (su, cu) = self.u.sin_cos();
        let (sv, cv) = self.v.sin_cos();
        self.chart.to_body(&Vector3::new(cu * cv, -cu * sv, su))
    }

    /// The point on the sphere of radius ρ: ρ Q f(u, v).
    pub fn point(&self, rho: f64) -> Vector3<f64> {
        self.unit() * rho
    }

    /// The Gauss frame [x | y | z] (columns, body frame): x = f_u/|f_u|,
    /// y = f_v/|f_v|, z = x × y = outward normal (SPEC §2.1).
    pub fn frame(&self) -> Matrix3<f64> {
        let (su, cu) = self.u.sin_cos();
        let (sv, cv) = self.v.sin_cos();
        let x = self.chart.to_body(&Vector3::new(-su * cv, su * sv, cu));
        let y = self.chart.to_body(&Vector3::new(-sv, -cv, 0.0));
        let z = self.chart.to_body(&Vector3::new(cu * cv, -cu * sv, su));
        Matrix3::from_columns(&[x, y, z])
    }

    /// The same point in the other chart.
    pub fn in_chart(&self, chart: ChartId) -> Self {
        if chart == self.chart {
            *self
        } else {
            Self::from_unit(chart, &self.unit())
        }
    }
}

/// Metric M = diag(ρ, ρ cos u) (SPEC §2.1): |f_u| and |f_v|.
pub fn metric(rho: f64, u: f64) -> Matrix2<f64> {
    Matrix2::new(rho, 0.0, 0.0, rho * u.cos())
}

/// Curvature form K = diag(1/ρ, 1/ρ) (SPEC §2.1).
pub fn curvature(rho: f64) -> Matrix2<f64> {
    Matrix2::new(1.0 / rho, 0.0, 0.0, 1.0 / rho)
}

/// Torsion form T = [0, −tan(u)/ρ] (SPEC §2.1).
pub fn torsion(rho: f64, u: f64) -> RowVector2<f64> {
    RowVector2::new(0.0, -u.tan() / rho)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_right_handed_and_outward() {
        for chart in [ChartId::Primary, ChartId::Secondary] {
            for (u, v) in [(0.3, -2.0), (-1.2, 3.0), (0.0, 0.0), (1.0, 1.0)] {
                let p = ChartPoint::new(chart, u, v);
                let f = p.frame();
                assert!((f.determinant() - 1.0).abs() < 1e-14);
                assert!((f.column(2) - p.unit()).norm() < 1e-15);
                let x: Vector3<f64> = f.column(0).into();
                let y: Vector3<f64> = f.column(1).into();
                assert!((x.cross(&y) - p.unit()).norm() < 1e-15);
            }
        }
    }

    #[test]
    fn wrap_is_half_open() {
        use core::f64::consts::PI;
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert!((wrap_angle(3.0 * PI + 0.1) - (-PI + 0.1)).abs() < 1e-12);
    }
}
