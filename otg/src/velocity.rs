//! Third-order velocity interface: reach a target velocity and acceleration
//! (position free) under acceleration and jerk limits (SPEC.md §5). Used by
//! the executor to bring a motion to a smooth stop (target velocity 0).
//!
//! Step 1 finds the time-optimal profile (at most three jerk phases), Step 2
//! stretches it to a synchronised duration.

use crate::block::Block;
use crate::candidates::{Keep, Valid};
use crate::limits::AccLim;
use crate::profile::{ControlSigns as S, Profile, ReachedLimits as L};
use crate::roots::EPS;

/// Step 1 of the velocity interface.
pub(crate) struct VelStep1 {
    a0: f64,
    af: f64,
    vd: f64,
}

impl VelStep1 {
    pub(crate) fn new(v0: f64, a0: f64, vf: f64, af: f64) -> Self {
        Self {
            a0,
            af,
            vd: vf - v0,
        }
    }

    fn acc0(&self, out: &mut Valid, m: &AccLim) {
        let Self { a0, af, vd } = *self;
        let (amax, j) = (m.a_max, m.j);
        let p = out.cur();
        p.t = [
            (-a0 + amax) / j,
            (a0 * a0 + af * af) / (2.0 * amax * j) - amax / j + vd / amax,
            (-af + amax) / j,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        if p.check_velocity(S::Uddu, L::Acc0, j, m.a_max, m.a_min) {
            out.accept();
        }
    }

    fn none(&self, out: &mut Valid, m: &AccLim, first_only: bool) {
        let Self { a0, af, vd } = *self;
        let j = m.j;
        let h1 = (a0 * a0 + af * af) / 2.0 + j * vd;
        if h1 < 0.0 {
            return;
        }
        let h1 = h1.sqrt();
        for s in [-1.0, 1.0] {
            let p = out.cur();
            p.t = [
                (-a0 + s * h1) / j,
                0.0,
                (-af + s * h1) / j,
                0.0,
                0.0,
                0.0,
                0.0,
            ];
            if p.check_velocity(S::Uddu, L::None, j, m.a_max, m.a_min) {
                out.accept();
                if first_only {
                    return;
                }
            }
        }
    }

    /// Time-optimal profile and blocked intervals.
    pub(crate) fn block(
        &self,
        input: &Profile,
        lim: &AccLim,
        block: &mut Block,
        out: &mut Valid,
    ) -> bool {
        out.reset(input, Keep::All, f64::INFINITY);
        let up = *lim;
        let down = lim.flip();
        if self.af.abs() < EPS {
            // No blocked interval when af == 0: first valid profile is optimal.
            let (fwd, bwd) = if self.vd >= 0.0 {
                (up, down)
            } else {
                (down, up)
            };
            for m in [&fwd, &bwd] {
                self.none(out, m, true);
                if out.n > 0 {
                    break;
                }
                self.acc0(out, m);
                if out.n > 0 {
                    break;
                }
            }
        } else {
            self.none(out, &up, false);
            self.none(out, &down, false);
            self.acc0(out, &up);
            self.acc0(out, &down);
        }
        let n = out.n;
        if n == 0 {
            return false;
        }
        if !block.build(&mut out.list, n) {
            block.build_unpaired(&out.list[..n]);
        }
        self.repair(&up, &down, block, out);
        true
    }

    /// Tails of profiles (a single ramp, or hold then ramp) whose general
    /// solutions sit exactly on a root boundary for states sampled from a
    /// trajectory; see `Step1::repair` of the position interface.
    fn tails(&self, out: &mut Valid, m: &AccLim) {
        let Self { a0, af, vd } = *self;
        let j = m.j;
        let bound = out.bound();
        let p = out.cur();
        p.t = [(af - a0) / j, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        if Valid::admits(p, bound) && p.check_velocity(S::Uddu, L::None, j, m.a_max, m.a_min) {
            out.accept();
        }
        if a0.abs() > EPS {
            let t2 = (a0 - af) / j;
            let p = out.cur();
            p.t = [
                0.0,
                (vd - (a0 * a0 - af * af) / (2.0 * j)) / a0,
                t2,
                0.0,
                0.0,
                0.0,
                0.0,
            ];
            if Valid::admits(p, bound) && p.check_velocity(S::Uddu, L::None, j, m.a_max, m.a_min) {
                out.accept();
            }
        }
    }

    fn repair(&self, up: &AccLim, down: &AccLim, block: &mut Block, extra: &mut Valid) {
        let t_old = block.p_min.t_sum[6];
        extra.restart(
            Keep::Shortest {
                exact: true,
                position: false,
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
        block.merge_shorter(&best);
    }
}

/// Step 2 of the velocity interface: duration `tf` prescribed.
pub(crate) struct VelStep2 {
    tf: f64,
    a0: f64,
    af: f64,
    vd: f64,
    ad: f64,
}

impl VelStep2 {
    pub(crate) fn new(tf: f64, v0: f64, a0: f64, vf: f64, af: f64) -> Self {
        Self {
            tf,
            a0,
            af,
            vd: vf - v0,
            ad: af - a0,
        }
    }

    fn done(p: &mut Profile) -> bool {
        p.pf = p.p[7];
        true
    }

    fn acc0(&self, p: &mut Profile, m: &AccLim) -> bool {
        let Self { tf, a0, af, vd, ad } = *self;
        let j = m.j;

        // Up, hold, down.
        let h1 = ((-ad * ad + 2.0 * j * ((a0 + af) * tf - 2.0 * vd)) / (j * j) + tf * tf).sqrt();
        p.t = [
            ad / (2.0 * j) + (tf - h1) / 2.0,
            h1,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        p.t[2] = tf - (p.t[0] + h1);
        if p.check_velocity(S::Uddu, L::Acc0, j, m.a_max, m.a_min) {
            return Self::done(p);
        }

        // Up, hold, up.
        let h1 = -ad + j * tf;
        p.t = [
            -ad * ad / (2.0 * j * h1) + (vd - a0 * tf) / h1,
            -ad / j + tf,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ];
        p.t[6] = tf - (p.t[0] + p.t[1]);
        if p.check_velocity(S::Uddu, L::Acc0, j, m.a_max, m.a_min) {
            return Self::done(p);
        }

        // Hold, then up.
        p.t = [0.0, -ad / j + tf, 0.0, 0.0, 0.0, 0.0, ad / j];
        if p.check_velocity(S::Uddu, L::Acc0, j, m.a_max, m.a_min) {
            return Self::done(p);
        }
        false
    }

    fn none(&self, p: &mut Profile, m: &AccLim) -> bool {
        let Self { tf, a0, af, vd, ad } = *self;
        let j = m.j;
        if a0.abs() < EPS && af.abs() < EPS && vd.abs() < EPS {
            p.t = [0.0, tf, 0.0, 0.0, 0.0, 0.0, 0.0];
            if p.check_velocity(S::Uddu, L::None, j, m.a_max, m.a_min) {
                return Self::done(p);
            }
        }
        // Reduced jerk, two phases.
        let h1 = 2.0 * (af * tf - vd);
        p.t = [h1 / ad, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        p.t[1] = tf - p.t[0];
        let jf = ad * ad / h1;
        if jf.abs() < j.abs() + 1e-12 && p.check_velocity(S::Uddu, L::None, jf, m.a_max, m.a_min) {
            return Self::done(p);
        }
        false
    }

    /// Fills `p` with a velocity profile of duration `tf`.
    pub(crate) fn profile(&self, p: &mut Profile, lim: &AccLim) -> bool {
        let (m, n) = if self.vd > 0.0 {
            (*lim, lim.flip())
        } else {
            (lim.flip(), *lim)
        };
        self.acc0(p, &m) || self.none(p, &m) || self.acc0(p, &n) || self.none(p, &n)
    }
}
