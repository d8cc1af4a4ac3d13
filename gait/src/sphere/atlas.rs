//! The two-chart atlas with hysteresis (SPEC §2.1).
//!
//! A chart is kept while the point's latitude satisfies |u| ≤
//! [`SWITCH_LATITUDE`] (60°). Beyond that the point is within 30° of a pole
//! of the current chart; that pole lies on the other chart's equator, so
//! there |u| ≤ 30°. The 30° gap between "switch away" and "arrive" is the
//! hysteresis: a contact wandering near the threshold never chatters
//! between the charts. Seams (v = ±π) are not singular for the kinematics,
//! only for the coordinates: longitudes are wrapped, never switched on.

use super::chart::{ChartId, ChartPoint};
use nalgebra::Vector3;

/// Latitude |u| beyond which the atlas switches to the other chart (60°).
pub const SWITCH_LATITUDE: f64 = core::f64::consts::FRAC_PI_3;

/// The chart in which the direction `n` has the smaller |u| (the primary
/// chart on ties): the natural chart to start with.
pub fn best_chart(n: &Vector3<f64>) -> ChartId {
    // Primary latitude is asin(n_z), secondary asin(n_y) (Qᵀ n = (−x, z, y)).
    if n.y.abs() < n.z.abs() {
        ChartId::Secondary
    } else {
        ChartId::Primary
    }
}

/// A chart change made by [`hysteresis`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartSwitch {
    /// The same point in the new chart.
    pub point: ChartPoint,
    /// χ: the new Gauss frame is the old one rotated by χ about the normal,
    /// x_new = cos χ x_old + sin χ y_old. A contact angle ψ measured against
    /// either frame becomes ψ + χ (see [`frame_angle`]).
    pub frame_angle: f64,
}

/// Angle χ from the Gauss frame of `from` to that of `to` (same point,
/// any charts), about the outward normal: x_to = cos χ x_from + sin χ y_from.
///
/// Contact angle bookkeeping (SPEC §2.2): ψ is defined by
/// x_o = cos ψ x_f − sin ψ y_f. Rotating either the object frame or the
/// fingertip frame by χ about its own normal turns ψ into ψ + χ (the
/// normals are opposite, which is why both cases add).
pub fn frame_angle(from: &ChartPoint, to: &ChartPoint) -> f64 {
    let a = from.frame();
    let b = to.frame();
    let x_to = b.column(0);
    x_to.dot(&a.column(1)).atan2(x_to.dot(&a.column(0)))
}

/// Switches `p` to the other chart if |u| > [`SWITCH_LATITUDE`].
pub fn hysteresis(p: &ChartPoint) -> Option<ChartSwitch> {
    if p.u.abs() <= SWITCH_LATITUDE {
        return None;
    }
    let q = p.in_chart(p.chart.other());
    Some(ChartSwitch {
        point: q,
        frame_angle: frame_angle(p, &q),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switching_lands_far_from_the_threshold() {
        for i in 0..200 {
            let t = i as f64 * 0.1;
            let n = Vector3::new(t.cos() * 0.4, (1.3 * t).sin() * 0.2, 0.9).normalize();
            let p = ChartPoint::from_unit(ChartId::Primary, &n);
            if let Some(s) = hysteresis(&p) {
                assert!(s.point.u.abs() <= core::f64::consts::FRAC_PI_6 + 1e-12);
                assert!((s.point.unit() - n).norm() < 1e-14);
            }
        }
    }
}
