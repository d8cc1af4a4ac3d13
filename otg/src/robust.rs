//! Fallbacks where the closed forms fail numerically (tiny moves, states on
//! a limit manifold): a bracketing search over the duration with the
//! Step 2 solutions, which are checked against the target and the limits,
//! so whatever is returned is valid and limit-respecting.

use crate::block::Block;
use crate::candidates::Valid;
use crate::input::ControlInterface;
use crate::limits::{DofLimits, MAX_DURATION};
use crate::position_step2::Step2;
use crate::profile::Profile;
use crate::velocity::{VelStep1, VelStep2};

/// Step 2 without fallback.
fn try_step2(iface: ControlInterface, tf: f64, lim: &DofLimits, p: &mut Profile) -> bool {
    let l = lim.lim();
    match iface {
        ControlInterface::Position => {
            Step2::new(tf, p.p[0], p.v[0], p.a[0], p.pf, p.vf, p.af, lim.j_max).profile(p, &l)
        }
        ControlInterface::Velocity => {
            VelStep2::new(tf, p.v[0], p.a[0], p.vf, p.af).profile(p, &lim.acc())
        }
    }
}

/// Step 1 failed: find (nearly) the shortest duration that Step 2 can
/// realise — geometric growth to a feasible duration, then bisection.
pub(crate) fn step1_fallback(
    iface: ControlInterface,
    boundary: &mut Profile,
    lim: &DofLimits,
    block: &mut Block,
) -> bool {
    let mut p = *boundary;
    // Natural time scale of the limits.
    let scale = lim.a_max / lim.j_max + lim.v_max / lim.a_max;
    let mut lo = 0.0;
    let mut hi = scale * 1e-9;
    let mut found = None;
    while hi <= MAX_DURATION {
        if try_step2(iface, hi, lim, &mut p) {
            found = Some(p);
            break;
        }
        lo = hi;
        hi *= 2.0;
    }
    let Some(mut best) = found else {
        return false;
    };
    for _ in 0..200 {
        if hi - lo <= 1e-12 * hi.max(1e-9) {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if try_step2(iface, mid, lim, &mut p) {
            hi = mid;
            best = p;
        } else {
            lo = mid;
        }
    }
    if iface == ControlInterface::Velocity {
        best.pf = best.p[7];
    }
    block.set_min(&best);
    true
}

/// Step 2 failed at `tf`: retry at durations perturbed by a few ulps of
/// relative precision (the result differs from `tf` by at most 1e-10·tf).
pub(crate) fn step2_fallback(
    iface: ControlInterface,
    tf: f64,
    lim: &DofLimits,
    p: &mut Profile,
) -> bool {
    for k in [1e-14, 1e-13, 1e-12, 1e-11, 1e-10] {
        for s in [-1.0, 1.0] {
            if try_step2(iface, tf * (1.0 + s * k), lim, p) {
                return true;
            }
        }
    }
    match iface {
        ControlInterface::Position => cruise_fallback(tf, lim, p),
        ControlInterface::Velocity => hold_fallback(tf, lim, p),
    }
}

/// Step 2 fallback for the velocity interface: "ramp to a velocity `vc`,
/// hold it, ramp to the target" — the hold absorbs any extra duration, so
/// the first `vc` (scanned between and around the boundary velocities)
/// whose ramps fit into `tf` gives a valid profile.
fn hold_fallback(tf: f64, lim: &DofLimits, p: &mut Profile) -> bool {
    let (v0, vf) = (p.v[0], p.vf);
    let span = (v0 - vf).abs() + (p.a[0].abs() + p.af.abs()).powi(2) / lim.j_max + 1e-9;
    let (lo, hi) = (v0.min(vf) - span, v0.max(vf) + span);
    const SAMPLES: usize = 64;
    // Start at the target velocity (no second ramp when af = 0).
    let scan = core::iter::once(vf)
        .chain((0..=SAMPLES).map(|k| lo + (hi - lo) * k as f64 / SAMPLES as f64));
    for vc in scan {
        if let Some((mut q, jf, signs, _)) = cruise_profile(p, vc, tf, lim) {
            let (a_max, a_min) = if jf > 0.0 {
                (lim.a_max, lim.a_min)
            } else {
                (lim.a_min, lim.a_max)
            };
            if q.check_velocity(signs, crate::profile::ReachedLimits::None, jf, a_max, a_min) {
                q.pf = q.p[7];
                *p = q;
                return true;
            }
        }
    }
    false
}

/// Time-optimal velocity ramp from `(v0, a0)` to `(v1, a1)`: phase
/// durations, jerk of the first phase (sign), and the end position offset.
fn ramp(v0: f64, a0: f64, v1: f64, a1: f64, lim: &DofLimits) -> Option<Profile> {
    let mut boundary = Profile::default();
    boundary.v[0] = v0;
    boundary.a[0] = a0;
    boundary.vf = v1;
    boundary.af = a1;
    let acc = lim.acc();
    let mut block = Block::default();
    VelStep1::new(v0, a0, v1, a1)
        .block(&boundary, &acc, &mut block, &mut Valid::new(&boundary))
        .then_some(block.p_min)
}

/// Sign of a ramp's first jerk phase (0 for an empty ramp).
fn first_jerk_sign(r: &Profile) -> f64 {
    let j = if r.t[0] > 0.0 { r.j[0] } else { r.j[2] };
    if j > 0.0 {
        1.0
    } else if j < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Composes "ramp to cruise velocity `vc`, cruise, ramp to the target" of
/// total duration `tf` into `p` (unchecked); `None` if the ramps alone take
/// longer than `tf`.
fn cruise_profile(
    p: &Profile,
    vc: f64,
    tf: f64,
    lim: &DofLimits,
) -> Option<(Profile, f64, S, f64)> {
    let r1 = ramp(p.v[0], p.a[0], vc, 0.0, lim)?;
    let r2 = ramp(vc, 0.0, p.vf, p.af, lim)?;
    let t3 = tf - r1.t_sum[6] - r2.t_sum[6];
    if t3.is_nan()
        || t3 < 0.0
        || r1.t[3..].iter().any(|&t| t != 0.0)
        || r2.t[3..].iter().any(|&t| t != 0.0)
    {
        return None;
    }
    let (s1, s2) = (first_jerk_sign(&r1), first_jerk_sign(&r2));
    let s1 = if s1 == 0.0 {
        if s2 == 0.0 { 1.0 } else { -s2 }
    } else {
        s1
    };
    let signs = if s2 == s1 { S::Udud } else { S::Uddu };
    let mut q = *p;
    q.t = [r1.t[0], r1.t[1], r1.t[2], t3, r2.t[0], r2.t[1], r2.t[2]];
    // Position reached with these phases, to bisect on.
    let (mut x, mut v, mut a) = (q.p[0], q.v[0], q.a[0]);
    let jf = s1 * lim.j_max;
    let j4 = if signs == S::Uddu { -jf } else { jf };
    let jerks = [jf, 0.0, -jf, 0.0, j4, 0.0, -j4];
    for (k, (t, j)) in q.t.iter().zip(jerks).enumerate() {
        (x, v, a) = crate::motion::integrate(*t, x, v, a, j);
        if k == 2 {
            // The cruise is at zero acceleration exactly (as the check
            // pins it): 1e-14 over an hour of cruise is 1e-7 of position.
            a = 0.0;
        }
    }
    Some((q, jf, signs, x - q.pf))
}

use crate::profile::ControlSigns as S;

/// Step 2 fallback for the position interface: bisection on the cruise
/// velocity of a "ramp, cruise, ramp" profile of duration `tf`.
fn cruise_fallback(tf: f64, lim: &DofLimits, p: &mut Profile) -> bool {
    let residual = |vc: f64| cruise_profile(p, vc, tf, lim).map(|(_, _, _, r)| r);
    const SAMPLES: usize = 64;
    let mut prev: Option<(f64, f64)> = None;
    for k in 0..=SAMPLES {
        let vc = lim.v_min + (lim.v_max - lim.v_min) * k as f64 / SAMPLES as f64;
        let Some(r) = residual(vc) else {
            prev = None;
            continue;
        };
        if let Some((v_prev, r_prev)) = prev
            && r_prev * r <= 0.0
        {
            let (mut lo, mut hi, mut r_lo) = (v_prev, vc, r_prev);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                let Some(r_mid) = residual(mid) else { break };
                if r_mid * r_lo <= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                    r_lo = r_mid;
                }
                if hi - lo <= 1e-15 * hi.abs().max(1.0) {
                    break;
                }
            }
            for vc in [lo, hi] {
                if let Some((mut q, jf, signs, _)) = cruise_profile(p, vc, tf, lim) {
                    let (v_max, v_min, a_max, a_min) = if jf > 0.0 {
                        (lim.v_max, lim.v_min, lim.a_max, lim.a_min)
                    } else {
                        (lim.v_min, lim.v_max, lim.a_min, lim.a_max)
                    };
                    if q.check(
                        signs,
                        crate::profile::ReachedLimits::Vel,
                        false,
                        jf,
                        v_max,
                        v_min,
                        a_max,
                        a_min,
                    ) {
                        *p = q;
                        return true;
                    }
                }
            }
        }
        prev = Some((vc, r));
    }
    false
}
