//! Step 2, third-order position interface: a profile of one DoF with a
//! prescribed duration `tf` (time synchronisation, Berscheid & Kröger 2021,
//! §IV-C). Shapes with a velocity plateau are here; those without one are
//! in `position_step2_flat.rs`.

use crate::position_step1::Lim;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, NEWTON_TOL, for_roots};

/// Boundary values, the duration and their powers.
#[derive(Clone, Copy)]
pub(crate) struct Step2 {
    pub(crate) tf: f64,
    pub(crate) tf_2: f64,
    pub(crate) tf_3: f64,
    pub(crate) pd: f64,
    pub(crate) v0: f64,
    pub(crate) vf: f64,
    pub(crate) vd: f64,
    pub(crate) vd_2: f64,
    pub(crate) vf_2: f64,
    pub(crate) a0: f64,
    pub(crate) af: f64,
    pub(crate) ad: f64,
    pub(crate) ad_2: f64,
    pub(crate) a0_2: f64,
    pub(crate) a0_3: f64,
    pub(crate) a0_4: f64,
    pub(crate) a0_5: f64,
    pub(crate) a0_6: f64,
    pub(crate) af_2: f64,
    pub(crate) af_3: f64,
    pub(crate) af_4: f64,
    pub(crate) af_5: f64,
    pub(crate) af_6: f64,
    pub(crate) jj: f64,
    /// `-pd + tf·v0`
    pub(crate) g1: f64,
    /// `-2·pd + tf·(v0 + vf)`
    pub(crate) g2: f64,
}

impl Step2 {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        tf: f64,
        p0: f64,
        v0: f64,
        a0: f64,
        pf: f64,
        vf: f64,
        af: f64,
        j_max: f64,
    ) -> Self {
        let pd = pf - p0;
        let tf_2 = tf * tf;
        let vd = vf - v0;
        let ad = af - a0;
        let (a0_2, af_2) = (a0 * a0, af * af);
        let (a0_3, af_3) = (a0 * a0_2, af * af_2);
        let (a0_4, af_4) = (a0_2 * a0_2, af_2 * af_2);
        Self {
            tf,
            tf_2,
            tf_3: tf_2 * tf,
            pd,
            v0,
            vf,
            vd,
            vd_2: vd * vd,
            vf_2: vf * vf,
            a0,
            af,
            ad,
            ad_2: ad * ad,
            a0_2,
            a0_3,
            a0_4,
            a0_5: a0_3 * a0_2,
            a0_6: a0_4 * a0_2,
            af_2,
            af_3,
            af_4,
            af_5: af_3 * af_2,
            af_6: af_4 * af_2,
            jj: j_max * j_max,
            g1: -pd + tf * v0,
            g2: -2.0 * pd + tf * (v0 + vf),
        }
    }

    #[inline]
    pub(crate) fn chk(p: &mut Profile, s: S, l: L, m: &Lim) -> bool {
        p.check(s, l, false, m.j, m.v_max, m.v_min, m.a_max, m.a_min)
    }

    /// Fills `p` with a profile of duration `tf`; `false` if none exists.
    pub(crate) fn profile(&self, p: &mut Profile, lim: &Lim) -> bool {
        // Guess the likely direction first.
        let up_first = self.pd > self.tf * self.v0;
        let (m, n) = if up_first {
            (*lim, lim.flip())
        } else {
            (lim.flip(), *lim)
        };
        self.acc0_acc1_vel(p, &m)
            || self.vel(p, &m)
            || self.acc0_vel(p, &m)
            || self.acc1_vel(p, &m)
            || self.acc0_acc1_vel(p, &n)
            || self.vel(p, &n)
            || self.acc0_vel(p, &n)
            || self.acc1_vel(p, &n)
            || self.acc0_acc1(p, &m)
            || self.acc0(p, &m)
            || self.acc1(p, &m)
            || self.none(p, &m)
            || self.acc0_acc1(p, &n)
            || self.acc0(p, &n)
            || self.acc1(p, &n)
            || self.none(p, &n)
    }

    fn acc0_acc1_vel(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            pd,
            vf,
            vd,
            vd_2,
            a0,
            af,
            ad,
            a0_2,
            a0_3,
            a0_4,
            af_2,
            af_3,
            af_4,
            jj,
            g1,
            ..
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);

        if (2.0 * (amax - amin) + ad) / j < tf {
            let h1 = ((a0_4 + af_4
                - 4.0 * a0_3 * (2.0 * amax + amin) / 3.0
                - 4.0 * af_3 * (amax + 2.0 * amin) / 3.0
                + 2.0 * (a0_2 - af_2) * amax * amax
                + (4.0 * a0 * amax - 2.0 * a0_2)
                    * (af_2 - 2.0 * af * amin
                        + (amin - amax) * amin
                        + 2.0 * j * (amin * tf - vd))
                + 2.0 * af_2 * (amin * amin + 2.0 * j * (amax * tf - vd))
                + 4.0
                    * j
                    * (2.0 * amin * (af * vd + j * g1)
                        + (amax * amax - amin * amin) * vd
                        + j * vd_2)
                + 8.0 * amax * jj * (pd - tf * vf))
                / (amax * amin)
                + 4.0 * af_2
                + 2.0 * a0_2
                + (4.0 * af + amax - amin) * (amax - amin)
                + 4.0 * j * (amin - amax + j * tf - 2.0 * af) * tf)
                .sqrt()
                * j.abs()
                / j;
            p.t[0] = (-a0 + amax) / j;
            p.t[1] = (-(af_2 - a0_2
                + 2.0 * amax * amax
                + amin * (amin - 2.0 * ad - 3.0 * amax)
                + 2.0 * j * (amin * tf - vd))
                + amin * h1)
                / (2.0 * (amax - amin) * j);
            p.t[2] = amax / j;
            p.t[3] = (amin - amax + h1) / (2.0 * j);
            p.t[4] = -amin / j;
            p.t[5] = tf - (p.t[0] + p.t[1] + p.t[2] + p.t[3] + 2.0 * p.t[4] + af / j);
            p.t[6] = p.t[4] + af / j;
            if Self::chk(p, S::Uddu, L::Acc0Acc1Vel, m) {
                return true;
            }
        }

        if (-a0 + 4.0 * amax - af) / j < tf {
            p.t[0] = (-a0 + amax) / j;
            p.t[1] = (3.0 * (a0_4 + af_4) - 4.0 * (a0_3 + af_3) * amax - 4.0 * af_3 * amax
                + 24.0 * (a0 + af) * amax * amax * amax
                - 6.0 * (af_2 + a0_2) * (amax * amax - 2.0 * j * vd)
                + 6.0 * a0_2 * (af_2 - 2.0 * af * amax - 2.0 * amax * j * tf)
                - 12.0 * amax * amax * (2.0 * amax * amax - 2.0 * amax * j * tf + j * vd)
                - 24.0 * af * amax * j * vd
                + 12.0 * jj * (2.0 * amax * g1 + vd_2))
                / (12.0
                    * amax
                    * j
                    * (a0_2 + af_2 - 2.0 * (a0 + af) * amax
                        + 2.0 * (amax * amax - amax * j * tf + j * vd)));
            p.t[2] = amax / j;
            p.t[3] = (-a0_2 - af_2 + 2.0 * amax * (a0 + af - 2.0 * amax) - 2.0 * j * vd)
                / (2.0 * amax * j)
                + tf;
            p.t[4] = p.t[2];
            p.t[5] = tf - (p.t[0] + p.t[1] + p.t[2] + p.t[3] + 2.0 * p.t[4] - af / j);
            p.t[6] = p.t[4] - af / j;
            if Self::chk(p, S::Udud, L::Acc0Acc1Vel, m) {
                return true;
            }
        }
        false
    }

    fn acc1_vel(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
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
            af_2,
            af_3,
            af_4,
            jj,
            g1,
            ..
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);

        // UDDU
        {
            let ph1 = a0_2 + af_2 - amin * (a0 + 2.0 * af - amin) - 2.0 * j * (vd - amin * tf);
            let ph2 = 2.0 * amin * (j * g1 + af * vd) - amin * amin * vd + j * vd_2;
            let ph3 = af_2 + amin * (amin - 2.0 * af) - 2.0 * j * (vd - amin * tf);
            let poly = [
                (2.0 * (2.0 * a0 - amin)) / j,
                (4.0 * a0_2 + ph1 - 3.0 * a0 * amin) / jj,
                (2.0 * a0 * ph1) / (jj * j),
                (3.0 * (a0_4 + af_4) - 4.0 * (a0_3 + 2.0 * af_3) * amin
                    + 6.0 * af_2 * (amin * amin - 2.0 * j * vd)
                    + 12.0 * j * ph2
                    + 6.0 * a0_2 * ph3)
                    / (12.0 * jj * jj),
            ];
            let t_min = -a0 / j;
            let t_max = ((tf + 2.0 * amin / j - (a0 + af) / j) / 2.0).min((amax - a0) / j);
            for_roots!(roots::quartic(&poly), |t| {
                if t < t_min || t > t_max {
                    continue;
                }
                if (a0 + j * t).abs() > 16.0 * EPS {
                    let h0 = j * t * t;
                    let orig = -pd
                        + (3.0 * (a0_4 + af_4) - 8.0 * af_3 * amin - 4.0 * a0_3 * amin
                            + 6.0 * af_2 * (amin * amin + 2.0 * j * (h0 - vd))
                            + 6.0
                                * a0_2
                                * (af_2 - 2.0 * af * amin
                                    + amin * amin
                                    + 2.0 * amin * j * (-2.0 * t + tf)
                                    + 2.0 * j * (5.0 * h0 - vd))
                            + 24.0
                                * a0
                                * j
                                * t
                                * (a0_2 + af_2 - 2.0 * af * amin
                                    + amin * amin
                                    + 2.0 * j * (amin * (-t + tf) + h0 - vd))
                            - 24.0 * af * amin * j * (h0 - vd)
                            + 12.0 * j * (amin * amin * (h0 - vd) + j * (h0 - vd) * (h0 - vd)))
                            / (24.0 * amin * jj)
                        + h0 * (tf - t)
                        + tf * v0;
                    let deriv = (a0 + j * t)
                        * ((a0_2 + af_2) / (amin * j)
                            + (amin - a0 - 2.0 * af) / j
                            + (4.0 * a0 * t + 2.0 * h0 - 2.0 * vd) / amin
                            + 2.0 * tf
                            - 3.0 * t);
                    t -= orig / deriv;
                }
                let h1 = -((a0_2 + af_2) / 2.0 + j * (-vd + 2.0 * a0 * t + j * t * t)) / amin;
                p.t[0] = t;
                p.t[1] = 0.0;
                p.t[2] = a0 / j + t;
                p.t[3] = tf - (h1 - amin + a0 + af) / j - 2.0 * t;
                p.t[4] = -amin / j;
                p.t[5] = (h1 + amin) / j;
                p.t[6] = p.t[4] + af / j;
                if Self::chk(p, S::Uddu, L::Acc1Vel, m) {
                    return true;
                }
            });
        }

        // UDUD
        {
            let ph1 =
                a0_2 - af_2 + (2.0 * af - a0) * amax - amax * amax - 2.0 * j * (vd - amax * tf);
            let ph2 = amax * amax + 2.0 * j * vd;
            let ph3 = af_2 + ph2 - 2.0 * amax * (af + j * tf);
            let ph4 = 2.0 * amax * j * g1 + amax * amax * vd + j * vd_2;
            let poly = [
                (4.0 * a0 - 2.0 * amax) / j,
                (4.0 * a0_2 - 3.0 * a0 * amax + ph1) / jj,
                (2.0 * a0 * ph1) / (jj * j),
                (3.0 * (a0_4 + af_4)
                    - 4.0 * (a0_3 + 2.0 * af_3) * amax
                    - 24.0 * af * amax * j * vd
                    + 12.0 * j * ph4
                    - 6.0 * a0_2 * ph3
                    + 6.0 * af_2 * ph2)
                    / (12.0 * jj * jj),
            ];
            let t_min = -a0 / j;
            let t_max = ((tf + ad / j - 2.0 * amax / j) / 2.0).min((amax - a0) / j);
            for_roots!(roots::quartic(&poly), |t| {
                if t > t_max || t < t_min {
                    continue;
                }
                let h1 = ((a0_2 - af_2) / 2.0 + jj * t * t - j * (vd - 2.0 * a0 * t)) / amax;
                p.t[0] = t;
                p.t[1] = 0.0;
                p.t[2] = t + a0 / j;
                p.t[3] = tf + (h1 + ad - amax) / j - 2.0 * t;
                p.t[4] = amax / j;
                p.t[5] = -(h1 + amax) / j;
                p.t[6] = p.t[4] - af / j;
                if Self::chk(p, S::Udud, L::Acc1Vel, m) {
                    return true;
                }
            });
        }
        false
    }

    fn acc0_vel(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            pd,
            vf,
            vd,
            vd_2,
            a0,
            af,
            ad,
            a0_2,
            a0_3,
            a0_4,
            af_2,
            af_3,
            af_4,
            jj,
            ..
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);

        if tf < ((-a0 + amax) / j).max(0.0) + (amax / j).max(0.0) {
            return false;
        }
        let ph1 = 12.0 * j * (-amax * amax * vd - j * vd_2 + 2.0 * amax * j * (-pd + tf * vf));

        // UDDU
        {
            let poly = [
                (2.0 * amax) / j,
                (a0_2 - af_2 + 2.0 * ad * amax + amax * amax + 2.0 * j * (vd - amax * tf)) / jj,
                0.0,
                -(-3.0 * (a0_4 + af_4) + 4.0 * (af_3 + 2.0 * a0_3) * amax
                    - 12.0 * a0 * amax * (af_2 - 2.0 * j * vd)
                    + 6.0 * a0_2 * (af_2 - amax * amax - 2.0 * j * vd)
                    + 6.0 * af_2 * (amax * amax - 2.0 * amax * j * tf + 2.0 * j * vd)
                    + ph1)
                    / (12.0 * jj * jj),
            ];
            let t_min = -af / j;
            let t_max = (tf - (2.0 * amax - a0) / j).min(-amin / j);
            for_roots!(roots::quartic(&poly), |t| {
                if t < t_min || t > t_max {
                    continue;
                }
                if t > EPS {
                    let h1 = j * t * t + vd;
                    let orig = (-3.0 * (a0_4 + af_4) + 4.0 * (af_3 + 2.0 * a0_3) * amax
                        - 24.0 * af * amax * jj * t * t
                        - 12.0 * a0 * amax * (af_2 - 2.0 * j * h1)
                        + 6.0 * a0_2 * (af_2 - amax * amax - 2.0 * j * h1)
                        + 6.0 * af_2 * (amax * amax - 2.0 * amax * j * tf + 2.0 * j * h1)
                        - 12.0
                            * j
                            * (amax * amax * h1
                                + j * h1 * h1
                                + 2.0 * amax * j * (pd + j * t * t * (t - tf) - tf * vf)))
                        / (24.0 * amax * jj);
                    let deriv = -t
                        * (a0_2 - af_2
                            + 2.0 * amax * (ad - j * tf)
                            + amax * amax
                            + 3.0 * amax * j * t
                            + 2.0 * j * h1)
                        / amax;
                    t -= orig / deriv;
                }
                let h1 = ((a0_2 - af_2) / 2.0 + j * (j * t * t + vd)) / amax;
                p.t[0] = (-a0 + amax) / j;
                p.t[1] = (h1 - amax) / j;
                p.t[2] = amax / j;
                p.t[3] = tf - (h1 + ad + amax) / j - 2.0 * t;
                p.t[4] = t;
                p.t[5] = 0.0;
                p.t[6] = af / j + t;
                if Self::chk(p, S::Uddu, L::Acc0Vel, m) {
                    return true;
                }
            });
        }

        // UDUD
        {
            let poly = [
                (-2.0 * amax) / j,
                -(a0_2 + af_2 - 2.0 * (a0 + af) * amax + amax * amax + 2.0 * j * (vd - amax * tf))
                    / jj,
                0.0,
                (3.0 * (a0_4 + af_4) - 4.0 * (af_3 + 2.0 * a0_3) * amax
                    + 6.0 * a0_2 * (af_2 + amax * amax + 2.0 * j * vd)
                    - 12.0 * a0 * amax * (af_2 + 2.0 * j * vd)
                    + 6.0 * af_2 * (amax * amax - 2.0 * amax * j * tf + 2.0 * j * vd)
                    - ph1)
                    / (12.0 * jj * jj),
            ];
            let t_min = af / j;
            let t_max = (tf - amax / j).min(amax / j);
            for_roots!(roots::quartic(&poly), |t| {
                if t < t_min || t > t_max {
                    continue;
                }
                {
                    let h1 = j * t * t - vd;
                    let orig = -(3.0 * (a0_4 + af_4) - 4.0 * (2.0 * a0_3 + af_3) * amax
                        + 24.0 * af * amax * jj * t * t
                        - 12.0 * a0 * amax * (af_2 - 2.0 * j * h1)
                        + 6.0 * a0_2 * (af_2 + amax * amax - 2.0 * j * h1)
                        + 6.0 * af_2 * (amax * amax - 2.0 * j * (tf * amax + h1))
                        + 12.0
                            * j
                            * (-amax * amax * h1 + j * h1 * h1
                                - 2.0 * amax * j * (-pd + j * t * t * (t - tf) + tf * vf)))
                        / (24.0 * amax * jj);
                    let deriv = t
                        * (a0_2 + af_2 - 2.0 * j * h1 - 2.0 * (a0 + af + j * tf) * amax
                            + amax * amax
                            + 3.0 * amax * j * t)
                        / amax;
                    t -= orig / deriv;
                }
                let h1 = ((a0_2 + af_2) / 2.0 + j * (vd - j * t * t)) / amax;
                p.t[0] = (-a0 + amax) / j;
                p.t[1] = (h1 - amax) / j;
                p.t[2] = amax / j;
                p.t[3] = tf - (h1 - a0 - af + amax) / j - 2.0 * t;
                p.t[4] = t;
                p.t[5] = 0.0;
                p.t[6] = -(af / j) + t;
                if Self::chk(p, S::Udud, L::Acc0Vel, m) {
                    return true;
                }
            });
        }
        false
    }

    fn vel(&self, p: &mut Profile, m: &Lim) -> bool {
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
