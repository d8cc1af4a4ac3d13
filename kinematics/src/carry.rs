//! A grasp of chain fingers carried by the object's rotation (SPEC §14.2):
//! the chain hand's counterpart of a free fingertip carried rigidly.
//!
//! The object (a sphere, centre O fixed) turns about a unit axis $k$ at unit
//! rate, $\omega_o = k$; each grasping finger's joints follow the rolling
//! law, $\dot q = J_v^{-1}\dot c$ with $\dot c$ from
//! [`crate::rolling_rates`], the contact normal read from the finger's own
//! state, $n = (c(q) - O)/|c(q) - O|$. [`carry`] integrates it (RK4 in the
//! turned angle); [`carry_range`] finds how far the grasp can go before a
//! finger leaves what SPEC §14.1 admits ([`GraspLimits`]): a joint limit
//! (with the chain's margin), the tip patch, link clearance to the object,
//! or the gap between two grasping fingers.
//!
//! A soft contact that spins is twisting (§14.2), and a two-finger grasp
//! holds only through torsion, so a pair must not spin. The spin at each
//! contact is linear in $\omega_o$ ([`spin_row`]: $s = \sigma\cdot\omega_o$),
//! so two contacts leave one direction, $\sigma_1\times\sigma_2$
//! ([`no_spin_axis`]), about which a pair can turn — an axis that moves
//! with the grasp. [`carry_pair`] follows it. Three fingers may spin (hard
//! contacts, §1.2) and turn about any axis.
//!
//! [`Carrier`] is the same law advanced tick by tick, for a loop: the
//! joints at the angle turned so far, moved on by RK4 sub-steps no longer
//! than a set step (one per tick at any speed a hand turns a ball).
//!
//! Allocation-free: fingers are passed as slices of at most three.

use nalgebra::Vector3;

use crate::chain::{Chain, ChainState};
use crate::description::Object;
use crate::rolling::rolling_rates;
use crate::workspace::{FingerGap, Margins, object_clearance};

/// Grasping fingers of one grasp: each finger's chain and joints.
pub type Fingers<'a> = &'a [&'a Chain<3>];

/// The object's outward unit normal at finger `chain`'s contact, from its
/// state: $n = (c(q) - O)/|c(q) - O|$.
pub fn contact_normal(s: &ChainState<3>, object: &Object) -> Vector3<f64> {
    (s.tip_centre() - object.centre).normalize()
}

/// Why a carry stopped, and which finger (or pair) stopped it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bound {
    /// It went as far as asked.
    Reached,
    /// A joint reached its limit (less the chain's margin).
    JointLimit {
        /// The finger (index into the grasp's slices).
        finger: usize,
    },
    /// The contact reached the edge of the tip patch (less its margin).
    TipPatch {
        /// The finger.
        finger: usize,
    },
    /// A link came closer to the object than the clearance.
    ObjectClearance {
        /// The finger.
        finger: usize,
    },
    /// Two grasping fingers came closer than the gap asked.
    FingerGap {
        /// The first of the two.
        a: usize,
        /// The second.
        b: usize,
    },
    /// $J_v$ or the rolling law's matrix is singular: the chain cannot
    /// follow.
    Singular {
        /// The finger.
        finger: usize,
    },
    /// A pair's two spin rows are parallel: no axis turns it without spin.
    NoSpinFree,
}

/// What a carried grasp must keep (SPEC §14.1): the margins of the
/// workspace test, and the smallest gap between two grasping fingers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspLimits {
    /// Tip patch and object clearance.
    pub margins: Margins,
    /// Smallest gap between the parts of two grasping fingers \[m\].
    pub finger_gap: f64,
}

/// The first limit the fingers at `q` break, if any (joint limits, tip
/// patch, clearance, then the gaps between pairs; `gaps[i]` compares
/// fingers of pair `i` in the order (0, 1), (0, 2), (1, 2)).
pub fn violation(
    fingers: Fingers<'_>,
    q: &[Vector3<f64>],
    object: &Object,
    gaps: &[FingerGap],
    limits: &GraspLimits,
) -> Option<Bound> {
    let mut states = [None; 3];
    for (k, (chain, q)) in fingers.iter().zip(q).enumerate() {
        if chain.limit_margin(q) < 0.0 {
            return Some(Bound::JointLimit { finger: k });
        }
        let s = chain.forward(q);
        let n = contact_normal(&s, object);
        if chain.patch.margin(&s.tip.rotation, &n) < limits.margins.patch {
            return Some(Bound::TipPatch { finger: k });
        }
        if object_clearance(chain, &s, object) < limits.margins.clearance {
            return Some(Bound::ObjectClearance { finger: k });
        }
        states[k] = Some(s);
    }
    let mut pair = 0;
    for a in 0..fingers.len() {
        for b in a + 1..fingers.len() {
            if let (Some(sa), Some(sb), Some(g)) = (&states[a], &states[b], gaps.get(pair))
                && g.gap((fingers[a], sa), (fingers[b], sb)) < limits.finger_gap
            {
                return Some(Bound::FingerGap { a, b });
            }
            pair += 1;
        }
    }
    None
}

/// The [`FingerGap`]s of a grasp's pairs (one or more fingers), in the
/// order [`violation`] reads them; entries past the grasp's pairs are
/// unused.
pub fn finger_gaps(fingers: Fingers<'_>) -> [FingerGap; 3] {
    let last = fingers.len().saturating_sub(1);
    let pair = |a: usize, b: usize| FingerGap::new(fingers[a.min(last)], fingers[b.min(last)]);
    [pair(0, 1), pair(0, 2), pair(1, 2)]
}

/// The object's angular velocity at a stage of a step, from the fingers'
/// joints there (a fixed axis, or the pair's no-spin axis).
type AngularVelocity<'a> = dyn FnMut(&[Vector3<f64>]) -> Result<Vector3<f64>, Bound> + 'a;

/// Joint rates of every finger at `q` for the object's angular velocity
/// `omega` (the rolling law), written to `out`.
fn rates(
    fingers: Fingers<'_>,
    q: &[Vector3<f64>],
    object: &Object,
    omega: &Vector3<f64>,
    out: &mut [Vector3<f64>; 3],
) -> Result<(), Bound> {
    for (k, (chain, q)) in fingers.iter().zip(q).enumerate() {
        let s = chain.forward(q);
        let n = contact_normal(&s, object);
        out[k] = rolling_rates(&s, omega, &n, object.radius, chain.tip_radius)
            .ok_or(Bound::Singular { finger: k })?
            .q_dot;
    }
    Ok(())
}

/// One RK4 step of `h` \[rad\] with the object's angular velocity given by
/// `omega` at each stage's joints.
fn rk4_step(
    fingers: Fingers<'_>,
    q: &mut [Vector3<f64>],
    object: &Object,
    h: f64,
    omega: &mut AngularVelocity<'_>,
) -> Result<(), Bound> {
    let m = fingers.len();
    let mut k = [[Vector3::zeros(); 3]; 4];
    let mut stage = [Vector3::zeros(); 3];
    for i in 0..4 {
        let scale = [0.0, 0.5, 0.5, 1.0][i] * h;
        for f in 0..m {
            stage[f] = if i == 0 {
                q[f]
            } else {
                q[f] + k[i - 1][f] * scale
            };
        }
        let w = omega(&stage[..m])?;
        rates(fingers, &stage[..m], object, &w, &mut k[i])?;
    }
    for f in 0..m {
        q[f] += (k[0][f] + 2.0 * k[1][f] + 2.0 * k[2][f] + k[3][f]) * (h / 6.0);
    }
    Ok(())
}

/// Steps no longer than `step` covering `angle`: (count, length).
fn steps(angle: f64, step: f64) -> (usize, f64) {
    let n = (angle / step).ceil().max(1.0) as usize;
    (n, angle / n as f64)
}

/// Turns the object about the unit `axis` by `angle` ≥ 0 with the fingers
/// at `q` following (RK4, steps of at most `step` \[rad\]); `q` ends at the
/// fingers' joints after the turn. Only the law's own failure (a singular
/// finger) stops it: limits are [`carry_range`]'s business.
pub fn carry(
    fingers: Fingers<'_>,
    q: &mut [Vector3<f64>],
    object: &Object,
    axis: &Vector3<f64>,
    angle: f64,
    step: f64,
) -> Result<(), Bound> {
    let (n, h) = steps(angle, step);
    for _ in 0..n {
        rk4_step(fingers, q, object, h, &mut |_| Ok(*axis))?;
    }
    Ok(())
}

/// How far a carry got, and what stopped it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// The angle turned within the limits \[rad\].
    pub angle: f64,
    /// What stopped it ([`Bound::Reached`] if nothing did before `limit`).
    pub bound: Bound,
}

/// Bisections of the first failing step in [`carry_range`]: the range is
/// found to `step / 2^BISECTIONS`.
const BISECTIONS: u32 = 12;

/// How a range is scanned: steps of at most `step` \[rad\], then
/// `bisections` halvings of the first failing step (the range is found
/// to `step / 2^bisections`, never beyond the last good angle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scan {
    /// Longest step \[rad\].
    pub step: f64,
    /// Halvings of the first failing step.
    pub bisections: u32,
}

/// How far (≤ `limit`) the grasp of `fingers` at `q` can be carried about
/// the unit `axis` (three fingers; a pair turned about a fixed axis spins, see
/// [`carry_pair`])
/// keeping `limits`: scanned in steps of at most `step` \[rad\], the first
/// failing step bisected. 0 if the start breaks a limit.
pub fn carry_range(
    fingers: Fingers<'_>,
    q: &[Vector3<f64>],
    object: &Object,
    axis: &Vector3<f64>,
    limit: f64,
    limits: &GraspLimits,
    step: f64,
) -> Range {
    let fine = Scan {
        step,
        bisections: BISECTIONS,
    };
    carry_range_with(fingers, q, object, axis, limit, limits, fine)
}

/// [`carry_range`] scanned as `scan_by` says (a coarser bisection where
/// the range only ranks choices).
pub fn carry_range_with(
    fingers: Fingers<'_>,
    q: &[Vector3<f64>],
    object: &Object,
    axis: &Vector3<f64>,
    limit: f64,
    limits: &GraspLimits,
    scan_by: Scan,
) -> Range {
    scan(fingers, q, object, limit, limits, scan_by, &mut |_| {
        Ok(*axis)
    })
}

/// The spin row σ of `chain` at `s` touching at `n`: the relative spin at
/// the contact is $s = \sigma\cdot\omega_o$ (§14.2's sign), linear in the
/// object's angular velocity through the rolling law.
pub fn spin_row(chain: &Chain<3>, s: &ChainState<3>, object: &Object) -> Option<Vector3<f64>> {
    let n = contact_normal(s, object);
    let mut row = Vector3::zeros();
    for i in 0..3 {
        let e = Vector3::ith(i, 1.0);
        row[i] = rolling_rates(s, &e, &n, object.radius, chain.tip_radius)?.spin;
    }
    Some(row)
}

/// The unit axis about which the pair at `q` turns with no spin at either
/// contact ($\sigma_1\times\sigma_2$), the sign chosen along `hint`
/// (positive dot product; any sign if perpendicular).
pub fn no_spin_axis(
    pair: [&Chain<3>; 2],
    q: &[Vector3<f64>],
    object: &Object,
    hint: &Vector3<f64>,
) -> Result<Vector3<f64>, Bound> {
    let mut rows = [Vector3::zeros(); 2];
    for k in 0..2 {
        let s = pair[k].forward(&q[k]);
        rows[k] = spin_row(pair[k], &s, object).ok_or(Bound::Singular { finger: k })?;
    }
    let a = rows[0].cross(&rows[1]);
    let norm = a.norm();
    // Parallel rows leave a plane (or nothing) and no one direction.
    if norm <= 1e-12 * rows[0].norm() * rows[1].norm() {
        return Err(Bound::NoSpinFree);
    }
    let a = a / norm;
    Ok(if a.dot(hint) < 0.0 { -a } else { a })
}

/// Turns the object by `angle` with the pair at `q`, about the axis that
/// keeps both contacts from spinning, followed as it moves (its sign kept
/// continuous, starting along `hint`); returns the last axis.
pub fn carry_pair(
    pair: [&Chain<3>; 2],
    q: &mut [Vector3<f64>],
    object: &Object,
    hint: &Vector3<f64>,
    angle: f64,
    step: f64,
) -> Result<Vector3<f64>, Bound> {
    let (n, h) = steps(angle, step);
    let mut last = *hint;
    for _ in 0..n {
        let mut along = last;
        rk4_step(&pair, q, object, h, &mut |stage| {
            let a = no_spin_axis(pair, stage, object, &along)?;
            along = a;
            Ok(a)
        })?;
        last = no_spin_axis(pair, q, object, &last)?;
    }
    Ok(last)
}

/// The scan behind [`carry_range`]: steps while every limit holds, then
/// bisects the first failing step from its last good start.
fn scan(
    fingers: Fingers<'_>,
    q0: &[Vector3<f64>],
    object: &Object,
    limit: f64,
    limits: &GraspLimits,
    Scan { step, bisections }: Scan,
    omega: &mut AngularVelocity<'_>,
) -> Range {
    let m = fingers.len();
    if m == 0 {
        return Range {
            angle: limit,
            bound: Bound::Reached,
        };
    }
    let gaps = finger_gaps(fingers);
    let gaps = &gaps[..m * (m - 1) / 2];
    let mut q = [Vector3::zeros(); 3];
    q[..m].copy_from_slice(&q0[..m]);
    if let Some(b) = violation(fingers, &q[..m], object, gaps, limits) {
        return Range {
            angle: 0.0,
            bound: b,
        };
    }
    let (n, h) = steps(limit, step);
    let mut done = 0.0;
    for _ in 0..n {
        let mut next = q;
        let fail = match rk4_step(fingers, &mut next[..m], object, h, omega) {
            Err(b) => Some(b),
            Ok(()) => violation(fingers, &next[..m], object, gaps, limits),
        };
        let Some(mut bound) = fail else {
            q = next;
            done += h;
            continue;
        };
        // Bisect within the step: [lo, hi) from the last good joints.
        let (mut lo, mut hi) = (0.0, h);
        for _ in 0..bisections {
            let mid = 0.5 * (lo + hi);
            let mut trial = q;
            let fail = match rk4_step(fingers, &mut trial[..m], object, mid, omega) {
                Err(b) => Some(b),
                Ok(()) => violation(fingers, &trial[..m], object, gaps, limits),
            };
            match fail {
                Some(b) => {
                    hi = mid;
                    bound = b;
                }
                None => lo = mid,
            }
        }
        return Range {
            angle: done + lo,
            bound,
        };
    }
    Range {
        angle: limit,
        bound: Bound::Reached,
    }
}

/// Most sub-steps one [`Carrier::advance_to`] takes: the work a call may
/// do is bounded; a longer jump is refused.
pub const MAX_SUBSTEPS: usize = 64;

/// A carry advanced tick by tick (module docs): the grasp's joints at the
/// angle turned so far about a fixed axis.
#[derive(Debug, Clone, Copy)]
pub struct Carrier<'a> {
    fingers: [&'a Chain<3>; 3],
    len: usize,
    q: [Vector3<f64>; 3],
    object: Object,
    axis: Vector3<f64>,
    angle: f64,
    step: f64,
}

/// Why a [`Carrier`] did not move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CarrierError {
    /// The law failed (a singular finger).
    Law(Bound),
    /// The jump needs more than [`MAX_SUBSTEPS`] sub-steps.
    TooFar,
}

impl<'a> Carrier<'a> {
    /// A carry about the unit `axis` of the grasp `fingers` (one to three;
    /// extra ones are ignored) at joints `q`, from angle 0, in sub-steps of
    /// at most `step` \[rad\]. Panics without a finger (a caller's
    /// mistake: a grasp has two or three).
    pub fn new(
        fingers: &[&'a Chain<3>],
        q: &[Vector3<f64>],
        object: &Object,
        axis: &Vector3<f64>,
        step: f64,
    ) -> Self {
        let len = fingers.len().min(3).min(q.len());
        let mut f = [fingers[0]; 3];
        let mut qs = [Vector3::zeros(); 3];
        f[..len].copy_from_slice(&fingers[..len]);
        qs[..len].copy_from_slice(&q[..len]);
        Self {
            fingers: f,
            len,
            q: qs,
            object: *object,
            axis: *axis,
            angle: 0.0,
            step,
        }
    }

    /// The angle turned so far \[rad\].
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// The joints at [`Carrier::angle`].
    pub fn joints(&self) -> &[Vector3<f64>] {
        &self.q[..self.len]
    }

    /// Moves on (or back) to the turned angle `angle`; returns the joints.
    /// On an error nothing moved.
    pub fn advance_to(&mut self, angle: f64) -> Result<&[Vector3<f64>], CarrierError> {
        let delta = angle - self.angle;
        let n = (delta.abs() / self.step).ceil() as usize;
        if n > MAX_SUBSTEPS {
            return Err(CarrierError::TooFar);
        }
        let mut q = self.q;
        let axis = self.axis;
        let fingers = &self.fingers[..self.len];
        for _ in 0..n {
            rk4_step(
                fingers,
                &mut q[..self.len],
                &self.object,
                delta / n as f64,
                &mut |_| Ok(axis),
            )
            .map_err(CarrierError::Law)?;
        }
        self.q = q;
        self.angle = angle;
        Ok(&self.q[..self.len])
    }

    /// The joint rates at [`Carrier::angle`] when the object turns at
    /// `rate` \[rad/s\] about the axis.
    pub fn rates(&self, rate: f64) -> Result<[Vector3<f64>; 3], Bound> {
        let mut out = [Vector3::zeros(); 3];
        rates(
            &self.fingers[..self.len],
            &self.q[..self.len],
            &self.object,
            &(self.axis * rate),
            &mut out,
        )?;
        Ok(out)
    }
}
