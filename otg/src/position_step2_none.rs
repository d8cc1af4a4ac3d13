//! Step 2 shapes that reach no limit (NONE), including reduced-jerk
//! profiles and the three-phase shapes that the general solutions miss
//! numerically.

use crate::limits::Lim;
use crate::position_step2::Step2;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, for_roots};

#[inline]
fn sq(x: f64) -> f64 {
    x * x
}

impl Step2 {
    #[inline]
    fn chk_free_jerk(p: &mut Profile, jf: f64, m: &Lim) -> bool {
        p.check_jerk(
            S::Uddu,
            L::None,
            jf,
            m.v_max,
            m.v_min,
            m.a_max,
            m.a_min,
            m.j,
        )
    }

    pub(crate) fn none(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
            tf_3,
            pd,
            v0,
            vf,
            vd,
            vd_2,
            vf_2,
            a0,
            af,
            ad,
            ad_2,
            a0_2,
            a0_3,
            a0_4,
            a0_5,
            a0_6,
            af_2,
            af_3,
            af_4,
            af_5,
            af_6,
            jj,
            g1,
            g2,
            ..
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);
        let tf_4 = tf_2 * tf_2;

        if v0.abs() < EPS && a0.abs() < EPS && af.abs() < EPS {
            let h1 = (tf_2 * vf_2 + sq(4.0 * pd - tf * vf)).sqrt();
            let jf = 4.0 * (4.0 * pd - 2.0 * tf * vf + h1) / tf_3;
            p.t = [tf / 4.0, 0.0, tf / 2.0, 0.0, 0.0, 0.0, tf / 4.0];
            if Self::chk_free_jerk(p, jf, m) {
                return true;
            }
        }

        if a0.abs() < EPS && af.abs() < EPS {
            // a3 != 0, UDDU: first accelerate, then constant.
            let poly = [
                -2.0 * tf,
                2.0 * vd / j + tf_2,
                4.0 * (pd - tf * vf) / j,
                (vd_2 + j * tf * g2) / jj,
            ];
            for_roots!(roots::quartic(&poly), |t| {
                if t > tf / 2.0 || t > (amax - a0) / j {
                    continue;
                }
                {
                    let h1 = (j * t * (t - tf) + vd) / (j * (2.0 * t - tf));
                    let h2 = (2.0 * j * t * (t - tf) + j * tf_2 - 2.0 * vd)
                        / (j * (2.0 * t - tf) * (2.0 * t - tf));
                    let orig = (-2.0 * pd
                        + 2.0 * tf * v0
                        + h1 * h1 * j * (tf - 2.0 * t)
                        + j * tf * (2.0 * h1 * t - t * t - (h1 - t) * tf))
                        / 2.0;
                    let deriv = (j * tf * (2.0 * t - tf) * (h2 - 1.0)) / 2.0
                        + h1 * j * (tf - (2.0 * t - tf) * h2 - h1);
                    t -= orig / deriv;
                }
                let t2 = (j * t * (t - tf) + vd) / (j * (2.0 * t - tf));
                p.t = [t, 0.0, t2, tf - 2.0 * t, t - t2, 0.0, 0.0];
                if Self::chk(p, S::Uddu, L::None, m) {
                    return true;
                }
            });
        }

        // UDUD, phases 0 2 4 6
        {
            let h0 = (2.0
                * jj
                * (2.0
                    * sq(a0_3 - af_3 - 3.0 * af_2 * j * tf + 9.0 * af * jj * tf_2
                        - 3.0 * a0_2 * (af + j * tf)
                        + 3.0 * a0 * sq(af + j * tf)
                        + 3.0 * jj * (8.0 * pd + j * tf_2 * tf - 8.0 * tf * vf))
                    - 3.0
                        * (a0_2 + af_2
                            - 2.0 * af * j * tf
                            - 2.0 * a0 * (af + j * tf)
                            - j * (j * tf_2 + 4.0 * v0 - 4.0 * vf))
                        * (a0_4 + af_4 + 4.0 * af_3 * j * tf + 6.0 * af_2 * jj * tf_2
                            - 3.0 * jj * jj * tf_2 * tf_2
                            - 4.0 * a0_3 * (af + j * tf)
                            + 6.0 * a0_2 * sq(af + j * tf)
                            - 12.0 * af * jj * (8.0 * pd + j * tf_2 * tf - 8.0 * tf * v0)
                            + 48.0 * jj * vd_2
                            + 48.0 * jj * j * tf * g2
                            - 4.0
                                * a0
                                * (af_3 + 3.0 * af_2 * j * tf
                                    - 9.0 * af * jj * tf_2
                                    - 3.0 * jj * (8.0 * pd + j * tf_2 * tf - 8.0 * tf * vf)))))
                .sqrt()
                / j;
            let h1 = 12.0
                * j
                * (-a0_2 - af_2
                    + 2.0 * af * j * tf
                    + 2.0 * a0 * (af + j * tf)
                    + j * (j * tf_2 + 4.0 * v0 - 4.0 * vf));
            let h2 = -4.0 * a0_3 + 4.0 * af_3 + 12.0 * a0_2 * af - 12.0 * a0 * af_2
                + 48.0 * jj * pd
                + 12.0 * (a0_2 - af_2) * j * tf
                - 24.0 * jj * tf * (v0 + vf)
                + 24.0 * ad * j * vd;
            let h3 = 2.0 * a0_3 - 2.0 * af_3 - 6.0 * a0_2 * af + 6.0 * a0 * af_2;
            p.t[0] = (h3 - 48.0 * jj * (tf * vf - pd) - 6.0 * (a0_2 + af_2) * j * tf
                + 12.0 * a0 * af * j * tf
                + 6.0 * (a0 + 3.0 * af + j * tf) * tf_2 * jj
                - h0)
                / h1;
            p.t[1] = 0.0;
            p.t[2] = (h2 + h0) / h1;
            p.t[3] = 0.0;
            p.t[4] = (-h2 + h0) / h1;
            p.t[5] = 0.0;
            p.t[6] = (-h3 + 48.0 * jj * (tf * v0 - pd) - 6.0 * (a0_2 + af_2) * j * tf
                + 12.0 * a0 * af * j * tf
                + 6.0 * (af + 3.0 * a0 + j * tf) * tf_2 * jj
                - h0)
                / h1;
            if Self::chk(p, S::Udud, L::None, m) {
                return true;
            }
        }

        // a3 != 0, UDDU, phases 0 2 3 4
        {
            let ph1 = af + j * tf;
            let poly = [
                -2.0 * (ad + j * tf) / j,
                2.0 * (a0_2 + af_2 + j * (af * tf + vd) - 2.0 * a0 * ph1) / jj + tf_2,
                2.0 * (a0_3 - af_3 - 3.0 * af_2 * j * tf + 3.0 * a0 * ph1 * (ph1 - a0)
                    - 6.0 * jj * (-pd + tf * vf))
                    / (3.0 * jj * j),
                (a0_4 + af_4 + 4.0 * af_3 * j * tf - 4.0 * a0_3 * ph1
                    + 6.0 * a0_2 * ph1 * ph1
                    + 24.0 * jj * af * g1
                    - 4.0 * a0 * (af_3 + 3.0 * af_2 * j * tf + 6.0 * jj * (-pd + tf * vf))
                    + 6.0 * jj * af_2 * tf_2
                    + 12.0 * jj * (vd_2 + j * tf * g2))
                    / (12.0 * jj * jj),
            ];
            let t_min = ad / j;
            let t_max = ((amax - a0) / j).min((ad / j + tf) / 2.0);
            for_roots!(roots::quartic_in(&poly, t_min, t_max), |t| {
                if t < t_min || t > t_max {
                    continue;
                }
                {
                    let h0 = j * (2.0 * t - tf) - ad;
                    let h1 = (ad_2 - 2.0 * af * j * t
                        + 2.0 * a0 * j * (t - tf)
                        + 2.0 * j * (j * t * (t - tf) + vd))
                        / (2.0 * j * h0);
                    let h2 = (-ad_2 + 2.0 * jj * (tf_2 + t * (t - tf)) + (a0 + af) * j * tf
                        - ad * h0
                        - 2.0 * j * vd)
                        / (h0 * h0);
                    let orig = (-a0_3
                        + af_3
                        + 3.0 * ad_2 * j * (h1 - t)
                        + 3.0 * ad * jj * (h1 - t) * (h1 - t)
                        - 3.0 * a0 * af * ad
                        + 3.0
                            * jj
                            * (a0 * tf_2 - 2.0 * pd
                                + 2.0 * tf * v0
                                + h1 * h1 * j * (tf - 2.0 * t)
                                + j * tf * (2.0 * h1 * t - t * t - (h1 - t) * tf)))
                        / (6.0 * jj);
                    let deriv = (h0 * (-ad + j * tf) * (h2 - 1.0)) / (2.0 * j)
                        + h1 * (-ad + j * (tf - h1) - h0 * h2);
                    t -= orig / deriv;
                }
                p.t[0] = t;
                p.t[1] = 0.0;
                p.t[2] = (ad_2 + 2.0 * j * (-a0 * tf - ad * t + j * t * (t - tf) + vd))
                    / (2.0 * j * (-ad + j * (2.0 * t - tf)));
                p.t[3] = ad / j + tf - 2.0 * t;
                p.t[4] = tf - (t + p.t[2] + p.t[3]);
                p.t[5] = 0.0;
                p.t[6] = 0.0;
                if Self::chk(p, S::Uddu, L::None, m) {
                    return true;
                }
            });
        }

        // a3 != 0, UDDU, phases 3 4 5 6
        {
            let h1 = 3.0 * j * (ad_2 + 2.0 * j * (a0 * tf - vd));
            let h2 = ad_2 + 2.0 * j * (a0 * tf - vd);
            let h0 = (4.0
                * sq(2.0 * (a0_3 - af_3) - 6.0 * a0_2 * (af - j * tf)
                    + 6.0 * jj * g1
                    + 3.0 * a0 * (2.0 * af_2 - 2.0 * j * af * tf + jj * tf_2)
                    + 6.0 * ad * j * vd)
                - 18.0 * h2 * h2 * h2)
                .sqrt()
                / h1
                * j.abs()
                / j;
            p.t[0] = 0.0;
            p.t[1] = 0.0;
            p.t[2] = 0.0;
            p.t[3] = (af_3 - a0_3 + 3.0 * (af_2 - a0_2) * j * tf
                - 3.0 * ad * (a0 * af + 2.0 * j * vd)
                - 6.0 * jj * g2)
                / h1;
            p.t[4] = (tf - p.t[3] - h0) / 2.0 - ad / (2.0 * j);
            p.t[5] = h0;
            p.t[6] = (tf - p.t[3] + ad / j - h0) / 2.0;
            if Self::chk(p, S::Uddu, L::None, m) {
                return true;
            }
        }

        // a3 != 0, UDDU, phases 2 3 4 6
        {
            let ph1 = ad_2 + 2.0 * (af + a0) * j * tf - j * (j * tf_2 + 4.0 * vd);
            let ph2 = j * tf_2 * g1 - vd * (-2.0 * pd - tf * v0 + 3.0 * tf * vf);
            let ph3 = 5.0 * af_2 - 8.0 * af * j * tf + 2.0 * j * (2.0 * j * tf_2 - vd);
            let ph4 = jj * tf_4 - 2.0 * vd_2 + 8.0 * j * tf * (-pd + tf * vf);
            let ph5 = 5.0 * af_4 - 8.0 * af_3 * j * tf - 12.0 * af_2 * j * (j * tf_2 + vd)
                + 24.0 * af * jj * (-2.0 * pd + j * tf_3 + 2.0 * tf * vf)
                - 6.0 * jj * ph4;
            let ph6 = -vd_2 + j * tf * (-2.0 * pd + 3.0 * tf * v0 - tf * vf) - af * g2;
            let c2 = 5.0 * af_3 - 9.0 * af_2 * j * tf - 6.0 * af * j * vd
                + 6.0 * jj * (-2.0 * pd - tf * v0 + 3.0 * tf * vf);
            let poly = [
                -(4.0 * (a0_3 - af_3) - 12.0 * a0_2 * (af - j * tf)
                    + 6.0 * a0 * (2.0 * af_2 - 2.0 * af * j * tf + j * (j * tf_2 - 2.0 * vd))
                    + 6.0 * af * j * (3.0 * j * tf_2 + 2.0 * vd)
                    - 6.0 * jj * (-4.0 * pd + j * tf_3 - 2.0 * tf * v0 + 6.0 * tf * vf))
                    / (3.0 * j * ph1),
                -(-a0_4 - af_4
                    + 4.0 * a0_3 * (af - j * tf)
                    + a0_2 * (-6.0 * af_2 + 8.0 * af * j * tf - 4.0 * j * (j * tf_2 - vd))
                    + 2.0 * af_2 * j * (j * tf_2 + 2.0 * vd)
                    - 4.0 * af * jj * (-3.0 * pd + j * tf_3 + 2.0 * tf * v0 + tf * vf)
                    + jj * (jj * tf_4 - 8.0 * vd_2
                        + 4.0 * j * tf * (-3.0 * pd + tf * v0 + 2.0 * tf * vf))
                    + 2.0
                        * a0
                        * (2.0 * af_3 - 2.0 * af_2 * j * tf
                            + af * j * (-3.0 * j * tf_2 - 4.0 * vd)
                            + jj * (-6.0 * pd + j * tf_3 - 4.0 * tf * v0 + 10.0 * tf * vf)))
                    / (jj * ph1),
                -(a0_5 - af_5 + af_4 * j * tf - 5.0 * a0_4 * (af - j * tf)
                    + 2.0 * a0_3 * ph3
                    + 4.0 * af_3 * j * (j * tf_2 + vd)
                    + 12.0 * jj * af * ph6
                    - 2.0 * a0_2 * c2
                    - 12.0 * jj * j * ph2
                    + a0 * ph5)
                    / (3.0 * jj * j * ph1),
                -(-a0_6 - af_6 + 6.0 * a0_5 * (af - j * tf) - 48.0 * af_3 * jj * g1
                    + 72.0 * jj * j * (j * g1 * g1 + vd_2 * vd + 2.0 * af * g1 * vd)
                    - 3.0 * a0_4 * ph3
                    - 36.0 * af_2 * jj * vd_2
                    + 6.0 * af_4 * j * vd
                    + 4.0 * a0_3 * c2
                    - 3.0 * a0_2 * ph5
                    + 6.0
                        * a0
                        * (af_5 - af_4 * j * tf - 4.0 * af_3 * j * (j * tf_2 + vd)
                            + 12.0 * jj * (-af * ph6 + j * ph2)))
                    / (18.0 * jj * jj * ph1),
            ];
            let t_max = (a0 - amin) / j;
            for_roots!(roots::quartic(&poly), |t| {
                if t > t_max {
                    continue;
                }
                {
                    let h1 = ad_2 / 2.0 + j * (af * t + (j * t - a0) * (t - tf) - vd);
                    let h2 = -ad + j * (tf - 2.0 * t);
                    let h3 = h1.sqrt();
                    let orig =
                        (af_3 - a0_3 + 3.0 * af * j * t * (af + j * t) + 3.0 * a0_2 * (af + j * t)
                            - 3.0 * a0 * (af_2 + 2.0 * af * j * t + jj * (t * t - tf_2))
                            + 3.0 * jj * (-2.0 * pd + j * t * (t - tf) * tf + 2.0 * tf * v0))
                            / (6.0 * jj)
                            - h3 * h3 * h3 / (j * j.abs())
                            + ((-ad - j * t) * h1) / jj;
                    let deriv = (6.0 * j * h2 * h3 / j.abs() + 2.0 * (-ad - j * tf) * h2
                        - 2.0
                            * (3.0 * ad_2
                                + af * j * (8.0 * t - 2.0 * tf)
                                + 4.0 * a0 * j * (-2.0 * t + tf)
                                + 2.0 * j * (j * t * (3.0 * t - 2.0 * tf) - vd)))
                        / (4.0 * j);
                    t -= orig / deriv;
                }
                let h1 = (2.0 * ad_2 + 4.0 * j * (ad * t + a0 * tf + j * t * (t - tf) - vd)).sqrt()
                    / j.abs();
                p.t[0] = 0.0;
                p.t[1] = 0.0;
                p.t[2] = t;
                p.t[3] = tf - 2.0 * t - ad / j - h1;
                p.t[4] = h1 / 2.0;
                p.t[5] = 0.0;
                p.t[6] = tf - (t + p.t[3] + p.t[4]);
                if Self::chk(p, S::Uddu, L::None, m) {
                    return true;
                }
            });
        }

        // a3 != 0, UDUD, phases 0 1 2 4
        {
            let ph0 = -2.0 * pd - tf * v0 + 3.0 * tf * vf;
            let ph1 = -ad + j * tf;
            let ph2 = j * tf_2 * g1 - vd * ph0;
            let ph3 = 5.0 * af_2 + 2.0 * j * (2.0 * j * tf_2 - vd - 4.0 * af * tf);
            let ph4 = jj * tf_4 - 2.0 * vd_2 + 8.0 * j * tf * (-pd + tf * vf);
            let ph5 = 5.0 * af_4 - 8.0 * af_3 * j * tf - 12.0 * af_2 * j * (j * tf_2 + vd)
                + 24.0 * af * jj * (-2.0 * pd + j * tf_3 + 2.0 * tf * vf)
                - 6.0 * jj * ph4;
            let ph6 = -vd_2 + j * tf * (-2.0 * pd + 3.0 * tf * v0 - tf * vf);
            let ph7 = 3.0 * jj * ph1 * ph1;
            let c2 = 5.0 * af_3 - 9.0 * af_2 * j * tf - 6.0 * af * j * vd + 6.0 * jj * ph0;
            let poly = [
                (4.0 * af * tf - 2.0 * j * tf_2 - 4.0 * vd) / ph1,
                (-2.0 * (a0_4 + af_4)
                    + 8.0 * af_3 * j * tf
                    + 6.0 * af_2 * jj * tf_2
                    + 8.0 * a0_3 * (af - j * tf)
                    - 12.0 * a0_2 * (af - j * tf) * (af - j * tf)
                    - 12.0 * af * jj * (-pd + j * tf_3 - 2.0 * tf * v0 + 3.0 * tf * vf)
                    + 2.0
                        * a0
                        * (4.0 * af_3 - 12.0 * af_2 * j * tf + 9.0 * af * jj * tf_2
                            - 3.0 * jj * (2.0 * pd + j * tf_3 - 2.0 * tf * vf))
                    + 3.0
                        * jj
                        * (jj * tf_4 + 4.0 * vd_2 - 4.0 * j * tf * (pd + tf * v0 - 2.0 * tf * vf)))
                    / ph7,
                (-a0_5 + af_5 - af_4 * j * tf + 5.0 * a0_4 * (af - j * tf)
                    - 2.0 * a0_3 * ph3
                    - 4.0 * af_3 * j * (j * tf_2 + vd)
                    + 12.0 * af_2 * jj * g2
                    - 12.0 * af * jj * ph6
                    + 2.0 * a0_2 * c2
                    + 12.0 * jj * j * ph2
                    + a0 * (-5.0 * af_4 + 8.0 * af_3 * j * tf + 12.0 * af_2 * j * (j * tf_2 + vd)
                        - 24.0 * af * jj * (-2.0 * pd + j * tf_3 + 2.0 * tf * vf)
                        + 6.0 * jj * ph4))
                    / (j * ph7),
                -(a0_6 + af_6 - 6.0 * a0_5 * (af - j * tf) + 48.0 * af_3 * jj * g1
                    - 72.0 * jj * j * (j * g1 * g1 + vd_2 * vd + 2.0 * af * g1 * vd)
                    + 3.0 * a0_4 * ph3
                    - 6.0 * af_4 * j * vd
                    + 36.0 * af_2 * jj * vd_2
                    - 4.0 * a0_3 * c2
                    + 3.0 * a0_2 * ph5
                    - 6.0
                        * a0
                        * (af_5 - af_4 * j * tf - 4.0 * af_3 * j * (j * tf_2 + vd)
                            + 12.0 * jj * (af_2 * g2 - af * ph6 + j * ph2)))
                    / (6.0 * jj * ph7),
            ];
            for_roots!(roots::quartic(&poly), |t| {
                if t > tf || t > (amax - a0) / j {
                    continue;
                }
                let h1 =
                    (ad_2 / (2.0 * jj) + (a0 * (t + tf) - af * t + j * t * tf - vd) / j).sqrt();
                p.t = [
                    t,
                    tf - ad / j - 2.0 * h1,
                    h1,
                    0.0,
                    ad / j + h1 - t,
                    0.0,
                    0.0,
                ];
                if Self::chk(p, S::Udud, L::None, m) {
                    return true;
                }
            });
        }

        // Three phases (UZD), sometimes missed numerically.
        {
            let h1 = (-ad_2 + j * (2.0 * (a0 + af) * tf - 4.0 * vd + j * tf_2)).sqrt() / j.abs();
            p.t = [
                (tf - h1 + ad / j) / 2.0,
                h1,
                (tf - h1 - ad / j) / 2.0,
                0.0,
                0.0,
                0.0,
                0.0,
            ];
            if Self::chk(p, S::Uddu, L::None, m) {
                return true;
            }
        }

        // Three phases (UZU) with reduced jerk.
        {
            let c0 = ad_2;
            let c1 = ad_2 * tf;
            let c2 = (a0_2 + af_2 + 10.0 * a0 * af) * tf_2
                + 24.0 * (tf * (af * v0 - a0 * vf) - pd * ad)
                + 12.0 * vd_2;
            let c3 = -3.0
                * tf
                * ((a0_2 + af_2 + 2.0 * a0 * af) * tf_2 - 4.0 * vd * (a0 + af) * tf + 4.0 * vd_2);
            for_roots!(roots::cubic(c0, c1, c2, c3), |t| {
                if t > tf {
                    continue;
                }
                let jf = ad / (tf - t);
                p.t[0] = (2.0 * (vd - a0 * tf) + ad * (t - tf)) / (2.0 * jf * t);
                p.t[1] = t;
                p.t[2] = 0.0;
                p.t[3] = 0.0;
                p.t[4] = 0.0;
                p.t[5] = 0.0;
                p.t[6] = tf - (p.t[0] + p.t[1]);
                if Self::chk_free_jerk(p, jf, m) {
                    return true;
                }
            });
        }

        // Three phases (UDU).
        {
            p.t[0] =
                (ad_2 / j + 2.0 * (a0 + af) * tf - j * tf_2 - 4.0 * vd) / (4.0 * (ad - j * tf));
            p.t[1] = 0.0;
            p.t[2] = -ad / (2.0 * j) + tf / 2.0;
            p.t[3] = 0.0;
            p.t[4] = 0.0;
            p.t[5] = 0.0;
            p.t[6] = tf - (p.t[0] + p.t[2]);
            if Self::chk(p, S::Uddu, L::None, m) {
                return true;
            }
        }
        false
    }
}
