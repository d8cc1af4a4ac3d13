//! Step 1 shapes with fewer phases, tried only when the general shapes of
//! `position_step1.rs` find no profile at all (numerically degenerate
//! boundary values); the shortest valid one is taken.

use crate::candidates::Valid;
use crate::limits::Lim;
use crate::position_step1::Step1;
use crate::profile::{ControlSigns as S, ReachedLimits as L};

impl Step1 {
    /// Fallbacks for numerically degenerate cases (ACC1_VEL with t0 = 0).
    pub(crate) fn acc1_vel_two_step(&self, out: &mut Valid, m: &Lim) {
        let bound = out.bound();
        let Self {
            pd,
            v0,
            a0,
            vf,
            af,
            vf_2,
            a0_2,
            a0_3,
            af_2,
            af_3,
            af_4,
            jj,
            ..
        } = *self;
        let (vmax, amin, j) = (m.v_max, m.a_min, m.j);
        let p = out.cur();
        p.t[0] = 0.0;
        p.t[1] = 0.0;
        p.t[2] = a0 / j;
        p.t[3] = -(3.0 * af_4 - 8.0 * amin * (af_3 - a0_3) - 24.0 * amin * j * (a0 * v0 - af * vf)
            + 6.0 * af_2 * (amin * amin - 2.0 * j * vf)
            - 12.0
                * j
                * (2.0 * amin * j * pd
                    + amin * amin * (vf + vmax)
                    + j * (vmax * vmax - vf_2)
                    + amin * a0 * (a0_2 - 2.0 * j * (v0 + vmax)) / j))
            / (24.0 * amin * jj * vmax);
        p.t[4] = -amin / j;
        p.t[5] = -(af_2 / 2.0 - amin * amin + j * (vmax - vf)) / (amin * j);
        p.t[6] = p.t[4] + af / j;
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Acc1Vel, false, m) {
            out.accept();
        }
    }

    /// Fallbacks for ACC0 shapes with fewer phases.
    pub(crate) fn acc0_two_step(&self, out: &mut Valid, m: &Lim) {
        let bound = out.bound();
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

        let p = out.cur();
        p.t = [
            0.0,
            (af_2 - a0_2 + 2.0 * j * (vf - v0)) / (2.0 * a0 * j),
            (a0 - af) / j,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Acc0, false, m) {
            out.accept();
            if out.first_only() {
                return;
            }
        }

        let p = out.cur();
        p.t = [
            (-a0 + amax) / j,
            (a0_2 + af_2 - 2.0 * amax * amax + 2.0 * j * (vf - v0)) / (2.0 * amax * j),
            (-af + amax) / j,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Acc0, false, m) {
            out.accept();
            if out.first_only() {
                return;
            }
        }

        let h0 = 3.0 * (af_2 - a0_2 + 2.0 * j * (v0 + vf));
        let h2 = a0_3 + 2.0 * af_3 + 6.0 * jj * pd + 6.0 * (af - a0) * j * vf - 3.0 * a0 * af_2;
        let h1 = (2.0
            * (2.0 * h2 * h2
                + h0 * (a0_4 - 6.0 * a0_2 * (af_2 + 2.0 * j * vf)
                    + 8.0 * a0 * (af_3 + 3.0 * jj * pd + 3.0 * af * j * vf)
                    - 3.0 * (af_4 + 4.0 * af_2 * j * vf + 4.0 * jj * (vf_2 - v0_2)))))
            .sqrt()
            * j.abs()
            / j;
        let p = out.cur();
        p.t = [
            (4.0 * af_3 + 2.0 * a0_3 - 6.0 * a0 * af_2
                + 12.0 * jj * pd
                + 12.0 * (af - a0) * j * vf
                + h1)
                / (2.0 * j * h0),
            -h1 / (j * h0),
            (-4.0 * a0_3 - 2.0 * af_3 + 6.0 * a0_2 * af + 12.0 * jj * pd
                - 12.0 * (af - a0) * j * v0
                + h1)
                / (2.0 * j * h0),
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Acc0, false, m) {
            out.accept();
            if out.first_only() {
                return;
            }
        }

        let t = (amax - amin) / j;
        let p = out.cur();
        p.t = [
            (-a0 + amax) / j,
            (a0_2 - af_2) / (2.0 * amax * j) + (vf - v0 + j * t * t) / amax - 2.0 * t,
            t,
            0.0,
            0.0,
            0.0,
            (af - amin) / j,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Acc0, false, m) {
            out.accept();
        }
    }

    /// Fallbacks for VEL shapes with fewer phases.
    pub(crate) fn vel_two_step(&self, out: &mut Valid, m: &Lim) {
        let bound = out.bound();
        let Self {
            pd,
            v0,
            a0,
            vf,
            af,

            a0_3,
            af_2,
            af_3,
            jj,
            ..
        } = *self;
        let (vmax, j) = (m.v_max, m.j);
        let h1 = (af_2 / (2.0 * jj) + (vmax - vf) / j).sqrt();

        let p = out.cur();
        p.t = [
            -a0 / j,
            0.0,
            0.0,
            (af_3 - a0_3) / (3.0 * jj * vmax)
                + (a0 * v0 - af * vf + (af_2 * h1) / 2.0) / (j * vmax)
                - (vf / vmax + 1.0) * h1
                + pd / vmax,
            h1,
            0.0,
            h1 + af / j,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Vel, false, m) {
            out.accept();
            if out.first_only() {
                return;
            }
        }

        let p = out.cur();
        p.t = [
            0.0,
            0.0,
            a0 / j,
            (af_3 - a0_3) / (3.0 * jj * vmax)
                + (a0 * v0 - af * vf + (af_2 * h1 + a0_3 / j) / 2.0) / (j * vmax)
                - (v0 / vmax + 1.0) * a0 / j
                - (vf / vmax + 1.0) * h1
                + pd / vmax,
            h1,
            0.0,
            h1 + af / j,
        ];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::Vel, false, m) {
            out.accept();
        }
    }

    /// Fallbacks for NONE shapes with one or two jerk phases.
    pub(crate) fn none_two_step(&self, out: &mut Valid, m: &Lim) {
        let bound = out.bound();
        let Self {
            v0,
            a0,
            vf,
            af,
            a0_2,
            af_2,
            ..
        } = *self;
        let j = m.j;
        let h0 = ((a0_2 + af_2) / 2.0 + j * (vf - v0)).sqrt() * j.abs() / j;
        let p = out.cur();
        p.t = [(h0 - a0) / j, 0.0, (h0 - af) / j, 0.0, 0.0, 0.0, 0.0];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::None, false, m) {
            out.accept();
            if out.first_only() {
                return;
            }
        }
        let p = out.cur();
        p.t = [(af - a0) / j, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::None, false, m) {
            out.accept();
        }
    }

    /// Two jerk phases with the intermediate acceleration of either sign
    /// (the tail of a profile sampled in its last jerk phases).
    pub(crate) fn two_jerk(&self, out: &mut Valid, m: &Lim) {
        let bound = out.bound();
        let Self {
            v0,
            a0,
            vf,
            af,
            a0_2,
            af_2,
            ..
        } = *self;
        let j = m.j;
        let h = ((a0_2 + af_2) / 2.0 + j * (vf - v0)).sqrt();
        for h0 in [h, -h] {
            let p = out.cur();
            p.t = [(h0 - a0) / j, 0.0, (h0 - af) / j, 0.0, 0.0, 0.0, 0.0];
            if Valid::admits(p, bound) && Self::chk(p, S::Uddu, L::None, false, m) {
                out.accept();
            }
        }
    }
}
