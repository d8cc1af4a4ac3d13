//! Step 2 shapes without a velocity plateau (ACC0_ACC1, ACC1, ACC0, NONE),
//! including profiles with a reduced jerk `jf < j_max` that stretch a short
//! motion to the synchronised duration.

use crate::limits::Lim;
use crate::position_step2::Step2;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::EPS;

#[inline]
fn sq(x: f64) -> f64 {
    x * x
}

impl Step2 {
    #[inline]
    fn chk_jerk(p: &mut Profile, s: S, l: L, jf: f64, m: &Lim) -> bool {
        p.check_jerk(s, l, jf, m.v_max, m.v_min, m.a_max, m.a_min, m.j)
    }

    pub(crate) fn acc0_acc1(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
            pd,
            v0,
            vf,
            vd,
            a0,
            af,
            ad,
            a0_2,
            a0_3,
            af_2,
            af_3,
            g1,
            g2,
            ..
        } = *self;
        let (amax, amin) = (m.a_max, m.a_min);

        if a0.abs() < EPS && af.abs() < EPS {
            let h1 = 2.0 * amin * g1 + vd * vd + amax * (2.0 * pd + amin * tf_2 - 2.0 * tf * vf);
            let h2 = (amax - amin) * (-amin * vd + amax * (amin * tf - vd));
            let jf = h2 / h1;
            p.t[0] = amax / jf;
            p.t[1] = (-2.0 * amax * h1 + amin * amin * g2) / h2;
            p.t[2] = p.t[0];
            p.t[3] = 0.0;
            p.t[4] = -amin / jf;
            p.t[5] = tf - (2.0 * p.t[0] + p.t[1] + 2.0 * p.t[4]);
            p.t[6] = p.t[4];
            return Self::chk_jerk(p, S::Uddu, L::Acc0Acc1, jf, m);
        }

        let den = 2.0 * amin * g1 + vd * vd + amax * (2.0 * pd + amin * tf * tf - 2.0 * tf * vf);
        let h1 = (144.0
            * sq(
                (amax - amin) * (-amin * vd + amax * (amin * tf - vd)) - af_2 * (amax * tf - vd)
                    + 2.0 * af * amin * (amax * tf - vd)
                    + a0_2 * (amin * tf + v0 - vf)
                    - 2.0 * a0 * amax * (amin * tf - vd),
            )
            + 48.0
                * ad
                * (3.0 * a0_3 - 3.0 * af_3
                    + 12.0 * amax * amin * (-amax + amin)
                    + 4.0 * af_2 * (amax + 2.0 * amin)
                    + a0 * (-3.0 * af_2
                        + 8.0 * af * (amin - amax)
                        + 6.0 * (amax * amax + 2.0 * amax * amin - amin * amin))
                    + 6.0 * af * (amax * amax - 2.0 * amax * amin - amin * amin)
                    + a0_2 * (3.0 * af - 4.0 * (2.0 * amax + amin)))
                * den)
            .sqrt();
        let jf = -(3.0 * af_2 * amax * tf - 3.0 * a0_2 * amin * tf - 6.0 * ad * amax * amin * tf
            + 3.0 * amax * amin * (amin - amax) * tf
            + 3.0 * (a0_2 - af_2) * vd
            + 6.0 * vd * (af * amin - a0 * amax)
            + 3.0 * (amax * amax - amin * amin) * vd
            + h1 / 4.0)
            / (6.0 * (2.0 * amin * g1 + vd * vd + amax * (2.0 * pd + amin * tf_2 - 2.0 * tf * vf)));
        p.t[0] = (amax - a0) / jf;
        p.t[1] = (a0_2 - af_2 + 2.0 * ad * amin
            - 2.0 * (amax * amax - 2.0 * amax * amin + amin * amin + amin * jf * tf - jf * vd))
            / (2.0 * (amax - amin) * jf);
        p.t[2] = amax / jf;
        p.t[3] = 0.0;
        p.t[4] = -amin / jf;
        p.t[5] = tf - (p.t[0] + p.t[1] + p.t[2] + 2.0 * p.t[4] + af / jf);
        p.t[6] = p.t[4] + af / jf;
        Self::chk_jerk(p, S::Uddu, L::Acc0Acc1, jf, m)
    }

    pub(crate) fn acc1(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
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
            g2,
            ..
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);

        // UDDU
        {
            let h0 = (jj
                * (a0_4 + af_4 - 4.0 * af_3 * j * tf + 6.0 * af_2 * jj * tf_2
                    - 4.0 * a0_3 * (af - j * tf)
                    + 6.0 * a0_2 * (af - j * tf) * (af - j * tf)
                    + 24.0 * af * jj * g1
                    - 4.0 * a0 * (af_3 - 3.0 * af_2 * j * tf + 6.0 * jj * (-pd + tf * vf))
                    - 12.0 * jj * (-vd_2 + j * tf * g2))
                / 3.0)
                .sqrt()
                / j;
            let h1 =
                ((a0_2 + af_2 - 2.0 * a0 * af - 2.0 * ad * j * tf + 2.0 * h0) / jj + tf_2).sqrt();
            p.t[0] = -(a0_2 + af_2 + 2.0 * a0 * (j * tf - af) - 2.0 * j * vd + h0)
                / (2.0 * j * (-ad + j * tf));
            p.t[1] = 0.0;
            p.t[2] = (tf - h1) / 2.0 - ad / (2.0 * j);
            p.t[3] = 0.0;
            p.t[4] = 0.0;
            p.t[5] = h1;
            p.t[6] = tf - (p.t[0] + p.t[2] + p.t[5]);
            if Self::chk(p, S::Uddu, L::Acc1, m) {
                return true;
            }
        }

        // UDUD
        {
            let h0 = (jj
                * (a0_4
                    + af_4
                    + 4.0 * (af_3 - a0_3) * j * tf
                    + 6.0 * af_2 * jj * tf_2
                    + 6.0 * a0_2 * (af + j * tf) * (af + j * tf)
                    + 24.0 * af * jj * g1
                    - 4.0
                        * a0
                        * (a0_2 * af + af_3 + 3.0 * af_2 * j * tf + 6.0 * jj * (-pd + tf * vf))
                    + 12.0 * jj * (vd_2 + j * tf * g2))
                / 3.0)
                .sqrt()
                / j;
            let h1 =
                ((a0_2 + af_2 - 2.0 * a0 * af + 2.0 * ad * j * tf + 2.0 * h0) / jj + tf_2).sqrt();
            p.t[0] = 0.0;
            p.t[1] = 0.0;
            p.t[2] = -(a0_2 + af_2 - 2.0 * a0 * af + 2.0 * j * (vd - a0 * tf) + h0)
                / (2.0 * j * (ad + j * tf));
            p.t[3] = 0.0;
            p.t[4] = ad / (2.0 * j) + (tf - h1) / 2.0;
            p.t[5] = h1;
            p.t[6] = tf - (p.t[5] + p.t[4] + p.t[2]);
            if Self::chk(p, S::Udud, L::Acc1, m) {
                return true;
            }
        }

        // UDDU, solution 2
        {
            let h0a = a0_3 - af_3 - 3.0 * a0_2 * amin
                + 3.0 * amin * amin * (a0 + j * tf)
                + 3.0 * af * amin * (-amin - 2.0 * j * tf)
                - 3.0 * af_2 * (-amin - j * tf)
                - 3.0 * jj * (-2.0 * pd - amin * tf_2 + 2.0 * tf * vf);
            let h0b =
                a0_2 + af_2 - 2.0 * (a0 + af) * amin + 2.0 * (amin * amin - j * (-amin * tf + vd));
            let h0c = a0_4 + 3.0 * af_4 - 4.0 * (a0_3 + 2.0 * af_3) * amin
                + 6.0 * a0_2 * amin * amin
                + 6.0 * af_2 * (amin * amin - 2.0 * j * vd)
                + 12.0 * j * (2.0 * amin * j * g1 - amin * amin * vd + j * vd_2)
                + 24.0 * af * amin * j * vd
                - 4.0
                    * a0
                    * (af_3 - 3.0 * af * amin * (-amin - 2.0 * j * tf)
                        + 3.0 * af_2 * (-amin - j * tf)
                        + 3.0
                            * j
                            * (-amin * amin * tf + j * (-2.0 * pd - amin * tf_2 + 2.0 * tf * vf)));
            let h1 = j.abs() / j * (4.0 * h0a * h0a - 6.0 * h0b * h0c).sqrt();
            let h2 = 6.0 * j * h0b;
            p.t[0] = 0.0;
            p.t[1] = 0.0;
            p.t[2] = (2.0 * h0a + h1) / h2;
            p.t[3] = -(a0_2 + af_2 - 2.0 * (a0 + af) * amin
                + 2.0 * (amin * amin + amin * j * tf - j * vd))
                / (2.0 * j * (a0 - amin - j * p.t[2]));
            p.t[4] = (a0 - amin) / j - p.t[2];
            p.t[5] = tf - (p.t[2] + p.t[3] + p.t[4] + (af - amin) / j);
            p.t[6] = (af - amin) / j;
            if Self::chk(p, S::Uddu, L::Acc1, m) {
                return true;
            }
        }

        // UDUD, solution 1
        {
            let h0a = -a0_3 + af_3 + 3.0 * (a0_2 - af_2) * amax
                - 3.0 * ad * amax * amax
                - 6.0 * af * amax * j * tf
                + 3.0 * af_2 * j * tf
                + 3.0 * j * (amax * amax * tf + j * (-2.0 * pd - amax * tf_2 + 2.0 * tf * vf));
            let h0b = a0_2 - af_2 + 2.0 * ad * amax + 2.0 * j * (amax * tf - vd);
            let h0c = a0_4 + 3.0 * af_4 - 4.0 * (a0_3 + 2.0 * af_3) * amax
                + 6.0 * a0_2 * amax * amax
                - 24.0 * af * amax * j * vd
                + 12.0 * j * (2.0 * amax * j * g1 + j * vd_2 + amax * amax * vd)
                + 6.0 * af_2 * (amax * amax + 2.0 * j * vd)
                - 4.0
                    * a0
                    * (af_3 + 3.0 * af * amax * (amax - 2.0 * j * tf)
                        - 3.0 * af_2 * (amax - j * tf)
                        + 3.0
                            * j
                            * (amax * amax * tf + j * (-2.0 * pd - amax * tf_2 + 2.0 * tf * vf)));
            let h1 = j.abs() / j * (4.0 * h0a * h0a - 6.0 * h0b * h0c).sqrt();
            let h2 = 6.0 * j * h0b;
            p.t[0] = 0.0;
            p.t[1] = 0.0;
            p.t[2] = -(2.0 * h0a + h1) / h2;
            p.t[3] = 2.0 * h1 / h2;
            p.t[4] = (amax - a0) / j + p.t[2];
            p.t[5] = tf - (p.t[2] + p.t[3] + p.t[4] + (-af + amax) / j);
            p.t[6] = (-af + amax) / j;
            if Self::chk(p, S::Udud, L::Acc1, m) {
                return true;
            }
        }
        false
    }

    pub(crate) fn acc0(&self, p: &mut Profile, m: &Lim) -> bool {
        let Self {
            tf,
            tf_2,
            pd,
            v0,
            vd,
            a0,
            af,
            ad,
            ad_2,
            a0_2,
            a0_3,
            af_2,
            af_3,
            jj,
            g1,
            g2,
            ..
        } = *self;
        let (amax, j) = (m.a_max, m.j);

        // UDUD
        {
            let h1 = (ad_2 / (2.0 * jj) - ad * (amax - a0) / jj + (amax * tf - vd) / j).sqrt();
            p.t = [
                (amax - a0) / j,
                tf - ad / j - 2.0 * h1,
                h1,
                0.0,
                (af - amax) / j + h1,
                0.0,
                0.0,
            ];
            if Self::chk(p, S::Udud, L::None, m) {
                return true;
            }
        }

        // UDUD
        {
            let h0a = -a0_2 + af_2 - 2.0 * ad * amax + 2.0 * j * (amax * tf - vd);
            let h0b = a0_3 + 2.0 * af_3
                - 6.0 * af_2 * amax
                - 3.0 * a0_2 * (af - j * tf)
                - 3.0 * a0 * amax * (amax - 2.0 * af + 2.0 * j * tf)
                - 3.0
                    * j
                    * (j * (-2.0 * pd + amax * tf_2 + 2.0 * tf * v0)
                        + amax * (amax * tf - 2.0 * vd))
                + 3.0 * af * (amax * amax + 2.0 * amax * j * tf - 2.0 * j * vd);
            let h0 = j.abs() * (4.0 * h0b * h0b - 18.0 * h0a * h0a * h0a).sqrt();
            let h1 = 3.0 * j * h0a;
            p.t[0] = (-a0 + amax) / j;
            p.t[1] = (-a0_3
                + af_3
                + af_2 * (-6.0 * amax + 3.0 * j * tf)
                + a0_2 * (-3.0 * af + 6.0 * amax + 3.0 * j * tf)
                + 6.0 * af * (amax * amax - j * vd)
                + 3.0 * a0 * (af_2 - 2.0 * (amax * amax + j * vd))
                - 6.0 * j * (amax * (amax * tf - 2.0 * vd) + j * g2))
                / h1;
            p.t[2] = -(ad + h0 / h1) / (2.0 * j) + tf / 2.0 - p.t[1] / 2.0;
            p.t[3] = h0 / (j * h1);
            p.t[4] = 0.0;
            p.t[5] = 0.0;
            p.t[6] = tf - (p.t[0] + p.t[1] + p.t[2] + p.t[3]);
            if Self::chk(p, S::Uddu, L::None, m) {
                return true;
            }
        }

        // UDDU, solution 1 (a3 != 0)
        {
            let h0a = a0_3 + 2.0 * af_3
                - 6.0 * (af_2 + amax * amax) * amax
                - 6.0 * (a0 + af) * amax * j * tf
                + 9.0 * amax * amax * (af + j * tf)
                + 3.0 * a0 * amax * (-2.0 * af + 3.0 * amax)
                + 3.0 * a0_2 * (af - 2.0 * amax + j * tf)
                - 6.0 * jj * g1
                + 6.0 * (af - amax) * j * vd
                - 3.0 * amax * jj * tf_2;
            let h0b = a0_2 + af_2 + 2.0 * (amax * amax - (a0 + af) * amax + j * (vd - amax * tf));
            let h1 = j.abs() / j * (4.0 * h0a * h0a - 18.0 * h0b * h0b * h0b).sqrt();
            let h2 = 6.0 * j * h0b;
            p.t[0] = (-a0 + amax) / j;
            p.t[1] = ad / j - 2.0 * p.t[0] - (2.0 * h0a - h1) / h2 + tf;
            p.t[2] = -(2.0 * h0a + h1) / h2;
            p.t[3] = (2.0 * h0a - h1) / h2;
            p.t[4] = tf - (p.t[0] + p.t[1] + p.t[2] + p.t[3]);
            p.t[5] = 0.0;
            p.t[6] = 0.0;
            if Self::chk(p, S::Uddu, L::Acc0, m) {
                return true;
            }
        }
        false
    }
}
