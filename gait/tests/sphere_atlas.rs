//! Sphere chart, Gauss frame, surface forms and the atlas (SPEC §2.1),
//! checked against their definitions by finite differences over seeded
//! random points.

mod common;

use gait::sphere::{
    ChartId, ChartPoint, SWITCH_LATITUDE, best_chart, curvature, frame_angle, hysteresis, metric,
    torsion,
};
use nalgebra::{Matrix2, Vector3};
use rand::Rng;

const CHARTS: [ChartId; 2] = [ChartId::Primary, ChartId::Secondary];

fn f(chart: ChartId, rho: f64, u: f64, v: f64) -> Vector3<f64> {
    ChartPoint::new(chart, u, v).point(rho)
}

#[test]
fn unit_vector_round_trip_in_both_charts() {
    let mut rng = common::rng(1);
    for _ in 0..20_000 {
        let n = common::unit(&mut rng);
        for c in CHARTS {
            let p = ChartPoint::from_unit(c, &n);
            assert!((p.unit() - n).norm() < 4e-16 * 4.0, "{p:?}");
            assert!(p.v > -std::f64::consts::PI && p.v <= std::f64::consts::PI);
            let q = ChartPoint::from_unit(c, &p.unit());
            assert!((q.u - p.u).abs() < 1e-12);
        }
        let b = ChartPoint::from_unit(best_chart(&n), &n);
        // The best chart always keeps the point at |u| ≤ 45°.
        assert!(b.u.abs() <= std::f64::consts::FRAC_PI_4 + 1e-12);
    }
}

#[test]
fn frame_metric_curvature_torsion_match_their_definitions() {
    let mut rng = common::rng(2);
    let h = 1e-6;
    for _ in 0..2000 {
        let rho = rng.random_range(0.05..2.0);
        let u = rng.random_range(-1.3..1.3);
        let v = rng.random_range(-3.1..3.1);
        for c in CHARTS {
            let p = ChartPoint::new(c, u, v);
            let fr = p.frame();
            let (x, y, z) = (fr.column(0), fr.column(1), fr.column(2));
            let fu = (f(c, rho, u + h, v) - f(c, rho, u - h, v)) / (2.0 * h);
            let fv = (f(c, rho, u, v + h) - f(c, rho, u, v - h)) / (2.0 * h);
            // x = f_u/|f_u|, y = f_v/|f_v|, z = x × y outward.
            assert!((fu.normalize() - x).norm() < 1e-8);
            assert!((fv.normalize() - y).norm() < 1e-8);
            assert!((x.cross(&y) - z).norm() < 1e-14);
            assert!(z.dot(&p.unit()) > 1.0 - 1e-14);
            // M = diag(|f_u|, |f_v|).
            let m = metric(rho, u);
            assert!((m[(0, 0)] - fu.norm()).abs() < 1e-8);
            assert!((m[(1, 1)] - fv.norm()).abs() < 1e-8);
            assert_eq!(m[(0, 1)], 0.0);
            // Montana: K = [x y]ᵀ [z_u z_v] M⁻¹, T = yᵀ [x_u x_v] M⁻¹.
            let frame_at = |uu: f64, vv: f64| ChartPoint::new(c, uu, vv).frame();
            let du = (frame_at(u + h, v) - frame_at(u - h, v)) / (2.0 * h);
            let dv = (frame_at(u, v + h) - frame_at(u, v - h)) / (2.0 * h);
            let (zu, zv) = (du.column(2), dv.column(2));
            let k = Matrix2::new(
                x.dot(&zu) / m[(0, 0)],
                x.dot(&zv) / m[(1, 1)],
                y.dot(&zu) / m[(0, 0)],
                y.dot(&zv) / m[(1, 1)],
            );
            assert!((k - curvature(rho)).norm() < 1e-6 / rho);
            let t = torsion(rho, u);
            assert!((y.dot(&du.column(0)) / m[(0, 0)] - t[0]).abs() < 1e-6 / rho);
            assert!((y.dot(&dv.column(0)) / m[(1, 1)] - t[1]).abs() < 1e-6 / rho);
        }
    }
}

#[test]
fn singular_sets_are_disjoint() {
    // Primary poles and seam are regular, away from the seam, in the
    // secondary chart, and vice versa.
    for i in 0..=1000 {
        let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / 1000.0;
        for c in CHARTS {
            // The seam v = π of chart c, poles included.
            let seam = ChartPoint::new(c, a, std::f64::consts::PI).unit();
            let other = ChartPoint::from_unit(c.other(), &seam);
            assert!(
                other.u.abs() < std::f64::consts::FRAC_PI_2 - 0.5,
                "{other:?}"
            );
            assert!(other.v.abs() < std::f64::consts::PI - 0.5, "{other:?}");
        }
    }
}

#[test]
fn hysteresis_switches_only_beyond_60_degrees_and_lands_within_30() {
    let mut rng = common::rng(3);
    let mut switches = 0;
    for _ in 0..200 {
        let mut n = common::unit(&mut rng);
        let mut p = ChartPoint::from_unit(best_chart(&n), &n);
        let axis = common::unit(&mut rng);
        for _ in 0..500 {
            n = nalgebra::UnitQuaternion::from_scaled_axis(axis * 0.01) * n;
            let moved = ChartPoint::from_unit(p.chart, &n);
            match hysteresis(&moved) {
                None => {
                    assert!(moved.u.abs() <= SWITCH_LATITUDE);
                    p = moved;
                }
                Some(s) => {
                    switches += 1;
                    assert!(moved.u.abs() > SWITCH_LATITUDE);
                    assert!(s.point.u.abs() <= std::f64::consts::FRAC_PI_6 + 1e-12);
                    assert_ne!(s.point.chart, p.chart);
                    assert!((s.point.unit() - n).norm() < 1e-14);
                    // χ rotates the old frame onto the new one about the normal.
                    let (a, b) = (moved.frame(), s.point.frame());
                    let (sc, cc) = s.frame_angle.sin_cos();
                    let x_new = a.column(0) * cc + a.column(1) * sc;
                    assert!((x_new - b.column(0)).norm() < 1e-13);
                    assert!((frame_angle(&s.point, &moved) + s.frame_angle).abs() < 1e-13);
                    p = s.point;
                }
            }
        }
    }
    assert!(switches > 100, "{switches} switches");
}
