//! State-to-state calculation for `N` DoFs: per-DoF brake and Step 1, then
//! time synchronisation (earliest duration feasible for all DoFs), phase
//! synchronisation for collinear inputs, and Step 2 for the others
//! (SPEC.md §5; Berscheid & Kröger 2021, §IV).

use crate::block::Block;
use crate::candidates::Valid;
use crate::error::OtgError;
use crate::input::{ControlInterface, DurationDiscretization, Input, Synchronization};
use crate::limits::{DofLimits, MAX_DURATION, close_tol};
use crate::position_step1::Step1;
use crate::position_step2::Step2;
use crate::profile::{Direction, Profile, ReachedLimits};
use crate::robust;
use crate::trajectory::Trajectory;
use crate::velocity::{VelStep1, VelStep2};

/// One DoF's boundary values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct DofCase {
    pub p0: f64,
    pub v0: f64,
    pub a0: f64,
    pub pf: f64,
    pub vf: f64,
    pub af: f64,
}

/// Brake plus Step 1 for one DoF: fills `profile` with the boundary (after
/// the brake) and `block` with the feasible durations.
pub(crate) fn step1_dof(
    iface: ControlInterface,
    c: &DofCase,
    lim: &DofLimits,
    profile: &mut Profile,
    block: &mut Block,
    scratch: &mut Valid,
) -> bool {
    *profile = Profile::default();
    match iface {
        ControlInterface::Position => {
            profile.brake.position(
                c.v0, c.a0, lim.v_max, lim.v_min, lim.a_max, lim.a_min, lim.j_max,
            );
            profile.pf = c.pf;
        }
        ControlInterface::Velocity => {
            profile
                .brake
                .velocity_interface(c.a0, lim.a_max, lim.a_min, lim.j_max);
        }
    }
    profile.vf = c.vf;
    profile.af = c.af;
    let (mut p, mut v, mut a) = (c.p0, c.v0, c.a0);
    profile.brake.finalize(&mut p, &mut v, &mut a);
    profile.p[0] = p;
    profile.v[0] = v;
    profile.a[0] = a;

    let found = match iface {
        ControlInterface::Position => Step1::new(p, v, a, c.pf, c.vf, c.af, lim.j_max).block(
            profile,
            &lim.lim(),
            block,
            scratch,
        ),
        ControlInterface::Velocity => {
            VelStep1::new(v, a, c.vf, c.af).block(profile, &lim.acc(), block, scratch)
        }
    };
    found || robust::step1_fallback(iface, profile, lim, block)
}

/// Step 2 for one DoF: a profile of total duration `duration` (brake
/// included) on the boundary stored in `p`.
pub(crate) fn step2_dof(
    iface: ControlInterface,
    duration: f64,
    lim: &DofLimits,
    p: &mut Profile,
) -> bool {
    let tf = duration - p.brake.duration;
    let found = match iface {
        ControlInterface::Position => {
            Step2::new(tf, p.p[0], p.v[0], p.a[0], p.pf, p.vf, p.af, lim.j_max)
                .profile(p, &lim.lim())
        }
        ControlInterface::Velocity => {
            VelStep2::new(tf, p.v[0], p.a[0], p.vf, p.af).profile(p, &lim.acc())
        }
    };
    found || robust::step2_fallback(iface, tf, lim, p)
}

/// Rounds `t` up to a multiple of `dt`; a `t` within rounding error of a
/// multiple snaps to it (`fmod` alone would add a whole cycle when
/// `t / dt` comes out as `k - 1e-15`).
#[inline]
fn round_up(t: f64, dt: f64) -> f64 {
    let q = t / dt;
    let k = q.round();
    if (q - k).abs() <= 1e-9 * k.max(1.0) {
        k * dt
    } else {
        q.ceil() * dt
    }
}

/// Reusable working memory of the calculation (no allocation).
#[derive(Clone, Copy, Debug)]
pub struct Calculator<const N: usize> {
    blocks: [Block; N],
    phase_jerk: [f64; N],
    scratch: Valid,
}

impl<const N: usize> Default for Calculator<N> {
    fn default() -> Self {
        Self {
            blocks: [Block::default(); N],
            phase_jerk: [0.0; N],
            scratch: Valid::new(&Profile::default()),
        }
    }
}

impl<const N: usize> Calculator<N> {
    fn limits(inp: &Input<N>, i: usize) -> DofLimits {
        DofLimits {
            v_max: inp.max_velocity[i],
            v_min: inp.v_min(i),
            a_max: inp.max_acceleration[i],
            a_min: inp.a_min(i),
            j_max: inp.max_jerk[i],
        }
    }

    /// Calculates the trajectory for a validated input.
    pub fn calculate(
        &mut self,
        inp: &Input<N>,
        traj: &mut Trajectory<N>,
        delta_time: f64,
    ) -> Result<(), OtgError> {
        let iface = inp.control_interface;
        traj.limiting_dof = None;
        for i in 0..N {
            let p = &mut traj.profiles[i];
            let b = &mut self.blocks[i];
            if !inp.enabled[i] {
                *p = Profile::default();
                p.p[7] = inp.current_position[i];
                p.v[7] = inp.current_velocity[i];
                p.a[7] = inp.current_acceleration[i];
                *b = Block::default();
                traj.independent_min_durations[i] = 0.0;
                continue;
            }
            let case = DofCase {
                p0: inp.current_position[i],
                v0: inp.current_velocity[i],
                a0: inp.current_acceleration[i],
                pf: inp.target_position[i],
                vf: inp.target_velocity[i],
                af: inp.target_acceleration[i],
            };
            if !step1_dof(iface, &case, &Self::limits(inp, i), p, b, &mut self.scratch) {
                return Err(OtgError::ExecutionTimeCalculation { dof: i as u16 });
            }
            traj.independent_min_durations[i] = b.t_min;
        }

        let discrete = inp.duration_discretization == DurationDiscretization::Discrete;
        if N == 1 && inp.minimum_duration.is_none() && !discrete {
            traj.duration = self.blocks[0].t_min;
            traj.profiles[0] = self.blocks[0].p_min;
            traj.limiting_dof = Some(0);
            return Ok(());
        }

        if inp.synchronization == Synchronization::None {
            // Independent DoFs: each runs its own time-optimal profile.
            let mut t = inp.minimum_duration.unwrap_or(0.0);
            for i in 0..N {
                if inp.enabled[i] {
                    traj.profiles[i] = self.blocks[i].p_min;
                    if self.blocks[i].t_min >= t {
                        t = self.blocks[i].t_min;
                        traj.limiting_dof = Some(i);
                    }
                }
            }
            traj.duration = t;
            return if t > MAX_DURATION {
                Err(OtgError::TrajectoryDuration)
            } else {
                Ok(())
            };
        }

        // If Step 2 fails for some DoF at the chosen duration (its blocked
        // intervals were numerically wrong), try the next candidate.
        let mut after = None;
        let mut failed = 0;
        for _ in 0..=3 * N {
            let Some((t_sync, limiting)) =
                self.synchronize(inp.minimum_duration, discrete, delta_time, after)
            else {
                break;
            };
            traj.duration = t_sync;
            traj.limiting_dof = None;
            if let Some((i, which)) = limiting {
                traj.limiting_dof = Some(i);
                let b = &self.blocks[i];
                traj.profiles[i] = match which {
                    1 => b.a.as_ref().map_or(b.p_min, |x| x.profile),
                    2 => b.b.as_ref().map_or(b.p_min, |x| x.profile),
                    _ => b.p_min,
                };
            }
            if traj.duration > MAX_DURATION {
                return Err(OtgError::TrajectoryDuration);
            }
            if traj.duration == 0.0 {
                for i in 0..N {
                    if inp.enabled[i] {
                        traj.profiles[i] = self.blocks[i].p_min;
                    }
                }
                return Ok(());
            }
            if inp.synchronization == Synchronization::Phase
                && let Some(lim_dof) = traj.limiting_dof
                && self.phase_synchronize(inp, traj, lim_dof)
            {
                return Ok(());
            }
            match self.time_synchronize(inp, traj, discrete) {
                Ok(()) => return Ok(()),
                Err(i) => {
                    failed = i;
                    after = Some(t_sync);
                }
            }
        }
        Err(OtgError::SynchronizationCalculation { dof: failed as u16 })
    }

    /// Step 2 for every DoF but the limiting one; `Err(dof)` on failure.
    fn time_synchronize(
        &self,
        inp: &Input<N>,
        traj: &mut Trajectory<N>,
        discrete: bool,
    ) -> Result<(), usize> {
        let limiting_dof = traj.limiting_dof;
        for i in 0..N {
            if !inp.enabled[i] || (Some(i) == limiting_dof && !discrete) {
                continue;
            }
            let b = &self.blocks[i];
            let p = &mut traj.profiles[i];
            // An extremal profile of Step 1 may already have the duration.
            let close = |t: f64| (traj.duration - t).abs() <= close_tol(t);
            if close(b.t_min) {
                *p = b.p_min;
                continue;
            }
            if let Some(x) = b.a.as_ref().filter(|x| close(x.right)) {
                *p = x.profile;
                continue;
            }
            if let Some(x) = b.b.as_ref().filter(|x| close(x.right)) {
                *p = x.profile;
                continue;
            }
            if !step2_dof(
                inp.control_interface,
                traj.duration,
                &Self::limits(inp, i),
                p,
            ) {
                return Err(i);
            }
        }
        Ok(())
    }

    /// The earliest duration feasible for every DoF, not below the minimum
    /// duration; with the DoF and extremal profile (0 = optimal, 1/2 =
    /// right end of a blocked interval) that defines it.
    fn synchronize(
        &self,
        minimum: Option<f64>,
        discrete: bool,
        dt: f64,
        after: Option<f64>,
    ) -> Option<(f64, Option<(usize, u8)>)> {
        let value = |k: usize| -> f64 {
            let raw = if k == 3 * N {
                minimum.unwrap_or(f64::INFINITY)
            } else {
                let b = &self.blocks[k % N];
                match k / N {
                    0 => b.t_min,
                    1 => b.a.as_ref().map_or(f64::INFINITY, |x| x.right),
                    _ => b.b.as_ref().map_or(f64::INFINITY, |x| x.right),
                }
            };
            if discrete && raw.is_finite() {
                round_up(raw, dt)
            } else {
                raw
            }
        };
        let floor = minimum.unwrap_or(0.0);
        // Durations below the largest t_min are blocked by that DoF.
        let mut lower = (0..N).map(value).fold(f64::NEG_INFINITY, f64::max);
        let mut inclusive = true;
        if let Some(a) = after
            && a >= lower
        {
            // Retry strictly after a duration where Step 2 failed.
            lower = a;
            inclusive = false;
        }
        loop {
            let mut best: Option<(f64, usize)> = None;
            for k in 0..=3 * N {
                let c = value(k);
                let above = if inclusive { c >= lower } else { c > lower };
                if above && c.is_finite() && best.is_none_or(|(b, _)| c < b) {
                    best = Some((c, k));
                }
            }
            let (c, k) = best?;
            lower = c;
            inclusive = false;
            if c < floor || self.blocks.iter().any(|b| b.is_blocked(c)) {
                continue;
            }
            let limiting = (k < 3 * N).then(|| (k % N, (k / N) as u8));
            return Some((c, limiting));
        }
    }

    /// Phase synchronisation: for collinear inputs every DoF takes the
    /// limiting DoF's phase durations with a proportionally scaled jerk, so
    /// the motion is a straight line. `false` if not applicable.
    fn phase_synchronize(
        &mut self,
        inp: &Input<N>,
        traj: &mut Trajectory<N>,
        lim_dof: usize,
    ) -> bool {
        let p_lim = traj.profiles[lim_dof];
        if !self.collinear(inp, p_lim.direction, lim_dof) {
            return false;
        }
        let mut ok = true;
        for i in 0..N {
            if !inp.enabled[i] || i == lim_dof {
                continue;
            }
            let l = Self::limits(inp, i);
            let p = &mut traj.profiles[i];
            p.t = p_lim.t;
            let jf = self.phase_jerk[i];
            ok &= match inp.control_interface {
                ControlInterface::Position => p.check_jerk(
                    p_lim.signs,
                    ReachedLimits::None,
                    jf,
                    l.v_max,
                    l.v_min,
                    l.a_max,
                    l.a_min,
                    l.j_max,
                ),
                ControlInterface::Velocity => p.check_velocity_jerk(
                    p_lim.signs,
                    ReachedLimits::None,
                    jf,
                    l.a_max,
                    l.a_min,
                    l.j_max,
                ),
            };
            p.limits = p_lim.limits;
            p.signs = p_lim.signs;
            if inp.control_interface == ControlInterface::Velocity {
                p.pf = p.p[7];
            }
        }
        ok
    }

    /// Whether the boundary vectors (Δp, v0, a0, vf, af) are collinear;
    /// fills the scaled jerks of the phase-synchronised DoFs.
    fn collinear(&mut self, inp: &Input<N>, dir: Direction, lim_dof: usize) -> bool {
        const EPS: f64 = f64::EPSILON;
        let position = inp.control_interface == ControlInterface::Position;
        let pd = |i: usize| inp.target_position[i] - inp.current_position[i];
        // Pick a reference vector with a non-zero component.
        let mut reference = None;
        for i in 0..N {
            if !inp.enabled[i] {
                continue;
            }
            let found = if position && pd(i).abs() > EPS {
                Some(0)
            } else if inp.current_velocity[i].abs() > EPS {
                Some(1)
            } else if inp.current_acceleration[i].abs() > EPS {
                Some(2)
            } else if inp.target_velocity[i].abs() > EPS {
                Some(3)
            } else if inp.target_acceleration[i].abs() > EPS {
                Some(4)
            } else {
                None
            };
            if let Some(kind) = found {
                reference = Some((i, kind));
                break;
            }
        }
        let Some((r, kind)) = reference else {
            return false;
        };
        let vec = |i: usize| match kind {
            0 => pd(i),
            1 => inp.current_velocity[i],
            2 => inp.current_acceleration[i],
            3 => inp.target_velocity[i],
            _ => inp.target_acceleration[i],
        };
        let scale = vec(r);
        let ratios = [
            pd(r) / scale,
            inp.current_velocity[r] / scale,
            inp.current_acceleration[r] / scale,
            inp.target_velocity[r] / scale,
            inp.target_acceleration[r] / scale,
        ];
        let scale_lim = vec(lim_dof);
        let jerk_lim = match dir {
            Direction::Up => inp.max_jerk[lim_dof],
            Direction::Down => -inp.max_jerk[lim_dof],
        };
        for i in 0..N {
            if !inp.enabled[i] {
                continue;
            }
            let s = vec(i);
            let off = |x: f64, ratio: f64| (x - ratio * s).abs() > EPS;
            if (position && off(pd(i), ratios[0]))
                || off(inp.current_velocity[i], ratios[1])
                || off(inp.current_acceleration[i], ratios[2])
                || off(inp.target_velocity[i], ratios[3])
                || off(inp.target_acceleration[i], ratios[4])
            {
                return false;
            }
            self.phase_jerk[i] = jerk_lim * s / scale_lim;
        }
        true
    }
}
