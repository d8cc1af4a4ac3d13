//! Step 2 shape with a free velocity plateau (VEL): the first phase
//! duration is a root of a quintic (UDDU) or sextic (UDUD), bracketed
//! between the extrema of the polynomial and refined by safeguarded Newton.

use crate::position_step1::Lim;
use crate::position_step2::Step2;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, NEWTON_TOL, for_roots};

impl Step2 {
    pub(crate) fn vel(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
            pd,
            v0,
            vf,
            vd,
            vd_2,
            a0,
            af,
            ad,
            a0_2,
            a0_3,
            a0_4,
            a0_5,
            a0_6,
            af_2,
            af_3,
            af_4,
            af_6,
            jj,
            g1,
            ..
        } = *self;
        let (amax, j) = (m.a_max, m.j);
        let tz_min = 0.0f64.max(-a0 / j);
        let tz_max = ((tf - a0 / j) / 2.0).min((amax - a0) / j);

        // UDDU
        if v0.abs() < EPS && a0.abs() < EPS && vf.abs() < EPS && af.abs() < EPS {
            for_roots!(roots::cubic(1.0, -tf / 2.0, 0.0, pd / (2.0 * j)), |t| {
                if t > tf / 4.0 {
                    continue;
                }
                if t > EPS {
                    let orig = -pd + j * t * t * (tf - 2.0 * t);
                    let deriv = 2.0 * j * t * (tf - 3.0 * t);
                    t -= orig / deriv;
                }
                p.t = [t, 0.0, t, tf - 4.0 * t, t, 0.0, t];
                if Self::chk(p, S::Uddu, L::Vel, m) {
                    return true;
                }
            });
        } else {
            let p1 = af_2 - 2.0 * j * (-2.0 * af * tf + j * tf_2 + 3.0 * vd);
            let ph1 = af_3 - 3.0 * jj * g1 - 3.0 * af * j * vd;
            let ph2 = af_4
                + 8.0 * af_3 * j * tf
                + 12.0
                    * j
                    * (3.0 * j * vd_2 - af_2 * vd + 2.0 * af * j * (g1 - tf * vd)
                        - 2.0 * jj * tf * g1);
            let ph3 = a0 * (af - j * tf);
            let ph4 = j * (-ad + j * tf);

            // Quintic in t0.
            let poly = [
                1.0,
                (15.0 * a0_2 + af_2 + 4.0 * af * j * tf
                    - 16.0 * ph3
                    - 2.0 * j * (j * tf_2 + 3.0 * vd))
                    / (4.0 * ph4),
                (29.0 * a0_3 - 2.0 * af_3 - 33.0 * a0 * ph3
                    + 6.0 * jj * g1
                    + 6.0 * af * j * vd
                    + 6.0 * a0 * p1)
                    / (6.0 * j * ph4),
                (61.0 * a0_4 - 76.0 * a0_2 * ph3 - 16.0 * a0 * ph1 + 30.0 * a0_2 * p1 + ph2)
                    / (24.0 * jj * ph4),
                (a0 * (7.0 * a0_4 - 10.0 * a0_2 * ph3 - 4.0 * a0 * ph1 + 6.0 * a0_2 * p1 + ph2))
                    / (12.0 * jj * j * ph4),
                (7.0 * a0_6 + af_6 - 12.0 * a0_4 * ph3 + 48.0 * af_3 * jj * g1
                    - 8.0 * a0_3 * ph1
                    - 72.0 * jj * j * (j * g1 * g1 + vd_2 * vd + 2.0 * af * g1 * vd)
                    - 6.0 * af_4 * j * vd
                    + 36.0 * af_2 * jj * vd_2
                    + 9.0 * a0_4 * p1
                    + 3.0 * a0_2 * ph2)
                    / (144.0 * jj * jj * ph4),
            ];
            let deriv: [f64; 5] = roots::monic_derivative(&poly);
            let dderiv: [f64; 4] = roots::derivative(&deriv);
            let extrema = roots::quartic_monic(deriv[1], deriv[2], deriv[3], deriv[4]);

            let mut check_root = |mut t: f64| -> bool {
                let h1 = ((a0_2 + af_2) / (2.0 * jj) + (2.0 * a0 * t + j * t * t - vd) / j).sqrt();
                let orig = -pd
                    - (2.0 * a0_3
                        + 4.0 * af_3
                        + 24.0 * a0 * j * t * (af + j * (h1 + t - tf))
                        + 6.0 * a0_2 * (af + j * (2.0 * t - tf))
                        + 6.0 * (a0_2 + af_2) * j * h1
                        + 12.0 * af * j * (j * t * t - vd)
                        + 12.0 * jj * (j * t * t * (h1 + t - tf) - tf * v0 - h1 * vd))
                        / (12.0 * jj);
                let slope = -(a0 + j * t) * (3.0 * (h1 + t) - 2.0 * tf + (a0 + 2.0 * af) / j);
                if !orig.is_nan() && !slope.is_nan() && slope.abs() > EPS {
                    t -= orig / slope;
                }
                if t > tf || t.is_nan() {
                    return false;
                }
                let h1 = ((a0_2 + af_2) / (2.0 * jj) + (t * (2.0 * a0 + j * t) - vd) / j).sqrt();
                p.t = [
                    t,
                    0.0,
                    t + a0 / j,
                    tf - 2.0 * (t + h1) - (a0 + af) / j,
                    h1,
                    0.0,
                    h1 + af / j,
                ];
                Self::chk(p, S::Uddu, L::Vel, m)
            };

            let mut tz_cur = tz_min;
            let (ext, n_ext) = extrema.sorted();
            for &tz0 in &ext[..n_ext] {
                let mut tz = tz0;
                if tz >= tz_max {
                    continue;
                }
                let orig = roots::eval(&deriv, tz);
                if orig.abs() > NEWTON_TOL {
                    tz -= orig / roots::eval(&dderiv, tz);
                }
                let val = roots::eval(&poly, tz);
                if val.abs() < 64.0 * roots::eval(&dderiv, tz).abs() * NEWTON_TOL {
                    if check_root(tz) {
                        return true;
                    }
                } else if roots::eval(&poly, tz_cur) * val < 0.0
                    && check_root(roots::shrink_interval::<6, 5>(&poly, tz_cur, tz))
                {
                    return true;
                }
                tz_cur = tz;
            }
            let val_max = roots::eval(&poly, tz_max);
            if roots::eval(&poly, tz_cur) * val_max < 0.0 {
                if check_root(roots::shrink_interval::<6, 5>(&poly, tz_cur, tz_max)) {
                    return true;
                }
            } else if val_max.abs() < 8.0 * EPS && check_root(tz_max) {
                return true;
            }
        }

        // UDUD
        {
            let ph1 = af_2 - 2.0 * j * (2.0 * af * tf + j * tf_2 - 3.0 * vd);
            let ph2 = af_3 - 3.0 * jj * g1 + 3.0 * af * j * vd;
            let ph3 = 2.0 * j * tf * g1 + 3.0 * vd_2;
            let ph4 = af_4 - 8.0 * af_3 * j * tf
                + 12.0 * j * (j * ph3 + af_2 * vd + 2.0 * af * j * (g1 - tf * vd));
            let ph5 = af + j * tf;

            // Sextic in t0.
            let poly = [
                1.0,
                (5.0 * a0 - ph5) / j,
                (39.0 * a0_2 - ph1 - 16.0 * a0 * ph5) / (4.0 * jj),
                (55.0 * a0_3 - 33.0 * a0_2 * ph5 - 6.0 * a0 * ph1 + 2.0 * ph2) / (6.0 * jj * j),
                (101.0 * a0_4 + ph4 - 76.0 * a0_3 * ph5 - 30.0 * a0_2 * ph1 + 16.0 * a0 * ph2)
                    / (24.0 * jj * jj),
                (a0 * (11.0 * a0_4 + ph4 - 10.0 * a0_3 * ph5 - 6.0 * a0_2 * ph1 + 4.0 * a0 * ph2))
                    / (12.0 * jj * jj * j),
                (11.0 * a0_6 - af_6 - 12.0 * a0_5 * ph5 - 48.0 * af_3 * jj * g1 - 9.0 * a0_4 * ph1
                    + 72.0 * jj * j * (j * g1 * g1 - vd_2 * vd - 2.0 * af * g1 * vd)
                    - 6.0 * af_4 * j * vd
                    - 36.0 * af_2 * jj * vd_2
                    + 8.0 * a0_3 * ph2
                    + 3.0 * a0_2 * ph4)
                    / (144.0 * jj * jj * jj),
            ];
            let deriv: [f64; 6] = roots::monic_derivative(&poly);
            let dderiv: [f64; 5] = roots::monic_derivative(&deriv);
            let ddderiv: [f64; 4] = roots::derivative(&dderiv);

            // Brackets of the derivative's roots, between its own extrema.
            let mut brackets = [(0.0, 0.0); 6];
            let mut n_br = 0;
            let mut dd_cur = tz_min;
            let (ext, n_ext) =
                roots::quartic_monic(dderiv[1], dderiv[2], dderiv[3], dderiv[4]).sorted();
            for &tz0 in &ext[..n_ext] {
                let mut tz = tz0;
                if tz >= tz_max {
                    continue;
                }
                let orig = roots::eval(&dderiv, tz);
                if orig.abs() > NEWTON_TOL {
                    tz -= orig / roots::eval(&ddderiv, tz);
                }
                if roots::eval(&deriv, dd_cur) * roots::eval(&deriv, tz) < 0.0 && n_br < 6 {
                    brackets[n_br] = (dd_cur, tz);
                    n_br += 1;
                }
                dd_cur = tz;
            }
            if roots::eval(&deriv, dd_cur) * roots::eval(&deriv, tz_max) < 0.0 && n_br < 6 {
                brackets[n_br] = (dd_cur, tz_max);
                n_br += 1;
            }
            // Sorted like Ruckig's set of pairs.
            brackets[..n_br]
                .sort_unstable_by(|x, y| x.partial_cmp(y).unwrap_or(core::cmp::Ordering::Equal));

            let mut check_root = |mut t: f64| -> bool {
                let h1f = |t: f64| {
                    ((af_2 - a0_2) / (2.0 * jj) - ((2.0 * a0 + j * t) * t - vd) / j).sqrt()
                };
                let res = |t: f64, h1: f64| {
                    -pd + (af_3 - a0_3 + 3.0 * a0_2 * j * (tf - 2.0 * t)) / (6.0 * jj)
                        + (2.0 * a0 + j * t) * t * (tf - t)
                        + (j * h1 - af) * h1 * h1
                        + tf * v0
                };
                let slope = |t: f64, h1: f64| {
                    (a0 + j * t) * (2.0 * (af + j * tf) - 3.0 * j * (h1 + t) - a0) / j
                };
                let h1 = h1f(t);
                t -= res(t, h1) / slope(t, h1);
                let h1 = h1f(t);
                let r = res(t, h1);
                if r.abs() > 1e-9 {
                    t -= r / slope(t, h1);
                }
                let h1 = h1f(t);
                p.t = [
                    t,
                    0.0,
                    t + a0 / j,
                    tf - 2.0 * (t + h1) + ad / j,
                    h1,
                    0.0,
                    h1 - af / j,
                ];
                Self::chk(p, S::Udud, L::Vel, m)
            };

            let mut tz_cur = tz_min;
            for &(lo, hi) in &brackets[..n_br] {
                let tz = roots::shrink_interval::<6, 5>(&deriv, lo, hi);
                if tz >= tz_max {
                    continue;
                }
                let val = roots::eval(&poly, tz);
                if val.abs() < 64.0 * roots::eval(&dderiv, tz).abs() * NEWTON_TOL {
                    if check_root(tz) {
                        return true;
                    }
                } else if roots::eval(&poly, tz_cur) * val < 0.0
                    && check_root(roots::shrink_interval::<7, 6>(&poly, tz_cur, tz))
                {
                    return true;
                }
                tz_cur = tz;
            }
            if roots::eval(&poly, tz_cur) * roots::eval(&poly, tz_max) < 0.0
                && check_root(roots::shrink_interval::<7, 6>(&poly, tz_cur, tz_max))
            {
                return true;
            }
        }
        false
    }
}
