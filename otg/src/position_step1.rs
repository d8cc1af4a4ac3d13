//! Step 1, third-order position interface: the time-optimal profile of one
//! DoF and its blocked duration intervals (Berscheid & Kröger 2021, §IV-A).
//!
//! Every candidate shape (which of the acceleration and velocity limits are
//! reached, and the jerk direction) has a closed-form or polynomial
//! condition; each real solution is integrated and checked. With a zero
//! target velocity and acceleration the first valid profile is optimal;
//! otherwise all are collected to find blocked intervals.

use crate::block::Block;
use crate::candidates::{Keep, Valid};
use crate::limits::{Lim, close_tol};
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::{self, EPS, for_roots};

/// Boundary values and their powers, shared by all candidate shapes.
#[derive(Clone, Copy)]
pub(crate) struct Step1 {
    pub(crate) pd: f64,
    pub(crate) v0: f64,
    pub(crate) a0: f64,
    pub(crate) vf: f64,
    pub(crate) af: f64,
    pub(crate) v0_2: f64,
    pub(crate) vf_2: f64,
    pub(crate) a0_2: f64,
    pub(crate) a0_3: f64,
    pub(crate) a0_4: f64,
    pub(crate) af_2: f64,
    pub(crate) af_3: f64,
    pub(crate) af_4: f64,
    pub(crate) jj: f64,
    /// Solve the quartics in units of their root scale (`quartic_scaled`).
    pub(crate) scaled: bool,
}

impl Step1 {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(p0: f64, v0: f64, a0: f64, pf: f64, vf: f64, af: f64, j_max: f64) -> Self {
        let (a0_2, af_2) = (a0 * a0, af * af);
        Self {
            pd: pf - p0,
            v0,
            a0,
            vf,
            af,
            v0_2: v0 * v0,
            vf_2: vf * vf,
            a0_2,
            a0_3: a0 * a0_2,
            a0_4: a0_2 * a0_2,
            af_2,
            af_3: af * af_2,
            af_4: af_2 * af_2,
            jj: j_max * j_max,
            scaled: false,
        }
    }

    #[inline]
    pub(crate) fn chk(p: &mut Profile, s: S, l: L, pin: bool, m: &Lim) -> bool {
        p.check(s, l, pin, m.j, m.v_max, m.v_min, m.a_max, m.a_min)
    }

    /// Shapes with a velocity plateau (ACC0_ACC1_VEL, ACC1_VEL, ACC0_VEL, VEL).
    fn all_vel(&self, out: &mut Valid, m: &Lim) {
        let Self {
            pd,
            v0,
            a0,
            vf,
            af,
            v0_2,
            vf_2,
            a0_2,
            a0_3,
            a0_4,
            af_2,
            af_3,
            af_4,
            jj,
            ..
        } = *self;
        let (vmax, amax, amin, j) = (m.v_max, m.a_max, m.a_min, m.j);

        let p = out.cur();
        p.t[0] = (-a0 + amax) / j;
        p.t[1] = (a0_2 / 2.0 - amax * amax - j * (v0 - vmax)) / (amax * j);
        p.t[2] = amax / j;
        p.t[3] = (3.0 * (a0_4 * amin - af_4 * amax)
            + 8.0 * amax * amin * (af_3 - a0_3 + 3.0 * j * (a0 * v0 - af * vf))
            + 6.0 * a0_2 * amin * (amax * amax - 2.0 * j * v0)
            - 6.0 * af_2 * amax * (amin * amin - 2.0 * j * vf)
            - 12.0
                * j
                * (amax * amin * (amax * (v0 + vmax) - amin * (vf + vmax) - 2.0 * j * pd)
                    + (amin - amax) * j * vmax * vmax
                    + j * (amax * vf_2 - amin * v0_2)))
            / (24.0 * amax * amin * jj * vmax);
        p.t[4] = -amin / j;
        p.t[5] = -(af_2 / 2.0 - amin * amin - j * (vf - vmax)) / (amin * j);
        p.t[6] = p.t[4] + af / j;
        if Self::chk(p, S::Uddu, L::Acc0Acc1Vel, false, m) {
            out.accept();
            return;
        }

        // ACC1_VEL (phases 4..6 as above)
        let t_acc0 = (a0_2 / (2.0 * jj) + (vmax - v0) / j).sqrt();
        let p = out.cur();
        p.t[0] = t_acc0 - a0 / j;
        p.t[1] = 0.0;
        p.t[2] = t_acc0;
        p.t[3] = -(3.0 * af_4 - 8.0 * amin * (af_3 - a0_3) - 24.0 * amin * j * (a0 * v0 - af * vf)
            + 6.0 * af_2 * (amin * amin - 2.0 * j * vf)
            - 12.0
                * j
                * (2.0 * amin * j * pd
                    + amin * amin * (vf + vmax)
                    + j * (vmax * vmax - vf_2)
                    + amin * t_acc0 * (a0_2 - 2.0 * j * (v0 + vmax))))
            / (24.0 * amin * jj * vmax);
        if Self::chk(p, S::Uddu, L::Acc1Vel, false, m) {
            out.accept();
            return;
        }

        // ACC0_VEL
        let t_acc1 = (af_2 / (2.0 * jj) + (vmax - vf) / j).sqrt();
        let p = out.cur();
        p.t[0] = (-a0 + amax) / j;
        p.t[1] = (a0_2 / 2.0 - amax * amax - j * (v0 - vmax)) / (amax * j);
        p.t[2] = amax / j;
        p.t[3] = (3.0 * a0_4
            + 8.0 * amax * (af_3 - a0_3)
            + 24.0 * amax * j * (a0 * v0 - af * vf)
            + 6.0 * a0_2 * (amax * amax - 2.0 * j * v0)
            - 12.0
                * j
                * (-2.0 * amax * j * pd
                    + amax * amax * (v0 + vmax)
                    + j * (vmax * vmax - v0_2)
                    + amax * t_acc1 * (-af_2 + 2.0 * (vf + vmax) * j)))
            / (24.0 * amax * jj * vmax);
        p.t[4] = t_acc1;
        p.t[5] = 0.0;
        p.t[6] = t_acc1 + af / j;
        if Self::chk(p, S::Uddu, L::Acc0Vel, false, m) {
            out.accept();
            return;
        }

        // VEL
        let p = out.cur();
        p.t[0] = t_acc0 - a0 / j;
        p.t[1] = 0.0;
        p.t[2] = t_acc0;
        p.t[3] = (af_3 - a0_3) / (3.0 * jj * vmax)
            + (a0 * v0 - af * vf + (af_2 * t_acc1 + a0_2 * t_acc0) / 2.0) / (j * vmax)
            - (v0 / vmax + 1.0) * t_acc0
            - (vf / vmax + 1.0) * t_acc1
            + pd / vmax;
        if Self::chk(p, S::Uddu, L::Vel, false, m) {
            out.accept();
        }
    }

    /// Both acceleration plateaus, no velocity plateau (two solutions).
    fn acc0_acc1(&self, out: &mut Valid, m: &Lim, first_only: bool) {
        let Self {
            pd,
            v0,
            a0,
            vf,
            af,
            v0_2,
            vf_2,
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

        let h1 = (3.0 * (af_4 * amax - a0_4 * amin)
            + amax
                * amin
                * (8.0 * (a0_3 - af_3) + 3.0 * amax * amin * (amax - amin) + 6.0 * amin * af_2
                    - 6.0 * amax * a0_2)
            + 12.0
                * j
                * (amax * amin * ((amax - 2.0 * a0) * v0 - (amin - 2.0 * af) * vf)
                    + amin * a0_2 * v0
                    - amax * af_2 * vf))
            / (3.0 * (amax - amin) * jj)
            + 4.0 * (amax * vf_2 - amin * v0_2 - 2.0 * amin * amax * pd) / (amax - amin);
        if h1 < 0.0 {
            return;
        }
        let h1 = h1.sqrt() / 2.0;
        let h2 = a0_2 / (2.0 * amax * j) + (amin - 2.0 * amax) / (2.0 * j) - v0 / amax;
        let h3 = -af_2 / (2.0 * amin * j) - (amax - 2.0 * amin) / (2.0 * j) + vf / amin;

        for sign in [-1.0, 1.0] {
            // sign = -1: shorter first plateau ("solution 2"), then "solution 1".
            if h2 > -sign * h1 / amax && h3 > sign * h1 / amin {
                let p = out.cur();
                p.t[0] = (-a0 + amax) / j;
                p.t[1] = h2 + sign * h1 / amax;
                p.t[2] = amax / j;
                p.t[3] = 0.0;
                p.t[4] = -amin / j;
                p.t[5] = h3 - sign * h1 / amin;
                p.t[6] = p.t[4] + af / j;
                if Self::chk(p, S::Uddu, L::Acc0Acc1, true, m) {
                    out.accept();
                    if first_only {
                        return;
                    }
                }
            }
        }
    }

    /// Shapes without a velocity plateau: NONE, ACC0, ACC1 (quartics).
    fn none_acc0_acc1(&self, out: &mut Valid, m: &Lim, first_only: bool) {
        let Self {
            pd,
            v0,
            a0,
            vf,
            af,
            v0_2,
            vf_2,
            a0_2,
            a0_3,
            a0_4,
            af_2,
            af_3,
            af_4,
            jj,
            scaled,
        } = *self;
        let (amax, amin, j) = (m.a_max, m.a_min, m.j);
        let quartic_in = if scaled {
            roots::quartic_in_scaled
        } else {
            roots::quartic_in
        };

        // NONE: t7 == 0 (UDDU and UDUD coincide); prone to numerical issues.
        let h2_none = (a0_2 - af_2) / (2.0 * j) + (vf - v0);
        let h2_h2 = h2_none * h2_none;
        let t_min_none = (a0 - af) / j;
        let t_max_none = (amax - amin) / j;
        let poly_none = [
            0.0,
            -2.0 * (a0_2 + af_2 - 2.0 * j * (v0 + vf)) / jj,
            4.0 * (a0_3 - af_3 + 3.0 * j * (af * vf - a0 * v0)) / (3.0 * j * jj) - 4.0 * pd / j,
            -h2_h2 / jj,
        ];

        // ACC0
        let h3_acc0 = (a0_2 - af_2) / (2.0 * amax * j) + (vf - v0) / amax;
        let t_min_acc0 = (amax - af) / j;
        let t_max_acc0 = (amax - amin) / j;
        let h0_acc0 = 3.0 * (af_4 - a0_4)
            + 8.0 * (a0_3 - af_3) * amax
            + 24.0 * amax * j * (af * vf - a0 * v0)
            - 6.0 * a0_2 * (amax * amax - 2.0 * j * v0)
            + 6.0 * af_2 * (amax * amax - 2.0 * j * vf)
            + 12.0 * j * (j * (vf_2 - v0_2 - 2.0 * amax * pd) - amax * amax * (vf - v0));
        let h2_acc0 = -af_2 + amax * amax + 2.0 * j * vf;
        let poly_acc0 = [
            -2.0 * amax / j,
            h2_acc0 / jj,
            0.0,
            h0_acc0 / (12.0 * jj * jj),
        ];

        // ACC1
        let h3_acc1 = -(a0_2 + af_2) / (2.0 * j * amin) + amin / j + (vf - v0) / amin;
        let t_min_acc1 = (amin - a0) / j;
        let t_max_acc1 = (amax - a0) / j;
        let h0_acc1 = (a0_4 - af_4) / 4.0
            + 2.0 * (af_3 - a0_3) * amin / 3.0
            + (a0_2 - af_2) * amin * amin / 2.0
            + j * (af_2 * vf
                + a0_2 * v0
                + 2.0 * amin * (j * pd - a0 * v0 - af * vf)
                + amin * amin * (v0 + vf)
                + j * (v0_2 - vf_2));
        let h2_acc1 = a0_2 - a0 * amin + 2.0 * j * v0;
        let poly_acc1 = [
            2.0 * (2.0 * a0 - amin) / j,
            (5.0 * a0_2 + amin * (amin - 6.0 * a0) + 2.0 * j * v0) / jj,
            2.0 * (a0 - amin) * h2_acc1 / (jj * j),
            h0_acc1 / (jj * jj),
        ];

        // Only roots in each shape's range are used: the quartics are
        // solved lazily, and not at all without a root there.
        for_roots!(quartic_in(&poly_none, t_min_none, t_max_none), |t| {
            if t < t_min_none || t > t_max_none {
                continue;
            }
            // One Newton step on the position equation.
            if t > EPS {
                let h1 = j * t * t;
                let orig = -h2_h2 / (4.0 * j * t)
                    + h2_none * (af / j + t)
                    + (4.0 * a0_3 + 2.0 * af_3 - 6.0 * a0_2 * (af + 2.0 * j * t)
                        + 12.0 * (af - a0) * j * v0
                        + 3.0 * jj * (-4.0 * pd + (h1 + 8.0 * v0) * t))
                        / (12.0 * jj);
                let deriv = h2_none + 2.0 * v0 - a0_2 / j + h2_h2 / (4.0 * h1) + (3.0 * h1) / 4.0;
                t -= orig / deriv;
            }
            let h0 = h2_none / (2.0 * j * t);
            let p = out.cur();
            p.t = [
                h0 + t / 2.0 - a0 / j,
                0.0,
                t,
                0.0,
                0.0,
                0.0,
                -h0 + t / 2.0 + af / j,
            ];
            if Self::chk(p, S::Uddu, L::None, false, m) {
                out.accept();
                if first_only {
                    return;
                }
            }
        });

        for_roots!(quartic_in(&poly_acc0, t_min_acc0, t_max_acc0), |t| {
            if t < t_min_acc0 || t > t_max_acc0 {
                continue;
            }
            if t > EPS {
                let h1 = j * t;
                let orig = h0_acc0 / (12.0 * jj * t) + t * (h2_acc0 + h1 * (h1 - 2.0 * amax));
                let deriv = 2.0 * (h2_acc0 + h1 * (2.0 * h1 - 3.0 * amax));
                t -= orig / deriv;
            }
            let p = out.cur();
            p.t = [
                (-a0 + amax) / j,
                h3_acc0 - 2.0 * t + j / amax * t * t,
                t,
                0.0,
                0.0,
                0.0,
                (af - amax) / j + t,
            ];
            if Self::chk(p, S::Uddu, L::Acc0, false, m) {
                out.accept();
                if first_only {
                    return;
                }
            }
        });

        for_roots!(quartic_in(&poly_acc1, t_min_acc1, t_max_acc1), |t| {
            if t < t_min_acc1 || t > t_max_acc1 {
                continue;
            }
            // Up to three Newton steps on the position equation.
            if t > EPS {
                let h5 = a0_3 + 2.0 * j * a0 * v0;
                let residual = |t: f64| {
                    let h1 = j * t;
                    -(h0_acc1 / 2.0
                        + h1 * (h5
                            + a0 * (amin - 2.0 * h1) * (amin - h1)
                            + a0_2 * (5.0 * h1 / 2.0 - 2.0 * amin)
                            + amin * amin * h1 / 2.0
                            + j * (h1 / 2.0 - amin) * (h1 * t + 2.0 * v0)))
                        / j
                };
                let slope = |t: f64| {
                    let h1 = j * t;
                    (amin - a0 - h1) * (h2_acc1 + h1 * (4.0 * a0 - amin + 2.0 * h1))
                };
                t -= (residual(t) / slope(t)).min(t);
                let r = residual(t);
                if r.abs() > 1e-9 {
                    t -= r / slope(t);
                    let r = residual(t);
                    if r.abs() > 1e-9 {
                        t -= r / slope(t);
                    }
                }
            }
            let p = out.cur();
            p.t = [
                t,
                0.0,
                (a0 - amin) / j + t,
                0.0,
                0.0,
                h3_acc1 - (2.0 * a0 + j * t) * t / amin,
                (af - amin) / j,
            ];
            if Self::chk(p, S::Uddu, L::Acc1, true, m) {
                out.accept();
                if first_only {
                    return;
                }
            }
        });
    }

    /// Computes the block (time-optimal profile and blocked intervals) for
    /// the boundary values stored in `input`; `false` if none was found.
    pub(crate) fn block(
        &self,
        input: &Profile,
        lim: &Lim,
        block: &mut Block,
        out: &mut Valid,
    ) -> bool {
        let found = self.block_unscaled(input, lim, block, out);
        if !(self.vf.abs() < EPS && self.af.abs() < EPS && self.tiny_scale(lim.j)) {
            return found;
        }
        // The quartics of a tiny motion (phases well below 10 ms) can lose
        // their roots to the solver's absolute zero tests (as Ruckig's),
        // leaving a much longer profile or none. Searched again with
        // scaled quartics, the shorter profile wins (both passed the same
        // check): Ruckig's result wherever it is the shorter one, and a
        // consistent optimum from states sampled on it.
        let scaled = Step1 {
            scaled: true,
            ..*self
        };
        out.reset(input, Keep::All, f64::INFINITY);
        let (fwd, bwd) = if self.pd >= 0.0 {
            (*lim, lim.flip())
        } else {
            (lim.flip(), *lim)
        };
        scaled.rest_search(out, &fwd, &bwd);
        let mut best = (out.n > 0).then(|| out.list[0]);
        out.reset(input, Keep::All, f64::INFINITY);
        if self.brake_tail(out, lim) && best.is_none_or(|b| out.list[0].duration() < b.duration()) {
            best = Some(out.list[0]);
        }
        let Some(best) = best else {
            return found;
        };
        if found && best.duration() >= block.t_min - close_tol(block.t_min) {
            return found;
        }
        out.reset(input, Keep::All, f64::INFINITY);
        *out.cur() = best;
        out.accept();
        block.set_min(&out.list[0]);
        block.a = None;
        block.b = None;
        scaled.repair(lim, &lim.flip(), block, out);
        true
    }

    /// [`Step1::block`] with the quartics solved as Ruckig does.
    fn block_unscaled(
        &self,
        input: &Profile,
        lim: &Lim,
        block: &mut Block,
        out: &mut Valid,
    ) -> bool {
        out.reset(input, Keep::All, f64::INFINITY);
        let up = *lim;
        let down = lim.flip();

        if self.vf.abs() < EPS && self.af.abs() < EPS {
            // At rest at the target: no blocked intervals, the first valid
            // profile in the likely direction is optimal.
            let (fwd, bwd) = if self.pd >= 0.0 {
                (up, down)
            } else {
                (down, up)
            };
            self.rest_search(out, &fwd, &bwd);
        } else {
            self.none_acc0_acc1(out, &up, false);
            self.none_acc0_acc1(out, &down, false);
            self.acc0_acc1(out, &up, false);
            self.acc0_acc1(out, &down, false);
            self.all_vel(out, &up);
            self.all_vel(out, &down);
        }

        if out.n == 0 {
            // Only reduced shapes remain: take the shortest of them all
            // (the first one found need not be optimal).
            out.reset(
                input,
                Keep::Shortest {
                    exact: false,
                    position: true,
                },
                f64::INFINITY,
            );
            for f in FALLBACKS {
                for m in [&up, &down] {
                    f(self, out, m);
                }
            }
            if out.n == 0 {
                return false;
            }
            block.set_min(&out.list[0]);
            return true;
        }
        let n = out.n;
        if !block.build(&mut out.list, n) {
            block.build_unpaired(&out.list[..n]);
        }
        self.repair(&up, &down, block, out);
        true
    }

    /// At rest at the target: the first valid profile, searched in the
    /// likely direction `fwd` first.
    fn rest_search(&self, out: &mut Valid, fwd: &Lim, bwd: &Lim) {
        if self.v0.abs() < EPS && self.a0.abs() < EPS && self.pd.abs() < EPS {
            self.none_acc0_acc1(out, fwd, true);
            return;
        }
        for m in [fwd, bwd] {
            self.all_vel(out, m);
            if out.n > 0 {
                return;
            }
            self.none_acc0_acc1(out, m, true);
            if out.n > 0 {
                return;
            }
            self.acc0_acc1(out, m, true);
            if out.n > 0 {
                return;
            }
        }
    }

    /// A state exactly on the braking curve of a rest target (one jerk
    /// phase takes velocity and acceleration to zero together, as in the
    /// last phase of a profile): that phase, if the check accepts where it
    /// stops. Re-planning from a trajectory that stops within the check's
    /// tolerance of the target (Ruckig's velocity-only fallback, which we
    /// match) then continues it instead of turning around for the exact
    /// target. Off the curve (every state not sampled on such a phase)
    /// nothing is added.
    fn brake_tail(&self, out: &mut Valid, up: &Lim) -> bool {
        let (v0, a0) = (self.v0, self.a0);
        if a0 == 0.0 {
            return false;
        }
        let j = up.j.abs();
        let v_end = v0 + a0 * a0.abs() / (2.0 * j);
        if v_end.abs() > 1e-9 * v0.abs() {
            return false;
        }
        // The phase's jerk is -m.j: against the acceleration.
        let m = if a0 > 0.0 { *up } else { up.flip() };
        let p = out.cur();
        p.t = [0.0, 0.0, a0.abs() / j, 0.0, 0.0, 0.0, 0.0];
        if Self::chk(p, S::Uddu, L::None, false, &m) {
            out.accept();
            return true;
        }
        false
    }

    /// Whether the natural time scale of the motion (the phase durations
    /// that the boundary values alone call for) is below 10 ms: only then
    /// can the quartics' absolute zero tests matter.
    #[inline]
    fn tiny_scale(&self, j: f64) -> bool {
        let j = j.abs();
        let t = (self.pd.abs() / j).cbrt()
            + (self.v0.abs() / j).sqrt()
            + self.a0.abs() / j
            + (self.vf.abs() / j).sqrt()
            + self.af.abs() / j;
        t < 1e-2
    }

    /// Bellman repair: on states exactly on a phase boundary or a limit
    /// (typically states sampled from an earlier trajectory) the quartic
    /// roots of the optimal shape can fall just outside their admissible
    /// range, leaving only a longer profile. The tails of profiles
    /// (`position_tails.rs`) catch these; if one is shorter, it becomes the
    /// optimum and the durations up to the former optimum are
    /// conservatively blocked.
    fn repair(&self, up: &Lim, down: &Lim, block: &mut Block, extra: &mut Valid) {
        // Only exact reproductions count: the check's tolerances would
        // otherwise admit trivially short "solutions" of tiny motions.
        let t_old = block.p_min.t_sum[6];
        extra.restart(
            Keep::Shortest {
                exact: true,
                position: true,
            },
            t_old - 1e-12 * t_old.max(1.0),
        );
        self.tails(extra, up);
        self.tails(extra, down);
        if extra.n == 0 {
            return;
        }
        let best = extra.list[0];
        let old = block.p_min;
        if best.t_sum[6] >= old.t_sum[6] - 1e-12 * old.t_sum[6].max(1.0) {
            return;
        }
        if self.vf.abs() < EPS && self.af.abs() < EPS {
            // At rest at the target no duration beyond the optimum is
            // blocked (see `block`): nothing to treat conservatively.
            block.set_min(&best);
            block.a = None;
            block.b = None;
            return;
        }
        block.merge_shorter(&best);
    }
}

type Fallback = fn(&Step1, &mut Valid, &Lim);

/// Reduced shapes tried when the general ones fail.
const FALLBACKS: [Fallback; 5] = [
    Step1::none_two_step,
    Step1::two_jerk,
    Step1::acc0_two_step,
    Step1::vel_two_step,
    Step1::acc1_vel_two_step,
];
