//! Step 2 shape with a free velocity plateau (VEL): the first phase
//! duration is a root of a quintic (UDDU) or sextic (UDUD), bracketed
//! between the extrema of the polynomial and refined by safeguarded Newton.

use crate::limits::Lim;
use crate::motion::integrate;
use crate::position_step2::Step2;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, NEWTON_TOL, for_roots};

impl Step2 {
    /// VEL shape (velocity plateau, no acceleration plateau) of duration
    /// `tf` in the direction of `m`. Each jerk pattern is solved only if its
    /// phase durations can be admissible at all (see `vel_*_admissible`).
    pub(crate) fn vel(&self, p: &mut Profile, m: &Lim) -> bool {
        (self.vel_uddu_admissible(m) && self.vel_uddu(p, m))
            || (self.vel_udud_admissible(m) && self.vel_udud(p, m))
    }

    /// Whether a VEL profile with jerk signs UDDU can pass the check.
    ///
    /// With `s = t0 + a0/j` (the third phase; `j·s` is the peak
    /// acceleration) the last ramp is `h1 = √(s² + q)`, increasing in `s`.
    /// Non-negative phases and peak accelerations within the limits bound
    /// `s` to an interval, on which the position reached is monotone in `s`
    /// (a larger `s` is faster at every instant: `∂v/∂s ≥ 0` in every
    /// phase), so the target must lie between the positions at its ends.
    /// Conservative (generous slack, and NaN admits): `false` only if
    /// `vel_uddu` cannot succeed; skipping it saves its quintic without
    /// changing any result.
    fn vel_uddu_admissible(&self, m: &Lim) -> bool {
        let ij = 1.0 / m.j;
        let (a0j, afj) = (self.a0 * ij, self.af * ij);
        let q = (self.af_2 - self.a0_2) * 0.5 * ij * ij - self.vd * ij;
        // Peaks: j·s ≤ a_max, |j·h1| ≤ |a_min|.
        let (s_acc, h_acc) = (m.a_max * ij, -m.a_min * ij);
        // Plateau t3 = 2·(w - s - h1) ≥ 0.
        let w = 0.5 * (self.tf - afj + a0j);
        let slack = 1e-7 * (self.tf + a0j.abs() + afj.abs() + s_acc + h_acc + q.abs().sqrt());
        // t0, t2 ≥ 0; h1 real and t6 = h1 + af/j ≥ 0.
        let h_min = (-afj).max(0.0);
        let lo = a0j.max(0.0).max((h_min * h_min - q).max(0.0).sqrt());
        let mut hi = s_acc.min(w).min(0.5 * (self.tf + a0j));
        if w > slack {
            // s + √(s² + q) ≤ w
            hi = hi.min((w * w - q) / (2.0 * w));
        }
        let hh = h_acc * h_acc - q;
        if hh >= 0.0 {
            hi = hi.min(hh.sqrt());
        }
        if w < -slack || q.max(0.0).sqrt() > h_acc + slack || lo > hi + slack {
            return false;
        }
        let reach = |s: f64| {
            let h1 = (s * s + q).max(0.0).sqrt();
            let t = [s - a0j, s, 2.0 * (w - s - h1), h1, h1 + afj];
            self.reach(&t, [m.j, -m.j, 0.0, -m.j, m.j])
        };
        lo > hi || self.between(reach(lo), reach(hi), hi.max(lo), slack, m.j)
    }

    /// Whether a VEL profile with jerk signs UDUD can pass the check: as
    /// `vel_uddu_admissible`, with `h1 = √(r² - s²)` decreasing in `s`.
    /// The plateau `t3 = 2·(w - s - h1)` is non-negative outside
    /// `(s_a, s_b)` (`s + h1 ≥ r`), which may split the interval in two;
    /// the position is monotone on each part (again `∂v/∂s ≥ 0`).
    fn vel_udud_admissible(&self, m: &Lim) -> bool {
        let ij = 1.0 / m.j;
        let (a0j, afj) = (self.a0 * ij, self.af * ij);
        let r2 = (self.af_2 + self.a0_2) * 0.5 * ij * ij + self.vd * ij;
        let s_acc = m.a_max * ij;
        let w = 0.5 * (self.tf + a0j + afj);
        let slack = 1e-7 * (self.tf + a0j.abs() + afj.abs() + s_acc + r2.abs().sqrt());
        if r2 < 0.0 && (-r2).sqrt() > slack {
            return false;
        }
        let r2 = r2.max(0.0);
        let r = r2.sqrt();
        // h1 real, t6 = h1 - af/j ≥ 0, second peak j·h1 ≤ a_max.
        let mut hi = s_acc.min(0.5 * (self.tf + a0j)).min(r);
        if afj > 0.0 {
            hi = hi.min((r2 - afj * afj).max(0.0).sqrt());
        }
        let lo = a0j.max(0.0).max((r2 - s_acc * s_acc).max(0.0).sqrt());
        if r > w + slack || afj > r + slack || lo > hi + slack {
            return false;
        }
        let reach = |s: f64| {
            let h1 = (r2 - s * s).max(0.0).sqrt();
            let t = [s - a0j, s, 2.0 * (w - s - h1), h1, h1 - afj];
            self.reach(&t, [m.j, -m.j, 0.0, m.j, -m.j])
        };
        // Parts of [lo, hi] where t3 ≥ 0.
        let (a, b) = if w * w >= 2.0 * r2 {
            (hi, hi)
        } else {
            let d = (2.0 * r2 - w * w).sqrt();
            (0.5 * (w - d), 0.5 * (w + d))
        };
        // Infeasible only if each part is empty (beyond the slack) or
        // misses the target.
        let excluded = |x: f64, y: f64| {
            if x <= y {
                !self.between(reach(x), reach(y), y, slack, m.j)
            } else {
                x > y + slack
            }
        };
        !(excluded(lo, hi.min(a)) && excluded(lo.max(b), hi))
    }

    /// Position reached from the start after the phases `t` (the VEL
    /// phases 0, 2, 3, 4, 6) with jerks `jk`.
    #[inline]
    fn reach(&self, t: &[f64; 5], jk: [f64; 5]) -> f64 {
        let (mut x, mut v, mut a) = (0.0, self.v0, self.a0);
        for (dt, j) in t.iter().zip(jk) {
            (x, v, a) = integrate(*dt, x, v, a, j);
        }
        x
    }

    /// Whether the target distance lies between `x0` and `x1`, the
    /// positions at the ends of a monotone part (`s ≤ s_max`) widened by the
    /// check's precision and by what an `s` up to `slack` outside can add
    /// (`|∂x/∂s| ≤ 2·|j|·s·tf`).
    #[inline]
    fn between(&self, x0: f64, x1: f64, s_max: f64, slack: f64, j: f64) -> bool {
        let ds = 2.0 * s_max.abs() * slack + slack * slack;
        let tol =
            2e-8 + 1e-9 * (x0.abs() + x1.abs() + self.pd.abs()) + 2.0 * self.tf * j.abs() * ds;
        let outside = self.pd < x0.min(x1) - tol || self.pd > x0.max(x1) + tol;
        !outside
    }

    /// VEL with jerk signs UDDU: the first phase duration is a root of a
    /// quintic.
    fn vel_uddu(&self, p: &mut Profile, m: &Lim) -> bool {
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

        false
    }

    /// VEL with jerk signs UDUD: the first phase duration is a root of a
    /// sextic.
    fn vel_udud(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
            pd,
            v0,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::block::Block;
    use crate::calculator::{DofCase, step1_dof};
    use crate::candidates::Valid;
    use crate::input::ControlInterface;
    use crate::limits::DofLimits;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The admissibility tests only skip work: whenever a VEL profile
    /// exists, its test passes. Random boundaries (limits over decades,
    /// zero terms, asymmetric limits), durations from just above the
    /// optimum to several times it, both directions.
    #[test]
    fn vel_gates_never_reject_a_solution() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let lu = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| {
            rng.random_range(f64::ln(lo)..f64::ln(hi)).exp()
        };
        let (mut found, mut skipped) = (0, 0);
        for _ in 0..40_000 {
            let v_max = lu(&mut rng, 0.05, 5.0);
            let a_max = v_max * lu(&mut rng, 1.0, 50.0);
            let j_max = a_max * lu(&mut rng, 2.0, 200.0);
            let asym = rng.random_bool(0.3);
            let f = |rng: &mut ChaCha8Rng| if asym { lu(rng, 0.3, 3.0) } else { 1.0 };
            let lim = DofLimits {
                v_max,
                v_min: -v_max * f(&mut rng),
                a_max,
                a_min: -a_max * f(&mut rng),
                j_max,
            };
            let x = |rng: &mut ChaCha8Rng, s: f64| {
                if rng.random_bool(0.2) {
                    0.0
                } else {
                    s * rng.random_range(-0.9..0.9)
                }
            };
            let (v0, vf) = (x(&mut rng, v_max), x(&mut rng, v_max));
            // Accelerations that keep the velocities inside the limits.
            let a0 = x(
                &mut rng,
                (2.0 * j_max * (v_max - v0.abs())).sqrt().min(a_max),
            );
            let af = x(
                &mut rng,
                (2.0 * j_max * (v_max - vf.abs())).sqrt().min(a_max),
            );
            let c = DofCase {
                p0: 0.0,
                v0,
                a0,
                pf: x(&mut rng, 3.0),
                vf,
                af,
            };
            let (mut p, mut b) = (Profile::default(), Block::default());
            let mut scratch = Valid::new(&p);
            if !step1_dof(
                ControlInterface::Position,
                &c,
                &lim,
                &mut p,
                &mut b,
                &mut scratch,
            ) {
                continue;
            }
            for k in 0..12 {
                let tf = b.t_min
                    * (1.0
                        + [
                            1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 0.01, 0.03, 0.1, 0.3, 1.0, 2.0, 5.0,
                        ][k]);
                let s2 = Step2::new(tf, p.p[0], p.v[0], p.a[0], p.pf, p.vf, p.af, j_max);
                let l = Lim {
                    v_max: lim.v_max,
                    v_min: lim.v_min,
                    a_max: lim.a_max,
                    a_min: lim.a_min,
                    j: lim.j_max,
                };
                for m in [l, l.flip()] {
                    let mut q = p;
                    if s2.vel_uddu(&mut q, &m) {
                        found += 1;
                        assert!(s2.vel_uddu_admissible(&m), "UDDU {c:?} {lim:?} tf {tf}");
                    } else if !s2.vel_uddu_admissible(&m) {
                        skipped += 1;
                    }
                    let mut q = p;
                    if s2.vel_udud(&mut q, &m) {
                        found += 1;
                        assert!(s2.vel_udud_admissible(&m), "UDUD {c:?} {lim:?} tf {tf}");
                    } else if !s2.vel_udud_admissible(&m) {
                        skipped += 1;
                    }
                }
            }
        }
        // The sweep exercises both outcomes.
        assert!(found > 10_000 && skipped > 10_000, "{found} {skipped}");
    }
}
