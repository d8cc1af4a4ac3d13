//! Fallbacks where the closed forms fail numerically (tiny moves, states on
//! a limit manifold): a bracketing search over the duration with the
//! Step 2 solutions, which are checked against the target and the limits,
//! so whatever is returned is valid and limit-respecting.

use crate::block::Block;
use crate::calculator::{DofLimits, MAX_DURATION};
use crate::input::ControlInterface;
use crate::position_step2::Step2;
use crate::profile::Profile;
use crate::velocity::VelStep2;

/// Step 2 without fallback.
fn try_step2(iface: ControlInterface, tf: f64, lim: &DofLimits, p: &mut Profile) -> bool {
    let l = crate::position_step1::Lim {
        v_max: lim.v_max,
        v_min: lim.v_min,
        a_max: lim.a_max,
        a_min: lim.a_min,
        j: lim.j_max,
    };
    match iface {
        ControlInterface::Position => {
            Step2::new(tf, p.p[0], p.v[0], p.a[0], p.pf, p.vf, p.af, lim.j_max).profile(p, &l)
        }
        ControlInterface::Velocity => {
            let acc = crate::velocity::AccLim {
                a_max: lim.a_max,
                a_min: lim.a_min,
                j: lim.j_max,
            };
            VelStep2::new(tf, p.v[0], p.a[0], p.vf, p.af).profile(p, &acc)
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
    false
}
