//! Step 2, third-order position interface: a profile of one DoF with a
//! prescribed duration `tf` (time synchronisation, Berscheid & Kröger 2021,
//! §IV-C). Shapes with a velocity plateau are here; those without one are
//! in `position_step2_flat.rs`.

use crate::limits::Lim;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, for_roots};

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
    ///
    /// The check accepts final positions within 1e-8, which for a tiny move
    /// can be a profile of another shape that really goes somewhere else
    /// (1e-8 instead of 2e-9); the state sampled on it is then not on the
    /// way to the target, and re-planning from it costs a turnaround. So if
    /// the first profile misses the target by more than 1e-12 relative, the
    /// remaining shapes are tried too and the one closest to the target
    /// wins (an alternative only if it respects the limits everywhere).
    pub(crate) fn profile(&self, p: &mut Profile, lim: &Lim) -> bool {
        type Shape = fn(&Step2, &mut Profile, &Lim) -> bool;
        const SHAPES: [(Shape, bool); 16] = [
            (Step2::acc0_acc1_vel, true),
            (Step2::vel, true),
            (Step2::acc0_vel, true),
            (Step2::acc1_vel, true),
            (Step2::acc0_acc1_vel, false),
            (Step2::vel, false),
            (Step2::acc0_vel, false),
            (Step2::acc1_vel, false),
            (Step2::acc0_acc1, true),
            (Step2::acc0, true),
            (Step2::acc1, true),
            (Step2::none, true),
            (Step2::acc0_acc1, false),
            (Step2::acc0, false),
            (Step2::acc1, false),
            (Step2::none, false),
        ];
        // Guess the likely direction first.
        let up_first = self.pd > self.tf * self.v0;
        let (m, n) = if up_first {
            (*lim, lim.flip())
        } else {
            (lim.flip(), *lim)
        };
        let mut best: Option<(f64, Profile)> = None;
        for (shape, first) in SHAPES {
            if !shape(self, p, if first { &m } else { &n }) {
                continue;
            }
            if best.is_none() && Self::on_target(p) {
                return true;
            }
            let miss = Self::miss(p);
            match best {
                None => best = Some((miss, *p)),
                Some((b, _)) if miss < b && Self::within(p, lim) => {
                    if Self::on_target(p) {
                        return true;
                    }
                    best = Some((miss, *p));
                }
                Some(_) => {}
            }
        }
        match best {
            Some((_, b)) => {
                *p = b;
                true
            }
            None => false,
        }
    }

    /// Whether a checked profile reaches the target to 1e-12 relative (far
    /// below the check's tolerances, well above rounding).
    #[inline]
    fn on_target(p: &Profile) -> bool {
        let near = |x: f64, x0: f64, target: f64| {
            (x - target).abs() <= 1e-12 * (1.0 + x0.abs() + target.abs())
        };
        near(p.p[7], p.p[0], p.pf) && near(p.v[7], p.v[0], p.vf) && near(p.a[7], p.a[0], p.af)
    }

    /// The largest fraction of the check's final-state tolerances (1e-8,
    /// 1e-8, 1e-10) that a checked profile uses.
    #[inline]
    fn miss(p: &Profile) -> f64 {
        ((p.p[7] - p.pf).abs() * 1e8)
            .max((p.v[7] - p.vf).abs() * 1e8)
            .max((p.a[7] - p.af).abs() * 1e10)
    }

    /// Whether a checked profile respects the velocity and acceleration
    /// limits at every instant (the check itself, as Ruckig's, does not
    /// look at velocity extrema inside the first two phases).
    fn within(p: &Profile, lim: &Lim) -> bool {
        let (v_hi, v_lo) = (lim.v_max.max(lim.v_min), lim.v_max.min(lim.v_min));
        let (a_hi, a_lo) = (lim.a_max.max(lim.a_min), lim.a_max.min(lim.a_min));
        (0..8).all(|i| (v_lo..=v_hi).contains(&p.v[i]) && (a_lo..=a_hi).contains(&p.a[i]))
            && (0..7).all(|i| {
                if p.j[i] == 0.0 || p.a[i] * p.a[i + 1] >= 0.0 {
                    return true;
                }
                let v_ext = p.v[i] - p.a[i] * p.a[i] / (2.0 * p.j[i]);
                (v_lo..=v_hi).contains(&v_ext)
            })
    }

    /// Which acceleration plateaus can fit: a plateau ramp from `v0` (or to
    /// `vf`) changes the velocity by at least `(2·a² - a₀²)/(2j)`, and the
    /// cruise velocity between the ramps is within the velocity limit, so
    /// shapes whose ramps cannot fit are skipped before their closed forms
    /// (necessary conditions for non-negative plateaus, compared in units
    /// of `v/j` with a margin far above the check's).
    #[inline]
    fn plateau_room(&self, m: &Lim) -> PlateauRoom {
        let ij = 1.0 / m.j;
        let (amax2, amin2) = (m.a_max * m.a_max, m.a_min * m.a_min);
        let fits = |room: f64, need: f64| {
            let short = room < need - 1e-9 * (room.abs() + need.abs()) - 1e-9 * ij.abs();
            !short
        };
        PlateauRoom {
            // Start ramp at a_max up to the cruise (≤ the limit).
            first: fits(
                (m.v_max - self.v0) * ij,
                (amax2 - 0.5 * self.a0_2) * ij * ij,
            ),
            // UDDU end ramp at a_min from the cruise (≤ the limit) to vf.
            last_down: fits(
                (m.v_max - self.vf) * ij,
                (amin2 - 0.5 * self.af_2) * ij * ij,
            ),
            // UDUD end ramp at a_max from the cruise up to vf (the start
            // ramp, without plateau, changes the velocity by ≥ -a0²/(2j)).
            last_up: fits(
                self.vd * ij,
                (amax2 - 0.5 * (self.a0_2 + self.af_2)) * ij * ij,
            ),
            // UDUD with both ramps at a_max.
            twice_up: fits(
                self.vd * ij,
                (2.0 * amax2 - 0.5 * (self.a0_2 + self.af_2)) * ij * ij,
            ),
        }
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

        let room = self.plateau_room(m);
        if room.first && room.last_down && (2.0 * (amax - amin) + ad) / j < tf {
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

        if room.first && room.twice_up && (-a0 + 4.0 * amax - af) / j < tf {
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
        let room = self.plateau_room(m);

        // UDDU: the end ramp has its a_min plateau.
        if room.last_down {
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
            for_roots!(roots::quartic_in(&poly, t_min, t_max), |t| {
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

        // UDUD: the end ramp has its a_max plateau.
        if room.last_up {
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
            for_roots!(roots::quartic_in(&poly, t_min, t_max), |t| {
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
        // Both jerk patterns start with the a_max plateau ramp.
        if !self.plateau_room(m).first {
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
            for_roots!(roots::quartic_in(&poly, t_min, t_max), |t| {
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
            for_roots!(roots::quartic_in(&poly, t_min, t_max), |t| {
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
}

/// Result of [`Step2::plateau_room`]: whether each plateau ramp can fit.
#[derive(Clone, Copy)]
struct PlateauRoom {
    first: bool,
    last_down: bool,
    last_up: bool,
    twice_up: bool,
}
