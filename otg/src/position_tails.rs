//! Tails of time-optimal profiles for the Step 1 repair (Bellman
//! consistency): the remainder of a profile sampled in its k-th phase is a
//! profile whose first phases vanish. The general closed forms then sit
//! exactly on the boundary of their admissible root range and can be lost
//! to rounding; these reduced shapes are solved directly, and are cheap:
//! a candidate with a negative phase or no shorter than the current
//! optimum is dropped before it is integrated.

use crate::candidates::Valid;
use crate::limits::Lim;
use crate::motion::integrate;
use crate::position_step1::Step1;
use crate::profile::{ControlSigns as S, ReachedLimits as L};

impl Step1 {
    /// Integrates and checks the candidate phases `t` (UDDU signs in the
    /// direction of `m`) if they can improve on the bound.
    #[inline]
    fn try_tail(&self, out: &mut Valid, t: [f64; 7], l: L, m: &Lim) {
        // NaN fails both tests.
        let usable = t.iter().all(|&x| x >= 0.0) && t.iter().sum::<f64>() < out.bound();
        if !usable {
            return;
        }
        // Three-phase tails reach the target velocity and acceleration by
        // construction; their distance decides, and is cheap to get first.
        if t[3..].iter().all(|&x| x == 0.0) && !self.reaches(t[0], t[1], t[2], m.j) {
            return;
        }
        Self::check_tail(out, t, l, m);
    }

    /// [`Step1::try_tail`] for a three-phase tail `(t0, t1, t2)`: the
    /// same tests, inlined without building the phase array (most tails
    /// fail them, and every Step 1 tries about eight).
    #[inline(always)]
    fn try_tail3(&self, out: &mut Valid, t0: f64, t1: f64, t2: f64, l: L, m: &Lim) {
        // NaN fails the tests.
        if t0 >= 0.0
            && t1 >= 0.0
            && t2 >= 0.0
            && t0 + t1 + t2 < out.bound()
            && self.reaches(t0, t1, t2, m.j)
        {
            Self::check_tail(out, [t0, t1, t2, 0.0, 0.0, 0.0, 0.0], l, m);
        }
    }

    /// Whether jerks `j`, 0, `-j` for `t0`, `t1`, `t2` end at the target
    /// distance (within the check's precision).
    #[inline(always)]
    fn reaches(&self, t0: f64, t1: f64, t2: f64, j: f64) -> bool {
        let (x, v, a) = integrate(t0, 0.0, self.v0, self.a0, j);
        let (x, v, a) = integrate(t1, x, v, a, 0.0);
        let (x, _, _) = integrate(t2, x, v, a, -j);
        (x - self.pd).abs() <= 1e-8
    }

    /// Integrates and checks a tail that passed the cheap tests (rare).
    #[cold]
    #[inline(never)]
    fn check_tail(out: &mut Valid, t: [f64; 7], l: L, m: &Lim) {
        let p = out.cur();
        p.t = t;
        if p.check(S::Uddu, l, false, m.j, m.v_max, m.v_min, m.a_max, m.a_min) {
            out.accept();
        }
    }

    /// All tails in the direction of `m`.
    pub(crate) fn tails(&self, out: &mut Valid, m: &Lim) {
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
        let (vmax, amax, amin, j) = (m.v_max, m.a_max, m.a_min, m.j);

        // One jerk phase.
        let t = (af - a0) / j;
        if t >= 0.0 {
            self.try_tail3(out, t, 0.0, 0.0, L::None, m);
        }

        // Two jerk phases, intermediate acceleration of either sign.
        let hh = (a0_2 + af_2) / 2.0 + j * (vf - v0);
        if hh >= 0.0 {
            let h = hh.sqrt();
            for h0 in [h, -h] {
                self.try_tail3(out, (h0 - a0) / j, 0.0, (h0 - af) / j, L::None, m);
            }
        }

        // Hold the current acceleration, then one jerk phase.
        let t2 = (a0 - af) / j;
        if a0 != 0.0 && t2 >= 0.0 {
            let t1 = (af_2 - a0_2 + 2.0 * j * (vf - v0)) / (2.0 * a0 * j);
            self.try_tail3(out, 0.0, t1, t2, L::Acc0, m);
        }

        // Jerk to the acceleration limit, hold, jerk to the target.
        let (t0, t2) = ((amax - a0) / j, (amax - af) / j);
        if t0 >= 0.0 && t2 >= 0.0 {
            let t1 = (a0_2 + af_2 - 2.0 * amax * amax + 2.0 * j * (vf - v0)) / (2.0 * amax * j);
            self.try_tail3(out, t0, t1, t2, L::Acc0, m);
        }

        // Tails with a cruise at the velocity limit: only from a state whose
        // acceleration ramps out exactly at the limit (within the velocity
        // precision of the check), i.e. on the way into the cruise.
        let tol = 1e-8 * vmax.abs().max(1.0);
        let ramp = a0_2 / (2.0 * j);
        let into_cruise_up = (v0 - ramp - vmax).abs() <= tol; // phase 0 with +j
        let into_cruise_down = (v0 + ramp - vmax).abs() <= tol; // phase 2 with -j
        if !(into_cruise_up || into_cruise_down) {
            return;
        }
        let h1 = (af_2 / (2.0 * jj) + (vmax - vf) / j).sqrt();
        let cruise_end = (af_3 - a0_3) / (3.0 * jj * vmax) - (vf / vmax + 1.0) * h1 + pd / vmax;
        if into_cruise_up {
            let t3 = cruise_end + (a0 * v0 - af * vf + (af_2 * h1) / 2.0) / (j * vmax);
            self.try_tail(
                out,
                [-a0 / j, 0.0, 0.0, t3, h1, 0.0, h1 + af / j],
                L::Vel,
                m,
            );
        }
        if into_cruise_down {
            let t3 = cruise_end + (a0 * v0 - af * vf + (af_2 * h1 + a0_3 / j) / 2.0) / (j * vmax)
                - (v0 / vmax + 1.0) * a0 / j;
            self.try_tail(out, [0.0, 0.0, a0 / j, t3, h1, 0.0, h1 + af / j], L::Vel, m);

            // As above, with the second acceleration plateau.
            let t3 =
                -(3.0 * af_4 - 8.0 * amin * (af_3 - a0_3) - 24.0 * amin * j * (a0 * v0 - af * vf)
                    + 6.0 * af_2 * (amin * amin - 2.0 * j * vf)
                    - 12.0
                        * j
                        * (2.0 * amin * j * pd
                            + amin * amin * (vf + vmax)
                            + j * (vmax * vmax - vf_2)
                            + amin * a0 * (a0_2 - 2.0 * j * (v0 + vmax)) / j))
                    / (24.0 * amin * jj * vmax);
            let t4 = -amin / j;
            let t5 = -(af_2 / 2.0 - amin * amin + j * (vmax - vf)) / (amin * j);
            self.try_tail(
                out,
                [0.0, 0.0, a0 / j, t3, t4, t5, t4 + af / j],
                L::Acc1Vel,
                m,
            );
        }
    }
}
